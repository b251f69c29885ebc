"""Fluid phase of the MP-PIC model: the modified SIMPLE loop of the paper's Algorithm 1 (section 4.2.2).

Each step solves the continuity equation Eq. 25,

    sum over the cell's faces of the outward flux (theta_f w u)_f l_f
        + [ (theta_f w - theta_f^o w^o)/dt + s_l ] dx dz - Q = 0        (l_f = dz or dx),

with the momentum predictor of Eq. 26 (:func:`momentum_predictor`: the NumPy reference or its Taichi kernel,
chosen by the particle backend), by pressure correction: predictor with the guessed pressure p* ->
pressure-correction equation (5-point, symmetric positive definite, assembled in scipy.sparse; its
coefficients do not depend on p, so one matrix per step, solved by conjugate gradients preconditioned with
the LU factors of an earlier step and refactorised (SuperLU) when that takes too many iterations; on CUDA,
Jacobi-preconditioned CG on the GPU, :mod:`hfgpu.proppant.correction_warp`) -> p = p* + p', u = u* + d (p'_W - p'_E)
-> repeat until max|p'| <= tolerance x max(max|p|, pressure_floor) (the paper's 1e-5 criterion, made
relative).
Because the predictor couples a face only to its own pressure difference, the correction is exact and
the loop ends after one or two passes.

Boundary conditions: domain edges and closed cells are walls; inlets are volumetric sources Q [m^3/s] per
cell (fluid volume); leak-off s_l [m/s] per cell (volume rate per unit fracture area, both faces); outlets
are fixed-pressure cells (the fluid that reaches them leaves the domain; e.g. a slot's outlet). A connected
open region with no outlet (a closed box) has its pressure level pinned in one cell.

Pressure p is dynamic (excess over the fluid hydrostatic, section 2.3.1); fluid gravity does not appear.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import splu

from ..errors import SceneError, SimulationError
from .closures import fluid_fraction, slurry_viscosity
from .correction_warp import WarpCorrectionSolver, cuda_available
from .engine import ENGINES
from .grid import StaggeredGrid, face_mean
from .momentum import momentum_predictor as numpy_predictor
from .params import MppicParams


@dataclass(frozen=True)
class FluidNumerics:
    """Knobs of the fluid step.

    c_max: Courant limit of Eq. 42 (< 1). tolerance: Algorithm 1's stopping rule on max|p'| relative to
    max|p| (paper: 1e-5); pressure_floor [Pa]: the pressure scale used instead of max|p| when the field is
    smaller (a fluid at rest). max_iterations: passes of the loop before :class:`SimulationError`.
    linear_rtol: relative residual to which the pressure-correction system is solved; reuse_iterations:
    conjugate-gradient iterations allowed with an earlier step's LU factors as preconditioner before the
    matrix is factorised again (0: factorise every step).
    """

    c_max: float = 0.5
    tolerance: float = 1e-5
    pressure_floor: float = 1e-6
    max_iterations: int = 50
    linear_rtol: float = 1e-12
    reuse_iterations: int = 20

    def __post_init__(self):
        if not (0.0 < self.c_max < 1.0):
            raise SceneError("mppic.c_max", self.c_max, "must be in (0, 1) (Eq. 42)")
        if not (0.0 < self.tolerance < 1.0):
            raise SceneError("mppic.simple_tolerance", self.tolerance, "must be in (0, 1)")
        if not (np.isfinite(self.pressure_floor) and self.pressure_floor > 0.0):
            raise SceneError("mppic.pressure_floor", self.pressure_floor, "must be a pressure > 0 [Pa]")
        if int(self.max_iterations) != self.max_iterations or self.max_iterations < 1:
            raise SceneError("mppic.simple_max_iterations", self.max_iterations, "must be an integer >= 1")
        if not (0.0 < self.linear_rtol < 1e-6):
            raise SceneError("mppic.linear_rtol", self.linear_rtol, "must be in (0, 1e-6)")
        if int(self.reuse_iterations) != self.reuse_iterations or self.reuse_iterations < 0:
            raise SceneError("mppic.reuse_iterations", self.reuse_iterations, "must be an integer >= 0")


@dataclass
class FluidState:
    """Fluid fields at the old time level, updated in place by :meth:`FluidSolver.step`.

    u (nz, nx+1), v (nz+1, nx) [m/s], p (nz, nx) [Pa]; theta_f and width (nz, nx): the fluid fraction and
    width the fields belong to (theta_f^o, w^o of Eq. 25-26).
    """

    u: np.ndarray
    v: np.ndarray
    p: np.ndarray
    theta_f: np.ndarray
    width: np.ndarray


@dataclass(frozen=True)
class StepInfo:
    """What one fluid step did.

    iterations: passes of Algorithm 1; pressure_correction: the last relative max|p'|;
    continuity_residual: max |Eq. 25 imbalance| over the cells where continuity is solved [m^3/s];
    courant: Eq. 42 with the new velocities and this dt (compare with c_max before accepting a step);
    volumes over the step [m^3]: injected (sources), leaked (s_l dA dt), outflow (through outlet cells),
    stored (change of fluid volume theta_f w dA in open cells), dropped (fluid in cells that closed), opened
    (fluid theta_f w dA placed in cells that opened during the step: a storage source, see FluidSolver.step).
    supplied: fluid a connected region without outlet needed beyond its sources because its prescribed width
    grows faster than they fill it (a width history inconsistent with the injected volume; spread over the
    region, see FluidSolver._supply_mismatch), negative when it holds less.
    Balance: injected + opened + supplied = stored + leaked + outflow to round-off.
    """

    iterations: int
    pressure_correction: float
    continuity_residual: float
    courant: float
    injected: float
    leaked: float
    outflow: float
    stored: float
    dropped: float
    opened: float
    supplied: float = 0.0


class CourantLimitExceeded(SimulationError):
    """dt breaks the Courant limit of Eq. 42; ``stable_dt`` is the largest step that satisfies it."""

    def __init__(self, dt: float, courant: float, c_max: float, stable_dt: float):
        self.dt = dt
        self.courant = courant
        self.stable_dt = stable_dt
        super().__init__(f"time step {dt:.6g} s gives Courant number {courant:.4g} > c_max = {c_max} "
                         f"(Eq. 42); largest stable step {stable_dt:.6g} s")


def courant_rates(u: np.ndarray, v: np.ndarray, dx: float, dz: float) -> np.ndarray:
    """|u|/dx + |v|/dz [1/s] per cell (nz, nx) (Eq. 42 per unit dt), each component the larger of the cell's
    two faces."""
    ru = np.maximum(np.abs(u[:, :-1]), np.abs(u[:, 1:])) / dx
    rv = np.maximum(np.abs(v[:-1]), np.abs(v[1:])) / dz
    return ru + rv


def courant_rate(u: np.ndarray, v: np.ndarray, dx: float, dz: float) -> float:
    """max over cells of :func:`courant_rates` [1/s]."""
    return float(np.max(courant_rates(u, v, dx, dz)))


def momentum_predictor(backend: str) -> Callable[..., tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """The momentum predictor (Eq. 26 / 49) of the particle backend ``backend`` (one of
    hfgpu.proppant.engine.ENGINES): the NumPy reference :func:`hfgpu.proppant.momentum.momentum_predictor` for
    "numpy", its Taichi kernel :func:`hfgpu.kernels.momentum.momentum_predictor` (same signature and results,
    imported only here: it starts Taichi) for "taichi". The fluid owns its predictor; it does not borrow the
    particle engine."""
    if backend == "numpy":
        return numpy_predictor
    if backend == "taichi":
        from ..kernels.momentum import momentum_predictor as taichi_predictor

        return taichi_predictor
    raise ValueError(f"backend: got {backend!r}; allowed: one of {list(ENGINES)}")


class FluidSolver:
    """Modified SIMPLE (Algorithm 1) on a :class:`StaggeredGrid`.

    rho_f [kg/m^3], mu_0 [Pa s]: fluid density and clean-fluid viscosity; ``backend``: the run's particle
    backend, "numpy" (default) or "taichi", whose momentum predictor the solver uses
    (:func:`momentum_predictor`). ``params``
    (:class:`hfgpu.proppant.params.MppicParams`): when given, the slurry viscosity mu_f(theta_p) of Eq. 10
    (:func:`hfgpu.proppant.closures.slurry_viscosity`) is used, else mu_0 everywhere. ``wall_friction``: the
    predictor's wall-friction law, "laminar" (Eq. 9) or "dean" (MppicParams.wall_friction).
    ``linear_solver`` ("auto", "scipy", "warp") and ``arch`` (the Taichi architecture in use,
    :func:`hfgpu.kernels.runtime.init`'s answer): the pressure-correction solver, see :func:`correction_solver`;
    the defaults keep SciPy on the CPU.
    """

    def __init__(self, grid: StaggeredGrid, rho_f: float, mu_0: float,
                 numerics: FluidNumerics = FluidNumerics(), backend: str = "numpy",
                 params: MppicParams | None = None, wall_friction: str = "laminar", linear_solver: str = "auto",
                 arch: str = "cpu"):
        for name, value in (("fluid.density", rho_f), ("fluid.viscosity", mu_0)):
            if not (np.isfinite(value) and value > 0.0):
                raise SceneError(name, value, "must be finite and > 0")
        self.rho_f = float(rho_f)
        self.mu_0 = float(mu_0)
        self.numerics = numerics
        self.params = params
        self.wall_friction = wall_friction
        self._linear = correction_solver(linear_solver, numerics.linear_rtol, numerics.reuse_iterations, arch)
        self.momentum_predictor = momentum_predictor(backend)
        self.set_grid(grid)

    @property
    def factorisations(self) -> int:
        """LU factorisations of the pressure-correction matrix so far (the rest were preconditioned CG)."""
        return self._linear.factorisations

    @property
    def linear(self) -> _CorrectionSolver | WarpCorrectionSolver:
        """The pressure-correction solver, whose LU factors carry over between steps (SciPy; the Warp solver
        carries nothing over); its state() and restore() serve checkpoints."""
        return self._linear

    # -- grid -------------------------------------------------------------------------------------

    def set_grid(self, grid: StaggeredGrid) -> None:
        """Use a new width field from the next step on (Eq. 25-26: the state keeps w^o); cells that open join
        the fluid, the fluid of cells that close is dropped (reported in StepInfo.dropped)."""
        if hasattr(self, "grid") and grid.shape != self.grid.shape:
            raise SceneError("grid.width", grid.shape, f"must keep the grid shape {self.grid.shape}")
        self.grid = grid
        nz, nx = grid.shape
        index = np.arange(nz * nx).reshape(nz, nx)
        hu, hv = grid.active_u[:, 1:-1], grid.active_v[1:-1]
        rows = np.concatenate([index[:, :-1][hu], index[:-1][hv]])
        cols = np.concatenate([index[:, 1:][hu], index[1:][hv]])
        graph = sp.coo_matrix((np.ones(rows.size), (rows, cols)), shape=(nz * nx, nz * nx))
        self._labels = connected_components(graph, directed=False)[1].reshape(nz, nx)

    # -- state and time step ------------------------------------------------------------------------

    def initial_state(self, theta_p: np.ndarray | None = None) -> FluidState:
        """Fluid at rest, p = 0, theta_f = 1 - theta_p (default 1), on the current width."""
        nz, nx = self.grid.shape
        theta_f = self._fluid_fraction(theta_p)
        return FluidState(u=np.zeros((nz, nx + 1)), v=np.zeros((nz + 1, nx)), p=np.zeros((nz, nx)),
                          theta_f=theta_f, width=self.grid.width.copy())

    @staticmethod
    def copy_state(state: FluidState) -> FluidState:
        """An independent copy (to try a step and retry with a smaller dt)."""
        return FluidState(*(getattr(state, name).copy() for name in FluidState.__dataclass_fields__))

    def stable_dt(self, state: FluidState) -> float:
        """Largest dt with Courant number (Eq. 42, old velocities) <= c_max; inf for a fluid at rest."""
        rate = courant_rate(state.u, state.v, self.grid.frame.dx, self.grid.frame.dz)
        return self.numerics.c_max / rate if rate > 0.0 else np.inf

    def check_dt(self, state: FluidState, dt: float) -> float:
        """Courant number of Eq. 42 for ``dt``; raises :class:`CourantLimitExceeded` above c_max."""
        if not (np.isfinite(dt) and dt > 0.0):
            raise SceneError("fluid.dt", dt, "must be a finite time step > 0 [s]")
        courant = dt * courant_rate(state.u, state.v, self.grid.frame.dx, self.grid.frame.dz)
        if courant > self.numerics.c_max:
            raise CourantLimitExceeded(dt, courant, self.numerics.c_max, self.stable_dt(state))
        return courant

    # -- one step -----------------------------------------------------------------------------------

    def step(self, state: FluidState, dt: float, theta_p: np.ndarray | None = None,
             force_x: np.ndarray | None = None, force_z: np.ndarray | None = None,
             sources: np.ndarray | None = None, leakoff: np.ndarray | None = None,
             outlets: np.ndarray | None = None, outlet_pressure: float | np.ndarray = 0.0,
             drag_x: np.ndarray | None = None, drag_z: np.ndarray | None = None,
             momentum_x: np.ndarray | None = None, momentum_z: np.ndarray | None = None) -> StepInfo:
        """Advance ``state`` by dt (Algorithm 1); updates state in place and returns a :class:`StepInfo`.

        theta_p (nz, nx): particle volume fraction at the new level (default 0; see _fluid_fraction); force_x (nz, nx+1),
        force_z (nz+1, nx): interphase force F [N/m^3] on the faces (default 0); sources (nz, nx): fluid
        inflow [m^3/s] per cell; leakoff (nz, nx): s_l [m/s]; outlets (nz, nx) bool: fixed-pressure cells,
        held at ``outlet_pressure`` [Pa] (dynamic pressure; scalar or (nz, nx)). drag_x (nz, nx+1), drag_z
        (nz+1, nx): optional drag coefficient beta [kg/(m^3 s)] on the faces (the simulator's: sum n rho_p V_p
        D_p (1 - r_p) I / V_face, less the share r_p the parcels follow, simulator.parcel_response); when
        given, the force is linearised about the old fluid velocity, F = F^o + beta (u - u^o), and the beta part
        is taken implicitly (see _implicit_drag): explicitly a packed bed's drag limits dt to about
        2 rho_f theta_f / beta. momentum_x (nz, nx+1), momentum_z (nz+1, nx): optional momentum the inlets' fluid
        carries into each face control volume per unit density [m^4/s^2] (the inlet source of Eq. 8 / 26, e.g.
        :meth:`hfgpu.proppant.injection.Injector.jet_momentum`), added to the face's drive as
        m / (w_f dx dz) [m/s^2] (_momentum_force).
        Raises :class:`CourantLimitExceeded` (state untouched) when dt breaks Eq. 42 with the old
        velocities, :class:`SceneError` for malformed input, :class:`SimulationError` when the loop does
        not converge.
        """
        grid = self.grid
        nz, nx = grid.shape
        dx, dz = grid.frame.dx, grid.frame.dz
        self.check_dt(state, dt)
        theta_f = self._fluid_fraction(theta_p)
        theta_p = 1.0 - theta_f
        mu = (np.full((nz, nx), self.mu_0) if self.params is None
              else slurry_viscosity(theta_p, self.mu_0, self.params))
        sources = self._check_cell("sources", sources, default=0.0, closed_zero=True)
        leakoff = self._check_cell("leakoff", leakoff, default=0.0, lower=0.0, closed_zero=True)
        force_x = self._check_array("force_x", force_x, (nz, nx + 1))
        force_z = self._check_array("force_z", force_z, (nz + 1, nx))
        if momentum_x is not None or momentum_z is not None:
            force_x = force_x + _momentum_force(self._check_array("momentum_x", momentum_x, (nz, nx + 1)),
                                                grid.width, 1, self.rho_f, dx * dz)
            force_z = force_z + _momentum_force(self._check_array("momentum_z", momentum_z, (nz + 1, nx)),
                                                grid.width, 0, self.rho_f, dx * dz)
        if drag_x is not None or drag_z is not None:
            drag_x = self._check_array("drag_x", drag_x, (nz, nx + 1))
            drag_z = self._check_array("drag_z", drag_z, (nz + 1, nx))
        outlet = np.zeros((nz, nx), dtype=bool) if outlets is None else np.asarray(outlets, dtype=bool)
        if outlet.shape != (nz, nx):
            raise SceneError("fluid.outlets", outlet.shape, f"must be a bool mask of shape {(nz, nx)}")
        if np.any(outlet & ~grid.active):
            raise SceneError("fluid.outlets", np.argwhere(outlet & ~grid.active)[0].tolist(),
                             "outlet cells must be open (width > 0)")
        outlet_pressure = self._check_array("outlet_pressure", np.broadcast_to(outlet_pressure, (nz, nx)),
                                            (nz, nx))
        active = grid.active
        q_new = np.where(active, theta_f * grid.width, 0.0)
        q_old = np.where(state.width > 0.0, state.theta_f * state.width, 0.0)
        # A cell that opens during the step (a growing fracture) is filled by the fracture's own flow, which the
        # proppant grid does not resolve: its fluid theta_f w dA is a storage source (q_old = q_new, no storage
        # term in Eq. 25) instead of being drawn through its faces within dt (that flux ~ 1/dt broke Eq. 42
        # however small the step).
        opened = active & ~(state.width > 0.0)
        q_old = np.where(opened, q_new, q_old)
        q_u = face_mean(theta_f * grid.width, active, axis=1)
        q_v = face_mean(theta_f * grid.width, active, axis=0)
        fixed_rate = (np.where(active, q_new - q_old, 0.0) * grid.cell_area / dt
                      + leakoff * grid.cell_area - sources)

        mismatch = self._supply_mismatch(fixed_rate, outlet, np.where(opened, 0.0, grid.width - state.width))
        fixed = outlet | self._pinned_cells(outlet)
        unknown = active & ~fixed
        number = np.full((nz, nx), -1)
        number[unknown] = np.arange(np.count_nonzero(unknown))

        p = state.p.copy()
        p[outlet] = outlet_pressure[outlet]
        p[~active] = 0.0
        matrix = None
        for iteration in range(1, self.numerics.max_iterations + 1):
            u, v, d_u, d_v = self.momentum_predictor(
                state.u, state.v, p, state.width, state.theta_f, grid.width, theta_f, mu,
                force_x, force_z, self.rho_f, dx, dz, dt, self.wall_friction)
            if drag_x is not None:  # both given (see the checks above)
                u, d_u = _implicit_drag(u, d_u, state.u, drag_x, dx)
                v, d_v = _implicit_drag(v, d_v, state.v, drag_z, dz)
            coef_u, coef_v = q_u * dz * d_u, q_v * dx * d_v
            if matrix is None:
                matrix = _correction_matrix(coef_u, coef_v, number, unknown)
                self._linear.begin(matrix, unknown)
            imbalance = _imbalance(u, v, q_u, q_v, dx, dz) + fixed_rate
            correction = np.zeros((nz, nx))
            if matrix is not None:
                correction[unknown] = self._linear.solve(-imbalance[unknown])
            p += correction
            u[:, 1:-1] += d_u[:, 1:-1] * (correction[:, :-1] - correction[:, 1:])
            v[1:-1] += d_v[1:-1] * (correction[:-1] - correction[1:])
            scale = max(float(np.max(np.abs(p[active]), initial=0.0)), self.numerics.pressure_floor)
            change = float(np.max(np.abs(correction), initial=0.0)) / scale
            if change <= self.numerics.tolerance:
                break
        else:
            raise SimulationError(f"SIMPLE did not converge in {self.numerics.max_iterations} iterations",
                                  residual=change)
        if not (np.all(np.isfinite(u)) and np.all(np.isfinite(v)) and np.all(np.isfinite(p))):
            raise SimulationError("fluid step produced non-finite velocity or pressure")

        imbalance = _imbalance(u, v, q_u, q_v, dx, dz) + fixed_rate
        residual = float(np.max(np.abs(imbalance[active & ~outlet]), initial=0.0))
        info = StepInfo(
            iterations=iteration, pressure_correction=change, continuity_residual=residual,
            courant=dt * courant_rate(u, v, dx, dz),
            injected=float(np.sum(sources)) * dt,
            leaked=float(np.sum(leakoff)) * grid.cell_area * dt,
            outflow=-float(np.sum(imbalance[outlet])) * dt,
            stored=float(np.sum(np.where(active, q_new - q_old, 0.0)) + np.sum(np.where(opened, q_new, 0.0)))
            * grid.cell_area,
            dropped=float(np.sum(np.where(active, 0.0, q_old))) * grid.cell_area,
            opened=float(np.sum(np.where(opened, q_new, 0.0))) * grid.cell_area,
            supplied=mismatch * dt)
        state.u, state.v, state.p = u, v, p
        state.theta_f, state.width = theta_f, grid.width.copy()
        return info

    # -- helpers ------------------------------------------------------------------------------------

    def _supply_mismatch(self, fixed_rate: np.ndarray, outlet: np.ndarray, growth: np.ndarray) -> float:
        """Make Eq. 25 solvable in every connected open region without an outlet, in place: there the sum of
        the cells' fixed terms (storage + leak-off - sources) must vanish, since no flux leaves the region.
        A prescribed width history (one-way coupling) need not satisfy it: a fracture engine whose cells take
        negative widths beside a barrier stores fluid there that the proppant grid (w <= 0 closed) does not
        see, so its open cells grow faster than the injection fills them. Left alone, the whole mismatch
        would enter at the region's pinned cell as a spurious jet; instead it is spread over the region's
        cells in proportion to their width growth ``growth`` (w - w^o, positive part). A region whose width
        does not grow keeps the old rule (its pinned cell takes the round-off of a closed vessel, or a bed's
        theta_f capped at close packing). Returns the spread mismatch [m^3/s], > 0 when the regions needed
        more fluid than they got."""
        labels = np.where(self.grid.active, self._labels, -1)
        free = (labels >= 0) & ~np.isin(labels, np.unique(labels[outlet]))
        if not free.any():
            return 0.0
        index = labels[free]
        total = np.bincount(index, weights=fixed_rate[free])
        weight = np.maximum(growth[free], 0.0)
        grown = np.bincount(index, weights=weight, minlength=total.size)
        total = np.where(grown > 0.0, total, 0.0)
        share = np.divide(weight, grown[index], out=np.zeros_like(weight), where=grown[index] > 0.0)
        fixed_rate[free] -= total[index] * share
        return float(total.sum())

    def _pinned_cells(self, outlet: np.ndarray) -> np.ndarray:
        """One cell (the first in row-major order) of every open region that has no outlet cell."""
        labels = np.where(self.grid.active, self._labels, -1)
        with_outlet = np.unique(labels[outlet])
        flat = labels.ravel()
        regions, first = np.unique(flat, return_index=True)
        keep = (regions >= 0) & ~np.isin(regions, with_outlet)
        pinned = np.zeros(flat.size, dtype=bool)
        pinned[first[keep]] = True
        return pinned.reshape(labels.shape)

    def _fluid_fraction(self, theta_p):
        """theta_f = 1 - theta_p (Eq. 18) on open cells, 1 on closed ones; with ``params``, theta_p capped at
        close packing (:func:`hfgpu.proppant.closures.fluid_fraction`, as the particle closures see it), since
        parcels piled up at a bridge can exceed it; without, theta_p must stay below 1."""
        upper = None if self.params is not None else 1.0
        theta_p = self._check_cell("theta_p", theta_p, default=0.0, lower=0.0, upper=upper)
        theta_f = 1.0 - theta_p if self.params is None else fluid_fraction(theta_p, self.params)
        return np.where(self.grid.active, theta_f, 1.0)

    def _check_array(self, name, value, shape):
        """A finite float64 array of ``shape`` (zeros when None)."""
        if value is None:
            return np.zeros(shape)
        array = np.asarray(value, dtype=np.float64)
        if array.shape != shape:
            raise SceneError(f"fluid.{name}", array.shape, f"must have shape {shape}")
        bad = ~np.isfinite(array)
        if np.any(bad):
            raise SceneError(f"fluid.{name}", float(array[bad].flat[0]), "must be finite")
        return array

    def _check_cell(self, name, value, default=None, lower=None, upper=None, closed_zero=False):
        """A (nz, nx) cell field, its range checked on open cells (and 0 required on closed ones)."""
        shape = self.grid.shape
        array = np.full(shape, float(default)) if value is None else self._check_array(name, value, shape)
        act = self.grid.active
        checks = [(lower is not None and act & (array < lower), f"must be >= {lower} in open cells"),
                  (upper is not None and act & (array >= upper), f"must be < {upper} in open cells"),
                  (closed_zero and ~act & (array != 0.0), "must be 0 in closed cells (width 0)")]
        for bad, allowed in checks:
            if bad is not False and np.any(bad):
                raise SceneError(f"fluid.{name}", float(array[bad][0]), allowed)
        return array


def _correction_matrix(coef_u, coef_v, number, unknown):
    """The pressure-correction matrix: sum_f a_f (p'_P - p'_nb) = -imbalance_P on unknown cells (fixed cells
    have p' = 0), a_f = (theta_f w)_f dy d_f; symmetric positive definite. None when nothing is unknown."""
    n = int(np.count_nonzero(unknown))
    if n == 0:
        return None
    diag = coef_u[:, :-1] + coef_u[:, 1:] + coef_v[:-1] + coef_v[1:]
    rows, cols, vals = [number[unknown]], [number[unknown]], [diag[unknown]]
    for a, b, c in ((number[:, :-1], number[:, 1:], coef_u[:, 1:-1]),
                    (number[:-1], number[1:], coef_v[1:-1])):
        link = (a >= 0) & (b >= 0) & (c > 0.0)
        rows += [a[link], b[link]]
        cols += [b[link], a[link]]
        vals += [-c[link], -c[link]]
    return sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))


class _CorrectionSolver:
    """Solves the pressure-correction systems of successive steps.

    The matrix changes every step (d depends on dt, theta_f and mu_f) but little: an LU factorisation
    (SuperLU, symmetric ordering) of an earlier step's matrix preconditions conjugate gradients; when CG
    needs more than ``reuse_iterations`` iterations, or the set of unknown cells changed, the current matrix
    is factorised and solved directly.
    """

    def __init__(self, rtol: float, reuse_iterations: int):
        self.rtol = rtol
        self.reuse_iterations = reuse_iterations
        self.lu = None
        self.factorised = None  # the matrix whose factors ``lu`` holds (a checkpoint rebuilds lu from it)
        self.key = b""
        self.matrix = None
        self.fresh = False
        self.scale = None
        self.factorisations = 0

    def begin(self, matrix, unknown: np.ndarray) -> None:
        """A new step's matrix on the unknown-cell mask ``unknown``."""
        key = np.packbits(unknown).tobytes() + str(unknown.shape).encode()
        if key != self.key:
            self.lu, self.key = None, key
        self.matrix, self.fresh, self.scale = matrix, False, None

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """The correction p' for right-hand side ``rhs``, to a residual of rtol x the norm of the step's first
        right-hand side (later passes of Algorithm 1 only remove what is left of it)."""
        if self.fresh:
            return self.lu.solve(rhs)
        if self.scale is None:
            self.scale = float(np.sqrt(np.sum(rhs * rhs)))
        if self.lu is not None and self.reuse_iterations > 0:
            x, converged = _preconditioned_cg(self.matrix, rhs, self.lu.solve, self.rtol * self.scale,
                                              self.reuse_iterations)
            if converged:
                return x
        self._factorise(self.matrix)
        self.fresh = True
        self.factorisations += 1
        return self.lu.solve(rhs)

    def _factorise(self, matrix) -> None:
        """LU factors of ``matrix`` (SuperLU, symmetric ordering; the same matrix gives the same factors)."""
        self.lu = splu(matrix, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
        self.factorised = matrix

    def state(self) -> dict:
        """What later steps reuse (a checkpoint): the unknown-cell key and the CSC arrays of the matrix
        factorised."""
        state = {"key": np.frombuffer(self.key, dtype=np.uint8).copy()}
        if self.factorised is not None:
            m = self.factorised
            state.update(data=m.data.copy(), indices=m.indices.copy(), indptr=m.indptr.copy(),
                         shape=np.array(m.shape))
        return state

    def restore(self, state: dict) -> None:
        """Back to a :meth:`state`: the same key and, refactorised from the same matrix, the same LU factors. The
        empty state of the Warp solver (a GPU run resumed on a CPU) restores no factors."""
        self.key = np.asarray(state.get("key", ()), dtype=np.uint8).tobytes()
        self.lu = self.factorised = None
        if "data" in state:
            self._factorise(sp.csc_matrix((state["data"], state["indices"], state["indptr"]),
                                          shape=tuple(int(n) for n in state["shape"])))


LINEAR_SOLVERS = ("auto", "scipy", "warp")


def correction_solver(kind: str, rtol: float, reuse_iterations: int,
                      arch: str = "cpu") -> _CorrectionSolver | WarpCorrectionSolver:
    """The pressure-correction solver of ``kind`` (one of LINEAR_SOLVERS) for the Taichi architecture ``arch``
    that runs ("cpu" or "cuda", :func:`hfgpu.kernels.runtime.init`'s answer):
    "scipy": :class:`_CorrectionSolver` (SuperLU, CG reusing an earlier step's factors; host memory);
    "warp": :class:`hfgpu.proppant.correction_warp.WarpCorrectionSolver` (Jacobi CG) on Warp's device of the
    same name as ``arch``; "auto": "warp" when ``arch`` is "cuda" and warp is installed and sees a CUDA device,
    else "scipy" (the CPU default).
    ValueError for another ``kind``; ImportError naming the extra to install when "warp" is asked without warp.
    """
    if kind not in LINEAR_SOLVERS:
        raise ValueError(f"linear_solver {kind!r}: allowed {', '.join(map(repr, LINEAR_SOLVERS))}")
    on_cuda = arch == "cuda"
    if kind == "auto":
        kind = "warp" if on_cuda and cuda_available() else "scipy"
    if kind == "scipy":
        return _CorrectionSolver(rtol, reuse_iterations)
    return WarpCorrectionSolver(rtol, "cuda" if on_cuda else "cpu")


def _preconditioned_cg(matrix, rhs, precondition, limit, max_iterations):
    """Preconditioned conjugate gradients (Hestenes & Stiefel 1952; Saad 2003, Algorithm 9.1) from x0 = M^-1 b
    to ||b - A x|| <= limit; returns (x, converged). Inner products as elementwise sums (no BLAS call: its
    threads stall on a busy machine)."""
    x = precondition(rhs)
    r = rhs - matrix @ x
    if np.sqrt(np.sum(r * r)) <= limit:
        return x, True
    z = precondition(r)
    direction = z
    rz = np.sum(r * z)
    for _ in range(max_iterations):
        a_dir = matrix @ direction
        alpha = rz / np.sum(direction * a_dir)
        x = x + alpha * direction
        r = r - alpha * a_dir
        if np.sqrt(np.sum(r * r)) <= limit:
            return x, True
        z = precondition(r)
        rz, rz_old = np.sum(r * z), rz
        direction = z + (rz / rz_old) * direction
    return x, False


def _momentum_force(momentum, width, axis, rho, area):
    """A momentum source m [m^4/s^2 per unit density] on faces as the interphase-force term of the predictor's
    drive w_f (-dp/dx - F) / rho (Eq. 26), so that dt w_f (-F / rho) = dt m / (dx dz): F = -rho m / (w_f dx dz)
    on open faces, 0 on walls and closed faces (where the source cannot enter)."""
    w_f = face_mean(width, width > 0.0, axis)
    return np.divide(-rho * momentum, w_f * area, out=np.zeros_like(momentum), where=w_f > 0.0)


def _imbalance(u, v, q_u, q_v, dx, dz):
    """Net volumetric outflow of fluid per cell through its faces [m^3/s], the flux part of Eq. 25."""
    flux_u = q_u * dz * u
    flux_v = q_v * dx * v
    return flux_u[:, 1:] - flux_u[:, :-1] + flux_v[1:] - flux_v[:-1]


def _implicit_drag(u_star, d, u_old, beta, spacing):
    """Implicit part of a drag F = F^o + beta (u - u^o) added to the predictor (Eq. 26): with the predictor's
    diagonal a_P = dt w / (rho_f spacing d), u* -> (u* + r u^o) / (1 + r) and d -> d / (1 + r),
    r = dt w beta / (rho_f a_P) = beta spacing d (0 where d = 0: walls and closed faces)."""
    r = beta * spacing * d
    return (u_star + r * u_old) / (1.0 + r), d / (1.0 + r)
