"""The MP-PIC run loop (the paper, sections 2.3, 4.2, 4.3): grid, fluid solver, parcels, inlets, outlets.

One fluid step of length dt (Courant limit Eq. 42 with C_max < 1, and the parcels' own Courant number over a
particle sub-step; a step whose Courant number comes out above C_max is undone, halved and retried):

1. the parcels entering during the step are added (:mod:`hfgpu.proppant.injection`);
2. particle sub-loop (section 4.3), ``particle_substeps`` times dt/n in the fluid of the step's start:
   scatter (Eq. 38) -> gather (Eq. 40-41) -> push (Eq. 43-44) -> exchange (Eq. 39); parcels in outlet cells
   are removed and their solid volume counted. The particle engine (:mod:`hfgpu.proppant.engine_seam`: Taichi
   kernels, or the NumPy oracle) owns the parcels and runs the whole sub-loop per call;
3. scatter: theta_p at the step's end, so that the fluid's storage term (theta_f w - theta_f^o w^o)/dt of
   Eq. 25 is the change over this very step;
4. fluid SIMPLE step (Algorithm 1) with theta_f = 1 - theta_p, the interphase force F averaged over the
   sub-loop (its pressure part with each face's own gradient, see particle_ops_numpy.pressure_reaction), the
   inlets' fluid sources (1 - c) Q (and the momentum of jet inlets), leak-off and the outlets;
5. a :class:`hfgpu.records.SolidBalanceRecord` goes to the sink; snapshots every ``output.every``.
This is the cycle scatter -> fluid -> particles of the paper entered at the particles: each fluid step sees
the force of the particle sub-loop over the same interval.

Solid balance: ``injected`` is all solid volume scheduled into the domain (the initial suspension plus the
inlets), ``in_domain`` the parcels' volume, ``outflow`` what left through outlets, ``screened_out`` what the
inlets held back because their cells were packed to theta_cp (a screen-out at the perforation: proppant cannot
enter a packed, bridged zone; :class:`hfgpu.proppant.injection.Injector`); injected = in_domain + outflow +
screened_out to round-off; :func:`simulate` ends with a RuntimeWarning line when any was held back (first
time, volume). A growing fracture can drive the loop through ``width_field(t) -> (width, leakoff)`` on the grid
(cells that open join the fluid grid; leak-off [m/s per unit area, both faces] is the sink s_l of Eq. 7).

The drag part of F is also handed to the fluid step as beta = sum n rho_p V_p D_p (1 - r_p) I / V_face, so
that the fluid takes F = F^o + beta (u_f - u_f^o) implicitly, r_p being the share of a change of u_f that the
parcel's own implicit update (Eq. 43) follows within the step (particle_ops_numpy.parcel_response). F^o is the drag on the parcels
pushed through the old fluid; with the drag implicit in both phases, F = D (u_f - u_p(u_f)) and
u_p = (u_p^o + dt (D u_f + a)) / (1 + D dt), so dF/du_f = D / (1 + D dt) per unit mass (derived here from
Eq. 43; over sub-steps h the lag 1 - r is the product of their 1/(1 + D h)). For D dt >> 1 the fluid then
carries the grains' inertia, theta_p rho_p. With beta = sum n rho_p V_p D_p (every parcel held at its pushed
velocity) a fine suspension anchored the fluid to its old velocity, as if its density were rho_f + beta dt: a
lock exchange of 20 um grains ran at Fr = 0.03 instead of ~0.4-0.5 (tests/proppant/test_lock_exchange.py;
docs/stability.md had named this linearisation as a suspect). Parcels that do not follow u_f keep r_p = 0, the
full drag implicit: those the push stopped (walls, packing cap, bed friction, the threshold of motion,
bridging: a velocity component exactly 0) and those in a dense bed (theta_p at the parcel >=
damping_threshold x theta_cp, where collision damping and the packing stress, not drag alone, set their
velocity); explicit drag there would limit dt to ~2 rho_f theta_f / beta
(under a millisecond in a packed bed of sand, where it drove spurious circulation).
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import warnings
from dataclasses import dataclass
from time import perf_counter
from typing import Callable

import numpy as np

from ..errors import SimulationError
from ..io.progress import limit as show_limit, note
from ..io.sink import ProppantSink
from ..records import GridFrame, ProppantSnapshot, SolidBalanceRecord
from .config import Geometry
from .engine_setup import ProppantEngineSetup, proppant_engine_setup
from .engine import make_engine
from .engine_seam import ParticleEngine
from .fluid import CourantLimitExceeded, FluidNumerics, FluidSolver, FluidState, courant_rates
from .health import KEYS, Watch
from .grid import StaggeredGrid
from .injection import Injector, batch_solid_volume, initial_suspension, ports_to_cells
from .parcels import Parcels

#: fluid volumes [m^3] the fluid step reports (hfgpu.proppant.fluid.StepInfo), summed in fluid_totals
FLUID_VOLUMES = ("injected", "opened", "supplied", "stored", "leaked", "outflow", "dropped")

WidthField = Callable[[float], "tuple[np.ndarray, np.ndarray]"]


def build_grid(geometry: Geometry, dx: float, dz: float) -> StaggeredGrid:
    """The staggered grid of a geometry: box/slot with round(length/dx) x round(height/dz) cells (the cell
    size adjusted to fit exactly), field on the width file's own grid."""
    if geometry.kind == "field":
        x, z = geometry.field_x, geometry.field_z
        frame = GridFrame(dx=float(x[1] - x[0]), dz=float(z[1] - z[0]), x0=float(x[0]), z0=float(z[0]))
        return StaggeredGrid.from_width(frame, geometry.field_w)
    nz, nx = box_shape(geometry, dx, dz)
    return StaggeredGrid.box(geometry.length, geometry.height, geometry.width, nx, nz)


def box_shape(geometry: Geometry, dx: float, dz: float) -> tuple[int, int]:
    """(nz, nx) of a box or slot grid: round(height / dz) x round(length / dx) cells, at least one each."""
    return max(1, round(geometry.height / dz)), max(1, round(geometry.length / dx))


def particles_per_parcel(setup, schedule, cell_volume: float, start: float = 0.0) -> list[float]:
    """Real particles per parcel of each class (``setup``: the scene's ProppantSetup or a ProppantEngineSetup,
    their ``classes`` and ``numerics``): the scene's value, or so that ``parcels_per_cell`` parcels fill a cell of
    volume ``cell_volume`` at the class's largest volume fraction (initial or injected from ``start`` on); with
    ``max_parcels`` (MppicNumerics), raised by one common factor where the schedule's proppant from ``start`` on
    would make more parcels than that (n_c = V_c / (ppp_c v_c) summed over the classes, V_c the class's solid
    volume scheduled after ``start``, v_c its mean particle volume)."""
    numerics = setup.numerics
    if numerics.particles_per_parcel is not None:
        return [numerics.particles_per_parcel] * len(setup.classes)
    out, parcels = [], 0.0
    for cls in setup.classes:
        fraction = cls.initial_volume_fraction
        for begin, first, stage in _stages_after(schedule, start):
            if stage.proppant == cls.name:
                fraction = max(fraction, stage.fraction_at(first, begin), stage.end_volume_fraction)
        ppp = fraction * cell_volume / (numerics.parcels_per_cell * cls.size.mean_particle_volume())
        ppp = ppp if ppp > 0.0 else 1.0
        out.append(ppp)
        parcels += scheduled_solid_volume(schedule, cls.name, start) / (ppp * cls.size.mean_particle_volume())
    if numerics.max_parcels is not None and parcels > numerics.max_parcels:
        out = [ppp * parcels / numerics.max_parcels for ppp in out]
    return out


def _stages_after(schedule, start: float) -> list[tuple[float, float, object]]:
    """(the stage's start, the later of it and ``start``, the stage) of each stage of ``schedule`` (None: none)
    that ends after ``start``."""
    out, begin = [], 0.0
    for stage in (schedule.stages if schedule is not None else ()):
        if stage.until > start:
            out.append((begin, max(begin, start), stage))
        begin = stage.until
    return out


def scheduled_solid_volume(schedule, name: str, start: float = 0.0) -> float:
    """Solid volume [m^3] the schedule injects of proppant class ``name`` after ``start``: sum of Q T (f0 + f1) / 2
    over its stages from ``start`` on (the slurry rate Q, the volume fraction ramped linearly from f0 at the
    stage's start, or at ``start`` within it, to f1)."""
    total = 0.0
    for begin, first, stage in _stages_after(schedule, start):
        if stage.proppant == name:
            total += stage.rate * (stage.until - first) * 0.5 * (stage.fraction_at(first, begin)
                                                                 + stage.end_volume_fraction)
    return total


@dataclass(frozen=True)
class StepInfo:
    """What one fluid step did."""

    time: float
    dt: float
    simple_iterations: int
    continuity_residual: float
    courant: float
    parcels: int
    retries: int


class ProppantSimulation:
    """State and stepping of one MP-PIC run (a :class:`hfgpu.engines.ProppantEngine`); :func:`simulate` drives it
    to the end time.

    Attributes a caller may read: ``time``, ``grid``, ``parcels`` (:class:`Parcels`), ``fluid`` (the fluid
    solver's state), ``injected``, ``outflow``, ``screened_out`` [m^3] (solids), ``screen_out_time`` [s] (first
    hold-back, NaN when none), ``fluid_totals`` (the fluid volumes of FLUID_VOLUMES summed over the steps;
    injected + opened + supplied = stored + leaked + outflow; ``supplied``: what a width history
    inconsistent with the injection needed beyond it, hfgpu.proppant.fluid.StepInfo), ``seconds`` (wall time [s]
    of the fluid steps, "fluid", and of the parcel sub-loops, "parcels", retries included). ``add_parcels``
    places extra parcels (counted as injected), e.g. a single test particle.

    It takes the engine's setup (engine_setup.py) and keeps the scene's clock: ``time`` starts at the setup's
    ``start``, and every record and message carries the scene's time. ``width_field(t) -> (width, leakoff)``
    (optional) drives the grid's width and leak-off at the scene's time t; ``inlet_split(t0, t1)`` (optional)
    splits the slurry rate among the inlets over a step (hfgpu.proppant.injection.Injector ``split``).
    """

    def __init__(self, setup: ProppantEngineSetup, width_field: WidthField | None = None, inlet_split=None):
        self.setup = setup
        self.params = setup.params
        self.numerics = setup.numerics
        self.rho_f = setup.fluid.density
        self.mu_f = setup.fluid.viscosity
        self.width_field = width_field
        self.grid = build_grid(setup.geometry, *setup.cell_size)
        self.leakoff = np.zeros(self.grid.shape)
        if width_field is not None:
            self._set_width(setup.start)
        self.outlets = np.zeros(self.grid.shape, dtype=bool)
        for k, i in ports_to_cells(setup.geometry.outlets, self.grid.frame, self.grid.width,
                                   "geometry.outlets"):
            self.outlets[k, i] = True
        self.engine: ParticleEngine = make_engine(self.numerics.backend, self.grid, self.params, self.rho_f,
                                                  self.mu_f, self.numerics.gravity, self.outlets,
                                                  arch=self.numerics.arch)
        self.time = setup.start
        self.seconds = {"fluid": 0.0, "parcels": 0.0}
        self.rng = np.random.default_rng(setup.seed)
        open_volume = self.grid.cell_volume[self.grid.active]
        schedule = setup.schedule
        self.particles_per_parcel = particles_per_parcel(setup, schedule, float(np.median(open_volume)), setup.start)
        self.injected = 0.0
        self.outflow = 0.0
        self.screen_out_time = math.nan  # start of the first step whose inlets held proppant back
        self.add_parcels(initial_suspension(setup.classes, self.grid.frame, self.grid.width,
                                            self.particles_per_parcel, self.rng, self.numerics.initial_placement))
        self.injector = self._make_injector(schedule, inlet_split)
        self.moments = self.engine.moments()
        n = self.numerics
        self.solver = FluidSolver(self.grid, self.rho_f, self.mu_f,
                                  FluidNumerics(c_max=n.c_max, tolerance=n.simple_tolerance,
                                                max_iterations=n.simple_max_iterations),
                                  backend=self.numerics.backend,
                                  params=self.params if n.slurry_viscosity else None,
                                  wall_friction=self.params.wall_friction, arch=self.engine.arch)
        self.fluid = self.solver.initial_state(self._fluid_theta_p())
        self.previous_pressure = self.fluid.p.copy()   # the pressure of the fluid step before the last
        self.steps = 0
        self.safety = 1.0
        self.limited_by = "dt_max"
        self.watch = Watch(self.params.theta_cp, min(c.size.d_min for c in setup.classes), setup.units,
                           width_history=width_field is not None, two_way=setup.two_way)
        self.fluid_totals = dict.fromkeys(FLUID_VOLUMES, 0.0)
        self.next_out = setup.start   # the next snapshot's time (run, advance)
        self.max_residual = 0.0   # the largest continuity residual of the steps so far

    # -- set-up ---------------------------------------------------------------------------------------

    def _make_injector(self, schedule, split) -> Injector | None:
        if schedule is None:
            return None
        names = [c.name for c in self.setup.classes]

        def loadings(t: float) -> list[tuple[int, float]]:
            name, fraction = schedule.proppant_fraction(t)
            return [] if name is None else [(names.index(name), fraction)]

        return Injector(self.setup.geometry.inlets, self.grid.frame, self.grid.width, self.setup.classes,
                        self.particles_per_parcel, rate=schedule.mean_rate, loadings=loadings, rng=self.rng,
                        split=split)

    def _set_width(self, t: float) -> None:
        width, leakoff = self.width_field(t)
        self.grid = self.grid.with_width(width)
        self.leakoff = np.asarray(leakoff, dtype=float)

    def add_parcels(self, batch: dict[str, np.ndarray]) -> None:
        """Place parcels (shared layout arrays) in the domain; their solid volume counts as injected."""
        if batch["x"].size:
            self.engine.append(Parcels(**batch))
            self.injected += batch_solid_volume(batch)

    @property
    def parcels(self) -> Parcels:
        """A host copy of the parcels (read back from the engine)."""
        return self.engine.parcels()

    def set_parcels(self, parcels: Parcels) -> None:
        """Replace the parcels (their volume is not counted as injected: a test's or a restart's)."""
        self.engine.set_parcels(parcels)
        self.moments = self.engine.moments()

    # -- stepping -------------------------------------------------------------------------------------

    def step_limits(self, limit: float) -> dict[str, float]:
        """What bounds the next step [s] (keys of hfgpu.proppant.health.KEYS): dt_max, ``limit`` (time to the
        next output, stage end or end time), the fluid Courant limit (Eq. 42) scaled by ``safety`` (which
        shrinks by 0.7 after a step needed a retry and recovers by 1.05 a step) and the parcels' Courant number
        per sub-step (<= C_max). A target less than two of the other limits away is reached in two equal steps
        (``output`` = limit / 2), never in a full step and a sliver: a sliver's fluid, one short implicit step
        from the last, is not the quasi-steady flow the parcels moved in, and an output written after it shows
        grains on a bed moving against a fluid they did not see (tests/test_field_grid.py)."""
        h = min(self.grid.frame.dx, self.grid.frame.dz)
        speed = self.engine.max_speed()
        limits = {"dt_max": self.numerics.dt_max,
                  "fluid Courant": self.safety * self.solver.stable_dt(self.fluid),
                  "parcel Courant": (self.numerics.c_max * h * self.numerics.particle_substeps / speed
                                     if speed > 0.0 else math.inf)}
        others = min(limits.values())
        limits["output"] = 0.5 * limit if others < limit < 2.0 * others else limit
        return limits

    def next_dt(self, limit: float) -> float:
        """Largest step allowed: the smallest of :meth:`step_limits`."""
        return min(self.step_limits(limit).values())

    def step(self, limit: float = math.inf) -> StepInfo:
        """Advance one fluid step (at most ``limit`` seconds); see the module docstring. A retry starts again
        from the parcels of the last accepted step (the engine keeps them until ``commit``)."""
        limits = self.step_limits(limit)
        dt = min(limits.values())
        self.limited_by = min(limits, key=limits.get)
        t0 = self.time
        saved = (copy.deepcopy(self.injector), self.injected, self.screen_out_time)
        for retry in range(self.numerics.max_step_retries + 1):
            if retry:
                injector, self.injected, self.screen_out_time = saved
                self.injector = copy.deepcopy(injector)
            if self.width_field is not None:
                self._set_width(t0 + dt)
                self.solver.set_grid(self.grid)
                self.engine.set_grid(self.grid)
            if not (dt > 0.0 and t0 + dt > t0):
                raise SimulationError(f"zero-length time step (dt = {dt:g} s)", time=t0)
            self.engine.begin_step(self.fluid.u, self.fluid.v, self.grain_pressure())
            if self.injector is not None:
                self._inject(t0, t0 + dt)
            t_a = perf_counter()
            loop = self.engine.substeps(dt, self.numerics.particle_substeps, t0)
            self.seconds["parcels"] += perf_counter() - t_a
            self.moments = self.engine.moments()
            sources, momentum = ((self.injector.fluid_sources(t0, t0 + dt, self.grid.width), self.injector.jet_momentum(t0, t0 + dt))
                                 if self.injector is not None else (np.zeros(self.grid.shape), (None, None)))
            trial = self.solver.copy_state(self.fluid)
            theta_p, t_a = self._fluid_theta_p(), perf_counter()
            try:
                info = self.solver.step(trial, dt, theta_p, loop.force_x, loop.force_z,
                                        sources=sources, leakoff=self.leakoff, outlets=self.outlets,
                                        drag_x=loop.beta_x, drag_z=loop.beta_z, momentum_x=momentum[0],
                                        momentum_z=momentum[1])
            except CourantLimitExceeded as exc:
                dt = min(0.5 * dt, exc.stable_dt)
                continue
            finally:
                self.seconds["fluid"] += perf_counter() - t_a
            if info.courant <= self.numerics.c_max:
                break
            dt *= min(0.5, 0.9 * self.numerics.c_max / info.courant)
        else:
            where = self.watch.fastest(self.grid.frame, self._fastest_cell(), np.asarray(self.grid.width),
                                       self.moments.volume_fraction)
            raise SimulationError(f"the fluid Courant number stayed above c_max = {self.numerics.c_max:g} "
                                  f"after {self.numerics.max_step_retries} reductions of the step "
                                  f"({KEYS['fluid Courant']}); {where}", time=t0)
        self.engine.commit()
        self.outflow += loop.outflow
        self.previous_pressure = self.fluid.p
        self.fluid = trial
        for name in FLUID_VOLUMES:
            self.fluid_totals[name] += getattr(info, name)
        self.safety = 0.7 * self.safety if retry else min(1.0, 1.05 * self.safety)
        self._check_fluid(t0 + dt)
        if retry:  # cut by the fluid's Courant number as it came out (Eq. 42), not by the limit foreseen
            limits = {**limits, "fluid Courant": dt}
            self.limited_by = "fluid Courant"
        theta = self.moments.volume_fraction
        self.watch.check_step(t0, dt, min(self.numerics.dt_max, limit), limits, self.grid.frame,
                              self._fastest_cell, np.asarray(self.grid.width), theta)
        self.watch.after_step(t0 + dt, self.grid.frame, np.asarray(self.grid.width), theta)
        self.time = t0 + dt
        self.steps += 1
        return StepInfo(time=self.time, dt=dt, simple_iterations=info.iterations,
                        continuity_residual=info.continuity_residual, courant=info.courant,
                        parcels=self.engine.live, retries=retry)

    def grain_pressure(self) -> np.ndarray:
        """The pressure the parcels take in the next step ([mppic] grain_pressure): the last fluid step's, or
        with "two-step" the mean of the last two, (p^n + p^(n-1)) / 2. Each step the parcels move with the
        pressure of the step before and the fluid then answers the volume they moved; where it answers with a
        pressure of the opposite sign (dense cells, docs/proppant-closures.md) the mean cancels that mode."""
        if self.numerics.grain_pressure == "two-step":
            return 0.5 * (self.fluid.p + self.previous_pressure)
        return self.fluid.p

    def _inject(self, t0: float, t1: float) -> None:
        """Add the inlets' parcels for (t0, t1] into the room left below close packing, theta_cp V_cell minus
        the solid volume of the scatter (Eq. 38) on the step's width, and none where the width is below the
        largest grain; what cannot enter is screened out."""
        moments = self.engine.moments()
        room = np.maximum(self.params.theta_cp * self.grid.cell_volume - moments.solid_volume, 0.0)
        room[self.grid.width < max(c.size.d_max for c in self.setup.classes)] = 0.0
        held = self.injector.screened_out
        self.add_parcels(self.injector.emit(t0, t1, room=room, width=self.grid.width))
        held = self.injector.screened_out - held
        self.injected += held
        if held > 0.0 and math.isnan(self.screen_out_time):
            self.screen_out_time = t0

    @property
    def screened_out(self) -> float:
        """Solid volume the inlets held back at packed cells so far [m^3]."""
        return self.injector.screened_out if self.injector is not None else 0.0

    def _fluid_theta_p(self) -> np.ndarray:
        """theta_p handed to the fluid, kept below 1 (only an over-packed cell, where the packing limiter
        failed, reaches it). Not capped at close packing: the fluid's storage term (theta_f w)^n - (theta_f
        w)^o must follow the parcels, or a bed reaching theta_cp breaks continuity (seen to blow up)."""
        return np.minimum(self.moments.volume_fraction, 1.0 - 1e-6)

    def _fastest_cell(self) -> tuple[int, int]:
        """(k, i) of the cell with the fluid's largest Courant rate (Eq. 42)."""
        rates = courant_rates(self.fluid.u, self.fluid.v, self.grid.frame.dx, self.grid.frame.dz)
        k, i = np.unravel_index(int(np.argmax(rates)), rates.shape)
        return int(k), int(i)

    def _check_fluid(self, t: float) -> None:
        for name in ("u", "v", "p"):
            values = getattr(self.fluid, name)
            bad = ~np.isfinite(values)
            if bad.any():
                cell = tuple(int(c) for c in np.argwhere(bad)[0])
                raise SimulationError(f"non-finite fluid {name}", time=t, cell=cell)

    # -- records --------------------------------------------------------------------------------------

    def snapshot(self) -> ProppantSnapshot:
        """Parcels and grid fields now (the records' layout)."""
        self.moments = self.engine.moments()
        return ProppantSnapshot(
            time=self.time, frame=self.grid.frame, parcels=self.parcels.as_dict(),
            grid=dict(volume_fraction=self.moments.volume_fraction.copy(), pressure=self.fluid.p.copy(),
                      width=np.array(self.grid.width), fluid_u=self.fluid.u.copy(),
                      fluid_v=self.fluid.v.copy()))

    def balance(self) -> SolidBalanceRecord:
        return SolidBalanceRecord(time=self.time, injected=self.injected,
                                  in_domain=self.engine.solid_volume(), outflow=self.outflow,
                                  screened_out=self.screened_out)

    def run(self, sink: ProppantSink, progress: Callable[[float], None] | None = None,
            on_step: Callable[[StepInfo], None] | None = None, checkpoint=None, resume: dict | None = None) -> dict:
        """Step to the end time, writing snapshots every ``output_every`` (and at the start and the end) and a
        balance record every step; returns a summary.

        Checkpoints (hfgpu.io.checkpoint): after the first step that ends at or past each interval,
        ``checkpoint.save(time, state)`` gets {"simulation": :meth:`state`, "next_out", "max_residual"};
        ``resume`` (such a state) continues from it, with the same steps as an uninterrupted run."""
        if resume is not None:
            self.resume(resume)
        self.advance(self.setup.end_time, sink, progress, on_step, checkpoint)
        return self.finish(sink)

    def checkpoint_state(self) -> dict:
        """What a checkpoint of the run stores (:meth:`run`): {"simulation": :meth:`state`, "next_out",
        "max_residual"}."""
        return {"simulation": self.state(), "next_out": self.next_out, "max_residual": self.max_residual}

    def resume(self, state: dict) -> None:
        """Continue from a :meth:`checkpoint_state`."""
        self.restore(state["simulation"])
        self.next_out, self.max_residual = state["next_out"], state["max_residual"]

    def advance(self, until: float, sink: ProppantSink, progress: Callable[[float], None] | None = None,
                on_step: Callable[[StepInfo], None] | None = None, checkpoint=None) -> None:
        """Step to ``until`` (a step lands on it), writing the snapshots due and a balance record every step
        (:meth:`run`; the two-way coupled loop of hfgpu.coupled calls it interval by interval)."""
        start, end, every = self.setup.start, self.setup.end_time, self.setup.output_every
        breaks = sorted(b for b in (self.setup.schedule.breakpoints() if self.setup.schedule is not None else ())
                        if start < b < end)
        eps = 1e-9 * (end - start)
        while True:
            if self.time >= self.next_out - eps:
                sink.proppant_snapshot(self.snapshot())
                self.next_out += every
            if self.time >= until - eps:
                break
            targets = [until, self.next_out] + [b for b in breaks if b > self.time + eps]
            if self.steps == 0 and self.engine.name == "taichi":
                note(progress, "compiling kernels")
            info = self.step(limit=min(targets) - self.time)
            self.max_residual = max(self.max_residual, info.continuity_residual)
            sink.proppant_balance(self.balance())
            if on_step is not None:
                on_step(info)
            if progress is not None:
                progress(self.time)
                show_limit(progress, info.dt, self.limited_by)
            if checkpoint is not None and checkpoint.due(self.time):
                checkpoint.save(self.time, self.checkpoint_state())

    def finish(self, sink: ProppantSink) -> dict:
        """The last snapshot (unless one was just written) and the run's summary (:meth:`run`)."""
        if abs(self.time - (self.next_out - self.setup.output_every)) > 1e-9 * (self.setup.end_time - self.setup.start):
            sink.proppant_snapshot(self.snapshot())
        record = self.balance()
        return dict(time=self.time, steps=self.steps, parcels=self.engine.live, injected=record.injected,
                    in_domain=record.in_domain, outflow=record.outflow, screened_out=record.screened_out,
                    screen_out_time=self.screen_out_time,
                    max_continuity_residual=self.max_residual, backend=self.engine.name, arch=self.engine.arch,
                    threads=self.engine.threads or 0, **self.watch.summary(),
                    **{f"fluid_{name}": value for name, value in self.fluid_totals.items()})

    # -- checkpoints ------------------------------------------------------------------------------------
    #: Attributes (numbers or arrays) a checkpoint carries as they are: list every new persistent one here.
    STATE_ATTRIBUTES = ("time", "steps", "safety", "injected", "outflow", "screen_out_time")

    def state(self) -> dict:
        """Everything needed to continue from now (a checkpoint): STATE_ATTRIBUTES, the fluid volumes, the parcels,
        the fluid fields and the pressure of the step before (grain_pressure), the width and leak-off the grid
        holds, the pressure solver's reused LU factors (as the matrix factorised), the random generator's state
        (numpy ``bit_generator.state``, as JSON), the unphysical states already reported (hfgpu.proppant.health, as
        JSON) and the inlets' owed volumes and next diameters."""
        rng = self.injector.rng if self.injector is not None else self.rng  # a step retry deep-copies it
        state = {**{name: getattr(self, name) for name in self.STATE_ATTRIBUTES},
                 "fluid_totals": dict(self.fluid_totals), "parcels": self.parcels.as_dict(),
                 "fluid": {f.name: getattr(self.fluid, f.name).copy() for f in dataclasses.fields(self.fluid)},
                 "previous_pressure": self.previous_pressure.copy(),
                 "width": np.array(self.grid.width), "leakoff": self.leakoff.copy(),
                 "linear": self.solver.linear.state(), "rng": json.dumps(rng.bit_generator.state),
                 "watch": json.dumps(self.watch.found)}
        if self.injector is not None:
            inlets = self.injector.inlets
            state["injector"] = {"screened_out": self.injector.screened_out,
                                 "owed": np.array([inlet.owed for inlet in inlets]),
                                 "next_diameter": np.array([inlet.next_diameter for inlet in inlets])}
        return state

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state` (of a simulation of the same setup, freshly built)."""
        for name in self.STATE_ATTRIBUTES:
            setattr(self, name, np.array(state[name]) if isinstance(state[name], np.ndarray) else state[name])
        self.fluid_totals = {name: float(state["fluid_totals"][name]) for name in FLUID_VOLUMES}
        self.grid = self.grid.with_width(np.array(state["width"]))
        self.leakoff = np.array(state["leakoff"])
        self.solver.set_grid(self.grid)
        self.engine.set_grid(self.grid)
        self.engine.set_parcels(Parcels(**{name: np.array(a) for name, a in state["parcels"].items()}))
        self.solver.linear.restore(state["linear"])
        self.fluid = FluidState(**{name: np.array(a) for name, a in state["fluid"].items()})
        self.previous_pressure = np.array(state["previous_pressure"]) if "previous_pressure" in state \
            else self.fluid.p.copy()
        self.rng.bit_generator.state = json.loads(state["rng"])
        self.watch.found = json.loads(state["watch"]) if "watch" in state else {}
        if self.injector is not None:
            self.injector.rng = self.rng
            self.injector.screened_out = state["injector"]["screened_out"]
            for inlet, owed, diameter in zip(self.injector.inlets, state["injector"]["owed"],
                                             state["injector"]["next_diameter"]):
                inlet.owed, inlet.next_diameter = np.array(owed), np.array(diameter)
        self.moments = self.engine.moments()


def warn_screen_out(summary: dict, theta_cp: float) -> None:
    """A RuntimeWarning line when a run's inlets held proppant back (``summary`` of :meth:`ProppantSimulation.run`)."""
    if summary["screened_out"] > 0.0:
        warnings.warn(f"screen-out: the inlets held back {summary['screened_out']:.4g} m^3 of proppant "
                      f"({100 * summary['screened_out'] / summary['injected']:.1f} % of the injected solids), "
                      f"first at t = {summary['screen_out_time']:g} s: their cells were packed to "
                      f"theta_cp = {theta_cp:g} or narrower than the largest grain", RuntimeWarning, stacklevel=3)


def simulate(scene, sink: ProppantSink, progress: Callable[[float], None] | None = None,
             width_field: WidthField | None = None, checkpoint=None, resume: dict | None = None) -> dict:
    """Run the MP-PIC proppant model of ``scene`` (physics "proppant") to its end time.

    ``sink`` receives ``proppant_snapshot`` and ``proppant_balance`` records (hfgpu.records); ``progress(t)``
    is called after every fluid step; ``width_field(t) -> (width, leakoff)`` optionally drives the width and
    leak-off fields (nz, nx) of the grid in time (coupling to a growing fracture). Returns a summary dict
    (time, steps, parcels, injected, in_domain, outflow, screened_out, screen_out_time (NaN when none),
    max_continuity_residual, backend). ``checkpoint``, ``resume``: see :meth:`ProppantSimulation.run`.
    """
    sim = ProppantSimulation(proppant_engine_setup(scene), width_field=width_field)
    summary = sim.run(sink, progress, checkpoint=checkpoint, resume=resume)
    warn_screen_out(summary, scene.proppant.params.theta_cp)
    return summary
