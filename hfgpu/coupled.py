"""The integrated coupled run (the paper, section 4.3 and Fig. 4): one-way, fracture first and proppant on it
(:func:`simulate`, below); two-way, the two interval by interval with the slurry acting on the fracture
(``[coupling] mode = "two-way"``, :func:`simulate_two_way`, which reads like Fig. 4 top to bottom).

One-way:

A scene with ``physics = ["fracture", "proppant"]`` runs

1. the planar-3D fracture engine over the whole schedule, its snapshots every ``[coupling] fracture_every``
   going both to the output sink (the results file) and to memory;
2. the MP-PIC proppant model on one fixed grid (:func:`hfgpu.coupling.proppant_frame`, cells of
   ``[coupling] cell_size``) whose width and leak-off follow the fracture history, linear in time
   (:class:`hfgpu.coupling.FractureHistory`); the fracture is not solved again (one-way coupling). The slurry
   enters through an annulus of cells around the perforation (the paper's annular injection zone) at the
   schedule's rate Q(t) and volume fraction. The proppant run starts at ``[coupling] proppant_start``
   (default: the start of the first stage that carries proppant, i.e. the end of the pad): before it the
   fracture holds clean fluid only, which the one-way coupling does not need to simulate.

Screen-out risk (reported, not fed back): each proppant snapshot gets a grid field ``bridging_risk`` (1 where a
cell holds proppant and its width is below ``bridging_factor`` x the largest parcel diameter in it, the
criterion of :func:`hfgpu.coupling.bridging_risk`); the summary has ``screen_out_cells`` (at the end),
``screen_out_cells_max`` and ``screen_out_first_time`` (NaN when never).

Screen-out at the perforation (handled): the inlet places proppant only into cells below close packing; what
cannot enter is held back and counted (``proppant_screened_out`` [m^3] in the summary and ``screened_out`` in
the solid balance, injected = in_domain + outflow + screened_out; ``proppant_screen_out_time`` is when it
first happened, on the scene's clock, NaN when never) and a RuntimeWarning line says so. The fracture does not
feel it (one-way coupling): its pressure and growth assume all the slurry enters.

Width-history mismatch (handled): the open cells of the resampled history may grow faster than the injection
minus leak-off fills them (the fracture engine's negative widths beside a barrier hold fluid the proppant grid
does not see: +40 % in the base case). The fluid step supplies the difference in the growing cells instead of
jetting it out of one pinned cell (hfgpu.proppant.fluid.FluidSolver._supply_mismatch; that jet reached 2-5 m/s
at the fracture's fringe and capped the step); the summary has ``proppant_fluid_supplied`` and a RuntimeWarning
line reports it above 5 % of the injected fluid.

``[coupling]`` keys (all optional): ``fracture_every`` (default end_time / 60), ``cell_size`` (one length or
[dx, dz]; default the fracture cells), ``inlet_inner_radius`` (default 0), ``inlet_radius`` (outer radius of the
annulus, default 1.5 x the larger proppant cell size: the injection cell and its eight neighbours),
``proppant_start`` (see above), ``margin`` (cells around the largest footprint, default 1), ``mode``
("one-way", the default, or "two-way").
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time as _time
import warnings
from typing import Callable, Iterator

import numpy as np

from .coupling import FractureHistory, proppant_frame, screen_out_cells
from .coupling_config import DEFAULT_INLET_CELLS
from .engines import FractureEngine, ProppantEngine
from .errors import SceneError
from .fracture.engine_setup import fracture_engine_setup
from .fracture.mesh import injection_cell_centre
from .fracture.simulator import FractureRun
from .io.sink import FractureSink, ProppantSink, ResultsSink
from .proppant.config import Geometry, Port
from .proppant.engine_setup import proppant_engine_setup
from .proppant.simulator import ProppantSimulation, warn_screen_out
from .records import BalanceRecord, FractureSnapshot, GridFrame, ProppantSnapshot, SolidBalanceRecord
from .scene import Scene
from .slurry_feedback import packed_cells, slurry_of

def proppant_start_time(scene: Scene) -> float:
    """When the proppant run starts: ``[coupling] proppant_start``, else the start of the first stage that
    carries proppant (the end of the pad); a scene whose schedule has no proppant stage is refused."""
    if scene.coupling.proppant_start is not None:
        return scene.coupling.proppant_start
    start = 0.0
    for stage in scene.injection.schedule.stages:
        if stage.proppant is not None:
            return start
        start = stage.until
    raise SceneError("injection.schedule", "(no proppant stage)",
                     'a coupled run needs a stage with proppant = "<class>" (or set [coupling] proppant_start)')


def late_start(scene: Scene, start: float, first: float) -> float:
    """The proppant start, moved to the fracture's first snapshot ``first`` when that comes later (a coarse grid
    starts the fracture only once it spans a few cells, hfgpu.fracture.simulator.start_time): nothing is open
    before it. The slurry pumped in between is not tracked; a warning says how much."""
    if first <= start:
        return start
    solids = scene.injection.schedule.solid_volume(start, first)
    warnings.warn(f"the fracture fills its first cells at {first:.4g} s, after the proppant start ({start:.4g} s): "
                  f"the proppant run starts then, and the {solids:.3g} m^3 of solids pumped before are not tracked "
                  f"(a finer mesh starts the fracture earlier)", RuntimeWarning, stacklevel=3)
    return first


def proppant_geometry(scene: Scene, frame: GridFrame, shape: tuple[int, int], width: np.ndarray) -> Geometry:
    """The coupled run's proppant domain: a "field" geometry on (frame, shape) with ``width``, and the annular
    inlet around the perforation (``[coupling] inlet_inner_radius``, ``inlet_radius``)."""
    nz, nx = shape
    x, z = frame.centres(nz, nx)
    cfg = scene.coupling
    outer = cfg.inlet_radius if cfg.inlet_radius is not None else DEFAULT_INLET_CELLS * max(frame.dx, frame.dz)
    x_inj, z_inj = injection_cell_centre(scene)   # the fracture's source cell, which holds the perforation
    inlet = Port("annulus", x=x_inj, depth=z_inj, inner_radius=cfg.inlet_inner_radius, outer_radius=outer)
    return Geometry(kind="field", length=nx * frame.dx, height=nz * frame.dz, field_x=x, field_z=z,
                    field_w=np.asarray(width, dtype=np.float64), inlets=(inlet,))


def proppant_simulation(scene: Scene, frame: GridFrame, shape: tuple[int, int], start: float,
                        width_at: Callable[[float], tuple[np.ndarray, np.ndarray]]) -> ProppantSimulation:
    """The proppant run of the coupled scene from ``start`` on the grid (frame, shape) (:func:`proppant_geometry`),
    its walls ``width_at(t)`` = (width, leak-off rate) at the scene's time t. It keeps the scene's clock: it
    starts at ``start``, ``advance(t)`` steps to the scene's time t, its records carry the scene's times."""
    geometry = proppant_geometry(scene, frame, shape, width_at(start)[0])
    return ProppantSimulation(proppant_engine_setup(scene, geometry=geometry, start=start), width_field=width_at)


class Timings:
    """Wall time [s] per phase of the coupled loop (time.perf_counter): fracture, fluid (SIMPLE steps), parcels
    (particle sub-loops), io (sinks), and in a two-way run footprint (the clean-fluid pass) and feedback (the
    slurry handed to the fracture); the rest of a run (scatter, injection, width resampling, set-up) is not split.
    The loop measures its phases (:meth:`measure`); the proppant run measures its fluid and parcels
    (``ProppantSimulation.seconds``, added by :meth:`add`)."""

    def __init__(self):
        self.seconds = {"fracture": 0.0, "fluid": 0.0, "parcels": 0.0, "io": 0.0}
        self._inner: list[float] = []  # per open measure: the time of the measures inside it

    @contextlib.contextmanager
    def measure(self, key: str) -> Iterator[None]:
        """Add the block's wall time to ``seconds[key]``, less that of the measures inside it (the sinks' io
        within the fracture's steps)."""
        t0 = _time.perf_counter()
        self._inner.append(0.0)
        try:
            yield
        finally:
            elapsed = _time.perf_counter() - t0
            self.seconds[key] += elapsed - self._inner.pop()
            if self._inner:
                self._inner[-1] += elapsed

    def add(self, seconds: dict[str, float]) -> None:
        """Add phases an engine measured itself."""
        for key, value in seconds.items():
            self.seconds[key] += value


class _FractureTee:
    """Sink of the fracture phase: records go on to ``sink``; snapshots are also kept in ``snapshots``, the
    last balance record in ``last``."""

    def __init__(self, sink: FractureSink, timings: Timings):
        self.snapshots: list[FractureSnapshot] = []
        self.last: BalanceRecord | None = None
        self.sink, self.timings = sink, timings

    def fracture_snapshot(self, snap: FractureSnapshot) -> None:
        self.snapshots.append(snap)
        with self.timings.measure("io"):
            self.sink.fracture_snapshot(snap)

    def fracture_balance(self, record: BalanceRecord) -> None:
        self.last = record
        with self.timings.measure("io"):
            self.sink.fracture_balance(record)


class _Snapshots:
    """A fracture sink that keeps the snapshots only (the clean-fluid pass of a two-way run)."""

    def __init__(self):
        self.snapshots: list[FractureSnapshot] = []

    def fracture_snapshot(self, snap: FractureSnapshot) -> None:
        self.snapshots.append(snap)

    def fracture_balance(self, record: BalanceRecord) -> None:
        pass


class _BridgingRisk:
    """Sink of the proppant phase: ``bridging_risk`` added to each snapshot's grid (screen_out_cells), the
    flagged cells counted; records go on to ``sink``."""

    def __init__(self, sink: ProppantSink, factor: float, timings: Timings):
        self.factor = factor
        self.sink, self.timings = sink, timings
        self.flagged = 0
        self.flagged_max = 0
        self.first_time = math.nan

    def proppant_snapshot(self, snap: ProppantSnapshot) -> None:
        risk = screen_out_cells(snap, self.factor)
        self.flagged = int(risk.sum())
        self.flagged_max = max(self.flagged_max, self.flagged)
        if self.flagged and math.isnan(self.first_time):
            self.first_time = snap.time
        flagged = dataclasses.replace(snap, grid={**snap.grid, "bridging_risk": risk.astype(np.int8)})
        with self.timings.measure("io"):
            self.sink.proppant_snapshot(flagged)

    def proppant_balance(self, record: SolidBalanceRecord) -> None:
        with self.timings.measure("io"):
            self.sink.proppant_balance(record)

    def state(self) -> dict:
        """The screen-out counters (a checkpoint)."""
        return {"flagged": self.flagged, "flagged_max": self.flagged_max, "first_time": self.first_time}

    def restore(self, state: dict) -> None:
        self.flagged, self.flagged_max = state["flagged"], state["flagged_max"]
        self.first_time = state["first_time"]


def _on_scene_clock(resume: dict, start: float) -> dict:
    """The proppant state of a coupled checkpoint, its times on the scene's clock: as stored when the checkpoint
    says ``clock = "scene"``, else (a file written when the proppant run's clock started at 0 at the proppant
    start) with ``start`` added to its time, next snapshot time and screen-out time."""
    state = resume["proppant"]
    if resume.get("clock") == "scene":
        return state
    simulation = dict(state["simulation"], time=state["simulation"]["time"] + start,
                      screen_out_time=state["simulation"]["screen_out_time"] + start)
    return dict(state, simulation=simulation, next_out=state["next_out"] + start)


#: Share of the injected fluid above which a width history's mismatch is reported (warn_inconsistent_width).
MISMATCH_WARNING = 0.05


def warn_inconsistent_width(summary: dict) -> None:
    """A RuntimeWarning line when the open cells of the fracture's width history on the proppant grid stored
    more (or less) fluid than was injected and leaked off, by more than MISMATCH_WARNING of the injected fluid
    (``summary`` of :meth:`ProppantSimulation.run`). The fluid step's balance is injected + opened + supplied =
    stored + leaked + outflow (hfgpu.proppant.fluid.StepInfo), with ``stored`` counting the fluid placed in
    cells that open (``opened``) and not the fluid of cells that close (``dropped``), so the history's
    mismatch is supplied + opened - dropped (tests/test_coupled.py checks ``supplied`` against the history).
    Known causes: slurry held back at a screen-out (the one-way coupled fracture assumed it entered); fracture
    cells with negative widths beside a stress barrier, whose fluid the proppant grid (w <= 0 closed) does not
    see."""
    injected = summary["fluid_injected"]
    mismatch = summary["fluid_supplied"] + summary["fluid_opened"] - summary["fluid_dropped"]
    if injected > 0.0 and abs(mismatch) > MISMATCH_WARNING * injected:
        warnings.warn(f"the fracture width history on the proppant grid is not mass-consistent with the injection: "
                      f"its open cells stored {mismatch:.4g} m^3 of fluid beyond the {injected:.4g} m^3 injected "
                      f"less leak-off ({100 * mismatch / injected:+.1f} %), supplied over the growing cells (known "
                      "causes: slurry held back by a screen-out; the width interpolated linearly between fracture "
                      "snapshots; coarse cells)", RuntimeWarning, stacklevel=3)


def simulate(scene: Scene, sink: ResultsSink, progress: Callable[[float], None] | None = None,
             timings: Timings | None = None, checkpoint=None, resume: dict | None = None) -> dict:
    """Run the coupled scene (module docstring): fracture, then proppant on the fracture history (a two-way
    scene goes to :func:`simulate_two_way`).

    ``sink`` gets the fracture and the proppant records (proppant times on the scene's clock); ``progress(t)``
    is called through both phases; ``timings`` (optional) collects wall time per phase. Returns a summary:
    the fracture's values prefixed ``fracture_``, the proppant's prefixed ``proppant_``, the proppant grid
    (``proppant_nx``, ``proppant_nz``, ``proppant_dx``, ``proppant_dz``), ``proppant_start``, the screen-out
    counts and ``time_<phase>`` wall times.

    Checkpoints (hfgpu.io.checkpoint): ``checkpoint`` gets {"phase": "fracture", "fracture": <the fracture
    engine's>} during the fracture phase, then {"phase": "proppant", "clock": "scene", "fracture_summary",
    "screen_out" (the bridging counters), "proppant": <the proppant model's, on the scene's clock>}; ``resume`` is such a state plus
    "fracture_snapshots", the fracture snapshots the results file kept (the history before the checkpoint).
    """
    if scene.coupling.mode == "two-way":
        return simulate_two_way(scene, sink, progress, timings, checkpoint, resume)
    timings = timings if timings is not None else Timings()
    start = proppant_start_time(scene)
    cfg = scene.coupling
    tee = _FractureTee(sink, timings)
    fracture_setup = fracture_engine_setup(scene, every=cfg.fracture_every)
    phase = resume["phase"] if resume is not None else "fracture"
    if resume is not None:
        tee.snapshots = list(resume["fracture_snapshots"])
    if phase == "fracture":
        with timings.measure("fracture"):
            run = FractureRun(fracture_setup, tee, progress, resume=resume and resume["fracture"],
                              checkpoint=checkpoint and checkpoint.within(
                                  0.0, lambda state: {"phase": "fracture", "fracture": state}))
            run.advance(fracture_setup.end_time)
            fracture = run.summary()
    else:
        fracture = resume["fracture_summary"]
    history = FractureHistory(tee.snapshots)
    start = late_start(scene, start, float(history.times[0]))
    frame, shape = proppant_frame(history, cfg.cell_size, cfg.margin, source=injection_cell_centre(scene))
    sim = proppant_simulation(scene, frame, shape, start, history.width_field(frame, shape, cfg.min_width))
    risk = _BridgingRisk(sink, scene.proppant.params.bridging_factor, timings)
    proppant = proppant_phase(sim, risk, start, fracture, scene.proppant.params.theta_cp, timings, progress,
                              checkpoint, resume)
    summary = {f"fracture_{k}": v for k, v in fracture.items()}
    summary.update({f"proppant_{k}": v for k, v in proppant.items()})
    summary.update(proppant_start=start, proppant_nx=shape[1], proppant_nz=shape[0], proppant_dx=frame.dx,
                   proppant_dz=frame.dz, screen_out_cells=risk.flagged, screen_out_cells_max=risk.flagged_max,
                   screen_out_first_time=risk.first_time, time=scene.run.end_time)
    summary.update({f"time_{k}": v for k, v in timings.seconds.items()})
    return summary


def proppant_phase(sim: ProppantSimulation, risk: _BridgingRisk, start: float, fracture: dict, theta_cp: float,
                   timings: Timings, progress: Callable[[float], None] | None, checkpoint, resume: dict | None) -> dict:
    """The one-way run's proppant phase from ``start`` (the fracture done, its summary ``fracture``): ``sim`` run to
    the end into ``risk`` (the bridging-risk sink), its checkpoints {"phase": "proppant", "clock": "scene",
    "fracture_summary": ``fracture``, "screen_out", "proppant"}, resumed from ``resume`` when that is a
    proppant-phase state; returns the proppant summary, after the warnings on a screen-out and on a width history
    inconsistent with the injection."""
    resuming = resume is not None and resume["phase"] == "proppant"
    if resuming:
        risk.restore(resume["screen_out"])
    elif checkpoint is not None:
        checkpoint.restart(start)

    def wrap(state: dict) -> dict:
        return {"phase": "proppant", "clock": "scene", "fracture_summary": fracture, "screen_out": risk.state(),
                "proppant": state}

    if hasattr(progress, "phase"):  # hfgpu.io.progress.Progress: a bar of its own for the proppant phase
        progress.phase("proppant", start)
    proppant = sim.run(risk, progress, checkpoint=checkpoint and checkpoint.within(0.0, wrap),
                       resume=_on_scene_clock(resume, start) if resuming else None)
    timings.add(sim.seconds)
    warn_screen_out(proppant, theta_cp)
    warn_inconsistent_width(proppant)
    return proppant


def simulate_two_way(scene: Scene, sink: ResultsSink, progress: Callable[[float], None] | None = None,
                     timings: Timings | None = None, checkpoint=None, resume: dict | None = None) -> dict:
    """The two-way coupled run (``[coupling] mode = "two-way"``): the paper's Fig. 4 with the arrow back.

    1. The proppant grid: the footprint of the fracture pumped with clean fluid (a pass without output, the
       one-way fracture), plus ``[coupling] margin`` cells: slurry shortens a fracture, the grid covers it.
    2. The pad: the fracture alone up to the proppant start (clean fluid; as the one-way run).
    3. Every interval [t, t + fracture_every]: the fracture steps over it in the slurry the proppant left at t
       (viscosity ratios, packed cells' Darcy resistance, bridged cells that stop the front, and after shut-in
       the width at which the walls meet the grains: hfgpu.slurry_feedback), then the proppant steps over it
       in that interval's geometry (the widths of its two ends, linear in time), then the slurry at
       t + fracture_every is handed to the fracture.
    4. The summary: as :func:`simulate`'s, plus the tip screen-out (``tip_screen_out_time``: the first interval
       end at which a bridged or packed cell holds the front along the length; ``net_pressure_rise``: the
       largest net pressure after it less the net pressure then, NaN without one) and ``packed_length`` (the
       length of fracture whose column holds a packed cell at the end).

    Checkpoints (hfgpu.io.checkpoint): at the first interval end at or past each checkpoint time, after the
    slurry is handed over, ``checkpoint`` gets {"phase": "two-way", "grid" (the proppant frame and shape),
    "start", "fracture" (FractureRun's state), "proppant" (the proppant run's, on the scene's clock),
    "screen_out" (the bridging counters), "tip" (the tip screen-out's time, net pressure then and largest net
    pressure since)}; ``resume`` is such a state plus "fracture_snapshots" (the history the results file kept).
    A resumed run skips the footprint pass and the pad, restores both runs, hands the fracture the slurry of
    the restored proppant and goes on with the same steps as an uninterrupted run. ``progress(t)`` follows the
    fracture.
    """
    timings = timings if timings is not None else Timings()
    timings.seconds.update(footprint=0.0, feedback=0.0)
    cfg, params = scene.coupling, scene.proppant.params
    fracture_setup = fracture_engine_setup(scene, every=cfg.fracture_every)
    tee = _FractureTee(sink, timings)
    run: FractureEngine
    if resume is None:
        with timings.measure("footprint"):
            clean = _Snapshots()
            FractureRun(fracture_setup, clean).advance(fracture_setup.end_time)
            history = FractureHistory(clean.snapshots)
            start = late_start(scene, proppant_start_time(scene), float(history.times[0]))
            frame, shape = proppant_frame(history, cfg.cell_size, cfg.margin, source=injection_cell_centre(scene))
        run = FractureRun(fracture_setup, tee, progress)
        with timings.measure("fracture"):
            run.advance(start)
    else:
        grid = resume["grid"]
        frame, shape, start = GridFrame.of(grid), (int(grid["nz"]), int(grid["nx"])), float(resume["start"])
        tee.snapshots = list(resume["fracture_snapshots"])
        run = FractureRun(fracture_setup, tee, progress, resume=resume["fracture"])
    geometry = {"width": FractureHistory(tee.snapshots).width_field(frame, shape, cfg.min_width)}
    sim: ProppantEngine = proppant_simulation(scene, frame, shape, start, lambda t: geometry["width"](t))
    risk = _BridgingRisk(sink, params.bridging_factor, timings)
    t_screen_out, p_screen_out, p_max = math.nan, math.nan, -math.inf
    if resume is not None:
        sim.resume(resume["proppant"])
        risk.restore(resume["screen_out"])
        t_screen_out, p_screen_out, p_max = (float(resume["tip"][name]) for name in ("time", "net_pressure", "max"))
        run.use_slurry(slurry_of(sim.snapshot(), params))
    every = cfg.fracture_every
    ends = [every * k for k in range(int(math.floor(start / every + 1e-9)) + 1,
                                     int(math.floor(scene.run.end_time / every + 1e-9)) + 1)]
    ends = sorted({t for t in ends if t > max(start, sim.time)} | {scene.run.end_time})
    for t_next in ends:
        with timings.measure("fracture"):
            run.advance(t_next)
        geometry["width"] = FractureHistory(tee.snapshots).width_field(frame, shape, cfg.min_width)
        sim.advance(t_next, risk)
        with timings.measure("feedback"):
            run.use_slurry(slurry_of(sim.snapshot(), params))
        p_net = tee.last.net_pressure
        if math.isnan(t_screen_out) and run.tips_held():
            t_screen_out, p_screen_out = t_next, p_net
        if not math.isnan(t_screen_out):
            p_max = max(p_max, p_net)
        if checkpoint is not None and checkpoint.due(t_next) and t_next < scene.run.end_time:
            checkpoint.save(t_next, {
                "phase": "two-way", "start": start, "fracture": run.state(),
                "grid": {**dataclasses.asdict(frame), "nz": shape[0], "nx": shape[1]},
                "proppant": sim.checkpoint_state(),
                "screen_out": risk.state(), "tip": {"time": t_screen_out, "net_pressure": p_screen_out, "max": p_max}})
    proppant = sim.finish(risk)
    timings.add(sim.seconds)
    warn_screen_out(proppant, params.theta_cp)
    warn_inconsistent_width(proppant)
    fracture = run.summary()
    packed = packed_cells(sim.snapshot(), params).any(axis=0)
    summary = {f"fracture_{k}": v for k, v in fracture.items()}
    summary.update({f"proppant_{k}": v for k, v in proppant.items()})
    summary.update(proppant_start=start, proppant_nx=shape[1], proppant_nz=shape[0], proppant_dx=frame.dx,
                   proppant_dz=frame.dz, screen_out_cells=risk.flagged, screen_out_cells_max=risk.flagged_max,
                   screen_out_first_time=risk.first_time, time=scene.run.end_time,
                   tip_screen_out_time=t_screen_out, net_pressure_rise=p_max - p_screen_out,
                   packed_length=float(packed.sum()) * frame.dx)
    summary.update({f"time_{k}": v for k, v in timings.seconds.items()})
    return summary
