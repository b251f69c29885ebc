"""Running a scene: pick the simulator the scene needs, fan its records out to the sinks, end the file.

Only what the scene requires is imported: physics ["fracture"] loads ``hfgpu.fracture.simulator`` and
no proppant code, ["proppant"] loads ``hfgpu.proppant.simulator`` and no fracture code; both at once run the
one-way coupled model of ``hfgpu.coupled`` (fracture first, proppant on its history).
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any, Callable

from .errors import HfgpuError
from .scene import Scene, load_scene

#: The module whose ``simulate(scene, sink, progress=None) -> dict`` runs each physics set.
SIMULATORS = {("fracture",): "hfgpu.fracture.simulator", ("proppant",): "hfgpu.proppant.simulator",
              ("fracture", "proppant"): "hfgpu.coupled"}

SINK_METHODS = ("fracture_snapshot", "fracture_balance", "proppant_snapshot", "proppant_balance")


class NotSupportedError(HfgpuError, NotImplementedError):
    """The scene asks for something this version does not run yet."""


class FanOut:
    """A sink that hands every record to each of ``sinks`` that has the method, in order."""

    def __init__(self, sinks: list[Any]):
        self.sinks = list(sinks)

    def __getattr__(self, name: str) -> Callable[[Any], None]:
        if name not in SINK_METHODS:
            raise AttributeError(name)
        targets = [getattr(sink, name) for sink in self.sinks if hasattr(sink, name)]

        def forward(record: Any) -> None:
            for target in targets:
                target(record)

        return forward


def check_supported(scene: Scene) -> None:
    """Raise :class:`NotSupportedError` for a physics set this version cannot run."""
    if tuple(scene.run.physics) not in SIMULATORS:
        raise NotSupportedError(f"run.physics = {list(scene.run.physics)}: allowed sets are "
                                f"{[list(k) for k in SIMULATORS]}")


def simulator_for(scene: Scene) -> Callable[..., dict]:
    """The ``simulate`` function for the scene's physics set, imported now (and nothing else)."""
    check_supported(scene)
    return importlib.import_module(SIMULATORS[tuple(scene.run.physics)]).simulate


def run(scene_or_path: Scene | str | Path, out: str | Path, *, progress: bool = True,
        rrd: str | Path | None = None, view: bool = False) -> dict[str, Any]:
    """Run a scene and write the results file ``out``; return the run's summary.

    ``progress`` shows a bar over simulated time and prints the summary table; ``rrd`` saves a Rerun
    recording to that file; ``view`` streams to a spawned Rerun viewer. On any error the results file
    is closed with status "failed: <message>" (every completed snapshot kept) and the error re-raised.
    """
    scene = scene_or_path if isinstance(scene_or_path, Scene) else load_scene(scene_or_path)
    simulate = simulator_for(scene)
    from .io.progress import Progress, summary_table
    from .io.results import ResultsWriter

    writer = ResultsWriter(out, scene)
    sinks: list[Any] = [writer]
    try:
        if rrd is not None or view:
            from .io.rerun_view import RerunRecorder

            sinks.append(RerunRecorder(scene, rrd=rrd, spawn=view))
    except BaseException as exc:
        writer.fail(str(exc) or type(exc).__name__)
        raise
    bar = Progress(scene.run.end_time, enabled=progress)
    sinks.append(bar)
    try:
        result = simulate(scene, FanOut(sinks), progress=bar)
    except BaseException as exc:
        _close_others(sinks[1:])
        message = str(exc) or type(exc).__name__
        writer.fail(message, {**bar.stats(), "error_type": type(exc).__name__})
        raise
    _close_others(sinks[1:])
    summary = {**(result or {}), **bar.stats(), "status": "complete", "out": str(out)}
    writer.close("complete", summary)
    if progress:
        print(summary_table(summary), flush=True)
    return summary


def _close_others(sinks: list[Any]) -> None:
    """Close the sinks besides the results writer (progress bar, Rerun recorder)."""
    for sink in sinks:
        close = getattr(sink, "close", None)
        if close is not None:
            close()
