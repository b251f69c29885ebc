"""Running a scene: pick the simulator the scene needs, fan its records out to the sinks, end the file.

Only what the scene requires is imported: physics ["fracture"] loads ``hfgpu.fracture.simulator`` and
no proppant code, ["proppant"] loads ``hfgpu.proppant.simulator`` and no fracture code; both at once run the
coupled model of ``hfgpu.coupled`` (one-way: fracture first, proppant on its history; two-way: interval by
interval, the fracture in the slurry).

Checkpoints: the simulator gets a :class:`hfgpu.io.checkpoint.Checkpointer` writing into the results file;
``resume=True`` continues a killed (or failed) run from the checkpoint in its results file.
"""

from __future__ import annotations

import importlib
import math
import signal
import sys
import warnings
from pathlib import Path
from typing import Any, Callable

from .errors import HfgpuError
from .simulators import NotSupportedError, check_supported, simulator_module
from .interrupts import signal_number, stop_signals_interrupt
from .io.sink import METHODS, FractureSink, ProppantSink
from .scene import Scene
from .scene_checks import validate
from .threads import blas_thread_limit, blas_threads

class FanOut:
    """A sink (hfgpu.io.sink.ResultsSink) that hands every record to each of ``sinks`` that has the method, in
    order."""

    def __init__(self, sinks: list[FractureSink | ProppantSink]):
        self.sinks = list(sinks)

    def __getattr__(self, name: str) -> Callable[[Any], None]:
        if name not in METHODS:
            raise AttributeError(name)
        targets = [getattr(sink, name) for sink in self.sinks if hasattr(sink, name)]

        def forward(record: Any) -> None:
            for target in targets:
                target(record)

        return forward


def warn_edited(scene: Scene) -> None:
    """Warn when the scene's values are not those of its TOML text (changed with ``Scene.replace`` after it was
    read): the results file stores that text under ``/scene``, which would then not describe the run."""
    from .scene import load_scene

    if not scene.source:
        return
    try:
        same = load_scene(scene.source) == scene
    except HfgpuError:  # a text that is not a whole scene (e.g. built in code from parts)
        same = False
    if not same:
        warnings.warn("the scene was changed after it was read (Scene.replace): the results file stores the text "
                      "it was read from, which does not describe this run; change keys with hfgpu.edit_scene",
                      UserWarning, stacklevel=3)


def simulator_for(scene: Scene) -> Callable[..., dict]:
    """The ``simulate`` function for the scene's physics set, imported now (and nothing else)."""
    check_supported(scene)
    return importlib.import_module(simulator_module(scene)).simulate


def run(scene_or_path: Scene | str | Path, out: str | Path, *, progress: bool = True,
        rrd: str | Path | None = None, view: bool = False, connect: str | None = None,
        resume: bool = False, viewer_required: bool = False) -> dict[str, Any]:
    """Run a scene and write the results file ``out``; return the run's summary.

    ``progress`` shows a bar over simulated time and prints the summary table; ``rrd`` saves a Rerun
    recording to that file; ``view`` streams to a spawned Rerun viewer, ``connect`` to a viewer or
    gRPC proxy already running at that URL. A viewer that cannot be reached (no display for ``view``, nothing
    listening at ``connect``) is found before any work: with ``viewer_required`` that is an :class:`HfgpuError`,
    else the run goes on without it and one line on stderr says so. On any error the results file
    is closed with status "failed: <message>" (every completed snapshot kept) and the error re-raised; Ctrl-C,
    SIGTERM and SIGHUP close it with status "interrupted" (summary and checkpoint kept, resumable) and re-raise
    the ``KeyboardInterrupt`` (:mod:`hfgpu.interrupts`).
    BLAS uses one thread except in large dense solves (:mod:`hfgpu.threads`, ``HFGPU_BLAS_THREADS``).
    Checkpoints go into ``out`` every :func:`hfgpu.io.checkpoint.checkpoint_interval` of simulated time.

    ``resume``: continue the run in ``out`` from its last checkpoint (the scene must equal the one stored
    there, else :class:`HfgpuError` naming what differs; a file without a checkpoint is an error too); the
    file then ends as an uninterrupted run's would. A file whose run is complete is left alone: a line says
    so and its stored summary is returned. The Rerun recording of a resumed run holds the resumed part only.
    """
    scene = validate(scene_or_path)  # as ``hfgpu check``: limits and the engine's start (hfgpu.scene_checks)
    if isinstance(scene_or_path, Scene):  # one read from a file is its text
        warn_edited(scene)
    return run_validated(scene, out, progress=progress, rrd=rrd, view=view, connect=connect, resume=resume,
                         viewer_required=viewer_required)


def run_validated(scene: Scene, out: str | Path, *, progress: bool = True, rrd: str | Path | None = None,
                  view: bool = False, connect: str | None = None, resume: bool = False,
                  viewer_required: bool = False) -> dict[str, Any]:
    """:func:`run` of a scene :func:`hfgpu.scene_checks.validate` returned, without checking it again (``hfgpu
    run`` validates the scene once, prints its warnings, then runs it)."""
    blas_thread_limit(0)  # a bad HFGPU_BLAS_THREADS is an error before any work
    simulate = simulator_for(scene)
    view, connect = _reachable_viewers(view, connect, viewer_required)
    from .io.checkpoint import Checkpointer, checkpoint_interval
    from .io.progress import Progress
    from .io.summary import falloff_values, schedule_table, summary_table
    from .io.results import ResultsWriter, open_results

    state = kept = None
    if resume:
        opened = _reopen(scene, Path(out))
        if isinstance(opened, dict):
            return opened
        writer, start, state, kept = opened
    else:
        writer, start = ResultsWriter(out, scene), 0.0
    checkpoint = Checkpointer(writer.write_checkpoint, checkpoint_interval(scene), start)
    sinks: list[FractureSink | ProppantSink] = [writer]
    try:
        if rrd is not None or view or connect is not None:
            from .io.rerun_view import RerunRecorder

            sinks.append(RerunRecorder(scene, rrd=rrd, spawn=view, connect=connect))
    except BaseException as exc:
        writer.fail(str(exc) or type(exc).__name__)
        raise
    bar = Progress(scene.run.end_time, enabled=progress, phase=scene.run.physics[0])
    if kept is not None:
        _carry_over(bar, kept)
    sinks.append(bar)
    try:
        with stop_signals_interrupt() as stop, blas_threads(), bar.holding_warnings():  # printed after the bar
            result = simulate(scene, FanOut(sinks), progress=_checked(bar, stop), checkpoint=checkpoint,
                              resume=state)
    except KeyboardInterrupt as exc:
        _close_others(sinks[1:])
        writer.close("interrupted", {**bar.stats(), "interrupted_by": signal.Signals(signal_number(exc)).name})
        raise
    except BaseException as exc:
        _close_others(sinks[1:])
        message = str(exc) or type(exc).__name__
        writer.fail(message, {**bar.stats(), "error_type": type(exc).__name__})
        raise
    _close_others(sinks[1:])
    summary = {**(result or {}), **bar.stats(), "status": "complete", "out": str(out),
               "checkpoints": checkpoint.written, "resumed_from": start if resume else math.nan}
    writer.close("complete", summary)
    closure = _write_closure(writer, scene) if scene.closure is not None else {}
    summary.update(closure)
    balance = open_results(writer.path).fracture_balance if scene.has("fracture") else None
    falloff = _write_falloff(writer, scene, balance)
    summary.update(falloff_values(falloff) if falloff is not None else {})
    if progress:  # in the output units; the file keeps SI
        if scene.injection is not None:
            print(schedule_table(scene, scene.output.units), flush=True)
        print(summary_table(summary, scene.output.units, scene, balance, falloff), flush=True)
    return summary


def _checked(bar: Any, stop: Any) -> Callable[[float], None]:
    """The progress callback, first raising a stop signal whose own raise was lost (hfgpu.interrupts): the
    engines call it after every step. Keeps the bar's ``phase`` (the coupled run's second bar), ``note`` and
    ``limit`` (hfgpu.io.progress)."""
    def progress(t: float) -> None:
        stop.check()
        bar(t)

    progress.phase, progress.note, progress.limit = bar.phase, bar.note, bar.limit  # type: ignore[attr-defined]
    return progress


def _write_falloff(writer: Any, scene: Scene, balance: dict[str, Any] | None) -> Any:
    """Read the fall-off of a complete run with a shut-in from its ``/fracture/balance`` (hfgpu.io.summary.falloff_of),
    add its ``falloff_*`` values to ``/summary`` and return the analysis (None without a shut-in)."""
    from .io.summary import falloff_of, falloff_values, pump_end

    if not balance or scene.injection is None:
        return None
    analysis = falloff_of(balance, pump_end(scene), scene.rock.plane_strain_modulus)
    if analysis is not None:
        writer.add_summary(falloff_values(analysis))
    return analysis


def _write_closure(writer: Any, scene: Scene) -> dict[str, Any]:
    """Close the fracture on the proppant of the complete results file (:mod:`hfgpu.closure`): write ``/closure``
    and its ``closure_*`` summary values, and return those (none when the run wrote no proppant snapshot; a failure
    costs one line on stderr, the complete run stays as written)."""
    from .closure.conductivity import closure_of
    from .io.results import open_results

    results = open_results(writer.path)
    if not len(results.proppant_snapshots):
        return {}
    try:
        closure = closure_of(results, scene)
        writer.write_closure(closure.frame, closure.fields, {**closure.scalars, **closure.labels})
        if closure.clusters:
            writer.add_summary(closure.cluster_summary())
    except Exception as exc:  # the run itself is complete and kept; closure is post-processing of it
        print(f"hfgpu run: closure not computed: {' '.join(str(exc).splitlines()) or type(exc).__name__}",
              file=sys.stderr, flush=True)
        return {}
    return closure.summary()


def _reachable_viewers(view: bool, connect: str | None, required: bool) -> tuple[bool, str | None]:
    """``view`` and ``connect`` less what cannot be reached (:func:`hfgpu.io.rerun_view.viewer_problem`, one
    line on stderr each), or :class:`HfgpuError` when ``required``."""
    if not view and connect is None:
        return view, connect
    from .io.rerun_view import viewer_problem

    kept = []
    for spawn, url in ((view, None), (False, connect)):
        problem = viewer_problem(spawn, url) if spawn or url is not None else None
        if problem and required:
            raise HfgpuError(f"{problem}; the run needs its viewer (--viewer-required), so it did not start")
        if problem:
            print(f"hfgpu run: {problem}; running without it", file=sys.stderr, flush=True)
        kept.append(problem is None)
    return view and kept[0], connect if kept[1] else None


def _reopen(scene: Scene, out: Path):
    """``out`` reopened at its checkpoint: (writer, checkpoint time, state, the file's Results as kept), the state
    of a coupled run with the file's fracture snapshots added; or the stored summary of a complete run."""
    from .io.checkpoint import scene_differences
    from .io.results import ResultsWriter, open_results

    results = open_results(out)
    if not results.scene_text:
        raise HfgpuError(f"cannot resume '{out}': it stores no scene text to check the scene against")
    differences = scene_differences(results.scene, scene)
    if differences:
        raise HfgpuError(f"cannot resume '{out}': the scene differs from the one it was run with: "
                         + "; ".join(differences))
    if results.status == "complete":
        print(f"{out}: the run is already complete; nothing to resume", flush=True)
        return results.summary
    writer, time, state = ResultsWriter.reopen(out, scene)   # the scene's [wellbore] gives the rows their STP
    kept = open_results(out)
    if len(scene.run.physics) > 1:
        state["fracture_snapshots"] = kept.fracture_snapshots[:]
        if scene.completion is not None:   # a stage's proppant (hfgpu.coupled_stage)
            state["stage_snapshots"] = [snaps[:] for snaps in kept.stage_snapshots]
            state["stage_balance"] = kept.stage_balance
    return writer, time, state, kept


def _carry_over(bar: Any, kept: Any) -> None:
    """Give the progress bar of a resumed run the counts and last balance rows of the records the file kept
    (``kept``: its Results), so that the summary counts the whole run."""
    from .records import BalanceRecord, SolidBalanceRecord

    for physics, record in (("fracture", BalanceRecord), ("proppant", SolidBalanceRecord)):
        rows = getattr(kept, f"{physics}_balance")
        steps = rows["time"].size if rows else 0
        bar.counts[f"{physics}_snapshots"] = len(getattr(kept, f"{physics}_snapshots"))
        bar.counts[f"{physics}_steps"] = steps
        if steps:
            setattr(bar, physics, record(**{name: float(column[-1]) for name, column in rows.items()}))
    bar(kept.checkpoint_time)


def _close_others(sinks: list[Any]) -> None:
    """Close the sinks besides the results writer (progress bar, Rerun recorder)."""
    for sink in sinks:
        close = getattr(sink, "close", None)
        if close is not None:
            close()
