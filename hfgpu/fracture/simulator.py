"""The planar-3D fracture engine's time loop: ``simulate(scene, sink, progress=None) -> summary``.

Each step [t, t + dt] solves the implicit elasticity-lubrication-leak-off system for the widths of the
active cells (Newton, :mod:`newton`) and moves the front by the strategy ``front_tracking`` names
(front_strategy.py: whole cells, front_cells.py, or the sub-grid front, front_subgrid.py), then chooses the next
step by Eq. 35 with V_T the larger of the last opening's speed (Eq. 34) and the front's measured speed over the
step just taken. Steps land on schedule breakpoints and the end time (physics), never on output times: a
snapshot between two accepted steps is interpolated between them (interpolate.py, views.py), so the steps and
the results do not depend on the output spacing. A step whose Newton iteration fails, or in which the front
moved more than ``max_front_advance`` cells, is redone with half the step (``max_step_retries`` times; then a
Newton failure raises SimulationError naming time, cell and residual, a long advance is accepted), so the front
does not over-run on long steps. Cells squeezed shut stay closed at w = 0 (contact, newton.solve_step). The
injected volume of a step is exact (Schedule.mean_rate), leak-off is Carter's law integrated exactly
(:mod:`leakoff`), the flux form conserves volume and each accepted step's widths balance its volume exactly
(newton.solve_step's volume-conserving shift), so injected = stored + leaked to round-off at every step.

Start. The run starts at t0 from a radial fracture of radius R0 = ``initial_radius_cells`` cells around the
injection cell's centre (the cells whose centres lie inside it; the grid is placed on the layer boundaries,
mesh.fit_layers, so that centre is up to half a cell from the injection depth). t0 is the latest of the times
at which the four radial vertex solutions (M, K, Mt, Kt: Savitski & Detournay 2002, Madyarova 2003) reach R0
with the properties at the injection point -- the slowest mechanism controls early growth -- and the cells'
opening times follow that vertex's R ~ t^a (tau = t0 (r / R0)^(1/a)). The cells hold the volume injected by t0 less the Carter volume leaked since
their opening times (at most 90 % of it), in the shape a uniform net pressure gives (C w = const).

Closure. Carter leak-off drains a shut-in fracture; the positivity ramp (leakoff.available_fraction) keeps a
draining cell's width above 0, so without a rule its walls would never meet. A cell whose width falls, over a
step without injection, below ``closure_width_fraction`` of the largest width the fracture has had (``w_peak``)
while Carter's demand over the step is at least that width (the ramp held it back: the film would leak off
within the step) is closed at the end of that step (while pumping, the ramp alone governs starved cells; a
cell thinned by the fluid flowing on, as in a spreading pulse without leak-off, stays open): width 0, the film
left in it added to the leak-off (the balance stays exact; after shut-in a width the contact passes leave below
0 within their tolerance is set to 0 the same way), and from then on it is a contact cell (newton.solve_step):
it leaks no more, counts no area (geometry.py), passes pressure to closed neighbours through a residual aperture
(newton.StepProblem.w_floor), and opens again when the fluid pressure exceeds the stress that holds it shut (a
second injection: the perforated cell starts that step open). A shut-in step in which cells closed is not
followed by a longer one (CLOSING_GROWTH), and Newton starts a step without injection from the drained widths
(newton.drained_start). A fracture whose cells are all closed and that takes no injection has nothing to solve:
its steps cost a record each and grow (the fall-off's record goes on past closure, as a gauge's does).
``t_closed`` is the time the last open cell closed (NaN while any cell is open), the crossing of the threshold
inside the step that closed it (``closing_time``, linear in time): a shut-in's steps grow to a good part of the
time, and the step's end would report closure up to a step late; the summary reports it. A sub-grid front pins
its tip cells to the asymptote of a propagating front (K_I = K_Ic), which a draining fracture's tip no longer is:
they would hold their width with no fluid to feed them. So when the first cell of a sub-grid run drains, the
front hands over to whole cells (``recede``, at ``t_receding``): every active cell becomes whole, its width
(hence the volume) kept, and the contact set recedes it from then on, re-injection included.

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

Slurry (two-way coupling, slurry.py). ``simulate(..., slurry=)`` or ``FractureRun.engine.use_slurry`` between
``FractureRun.advance`` calls give the engine per-cell viscosity ratios (the lubrication faces' mu'), blocked
cells the front cannot pass (front.cells_to_open) and, in steps without injection, the width at which the walls
meet the proppant (newton.py's contact at ``w_contact``). Without one the engine runs as above, bit for bit.

Checkpoints: engine_state.py. What the run reports (balance records aside): views.py.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from ..errors import SceneError, SimulationError
from ..io.progress import limit as show_limit
from ..records import BalanceRecord
from ..threads import blas_threads
from .coarsen import coarse_grid, coarsen
from .elasticity import ElasticityOperator
from .engine_setup import FractureEngineSetup, fracture_engine_setup
from .engine_state import engine_state, restore_engine
from .front import TipModel, edge_cells
from .front_cells import CellFront
from .front_strategy import front_strategy
from .interpolate import StepEnds
from .leakoff import carter_demand, carter_volume
from .lubrication import build_faces
from .mesh import GROW, Grid
from .newton import drained_start, Elasticity, NewtonWork, StepProblem, StepResult, solve_step, start_widths
from .slurry import Slurry, held_tips
from .solver_choice import use_dense
from .views import View, front_extents, geometry, snapshot

K_PRIME_FACTOR = math.sqrt(32.0 / math.pi)   # K' = sqrt(32/pi) K_Ic
MIN_STEP_FRACTION = 1e-9   # a step shorter than this fraction of the time stops the run
FAILED_STEP_MARGIN = 0.8     # the next steps stay below this fraction of the last step whose Newton failed ...
FAILED_STEP_RELEASE = 1.02  # ... a bound that grows by this factor with every accepted step
CLOSING_GROWTH = 1.0        # after a shut-in step in which cells closed, the next grows no more than this
#                             (not < 1: cells may close over many steps; shrinking steps would meet MIN_STEP_FRACTION)


def check_scene(scene) -> None:
    """Reject what the engine cannot run before any work starts: called once per command by
    hfgpu.limits.check_engine_start (``hfgpu check`` and ``hfgpu run`` validate a scene once)."""
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
    (R ~ t^a). Vertices (Savitski & Detournay 2002; Madyarova 2003): M R = 0.6955 (E' Q^3 t^4 / mu')^(1/9); K R = 0.8546
    (E' Q t / K')^(2/5); Mt = Kt R = 0.4502 (Q^2 t / C'^2)^(1/4). In float64 arithmetic: an absurd rate
    (Q^3 past 1e308) gives t0 = 0, and an absurd radius (R^9 past 1e308) t0 = inf, not an OverflowError from
    Python's float power."""
    q, radius = np.float64(q), np.float64(radius)
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


class _Engine:
    """Mutable state of one run (grid fields, active-set systems, counters) and the implicit step on it; the
    front strategy (``front_tracking``) moves the front, views.py reports, engine_state.py checkpoints."""

    def __init__(self, setup: FractureEngineSetup, slurry: Slurry | None = None):
        self.setup, self.num, self.slurry = setup, setup.numerics, slurry
        numerics = setup.numerics
        #: Extra normal stress [Pa] on the active cells (ix, iz), added to sigma_0 in each step's system (the
        #: shadow of the other planes and a cluster's offset, stage.py); None: none.
        self.stress_shift: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None
        rock = setup.rock
        self.dx, self.dz = setup.mesh.dx, setup.mesh.dz
        self.area = self.dx * self.dz
        self.e_prime = rock.plane_strain_modulus
        self.mu_prime = 12.0 * setup.viscosity
        mu_start = self.mu_prime   # the start (start_time, the tip) in the slurry at the perforation
        if slurry is not None:
            mu_start *= float(slurry.at(*setup.source)[0])
        self.schedule = setup.schedule
        self.tip = TipModel(self.e_prime, mu_start, numerics.tip_asymptote, numerics.tip_velocity)
        self.front_tracking = front_strategy(numerics.front_tracking)
        self.pumping = True   # the run starts while pumping (start_time); step() follows the schedule
        self.op = ElasticityOperator(self.dx, self.dz, self.e_prime)
        h = max(self.dx, self.dz)
        r0 = numerics.initial_radius_cells * h
        half = int(math.ceil(r0 / min(self.dx, self.dz))) + GROW
        self.grid = Grid.around_injection(self.dx, self.dz, *setup.source, half)
        self.load_properties()
        k0 = K_PRIME_FACTOR * float(rock.toughness_at(np.array(setup.injection_depth)))
        c0 = 2.0 * float(rock.leakoff_at(np.array(setup.injection_depth)))
        self.t0, power = start_time(self.schedule, self.e_prime, mu_start, k0, c0, r0)
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
        self.rebuild()
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
        self.closing = False        # cells closed in the last step: the next one does not grow (next_dt)
        self.w_peak = float(g["w"].max())   # the largest width the fracture has had (closure)
        self.t_closed = math.nan            # when the last open cell closed (NaN while any is open)
        self.t_receding = math.nan          # when a sub-grid front handed over to whole cells (closure)
        self.max_balance_error = 0.0
        self.ends: StepEnds | None = None   # the last step's two ends, when asked for (step's keep_ends)
        g["fill"][act] = 1.0

    def load_properties(self) -> None:
        """sigma_0, K' = sqrt(32/pi) K_Ic and C' = 2 C_L at every box cell, from the layer table (again after
        the box grows or the grid changes), and the slurry's viscosity ratio, blocked cells and width floor
        (slurry.py; None without one)."""
        x, z = self.grid.centres()
        self.ratio_box, self.blocked_box, self.floor_box = (None, None, None) if self.slurry is None \
            else self.slurry.at(x, z)
        rock = self.setup.rock
        self.sigma_box = rock.min_stress_at(z)
        self.kprime_box = K_PRIME_FACTOR * rock.toughness_at(z)
        self.cprime_box = 2.0 * rock.leakoff_at(z)

    def rebuild(self) -> None:
        """Systems of the current active set: indices, faces, C (dense or FFT, solver_choice.use_dense; while the
        pumps are stopped, for a footprint expected to keep its cells), properties (after every change of the
        active set, and when the pumps stop or start; clears the cached front distances, views.distances)."""
        self.rows, self.cols, self.ix, self.iz = self.grid.active_indices()
        dense = use_dense(self.num.linear_solver, self.num.krylov_threshold, self.ix, self.iz,
                          stationary=not self.pumping)
        self.elastic = Elasticity(self.op, self.ix, self.iz, dense)
        self.slurry_faces()
        sel = (self.rows, self.cols)
        self.sigma_a, self.cprime_a = self.sigma_box[sel], self.cprime_box[sel]
        self.inj = int(np.flatnonzero((self.ix == 0) & (self.iz == 0))[0])
        self.distances = None

    def slurry_faces(self) -> None:
        """The lubrication faces of the active set with the slurry's viscosity ratio (slurry.py), and the tip
        asymptote's mu' times the mean ratio of the edge cells the slurry does not block (1 without any)."""
        if self.ratio_box is None:
            self.faces = build_faces(self.ix, self.iz, self.dx, self.dz, self.mu_prime)
            return
        ratio = self.ratio_box[self.rows, self.cols]
        self.faces = build_faces(self.ix, self.iz, self.dx, self.dz, self.mu_prime, ratio)
        moving = edge_cells(self.grid["active"]) & ~self.blocked_box
        tip_ratio = float(self.ratio_box[moving].mean()) if moving.any() else 1.0
        self.tip = dataclasses.replace(self.tip, mu_prime=self.mu_prime * tip_ratio)

    def use_slurry(self, slurry: Slurry) -> None:
        """Continue with the slurry's fields (two-way coupling, hfgpu.coupled): viscosity ratios, blocked
        cells, the width floor after shut-in."""
        self.slurry = slurry
        self.load_properties()
        self.slurry_faces()

    def use_grid(self, grid: Grid) -> None:
        """Continue on ``grid`` (a grown box, or the step's start grid again for a retry)."""
        self.grid = grid
        self.load_properties()
        self.rebuild()

    # ------------------------------------------------------------------------------------------
    def step(self, dt: float, keep_ends: bool = False) -> float:
        """Advance by dt with the front strategy (front_strategy.py); returns the step taken (shorter after a
        retry). With ``keep_ends`` the step's two ends are kept in ``ends`` (interpolate.StepEnds), else
        ``ends`` is None."""
        if (self.schedule.rate(self.t) > 0.0) != self.pumping:   # the solver's choice changes at shut-in
            self.pumping = not self.pumping
            self.rebuild()
        return self.front_tracking.step(self, dt, keep_ends)

    def solve(self, dt: float, pinned: np.ndarray | None = None, w_start: np.ndarray | None = None,
              preconditioner=None, tolerance: float | None = None, simplified_exit: bool = False):
        """One implicit step [t, t + dt] from the grid's state (newton.solve_step) on the current active set;
        ``pinned``: prescribed widths (NaN: unknown) of the active cells, whose ``fill`` is their wetted
        fraction (sub-grid front); ``w_start``: Newton's first iterate (None: newton.start_widths);
        ``preconditioner``: an earlier solve's on the same active set (StepResult.preconditioner);
        ``tolerance``: Newton's (None: the scene's newton_tolerance); ``simplified_exit``: newton.solve_step's.
        The Newton work is added to the run's counters; the grid is not changed."""
        g = self.grid
        sel = (self.rows, self.cols)
        w_old, tau, leaked_old = g["w"][sel], g["opened"][sel], g["leaked"][sel]
        filled = g["filled"][sel] if self.num.partial_tip_cells and pinned is None else None
        wetted = None if pinned is None else np.where(np.isfinite(pinned), g["fill"][sel], 1.0)
        source = np.zeros(w_old.size)
        source[self.inj] = self.schedule.mean_rate(self.t, self.t + dt) * dt
        closed = g.shut(self.t)[sel] if pinned is None else None   # the last step's contact set
        if closed is not None and source[self.inj] > 0.0:
            closed[self.inj] = False   # the injected fluid opens the perforated cell of a closed fracture
        contact = None   # without injection, the walls meet on the proppant (slurry.py's floor; never above w_old)
        if self.floor_box is not None and closed is not None and not source.any():
            contact = np.minimum(self.floor_box[sel], np.maximum(w_old, 0.0))
            closed |= (contact > 0.0) & (w_old <= contact)
        if closed is not None and closed.all() and not source.any():   # a closed fracture: nothing moves
            zero = np.zeros(w_old.size)
            return StepResult(w=zero if contact is None else contact.copy(), p=g["p"][sel].copy(), leaked=zero,
                              demand=zero, iterations=0, converged=True, residual=zero, work=NewtonWork(),
                              contact=contact)
        if self.num.leakoff_clock:   # with a wetted fraction: the volume leaked per wetted area
            clock = leaked_old if wetted is None else np.divide(leaked_old, wetted, out=np.zeros_like(leaked_old),
                                                                where=wetted > 0.0)
            demand = carter_demand(self.cprime_a, tau, clock, self.t, self.t + dt, filled)
        else:
            demand = carter_volume(self.cprime_a, tau, self.t, self.t + dt, filled)
        w_eps = np.maximum(self.num.leakoff_width_fraction * demand, 1e-2 * float(w_old.max()))
        sigma = self.sigma_a if self.stress_shift is None else self.sigma_a + self.stress_shift(self.ix, self.iz)
        prob = StepProblem(self.ix, self.iz, w_old, sigma, self.faces, self.area, dt, source,
                           demand, w_eps, 1e-3 * float(w_old.max()), pinned, wetted, self.closure_width, contact)
        if w_start is not None:
            first = np.where(w_start > 0.0, w_start, start_widths(prob))
        else:
            first = drained_start(prob) if not source.any() and pinned is None else None
        with blas_threads(self.ix.size):
            res = solve_step(prob, self.elastic, tolerance or self.num.newton_tolerance,
                             self.num.newton_max_iterations, first, closed, preconditioner, simplified_exit)
        self.newton_iterations += res.iterations
        self.factorisations += res.work.factorisations
        self.gmres_iterations += res.work.gmres_iterations
        return res

    def newton_retry(self, dt: float) -> None:
        """Count a step of length dt whose Newton iteration failed and is redone shorter; the steps after it
        stay below it (``dt_failed``, next_dt)."""
        self.retries += 1
        self.dt_failed = dt

    def newton_failed(self, res, dt: float) -> None:
        """Raise the SimulationError of a step whose Newton iteration failed after the allowed retries, naming
        its end time and the cell with the largest residual."""
        worst = int(np.nanargmax(np.where(np.isfinite(res.residual), np.abs(res.residual), np.inf)))
        raise SimulationError("Newton iteration failed after the allowed step retries",
                              time=self.t + dt, cell=(int(self.ix[worst]), int(self.iz[worst])),
                              residual=float(np.abs(res.residual[worst]) / self.area))

    def accept(self, res, dt: float, advance: float, start: Grid | None, pinned: np.ndarray | None = None) -> None:
        """Store an accepted step's widths, pressures and leak-off, its front advance [m] and move the clock,
        closing the drained cells (module docstring, "Closure") other than those ``pinned`` (the sub-grid
        front's tip cells, whose width the front sets); with ``start`` (the grid at the step's start) keep both
        ends in ``ends``."""
        if not (np.all(np.isfinite(res.w)) and np.all(np.isfinite(res.p))):
            raise SimulationError("non-finite width or pressure", time=self.t + dt)
        g, sel = self.grid, (self.rows, self.cols)
        t_a, leaked_a = self.t, self.leaked_total
        self.t += dt
        self.w_peak = max(self.w_peak, float(res.w.max()))
        shut_in = self.schedule.mean_rate(t_a, self.t) <= 0.0
        base = 0.0 if res.contact is None else res.contact   # the walls close on the proppant (slurry.py)
        film = res.w - base
        drained = shut_in & (film > 0.0) & (film < self.closure_width) \
            & (res.demand >= film * self.area) & (g["opened"][sel] < t_a)   # one step to fill a new cell
        if pinned is not None:
            drained &= ~pinned
            if drained.any():
                self.recede()
        w_start = g["w"][sel]
        emptied = drained | (shut_in & (film < 0.0))   # and a width the contact passes left below 0
        w = np.where(emptied, base, res.w)
        leaked = res.leaked + np.where(emptied, film * self.area, 0.0)   # the film leaks off as the walls meet
        g["w"][sel] = w
        g["p"][sel] = res.p
        self.distances = None
        g["leak_rate"][sel] = leaked / (self.area * dt)
        g["leaked"][sel] = g["leaked"][sel] + leaked / self.area
        self.leaked_total += float(leaked.sum())
        shut = (w_start > 0.0) & (w <= 0.0)   # drained, or squeezed shut by contact (width 0), in this step
        self.closing = shut_in and bool(shut.any())   # next_dt
        if np.any(w > 0.0):
            self.t_closed = math.nan
        elif math.isnan(self.t_closed):
            self.t_closed = closing_time(t_a, dt, w_start[shut], np.maximum(res.w[shut], 0.0), self.closure_width)
        self.v_tip = advance / dt
        self.dt_failed *= FAILED_STEP_RELEASE
        self.steps += 1
        self.ends = None if start is None else StepEnds(t_a, self.t, start, g.copy(), leaked_a, self.leaked_total,
                                                        self.kprime_box, self.cprime_box)

    @property
    def closure_width(self) -> float:
        """The width below which a draining cell closes: ``closure_width_fraction`` x ``w_peak`` [m]."""
        return self.num.closure_width_fraction * self.w_peak

    def recede(self) -> None:
        """Hand a sub-grid front over to whole cells (module docstring, "Closure"): every active cell whole
        (its width kept, so the volume is), the contact set's from now on."""
        self.front_tracking = CellFront()
        self.grid["fill"][self.grid["active"]] = 1.0
        self.t_receding = self.t

    def coarsen_if_wide(self) -> None:
        """Continue on a grid ``mesh.coarsening_factor`` times coarser (coarsen.coarse_grid: 3x3 merges, or
        PyFrac's 2x remeshing) once the footprint spans more than ``mesh.max_cells_across`` cells along x or z,
        with the front the strategy carries across (its ``carried_front``)."""
        cap = self.setup.mesh.max_cells_across
        if cap is None or max(np.ptp(self.ix), np.ptp(self.iz)) + 1 <= cap:
            return
        c = coarsen(self.ix, self.iz, factor=self.setup.mesh.coarsening_factor)
        fill, advance = self.front_tracking.carried_front(self, c)
        self.grid = coarse_grid(self.grid, c, self.rows, self.cols, fill, advance)
        self.dx, self.dz = self.grid.dx, self.grid.dz
        self.area = self.dx * self.dz
        self.op = ElasticityOperator(self.dx, self.dz, self.e_prime)
        self.coarsenings += 1
        self.load_properties()
        self.rebuild()

    def next_dt(self, dt_prev: float) -> float:
        """Eq. 35, dt = lambda min(dx, dz) / V_T, with V_T the larger of the latest opening's front speed
        (Eq. 34; no larger than h / (time since that opening)) and the front's measured speed over the last
        step, and growth limited by max_step_growth and by FAILED_STEP_MARGIN times the last step whose Newton
        failed (that bound growing by FAILED_STEP_RELEASE a step, so the steps do not grow back into the
        failure at once and fail every other step)."""
        h = min(self.dx, self.dz)
        v = self.v_front
        if self.t > self.t_front:
            v = min(v, h / (self.t - self.t_front))
        v = max(v, self.v_tip, 1e-300)
        growth = min(CLOSING_GROWTH, self.num.max_step_growth) if self.closing else self.num.max_step_growth
        return min(self.num.time_step_relaxation * h / v, growth * dt_prev, FAILED_STEP_MARGIN * self.dt_failed)

    # ------------------------------------------------------------------------------------------
    def balance(self) -> BalanceRecord:
        """The volume balance and the pressure history at the current state (records.BalanceRecord)."""
        g = self.grid
        stored = float(g["w"][g["active"]].sum()) * self.area
        injected = self.schedule.volume(self.t)
        inlet = (self.rows[self.inj], self.cols[self.inj])
        pressure = float(g["p"][inlet])
        size = geometry(self, self.now())
        return BalanceRecord(time=self.t, injected=injected, stored=stored, leaked=self.leaked_total,
                             injection_pressure=pressure, net_pressure=pressure - float(self.sigma_a[self.inj]),
                             efficiency=stored / injected if injected > 0.0 else math.nan, area=size["area"],
                             length=size["length"], height=size["height"],
                             inlet_width=float(g["w"][inlet]))

    def now(self) -> View:
        """The current state as a :class:`views.View`."""
        return View(self.grid, self.t, self.leaked_total, self.kprime_box, self.cprime_box)

    def between(self, t: float) -> View:
        """The state at a time t inside the last step, interpolated between its two ends (interpolate.py;
        the step was taken with ``keep_ends``)."""
        e = self.ends
        return View(e.state_at(t, self.t0), t, e.leaked(t), e.kprime_box, e.cprime_box)

    def state(self) -> dict:
        """Everything needed to continue from now (a checkpoint, engine_state.engine_state)."""
        return engine_state(self)

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state` (of a run of the same setup): same fields, same systems."""
        restore_engine(self, state)


def closing_time(t_a: float, dt: float, w_start: np.ndarray, w_end: np.ndarray, threshold: float) -> float:
    """When the last of the cells that closed over the step [t_a, t_a + dt] (drained, or squeezed shut by
    contact: ``w_end`` 0) crossed the closure ``threshold`` width: the latest of the crossings of their widths,
    linear in time from ``w_start`` to ``w_end`` (a cell already below it at the start crossed at t_a);
    t_a + dt when none closed in the step."""
    if w_start.size == 0:
        return t_a + dt
    drop = w_start - w_end
    share = np.where(drop > 0.0, (w_start - threshold) / np.where(drop > 0.0, drop, 1.0), 1.0)
    return t_a + dt * float(np.clip(share, 0.0, 1.0).max())


def _step_times(setup: FractureEngineSetup, t0: float) -> tuple[list[float], list[float]]:
    """(times steps must land on, output times), both sorted: the schedule's breakpoints and the end (physics),
    and the setup's output times, after t0."""
    end = setup.end_time
    breaks = {b for b in setup.schedule.breakpoints() if t0 < b < end}
    return sorted(breaks | {end}), [t for t in setup.output_times if t > t0]


def _landed(output: float, t: float) -> bool:
    """Whether a step ending at t lands on the output time (within 1e-9 relative: 3 x 0.1 s is 0.3 s)."""
    return abs(output - t) <= 1e-9 * t


class FractureRun:
    """One run of the engine driven to a time (a :class:`hfgpu.engines.FractureEngine`): ``advance(until)`` steps
    it there (landing a step on it), so a caller can hand it a slurry between calls (``use_slurry``, the two-way
    coupled loop of hfgpu.coupled); :func:`simulate` advances it to the end at once. It takes the engine's
    setup (engine_setup.py, of a scene validated before it: hfgpu.scene_checks.validate; it checks nothing
    itself), the sink, ``progress``, ``checkpoint`` and ``resume`` as :func:`simulate`, and the ``slurry`` it
    starts in (fracture/slurry.py; None: clean fluid)."""

    def __init__(self, setup: FractureEngineSetup, sink, progress: Callable[[float], None] | None = None,
                 checkpoint=None, resume: dict | None = None, slurry: Slurry | None = None):
        numerics = setup.numerics
        self.setup = setup
        self.sink, self.progress, self.checkpoint = sink, progress, checkpoint
        self.engine = eng = _Engine(setup, slurry)
        self.targets, self.outputs = _step_times(setup, eng.t0)
        self.dt = numerics.time_step_relaxation * min(eng.dx, eng.dz) / eng.v_front
        self.index = 0   # the step target being approached
        if resume is not None:
            eng.restore(resume["engine"])
            self.dt, self.index = resume["dt"], int(resume["target"])
        self.k = sum(1 for t in self.outputs if t < eng.t or _landed(t, eng.t)) if resume is not None else 0

    @property
    def time(self) -> float:
        """The engine's clock [s]: the time its last step reached (its start time before the first)."""
        return self.engine.t

    def use_slurry(self, slurry: Slurry) -> None:
        """Step on in the slurry's fields (:meth:`_Engine.use_slurry`)."""
        self.engine.use_slurry(slurry)

    def tips_held(self) -> int:
        """Cells where the slurry holds the front's lateral tip now (:func:`hfgpu.fracture.slurry.held_tips`)."""
        return held_tips(self.engine.grid["active"], self.engine.blocked_box)

    def advance(self, until: float) -> None:
        """Step to ``until`` (or the end), writing records and snapshots (:func:`simulate`)."""
        eng, targets, outputs, sink, progress = self.engine, self.targets, self.outputs, self.sink, self.progress
        while self.index < len(targets):
            target = min(targets[self.index], until)
            while eng.t < target * (1 - 1e-12):
                remaining = target - eng.t
                step = min(self.dt, remaining)
                if remaining - step < 1e-3 * step:
                    step = remaining
                if step < MIN_STEP_FRACTION * eng.t:   # of the time reached, not of the next target (a long shut-in)
                    raise SimulationError(f"the time step fell to {step:.3g} s (below {MIN_STEP_FRACTION:g} of the "
                                          "time): the front keeps moving more than max_front_advance cells however "
                                          "short the step; raise [fracture] max_front_advance", time=eng.t)
                taken = eng.step(step, keep_ends=self.k < len(outputs) and outputs[self.k] < eng.t + step)
                if abs(eng.t - target) < 1e-9 * target:
                    eng.t = target
                record = eng.balance()
                error = abs(record.injected - record.stored - record.leaked) / record.injected
                eng.max_balance_error = max(eng.max_balance_error, error)
                sink.fracture_balance(record)
                if progress is not None:
                    progress(eng.t)
                    show_limit(progress, taken, "snapshot interval" if taken == step == remaining else "front advance")
                while self.k < len(outputs) and (outputs[self.k] < eng.t or _landed(outputs[self.k], eng.t)):
                    view = eng.now() if _landed(outputs[self.k], eng.t) else eng.between(outputs[self.k])
                    sink.fracture_snapshot(snapshot(eng, view, outputs[self.k]))
                    self.k += 1
                if eng.t < targets[-1]:   # a merge is for the steps that follow
                    eng.coarsen_if_wide()
                self.dt = eng.next_dt(self.dt if taken == step else taken)
                if self.checkpoint is not None and self.checkpoint.due(eng.t):
                    self.checkpoint.save(eng.t, self.state())
            if target < targets[self.index]:
                return
            self.index += 1

    def state(self) -> dict:
        """What a checkpoint stores (:func:`simulate`), the ``resume`` that continues from now: {"engine", "dt",
        "target"}."""
        return {"engine": self.engine.state(), "dt": self.dt, "target": self.index}

    def summary(self) -> dict:
        """The run's summary (:func:`simulate`)."""
        eng = self.engine
        final = eng.balance()
        return dict(time=eng.t, t0=eng.t0, steps=eng.steps, newton_iterations=eng.newton_iterations,
                    factorisations=eng.factorisations, gmres_iterations=eng.gmres_iterations, retries=eng.retries,
                    rejected=eng.rejected, coarsenings=eng.coarsenings, dx=eng.dx, dz=eng.dz,
                    cells=int(eng.grid["active"].sum()), w_inlet=final.inlet_width,
                    p_inlet=final.injection_pressure, injected=final.injected, stored=final.stored,
                    leaked=final.leaked, max_balance_error=eng.max_balance_error, closed_at=eng.t_closed,
                    **front_extents(eng, eng.now()),
                    **geometry(eng, eng.now()))


def simulate(scene, sink, progress: Callable[[float], None] | None = None, checkpoint=None,
             resume: dict | None = None, slurry: Slurry | None = None) -> dict:
    """Run the planar-3D fracture model of ``scene`` to ``run.end_time`` (paper sections 2.2, 3.1): a
    :class:`FractureRun` of its setup (engine_setup.fracture_engine_setup).

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
    that step's snapshots), ``checkpoint.save(t, state)`` gets {"engine": the engine's state (engine_state.py),
    "dt": next step, "target": index of the step target}; ``resume`` (such a state) continues from it, with the
    same steps as an uninterrupted run and the snapshots after t. ``slurry`` (fracture/slurry.py): the run in
    that slurry throughout (None: the clean fluid).
    """
    run = FractureRun(fracture_engine_setup(scene), sink, progress, checkpoint, resume, slurry)
    run.advance(run.setup.end_time)
    return run.summary()
