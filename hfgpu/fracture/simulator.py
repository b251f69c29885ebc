"""The planar-3D fracture engine's time loop: ``simulate(scene, sink, progress=None) -> summary``.

Each step [t, t + dt] solves the implicit elasticity-lubrication-leak-off system for the widths of the
active cells (Newton, :mod:`newton`), then opens the cells the front criterion selects (:mod:`front`) and
chooses the next step by Eq. 35 with V_T the larger of the last opening's speed (Eq. 34) and the sub-grid
front's measured speed over the step just taken. Steps land on schedule breakpoints and the end time (physics),
never on output times: a snapshot between two accepted steps is interpolated between them (interpolate.py),
so the steps and the results do not depend on the output spacing. A step whose Newton iteration fails, or in
which the sub-grid front (front.front_distances) moved more than ``max_front_advance`` cells, is redone with
half the step (``max_step_retries`` times; then a Newton failure raises SimulationError naming time, cell and
residual, a long advance is accepted), so the front does not over-run on long steps. Cells squeezed shut stay
closed at w = 0 (contact, newton.solve_step). The injected volume of a step is exact
(Schedule.mean_rate), leak-off is Carter's law integrated exactly (:mod:`leakoff`), and the flux form
conserves volume, so injected = stored + leaked to the Newton tolerance at every step.

Start. The run starts at t0 from a radial fracture of radius R0 = ``initial_radius_cells`` cells around the
injection cell's centre (the cells whose centres lie inside it; the grid is placed on the layer boundaries,
mesh.fit_layers, so that centre is up to half a cell from the injection depth). t0 is the latest of the times
at which the four radial vertex solutions (M, K, Mt, Kt; REFERENCE.md 1.1) reach R0 with the properties at the
injection point -- the slowest mechanism controls early growth -- and the cells' opening times follow that
vertex's R ~ t^a
(tau = t0 (r / R0)^(1/a)). The cells hold the volume injected by t0 less the Carter volume leaked since
their opening times (at most 90 % of it), in the shape a uniform net pressure gives (C w = const).

Coarsening. With ``mesh.max_cells_across`` set, the grid is coarsened by ``mesh.coarsening_factor`` (coarsen.py:
3x3 merges, or PyFrac's 2x remeshing by area overlap; both centre a coarse cell on the injection cell) after a
step whose footprint spans more cells than that along x or z; volume is carried exactly, so the balance holds
across the merge, and the active-cell count stays bounded. The merge comes after the step's records and
snapshots (``coarsen_if_wide``, called by ``simulate`` before it sets the next step), so they are of the fine
grid's state: a merged state is only the next step's start, its overlap means of widths and tip cells not a
solution.

Partially filled tip cells (``partial_tip_cells``). A newly opened cell records, besides its opening time,
the time the front will have crossed it (its parent's crossing time, Eq. 34); its Carter leak-off is the
exact average over opening times spread uniformly between the two (leakoff.carter_cumulative).

Leak-off clock (``leakoff_clock``). Every cell also records the volume per unit area it has leaked (grid
field ``leaked``); a cell the positivity ramp held below its Carter demand (opened ahead of the fluid)
continues from the exposure time that volume corresponds to, not from its opening time
(leakoff.carter_demand), so the time it spent dry does not count as exposure and the lost demand is
not lost for good. Coarsening carries it as a volume (sum of the children / 9).

Sub-grid front (``front_tracking = "subgrid"``; tip_cells.py). Instead of opening whole cells, the front
lies inside tip cells: their widths are pinned to the tip asymptote's mean over the part behind the front
(their fluid pressure is then the unknown of their mass balance, newton.py), only that part leaks (``fill``,
the wetted fraction; the leak-off clock runs per wetted area), and the front is placed by the level set
from the ribbon cells' widths (the tip asymptote inverted, refined by the two-term fit of tip_cells.py with
``ribbon_fit = "two_term"``), with the viscous asymptote's V at least the front's own speed over the step,
(s - s_0) / dt (s_0: the ribbon's distance at the step's start, kept in ``advance``).
Each step iterates solve -> front -> solve until the front's position at every tip cell reproduces itself
(``_front_iterations``; Newton's first iterate is the widths extrapolated along the last step's dw/dt, grid
field ``w_rate``); cells the front enters become tip cells, cells it has crossed join the channel
once the step is accepted. This removes the whole-ring openings that, in leak-off dominated growth, starve
the fracture after each opening (case IV: inlet width -57 % -> +2.9 %). The time step follows the measured
front advance (Eq. 35 with V_T = advance / dt). The 2x remeshing carries the front: a coarse cell it crosses
is a tip cell wetted by the overlap mean of the fine fractions (coarsen.coarse_front; the coarse ribbons' s_0
is unknown until the next step places the front). A 3x3 merge makes every coarse cell a channel cell and the
next step places the front again: carrying it through a 3x3 merge (measured) removed radial_long's jumps
(largest R error over the run 14.7 -> 5.7 %) but failed Newton in 2 of 9 coarse radial case I runs (2-3 coarse
cells per radius).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from ..errors import SceneError, SimulationError
from ..io.progress import limit as show_limit
from ..records import BalanceRecord, FractureSnapshot, GridFrame
from ..threads import blas_threads
from .coarsen import coarse_front, coarsen
from .config import FractureNumerics
from .elasticity import ElasticityOperator
from .front import DIRECTIONS, TipModel, _shift, cells_to_open, edge_cells, front_distances
from .geometry import filled_fraction, footprint
from .interpolate import StepEnds
from .leakoff import carter_demand, carter_volume
from .lubrication import build_faces
from .mesh import GROW, Grid, injection_cell_centre
from .newton import Elasticity, StepProblem, solve_step, start_widths
from .solver_choice import use_dense
from .tip_cells import fill_and_width, level_set, ribbon_distances

K_PRIME_FACTOR = math.sqrt(32.0 / math.pi)   # K' = sqrt(32/pi) K_Ic
FRONT_ITERATIONS = 30
FRONT_TOLERANCE = 1e-2
FRONT_SOLVE_TOLERANCE = 1e-3   # Newton's tolerance in the front iterations (_front_iterations)
MIN_STEP_FRACTION = 1e-9   # a step shorter than this fraction of the time stops the run
FAILED_STEP_MARGIN = 0.8     # the next steps stay below this fraction of the last step whose Newton failed ...
FAILED_STEP_RELEASE = 1.02  # ... a bound that grows by this factor with every accepted step


def _check_scene(scene) -> None:
    """Reject what the engine cannot run before any work starts."""
    if scene.rock is None or scene.injection is None:
        raise SceneError("rock" if scene.rock is None else "injection", "(missing)",
                         "the fracture engine needs [rock] and [injection]")
    first = scene.injection.schedule.stages[0]
    if first.rate <= 0.0:
        raise SceneError("injection.schedule[0].rate", first.rate,
                         "the first stage must inject (rate > 0) to start a fracture")


def initial_time(e_prime: float, mu_prime: float, k_prime: float, c_prime: float, q: float,
                 radius: float) -> tuple[float, float]:
    """(t0, a): the latest time at which a radial vertex solution reaches ``radius`` and its exponent a
    (R ~ t^a). Vertices (REFERENCE.md 1.1): M R = 0.6955 (E' Q^3 t^4 / mu')^(1/9); K R = 0.8546
    (E' Q t / K')^(2/5); Mt = Kt R = 0.4502 (Q^2 t / C'^2)^(1/4). In float64 arithmetic: an absurd rate
    (Q^3 past 1e308) gives t0 = 0, not an OverflowError from Python's float power."""
    q = np.float64(q)
    with np.errstate(over="ignore"):
        times = [((radius / 0.6955) ** 9 * mu_prime / (e_prime * q**3)) ** 0.25, ]
        powers = [4.0 / 9.0]
        if k_prime > 0.0:
            times.append((radius / 0.8546) ** 2.5 * k_prime / (e_prime * q))
            powers.append(0.4)
        if c_prime > 0.0:
            times.append((radius / 0.4502) ** 4 * c_prime**2 / q**2)
            powers.append(0.25)
    i = int(np.argmax(times))
    return float(times[i]), powers[i]


def start_time(schedule, e_prime: float, mu_prime: float, k_prime: float, c_prime: float,
               radius: float) -> tuple[float, float]:
    """(t0, a) of :func:`initial_time` at the schedule's mean rate to t0: the root of
    t0 = initial_time(q = V(t0) / t0) (the first stage's rate while t0 lies in it; bisection beyond, where
    V(t) / t is continuous). The starting fracture then holds the volume injected to t0. inf when it never
    reaches ``radius`` before the schedule ends."""
    def late(t: float) -> float:
        return initial_time(e_prime, mu_prime, k_prime, c_prime, schedule.volume(t) / t, radius)[0] - t

    t0, power = initial_time(e_prime, mu_prime, k_prime, c_prime, schedule.stages[0].rate, radius)
    if t0 <= schedule.stages[0].until:
        return t0, power
    if late(schedule.end) > 0.0:
        return math.inf, power
    t0 = brentq(late, schedule.stages[0].until, schedule.end, xtol=1e-12 * schedule.end)
    return t0, initial_time(e_prime, mu_prime, k_prime, c_prime, schedule.volume(t0) / t0, radius)[1]


class _Brackets:
    """Per-cell brackets [lo, hi] of the root of r(ell) = F(ell) - ell, r decreasing (positive below the
    root), with r at both ends, for ``_Engine._front_iterations``."""

    def __init__(self, shape: tuple[int, int]):
        self.lo, self.r_lo, self.hi, self.r_hi = (np.full(shape, np.nan) for _ in range(4))
        self.side = np.zeros(shape, int)

    def next(self, ell: np.ndarray, target: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """The next iterate from ell and F(ell) = target: regula falsi inside the bracket where both ends
        are known (Illinois: an end kept twice in a row has its residual halved), else F(ell)."""
        r = target - ell
        up, down = cells & (r > 0.0), cells & (r <= 0.0)
        self.r_hi[up & (self.side == 1)] *= 0.5
        self.r_lo[down & (self.side == -1)] *= 0.5
        self.lo[up], self.r_lo[up] = ell[up], r[up]
        self.hi[down], self.r_hi[down] = ell[down], r[down]
        self.side[up], self.side[down] = 1, -1
        both = np.isfinite(self.lo) & np.isfinite(self.hi)
        with np.errstate(invalid="ignore", divide="ignore"):
            falsi = self.lo + self.r_lo * (self.hi - self.lo) / (self.r_lo - self.r_hi)
        return np.where(both, falsi, target)

    def width(self) -> np.ndarray:
        """|hi - lo| where both ends are known, inf elsewhere."""
        return np.where(np.isfinite(self.lo) & np.isfinite(self.hi), np.abs(self.hi - self.lo), np.inf)


@dataclass(frozen=True)
class _View:
    """A state of the run that a snapshot is made of: the grid, its time, the leaked total [m^3] and K', C' on
    the grid's box."""

    grid: Grid
    t: float
    leaked: float
    kprime_box: np.ndarray
    cprime_box: np.ndarray


class _Engine:
    """Mutable state of one run (grid fields, active-set systems, counters)."""

    def __init__(self, scene, numerics: FractureNumerics):
        self.scene, self.num = scene, numerics
        rock, inj = scene.rock, scene.injection
        self.dx, self.dz = scene.mesh.dx, scene.mesh.dz
        self.area = self.dx * self.dz
        self.e_prime = rock.plane_strain_modulus
        self.mu_prime = 12.0 * scene.fluid.viscosity
        self.schedule = inj.schedule
        self.tip = TipModel(self.e_prime, self.mu_prime, numerics.tip_asymptote, numerics.tip_velocity)
        self.op = ElasticityOperator(self.dx, self.dz, self.e_prime)
        h = max(self.dx, self.dz)
        r0 = numerics.initial_radius_cells * h
        half = int(math.ceil(r0 / min(self.dx, self.dz))) + GROW
        self.grid = Grid.around_injection(self.dx, self.dz, *injection_cell_centre(scene), half)
        self._properties()
        k0 = K_PRIME_FACTOR * float(rock.toughness_at(np.array(inj.depth)))
        c0 = 2.0 * float(rock.leakoff_at(np.array(inj.depth)))
        self.t0, power = start_time(self.schedule, self.e_prime, self.mu_prime, k0, c0, r0)
        if self.t0 >= 0.5 * self.schedule.end or self.schedule.rate(self.t0) <= 0.0:
            raise SceneError("fracture.initial_radius_cells", numerics.initial_radius_cells,
                             f"the starting fracture ({r0:.3g} m) would take "
                             f"{'longer than the schedule' if math.isinf(self.t0) else f'{self.t0:.3g} s'} to form, past half "
                             f"the run ({self.schedule.end:g} s) or in a stage that does not inject; use a finer "
                             f"mesh")
        g = self.grid
        xo, zo = g.offsets()
        r = np.hypot(xo, zo)
        g["active"][...] = r < r0
        g["active"][r == r.min()] = True
        act = g["active"]
        g["opened"][act] = self.t0 * (r[act] / r0) ** (1.0 / power)
        g["reached"][act] = g["opened"][act]
        g["filled"][act] = g["opened"][act]
        self._rebuild()
        leaked = self.area * carter_volume(self.cprime_a, g["opened"][act], 0.0, self.t0)
        injected = self.schedule.volume(self.t0)
        if leaked.sum() > 0.9 * injected:
            leaked *= 0.9 * injected / leaked.sum()
        shape = np.linalg.solve(self.elastic.matrix if self.elastic.matrix is not None
                                else self.op.dense(self.ix, self.iz), np.ones(self.ix.size))
        g["w"][act] = shape * (injected - leaked.sum()) / (self.area * shape.sum())
        g["leaked"][act] = leaked / self.area
        self.leaked_total = float(leaked.sum())
        self.t = self.t0
        self.v_front = power * r0 / self.t0
        self.t_front = self.t0
        self.steps = self.newton_iterations = self.retries = self.rejected = self.coarsenings = 0
        self.factorisations = self.gmres_iterations = 0
        self.v_tip = 0.0
        self.dt_failed = math.inf   # the last step whose Newton failed, released step by step (next_dt)
        self.max_balance_error = 0.0
        self.ends: StepEnds | None = None   # the last step's two ends, when asked for (step's keep_ends)
        g["fill"][act] = 1.0

    def _properties(self) -> None:
        """sigma_0, K' = sqrt(32/pi) K_Ic and C' = 2 C_L at every box cell, from the layer table."""
        _, z = self.grid.centres()
        rock = self.scene.rock
        self.sigma_box = rock.min_stress_at(z)
        self.kprime_box = K_PRIME_FACTOR * rock.toughness_at(z)
        self.cprime_box = 2.0 * rock.leakoff_at(z)

    def _rebuild(self) -> None:
        """Systems of the current active set: indices, faces, C (dense or FFT), properties."""
        self.rows, self.cols, self.ix, self.iz = self.grid.active_indices()
        dense = use_dense(self.num.linear_solver, self.num.krylov_threshold, self.ix, self.iz)
        self.elastic = Elasticity(self.op, self.ix, self.iz, dense)
        self.faces = build_faces(self.ix, self.iz, self.dx, self.dz, self.mu_prime)
        sel = (self.rows, self.cols)
        self.sigma_a, self.cprime_a = self.sigma_box[sel], self.cprime_box[sel]
        self.inj = int(np.flatnonzero((self.ix == 0) & (self.iz == 0))[0])
        self.distances = None

    # ------------------------------------------------------------------------------------------
    def step(self, dt: float, keep_ends: bool = False) -> float:
        """Advance by dt; returns the step taken. A step whose Newton iteration fails, or in which the front
        moves more than ``max_front_advance`` cells (``_front_advance``), is redone with half the step. With
        ``keep_ends`` the step's two ends are kept in ``ends`` (interpolate.StepEnds), else ``ends`` is None."""
        if self.num.front_tracking == "subgrid":
            return self._step_subgrid(dt, keep_ends)
        g = self.grid
        start = g.copy() if keep_ends else None
        reach_old = self._front_reach(self._view_distances(self.now()))
        h = min(self.dx, self.dz)
        for attempt in range(self.num.max_step_retries + 1):
            res = self._solve(dt)
            if res.converged:
                advance = self._front_advance(reach_old, res.w, res.p, self.t + dt)
                if advance <= self.num.max_front_advance * h or attempt == self.num.max_step_retries:
                    break
                self.rejected += 1
            elif attempt == self.num.max_step_retries:
                self._newton_failed(res, dt)
            else:
                self._newton_retry(dt)
            dt *= 0.5
        self._accept(res, dt, advance, start)
        self._advance_front()
        return dt

    def _solve(self, dt: float, pinned: np.ndarray | None = None, w_start: np.ndarray | None = None,
               preconditioner=None, tolerance: float | None = None, simplified_exit: bool = False):
        """One implicit step [t, t + dt] from the grid's state (newton.solve_step) on the current active set;
        ``pinned``: prescribed widths (NaN: unknown) of the active cells, whose ``fill`` is their wetted
        fraction (sub-grid front); ``w_start``: Newton's first iterate (None: newton.start_widths);
        ``preconditioner``: an earlier solve's on the same active set (StepResult.preconditioner);
        ``tolerance``: Newton's (None: the scene's newton_tolerance); ``simplified_exit``: newton.solve_step's."""
        g = self.grid
        sel = (self.rows, self.cols)
        w_old, tau, leaked_old = g["w"][sel], g["opened"][sel], g["leaked"][sel]
        filled = g["filled"][sel] if self.num.partial_tip_cells and pinned is None else None
        wetted = None if pinned is None else np.where(np.isfinite(pinned), g["fill"][sel], 1.0)
        source = np.zeros(w_old.size)
        source[self.inj] = self.schedule.mean_rate(self.t, self.t + dt) * dt
        if self.num.leakoff_clock:   # with a wetted fraction: the volume leaked per wetted area
            clock = leaked_old if wetted is None else np.divide(leaked_old, wetted, out=np.zeros_like(leaked_old),
                                                                where=wetted > 0.0)
            demand = carter_demand(self.cprime_a, tau, clock, self.t, self.t + dt, filled)
        else:
            demand = carter_volume(self.cprime_a, tau, self.t, self.t + dt, filled)
        w_eps = np.maximum(self.num.leakoff_width_fraction * demand, 1e-2 * float(w_old.max()))
        prob = StepProblem(self.ix, self.iz, w_old, self.sigma_a, self.faces, self.area, dt, source,
                           demand, w_eps, 1e-3 * float(w_old.max()), pinned, wetted)
        closed = g.shut(self.t)[sel] if pinned is None else None   # the last step's contact set
        with blas_threads(self.ix.size):
            res = solve_step(prob, self.elastic, tolerance or self.num.newton_tolerance,
                             self.num.newton_max_iterations,
                             None if w_start is None else np.where(w_start > 0.0, w_start, start_widths(prob)),
                             closed, preconditioner, simplified_exit)
        self.newton_iterations += res.iterations
        self.factorisations += res.work.factorisations
        self.gmres_iterations += res.work.gmres_iterations
        return res

    def _newton_retry(self, dt: float) -> None:
        """Count a step of length dt whose Newton iteration failed and is redone shorter; the steps after it
        stay below it (``dt_failed``, next_dt)."""
        self.retries += 1
        self.dt_failed = dt

    def _newton_failed(self, res, dt: float) -> None:
        worst = int(np.nanargmax(np.where(np.isfinite(res.residual), np.abs(res.residual), np.inf)))
        raise SimulationError("Newton iteration failed after the allowed step retries",
                              time=self.t + dt, cell=(int(self.ix[worst]), int(self.iz[worst])),
                              residual=float(np.abs(res.residual[worst]) / self.area))

    def _accept(self, res, dt: float, advance: float, start: Grid | None) -> None:
        """Store an accepted step's widths, pressures and leak-off and move the clock; with ``start`` (the grid
        at the step's start) keep both ends in ``ends``."""
        if not (np.all(np.isfinite(res.w)) and np.all(np.isfinite(res.p))):
            raise SimulationError("non-finite width or pressure", time=self.t + dt)
        g, sel = self.grid, (self.rows, self.cols)
        t_a, leaked_a = self.t, self.leaked_total
        self.t += dt
        g["w"][sel] = res.w
        g["p"][sel] = res.p
        self.distances = None
        g["leak_rate"][sel] = res.leaked / (self.area * dt)
        g["leaked"][sel] = g["leaked"][sel] + res.leaked / self.area
        self.leaked_total += float(res.leaked.sum())
        self.v_tip = advance / dt
        self.dt_failed *= FAILED_STEP_RELEASE
        self.steps += 1
        self.ends = None if start is None else StepEnds(t_a, self.t, start, g.copy(), leaked_a, self.leaked_total,
                                                        self.kprime_box, self.cprime_box)

    # -- sub-grid front (front_tracking = "subgrid") ------------------------------------------------
    def _step_subgrid(self, dt: float, keep_ends: bool) -> float:
        """One step with tip cells (module docstring): the front's position at the tip cells and the step's
        solution are iterated to a fixed point (``_front_iterations``). A step whose Newton iteration fails,
        or in which the front moves more than ``max_front_advance`` cells, is redone with half the step."""
        h = min(self.dx, self.dz)
        before = self.grid.shape
        self.grid.ensure_margin(4)   # room for the front to move within the step without growing the box
        if self.grid.shape != before:
            self._use_grid(self.grid)
        start = self.grid.copy()
        for attempt in range(self.num.max_step_retries + 1):
            res, advance, ok = self._front_iterations(dt, start)
            if ok and (advance <= self.num.max_front_advance * h or attempt == self.num.max_step_retries):
                break
            if not ok and attempt == self.num.max_step_retries:
                self._newton_failed(res, dt)
            if ok:
                self.rejected += 1
            else:
                self._newton_retry(dt)
            self._use_grid(start.copy())
            dt *= 0.5
        self._accept(res, dt, advance, start if keep_ends else None)
        self.v_front, self.t_front = self.v_tip, self.t
        g = self.grid
        g["w_rate"][...] = np.where(g["active"] & start["active"], (g["w"] - start["w"]) / dt, 0.0)
        return dt

    def _front_iterations(self, dt: float, start) -> tuple:
        """(result, front advance [m], converged) of a step from the grid ``start``: solve with the tip
        widths pinned, place the front (tip_cells: ribbon distances, level set; never backwards), until the
        front's position at every tip cell reproduces itself, |F(a) - a| < FRONT_TOLERANCE cells (a = how far
        the front is past the cell's centre). F decreases with a (a wider tip leaves less fluid to the
        ribbon), so each cell's root is bracketed as the iterations go and found by regula falsi (Illinois)
        inside its bracket, plain iteration a = F(a) until it has one. The channel and its ribbon cells are
        those of the step's start throughout the step (as in PyFrac's ILSA, Zia & Lecampion 2020): a cell the
        front enters becomes a tip cell (active, its Carter opening time the step's middle, which restarts the
        brackets), and one it crosses stays a pinned tip cell, wholly wetted, until the step is accepted. (Turning
        crossed cells into channel cells within the step swapped their width from the asymptote's mean to the
        elastic solution, a jump that made the front leap by most of a cell in radial case IV.) The ribbons'
        distances take the step's own front speed (tip_cells.ribbon_distances with s_0 = their ``advance``
        at the start), and the converged ones are kept there for the next step. An iterate
        that puts the front more than twice ``max_front_advance`` past its start ends the iterations: the step
        is redone shorter (the level set reaches LAYERS cells out, and pinning tip cells that far out in one
        go can stop Newton). Newton starts from the widths extrapolated along the last step's dw/dt (``w_rate``),
        then from the last iterate's. The iterates' solves stop at FRONT_SOLVE_TOLERANCE (their widths only place
        the front, to FRONT_TOLERANCE cells); once it has converged the step is solved to ``newton_tolerance``
        with that front (radial_viscosity_subgrid.toml: 2.1 Newton iterations in a step's first solve instead of
        3.7; 10.1-10.4 s against 10.3-10.9 s with only that solve loose; the same results to the printed
        digits)."""
        g = self.grid
        h = min(self.dx, self.dz)
        channel = start["active"] & (start["fill"] >= 1.0)
        was_tip = start["active"] & ~channel
        floor = np.where(was_tip, start["advance"], -np.inf)
        pinned_box = np.where(was_tip, g["w"], np.nan)
        advance = 0.0
        # Newton's first iterate: the widths extrapolated along the last step's rate, then the last solved ones
        last = g["w"] + g["w_rate"] * dt
        bracket = _Brackets(g.shape)
        s_start = np.where(channel, start["advance"], np.nan)   # the ribbons' distances at the start, if known
        precond = None     # the last solve's Newton-Krylov preconditioner, while the active set stays
        loose = max(FRONT_SOLVE_TOLERANCE, self.num.newton_tolerance)
        for _ in range(FRONT_ITERATIONS):
            res = self._solve(dt, pinned_box[self.rows, self.cols], last[self.rows, self.cols], precond, loose,
                              simplified_exit=True)
            precond = res.preconditioner
            if not res.converged:
                return res, advance, False
            w_box, p_box = g["w"].copy(), g["p"].copy()
            w_box[self.rows, self.cols], p_box[self.rows, self.cols] = res.w, res.p
            last = np.where(g["active"], w_box, 0.0)
            s_rib, v_rib = ribbon_distances(self.tip, channel, w_box, p_box, self.kprime_box, self.cprime_box,
                                            g["reached"], self.t + dt, self.dx, self.dz, (s_start, dt),
                                            self.num.ribbon_fit)
            target, nx, nz, src = level_set(s_rib, channel, self.dx, self.dz)
            cand = np.isfinite(target)
            target = np.where(cand, np.fmax(target, floor), np.nan)
            reach = -0.5 * (np.abs(nx) * self.dx + np.abs(nz) * self.dz)   # the front at the cell's nearest corner
            known = g["active"] & np.isfinite(g["advance"])
            now = np.where(known, g["advance"], reach)
            # how far each cell's front position is from reproducing itself; settled: a cell the front has
            # not reached either way (both below reach: dry), or whose root the bracket holds to the
            # tolerance (F may jump across its root)
            gap = np.where(cand & (bracket.width() >= FRONT_TOLERANCE * h),
                           np.abs(np.maximum(target, reach) - np.maximum(now, reach)), 0.0)
            ribbon = np.isfinite(s_rib)
            g["advance"][ribbon] = s_rib[ribbon]   # the ribbons' distances: the next step's s_0
            if float(gap.max()) < FRONT_TOLERANCE * h:
                if loose > self.num.newton_tolerance:   # the step itself to the scene's tolerance
                    res = self._solve(dt, pinned_box[self.rows, self.cols], last[self.rows, self.cols], precond,
                                      simplified_exit=True)
                return res, advance, res.converged
            moved = np.where(cand, bracket.next(np.where(cand, now, 0.0), np.where(cand, target, 0.0), cand), np.nan)
            advance, entered = self._place_front(moved, (cand, nx, nz, src, v_rib), pinned_box, was_tip, floor,
                                                 dt)
            if advance > 2.0 * self.num.max_front_advance * h:
                break   # far past the limit already: the step will be redone shorter
            if entered:
                bracket = _Brackets(g.shape)
                precond = None
        res = self._solve(dt, pinned_box[self.rows, self.cols], simplified_exit=True)   # the last front
        return res, advance, res.converged

    def _place_front(self, moved: np.ndarray, geometry: tuple, pinned_box: np.ndarray, was_tip: np.ndarray,
                     floor: np.ndarray, dt: float) -> tuple[float, bool]:
        """Put the front ``moved`` past the centres of the level set's cells (``geometry``: those cells, the
        normal, the ribbon each leans on, its tip velocity): their wetted fraction, ``advance`` and pinned
        width (in ``pinned_box``, in place: the asymptote's mean, which may fall below the step's start width:
        flooring it there, with tip cells now staying tips until crossed, held back fluid and stopped Newton in
        radial case II); a cell the front enters (one next to an active cell: one layer per iteration, so a start whose
        ribbons put the front two layers out, as the initial fracture's can, does not pin both at once and
        stop Newton) becomes active with its Carter opening time at the step's middle.
        Returns (the farthest the front now is past where it was at the step's start, in m; whether cells
        entered)."""
        g, h = self.grid, min(self.dx, self.dz)
        cand, nx, nz, src, v_rib = geometry
        ks = src[cand]
        fill, width = fill_and_width(self.tip, moved[cand], nx[cand], nz[cand], self.kprime_box.ravel()[ks],
                                     self.cprime_box.ravel()[ks], v_rib.ravel()[ks], self.dx, self.dz)
        fill_box, width_box = np.zeros(g.shape), np.zeros(g.shape)
        fill_box[cand], width_box[cand] = fill, width
        beside = np.zeros(g.shape, bool)   # next to an active cell: the front enters one layer per iteration
        for dk, di in DIRECTIONS:
            beside |= _shift(g["active"], dk, di, False)
        tip = cand & (fill_box > 0.0)
        entered = tip & ~g["active"] & beside
        if entered.any():
            g.fields["active"] = g["active"] | entered
            for name in ("opened", "reached", "filled"):
                g[name][entered] = self.t + 0.5 * dt
            g["w"][entered] = 0.0
        update = cand & g["active"]   # an entered cell the front has left again keeps fill 0 and width 0
        moved_by = float(np.max((moved - np.where(was_tip, floor, -0.5 * h))[update & tip], initial=0.0))
        g["advance"][update] = moved[update]
        g["fill"][update] = fill_box[update]
        pinned_box[update] = width_box[update]
        if entered.any():
            self._rebuild()
        return moved_by, bool(entered.any())

    def _use_grid(self, grid) -> None:
        self.grid = grid
        self._properties()
        self._rebuild()

    def _front_reach(self, distances: list[np.ndarray]) -> np.ndarray:
        """Largest sub-grid front distance s (Eq. 33 inverted, front.front_distances) of every box cell,
        capped at 2 cells; 0 where a cell faces no inactive cell."""
        return np.minimum(np.nan_to_num(np.fmax.reduce(distances), nan=0.0), 2.0 * max(self.dx, self.dz))

    def _front_advance(self, reach_old: np.ndarray, w: np.ndarray, p: np.ndarray, t: float) -> float:
        """Largest distance any front point moved over a step that ends at t with active widths w and
        pressures p (the measured tip advance of Eq. 34)."""
        g, sel = self.grid, (self.rows, self.cols)
        w_box, p_box = g["w"].copy(), g["p"].copy()
        w_box[sel], p_box[sel] = w, p
        reach = self._front_reach(front_distances(self.tip, g["active"], w_box, p_box, self.kprime_box,
                                                  self.cprime_box, g["reached"], t, self.dx, self.dz))
        return float(np.max(reach - reach_old))

    def _advance_front(self) -> None:
        """Open the cells the front criterion selects (Eq. 33) and record the tip speed (Eq. 34)."""
        g = self.grid
        to_open, speed = cells_to_open(self.tip, g["active"], g["w"], g["p"], self.kprime_box, self.cprime_box,
                                       g["reached"], self.t, self.dx, self.dz)
        if not to_open.any():
            return
        g.fields["active"] = g["active"] | to_open
        g["reached"][to_open] = self.t
        g["opened"][to_open] = self.t
        g["filled"][to_open] = self.t + min(self.dx, self.dz) / speed[to_open]
        g["w"][to_open] = 0.0
        self.v_front = float(np.nanmax(speed))
        self.t_front = self.t
        before = g.shape
        g.ensure_margin()
        if g.shape != before:
            self._properties()
        self._rebuild()

    def coarsen_if_wide(self) -> None:
        """Continue on a grid ``mesh.coarsening_factor`` times coarser (coarsen.py: 3x3 merges, or PyFrac's 2x
        remeshing) once the footprint spans more than ``mesh.max_cells_across`` cells along x or z. Fluid volume
        is carried exactly (w = sum of the fine cells' share x w / f^2), pressure as the mean, opening and
        front-arrival times as the earliest fine cell's. With the 2x remeshing the sub-grid front is carried
        too (coarsen.coarse_front: coarse tip cells where it crosses, wetted area exact); a 3x3 merge makes
        every coarse cell a channel cell (module docstring)."""
        cap = self.scene.mesh.max_cells_across
        if cap is None or max(np.ptp(self.ix), np.ptp(self.iz)) + 1 <= cap:
            return
        g, sel = self.grid, (self.rows, self.cols)
        f = self.scene.mesh.coarsening_factor
        c = coarsen(self.ix, self.iz, factor=f)
        if self.num.front_tracking == "subgrid" and f == 2:
            tips, nx, nz = self._tip_normals(self.now())
            fill, advance = coarse_front(c, self.ix, self.iz, g["fill"][sel], np.where(tips, nx, 0.0)[sel],
                                         np.where(tips, nz, 0.0)[sel], self.dx, self.dz)
        else:
            fill, advance = np.ones(c.ix.size), np.full(c.ix.size, np.nan)
        half = int(max(np.abs(c.ix).max(), np.abs(c.iz).max())) + GROW
        new = Grid.around_injection(f * self.dx, f * self.dz, g.x_inj, g.z_inj, half)
        at = (c.iz + half, c.ix + half)
        new["active"][at] = True
        new["w"][at] = c.width(g["w"][sel])
        new["p"][at] = c.mean(g["p"][sel])
        new["leak_rate"][at] = c.total(g["leak_rate"][sel]) / f**2
        new["leaked"][at] = c.total(g["leaked"][sel]) / f**2
        new["opened"][at] = c.earliest(g["opened"][sel])
        new["reached"][at] = c.earliest(g["reached"][sel])
        new["filled"][at] = -c.earliest(-g["filled"][sel])
        new["fill"][at] = fill
        new["advance"][at] = advance
        new["w_rate"][at] = c.width(g["w_rate"][sel])
        self.grid = new
        self.dx, self.dz = new.dx, new.dz
        self.area = self.dx * self.dz
        self.op = ElasticityOperator(self.dx, self.dz, self.e_prime)
        self.coarsenings += 1
        self._properties()
        self._rebuild()

    def next_dt(self, dt_prev: float) -> float:
        """Eq. 35, dt = lambda min(dx, dz) / V_T, with V_T the larger of the latest opening's front speed
        (Eq. 34; no larger than h / (time since that opening)) and the sub-grid front's measured speed over
        the last step, and growth limited by max_step_growth and by FAILED_STEP_MARGIN times the last step
        whose Newton failed (that bound growing by FAILED_STEP_RELEASE a step: without it the sub-grid front
        grew each step by 1.5 into a failure and a halved retry, every second step in radial case II)."""
        h = min(self.dx, self.dz)
        v = self.v_front
        if self.t > self.t_front:
            v = min(v, h / (self.t - self.t_front))
        v = max(v, self.v_tip, 1e-300)
        return min(self.num.time_step_relaxation * h / v, self.num.max_step_growth * dt_prev,
                   FAILED_STEP_MARGIN * self.dt_failed)

    # ------------------------------------------------------------------------------------------
    def balance(self) -> BalanceRecord:
        """The volume balance and the pressure history at the current state (records.BalanceRecord)."""
        g = self.grid
        stored = float(g["w"][g["active"]].sum()) * self.area
        injected = self.schedule.volume(self.t)
        inlet = (self.rows[self.inj], self.cols[self.inj])
        pressure = float(g["p"][inlet])
        size = self.geometry(self.now())
        return BalanceRecord(time=self.t, injected=injected, stored=stored, leaked=self.leaked_total,
                             injection_pressure=pressure, net_pressure=pressure - float(self.sigma_a[self.inj]),
                             efficiency=stored / injected if injected > 0.0 else math.nan, area=size["area"],
                             length=size["length"], height=size["height"],
                             inlet_width=float(g["w"][inlet]))

    def now(self) -> _View:
        """The current state as a :class:`_View`."""
        return _View(self.grid, self.t, self.leaked_total, self.kprime_box, self.cprime_box)

    def between(self, t: float) -> _View:
        """The state at a time t inside the last step, interpolated between its two ends (interpolate.py;
        the step was taken with ``keep_ends``)."""
        e = self.ends
        return _View(e.state_at(t, self.t0), t, e.leaked(t), e.kprime_box, e.cprime_box)

    def snapshot(self, view: _View, time: float) -> FractureSnapshot:
        """The snapshot of ``view`` stamped ``time``: the fields on the footprint's bounding box plus one cell,
        the front summary (``front_*``), the footprint's size (geometry.footprint) and the volume balance
        (``injected_volume``, ``stored_volume``, ``leaked_volume``) as scalar extras."""
        g = view.grid
        rs, cs = g.bounding_box(1)
        x, z = g.centres()
        act = g["active"][rs, cs]
        width = np.where(act, g["w"][rs, cs], 0.0)
        frame = GridFrame(g.dx, g.dz, float(x[rs, cs][0, 0]), float(z[rs, cs][0, 0]))
        scalars = {f"front_{k}": v for k, v in self.front(view).items()} | self.geometry(view) | dict(
            injected_volume=self.schedule.volume(view.t), stored_volume=float(width.sum()) * g.dx * g.dz,
            leaked_volume=view.leaked)
        return FractureSnapshot(
            time=time, frame=frame, width=width, pressure=np.where(act, g["p"][rs, cs], 0.0),
            leakoff_rate=np.where(act, g["leak_rate"][rs, cs], 0.0),
            opening_time=np.where(act, g["opened"][rs, cs], np.nan),
            extras={k: np.array(v) for k, v in scalars.items()})

    def _view_distances(self, view: _View) -> list[np.ndarray]:
        """front.front_distances of ``view`` (per side, from each edge cell's centre to the front). The current
        state's are computed once and kept in ``distances``: the balance's area, the front summary and the next
        step's front reach share them (a change of the widths or of the active set clears them)."""
        now = view.grid is self.grid and view.t == self.t
        if now and self.distances is not None:
            return self.distances
        g = view.grid
        distances = front_distances(self.tip, g["active"], g["w"], g["p"], view.kprime_box, view.cprime_box,
                                    g["reached"], view.t, g.dx, g.dz)
        if now:
            self.distances = distances
        return distances

    def geometry(self, view: _View) -> dict:
        """Area, equal-area radius, length and height of the footprint, tip cells by their filled fraction
        (geometry.py)."""
        g = view.grid
        distances = None if self.num.front_tracking == "subgrid" else self._view_distances(view)
        fraction = filled_fraction(self.num.front_tracking, g["active"], g["fill"], distances, g.dx, g.dz,
                                   g.shut(view.t))
        return footprint(fraction, g.dx, g.dz)

    def _tip_normals(self, view: _View) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tips, nx, nz): the sub-grid front's tip cells (active, not wholly wetted, placed) and the level
        set's unit normal (tip_cells.level_set from the ribbons' inverted widths; NaN off its cells)."""
        g = view.grid
        channel = g["active"] & (g["fill"] >= 1.0)
        s_rib, _ = ribbon_distances(self.tip, channel, g["w"], g["p"], view.kprime_box, view.cprime_box,
                                    g["reached"], view.t, g.dx, g.dz, fit=self.num.ribbon_fit)
        _, nx, nz, _ = level_set(s_rib, channel, g.dx, g.dz)
        return g["active"] & ~channel & np.isfinite(g["advance"]) & np.isfinite(nx), nx, nz

    def front(self, view: _View) -> dict:
        """Sub-grid front: distances from the injection point to the front and its extents up (-z), down
        (+z), left (-x), right (+x). With cells: r + s at the edge cells (s from the inverted tip asymptote,
        capped at one cell); with the sub-grid front: the points x + a n of the tip cells (tip_cells), or as
        with cells where there are none (right after a coarsening)."""
        g, dx, dz = view.grid, view.grid.dx, view.grid.dz
        xo, zo = g.offsets()
        zo = zo + (g.z_inj - self.scene.injection.depth)   # the injection cell's centre is up to dz/2 off it (mesh.py)
        tips = np.zeros(g.shape, bool)
        if self.num.front_tracking == "subgrid":
            tips, nx, nz = self._tip_normals(view)
        if tips.any():   # none right after a 3x3 merge: every cell is then a channel cell
            px, pz = (xo + g["advance"] * nx)[tips], (zo + g["advance"] * nz)[tips]
            radii = np.hypot(px, pz)
            ext = dict(right=px.max(), left=-px.min(), down=pz.max(), up=-pz.min())
        else:
            dist = self._view_distances(view)
            best = np.zeros(xo.shape)
            ext = {}
            for name, (dk, di), s in zip(("right", "left", "down", "up"), DIRECTIONS, dist):
                s = np.minimum(s, dz if dk else dx)
                coord = (zo * dk if dk else xo * di) + s
                ext[name] = np.nanmax(coord) if np.isfinite(coord).any() else 0.0
                best = np.fmax(best, s)
            edge = edge_cells(g["active"])
            radii = np.hypot(xo, zo)[edge] + best[edge]
        return dict(radius=float(radii.mean()), radius_min=float(radii.min()), radius_max=float(radii.max()),
                    **{k: max(float(v), 0.0) for k, v in ext.items()})

    # -- checkpoints ------------------------------------------------------------------------------
    #: Attributes (numbers or arrays) a checkpoint carries besides the grid: list every new persistent one here.
    STATE_ATTRIBUTES = ("t", "t0", "v_front", "t_front", "leaked_total", "steps", "newton_iterations", "retries",
                        "coarsenings", "max_balance_error", "v_tip", "rejected", "dt_failed", "factorisations",
                        "gmres_iterations")

    def state(self) -> dict:
        """Everything needed to continue from now (a checkpoint): STATE_ATTRIBUTES, the grid (placement and every
        field) and the capacity of the elasticity kernel cache (so FFT products keep their size, hence their
        round-off). Derived systems (active set, faces, C, properties) are rebuilt by :meth:`restore`."""
        g = self.grid
        return {**{name: getattr(self, name) for name in self.STATE_ATTRIBUTES},
                "grid": {"dx": g.dx, "dz": g.dz, "x_inj": g.x_inj, "z_inj": g.z_inj, "ix0": g.ix0, "iz0": g.iz0,
                         "fields": {name: array.copy() for name, array in g.fields.items()}},
                "elasticity_capacity": np.array(self.op._capacity)}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state` (of a run of the same scene): same fields, same systems."""
        for name in self.STATE_ATTRIBUTES:
            setattr(self, name, np.array(state[name]) if isinstance(state[name], np.ndarray) else state[name])
        s = state["grid"]
        self.grid = Grid(s["dx"], s["dz"], s["x_inj"], s["z_inj"], int(s["ix0"]), int(s["iz0"]),
                         {name: np.array(array) for name, array in s["fields"].items()})
        self.dx, self.dz = self.grid.dx, self.grid.dz
        self.area = self.dx * self.dz
        self.op = ElasticityOperator(self.dx, self.dz, self.e_prime)
        self.op._ensure(*(int(n) for n in state["elasticity_capacity"]))
        self._properties()
        self._rebuild()


def _times(scene, t0: float) -> tuple[list[float], list[float]]:
    """(times steps must land on, output times), both sorted: the schedule's breakpoints and the end (physics),
    and every ``output.every`` and the end, after t0."""
    end = scene.run.end_time
    every = scene.output.every
    outputs = {every * k for k in range(1, int(math.floor(end / every + 1e-9)) + 1)} | {end}
    breaks = {b for b in scene.injection.schedule.breakpoints() if t0 < b < end}
    return sorted(breaks | {end}), sorted(t for t in outputs if t0 < t <= end)


def _landed(output: float, t: float) -> bool:
    """Whether a step ending at t lands on the output time (within 1e-9 relative: 3 x 0.1 s is 0.3 s)."""
    return abs(output - t) <= 1e-9 * t


def simulate(scene, sink, progress: Callable[[float], None] | None = None, checkpoint=None,
             resume: dict | None = None) -> dict:
    """Run the planar-3D fracture model of ``scene`` to ``run.end_time`` (paper sections 2.2, 3.1).

    Calls ``sink.fracture_balance(BalanceRecord)`` after every accepted step and
    ``sink.fracture_snapshot(FractureSnapshot)`` at every ``output.every`` and at the end; ``progress(t)``
    after each step. Steps land on the schedule's breakpoints and the end time, never on output times: a
    snapshot at a time inside a step is interpolated between the step's two ends (interpolate.py), one at
    a time a step lands on (within 1e-9 relative, the end time always) is that step's state, so the steps
    and the solution do not depend on ``output.every``. With ``mesh.max_cells_across`` set, the grid is
    coarsened (3x3, or by 2: ``mesh.coarsening_factor``) each time the footprint spans more cells than that
    along x or z (snapshots then carry the coarser frame). Returns a summary: time, steps, newton_iterations, factorisations and gmres_iterations
    (the linear solver's work, newton.NewtonWork), retries, rejected (steps redone for a too-long front
    advance), coarsenings, dx, dz (final cell sizes), cells, the sub-grid front (radius, radius_min,
    radius_max, up, down, left, right), the footprint (area, area_radius, length, height; geometry.py),
    w_inlet, p_inlet, the final balance (injected, stored, leaked) and max_balance_error (relative).

    Checkpoints (hfgpu.io.checkpoint): after the first step that ends at or past each interval (and after
    that step's snapshots), ``checkpoint.save(t, state)`` gets {"engine": _Engine.state(), "dt": next step,
    "target": index of the step target}; ``resume`` (such a state) continues from it, with the same steps as
    an uninterrupted run and the snapshots after t.
    """
    _check_scene(scene)
    numerics = scene.fracture if scene.fracture is not None else FractureNumerics()
    eng = _Engine(scene, numerics)
    targets, outputs = _times(scene, eng.t0)
    dt = numerics.time_step_relaxation * min(eng.dx, eng.dz) / eng.v_front
    first = 0
    if resume is not None:
        eng.restore(resume["engine"])
        dt, first = resume["dt"], int(resume["target"])
    k = sum(1 for t in outputs if t < eng.t or _landed(t, eng.t)) if resume is not None else 0   # next output
    for index in range(first, len(targets)):
        target = targets[index]
        while eng.t < target * (1 - 1e-12):
            remaining = target - eng.t
            step = min(dt, remaining)
            if remaining - step < 1e-3 * step:
                step = remaining
            if step < MIN_STEP_FRACTION * target:
                raise SimulationError(f"the time step fell to {step:.3g} s (below {MIN_STEP_FRACTION:g} of the "
                                      "time): the front keeps moving more than max_front_advance cells however "
                                      "short the step; raise [fracture] max_front_advance", time=eng.t)
            taken = eng.step(step, keep_ends=k < len(outputs) and outputs[k] < eng.t + step)
            if abs(eng.t - target) < 1e-9 * target:
                eng.t = target
            record = eng.balance()
            error = abs(record.injected - record.stored - record.leaked) / record.injected
            eng.max_balance_error = max(eng.max_balance_error, error)
            sink.fracture_balance(record)
            if progress is not None:
                progress(eng.t)
                show_limit(progress, taken, "snapshot interval" if taken == step == remaining else "front advance")
            while k < len(outputs) and (outputs[k] < eng.t or _landed(outputs[k], eng.t)):
                view = eng.now() if _landed(outputs[k], eng.t) else eng.between(outputs[k])
                sink.fracture_snapshot(eng.snapshot(view, outputs[k]))
                k += 1
            if eng.t < targets[-1]:   # a merge is for the steps that follow
                eng.coarsen_if_wide()
            dt = eng.next_dt(dt if taken == step else taken)
            if checkpoint is not None and checkpoint.due(eng.t):
                checkpoint.save(eng.t, {"engine": eng.state(), "dt": dt, "target": index})
    final = eng.balance()
    return dict(time=eng.t, t0=eng.t0, steps=eng.steps, newton_iterations=eng.newton_iterations,
                factorisations=eng.factorisations, gmres_iterations=eng.gmres_iterations, retries=eng.retries,
                rejected=eng.rejected, coarsenings=eng.coarsenings, dx=eng.dx, dz=eng.dz,
                cells=int(eng.grid["active"].sum()), w_inlet=final.inlet_width,
                p_inlet=final.injection_pressure, injected=final.injected, stored=final.stored,
                leaked=final.leaked, max_balance_error=eng.max_balance_error, **eng.front(eng.now()),
                **eng.geometry(eng.now()))
