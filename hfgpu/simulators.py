"""Which module runs each physics set, and the check that a scene asks for one of them (``hfgpu check`` and
``hfgpu run`` both apply it before any work)."""

from __future__ import annotations

from typing import Any

from .errors import HfgpuError

#: The module whose ``simulate(scene, sink, progress=None, checkpoint=None, resume=None) -> dict`` runs each
#: physics set.
SIMULATORS = {("fracture",): "hfgpu.fracture.simulator", ("proppant",): "hfgpu.proppant.simulator",
              ("fracture", "proppant"): "hfgpu.coupled"}


#: The modules that run a scene with ``[completion]`` (a stage of N planes, N >= 1), per physics set.
STAGE_SIMULATORS = {("fracture",): "hfgpu.fracture.stage", ("fracture", "proppant"): "hfgpu.coupled_stage"}


def simulator_module(scene: Any) -> str:
    """The module of :data:`SIMULATORS` that runs ``scene``; of :data:`STAGE_SIMULATORS` with ``[completion]``."""
    if getattr(scene, "completion", None) is not None:
        return STAGE_SIMULATORS[tuple(scene.run.physics)]
    return SIMULATORS[tuple(scene.run.physics)]


class NotSupportedError(HfgpuError, NotImplementedError):
    """The scene asks for something this version does not run yet."""


def check_supported(scene: Any) -> None:
    """Raise :class:`NotSupportedError` for a physics set this version cannot run."""
    if tuple(scene.run.physics) not in SIMULATORS:
        raise NotSupportedError(f"run.physics = {list(scene.run.physics)}: allowed sets are "
                                f"{[list(k) for k in SIMULATORS]}")
