"""What the planar-3D fracture engine reads, as one typed frozen value (:class:`FractureEngineSetup`), and the one
function that builds it from a scene (:func:`fracture_engine_setup`). The engine (simulator.py: ``_Engine``,
``FractureRun``) takes only this, never the scene."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .config import FractureNumerics
from .mesh import injection_cell_centre

if TYPE_CHECKING:
    from ..scene import Mesh, Rock, Schedule


@dataclass(frozen=True)
class FractureEngineSetup:
    """One fracture's engine configuration (SI units, the scene's clock).

    ``source`` is the injection cell's centre (mesh.injection_cell_centre: the perforation moved by up to half a
    cell so that the layer boundaries lie on cell faces); ``injection_depth`` the perforation's own depth (the
    front's extents are measured from it). ``schedule`` is what enters this fracture: the scene's schedule, or a
    cluster's share of it in a stage (stage.ClusterInlet, the same methods). ``output_times``: the snapshot
    times, sorted, the end time last."""

    rock: Rock
    viscosity: float                     # the fracturing fluid's [Pa s]
    schedule: Schedule
    injection_depth: float               # [m]
    source: tuple[float, float]          # (x, z) of the injection cell's centre [m]
    mesh: Mesh                           # cell sizes dx, dz; max_cells_across and coarsening_factor
    numerics: FractureNumerics
    end_time: float                      # [s]
    output_times: tuple[float, ...]      # [s]


def output_times(end_time: float, every: float) -> tuple[float, ...]:
    """Every ``every`` up to ``end_time`` and ``end_time`` itself, sorted (k every within 1e-9 of a step of the
    end counts as reaching it)."""
    times = {every * k for k in range(1, int(math.floor(end_time / every + 1e-9)) + 1)} | {end_time}
    return tuple(sorted(t for t in times if t <= end_time))


def fracture_engine_setup(scene, every: float | None = None) -> FractureEngineSetup:
    """The fracture engine's setup of a scene with ``[rock]`` and ``[injection]`` (validated before:
    hfgpu.scene_checks.validate): its rock, fluid viscosity, schedule, injection point, mesh, ``[fracture]``
    numerics (the defaults without the table), end time and snapshots every ``every`` [s] (the scene's
    ``output.every`` when None; a coupled run's ``[coupling] fracture_every``)."""
    every = scene.output.every if every is None else every
    return FractureEngineSetup(rock=scene.rock, viscosity=scene.fluid.viscosity,
                               schedule=scene.injection.schedule, injection_depth=scene.injection.depth,
                               source=injection_cell_centre(scene), mesh=scene.mesh,
                               numerics=scene.fracture if scene.fracture is not None else FractureNumerics(),
                               end_time=scene.run.end_time, output_times=output_times(scene.run.end_time, every))
