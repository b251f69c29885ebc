"""Newton-Raphson for one implicit time step of the coupled elasticity-lubrication system (Eq. 28-32).

The pressure is eliminated with the elasticity residual Eq. 28 taken exactly, p = sigma + C w, so the
unknowns are the N widths of the active cells and the residual is Eq. 29 (volume per cell over the step):

    F_P(w) = A (w_P - w_P^o) + A dL_P g(w_P) - dt [L(w) (sigma + C w)]_P - S_P,

with A = dx dz, L(w) the lubrication operator of :mod:`lubrication`, dL the Carter demand of the step and
g the positivity ramp of :mod:`leakoff` (times the wetted fraction, see Pinned cells), S the injected volume. Its analytic Jacobian is

    J = diag(A (1 + dL g')) - dt L(w) C - dt D(w),   D = d(L(w) p)/dw at fixed p (conductance derivative).

Each Newton update solves J dw = -F, either directly (dense LU, scipy.linalg.lu_factor) or, for large N,
matrix-free by GMRES (``krylov.gmres_solve``) with C applied by FFT and a SuperLU preconditioner M of J with
C cut to its near field of radius NEAR_FIELD_RADIUS, the cell and its 8 neighbours: a sparser factorisation
for more GMRES iterations, cheaper per Newton iteration than a wider near field (bench/bench_solver.py
--near-field-radius compares them). The update is damped by Deuflhard's natural monotonicity test
(Deuflhard 2004, "Newton Methods for Nonlinear Problems", section 3.3, NLEQ-ERR): the step fraction lambda is
halved (at most MONOTONICITY_HALVINGS times) until the simplified Newton correction shrinks,
||J^-1 F(w + lambda dw)|| <= (1 - lambda/4) ||J^-1 F(w)||, with the current factorisation (M for GMRES).
This test is affine invariant; a test on ||F|| is not, and with the cubic conductance w^3 ||F|| grows along
good Newton directions when the step is long (large dt, leak-off dominated growth), so a residual-norm line
search took tiny steps and exhausted the iterations. Convergence is the relative update norm of Eq. 32,
||dw|| < eps ||w||.

Jacobian reuse (``_newton``). The monotonicity test of an undamped update computes the simplified correction
dw' = -J^-1 F(w + dw) with the current factorisation; when ||dw'|| <= REUSE_CONTRACTION ||dw|| the next
iteration takes dw' as its update with the same LU (a chord step: no Jacobian, no factorisation) and, on the
GMRES path, keeps the preconditioner M for the next solve. A chord update that fails the monotonicity test
is not taken; the Jacobian is rebuilt at the same iterate. A well-contracting iteration so costs no
factorisation. GMRES solves to rtol min(1e-3, GMRES_TOLERANCE_FACTOR eps): Newton's convergence needs no
tighter linear solve, and a tighter one costs GMRES iterations. A solve may start from the preconditioner of an
earlier solve on the same cells (``solve_step(..., preconditioner)``: the sub-grid front's solves within a
step), built anew where GMRES fails with it, so the repeated solves of one step share one factorisation.

Exit on the simplified correction (``solve_step(..., simplified_exit=True)``, the sub-grid front's solves).
The monotonicity test of an undamped update has computed dw' = -J^-1 F(w_k+1) with the current factorisation
(M on the GMRES path), Newton's next correction to first order. When ||dw'|| < eps ||w|| Newton takes it and
stops, the termination of Deuflhard's NLEQ-ERR, instead of spending one more iteration to find an update below
eps. The result stays within eps of the root (tests/fracture/test_solver_choice.py); the sub-grid front's
repeated solves of a step each save about one iteration. The whole-cell front keeps the update test: the exit
moves the widths within eps, and the proppant transport of a coupled run, which follows the widths, would take
a different sequence of steps.

Volume-conserving acceptance (``_volume_conserving``). Summed over the cells, Eq. 29 is the step's volume balance
(the fluxes cancel): sum F = A sum (w - w_old) + leaked - injected. The update of a converged Newton iteration
is within eps ||w||, and the leak-off ramp's curvature over it, A dL g'' dw^2 / 2 per cell, leaves sum F at a
level set by the tolerance where cells drain to near their ramp width (cells near closure, a tip held by
bridged proppant: 1e-11 of the injected volume a step at eps = 1e-6 in hfgpu/scenes/frac_pack_tso.toml, summing
to 1.5e-10 over its steps). The accepted widths are shifted at the open cells by the one uniform width that
makes sum F = 0, a scalar Newton on a monotone function; the shift is of the order of sum F over the open area,
far below the tolerance's width, and the balance holds to round-off at every step.

Contact. Widths cannot go negative (the faces would interpenetrate). After Newton converges, an open cell
with w < 0 is closed: its width is held at 0 and its unknown becomes its fluid pressure (p = sigma + c0 x,
c0 = C_PP, so x is in metres), which is no longer tied to the elastic relation Eq. 28 (the difference
sigma + C w - p >= 0 is the contact traction); a closed cell whose fluid pressure exceeds sigma + C w opens
again. Newton is rerun until the set settles (at most CONTACT_PASSES passes). Every cell keeps its mass
balance (a closing cell drains through its faces), so the volume balance stays exact.

Pinned cells. The tip cells of the sub-grid front (front_subgrid.py, tip_cells.py) enter the same way with their
prescribed width (``pinned``) in place of 0: their unknown is their fluid pressure, their width is fixed for
the solve and their mass balance decides how much fluid flows in; ``wetted`` scales each cell's leak-off to
the part of it behind the front.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import partial
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg
import scipy.sparse
from scipy.optimize import brentq
from scipy.sparse.linalg import LinearOperator

from .elasticity import ElasticityOperator
from .krylov import gmres_solve, splu_preconditioner
from .leakoff import available_fraction
from .lubrication import Faces, conductance, divergence_matrix, net_inflow

MONOTONICITY_HALVINGS = 10
CONTACT_PASSES = 6
CONTACT_TOLERANCE = 1e-7
REUSE_JACOBIAN = True      # chord steps and kept preconditioners (module docstring); tests compare without
REUSE_CONTRACTION = 0.5
GMRES_TOLERANCE_FACTOR = 1000.0
NEAR_FIELD_RADIUS = 1      # cells of C kept in the preconditioner (module docstring)


@dataclass(frozen=True)
class StepProblem:
    """Everything one implicit step needs (arrays over the N active cells, SI units)."""

    ix: np.ndarray
    iz: np.ndarray
    w_old: np.ndarray
    sigma: np.ndarray
    faces: Faces
    area: float
    dt: float
    source: np.ndarray        # injected volume per cell over the step [m^3]
    demand: np.ndarray        # Carter leak-off demand per unit area over the step [m]
    w_eps: np.ndarray         # positivity-ramp width per cell [m]
    w_smooth: float = 0.0     # smoothing width of the conductance's positive part [m]
    pinned: np.ndarray | None = None   # prescribed widths (tip cells of the sub-grid front), NaN: unknown [m]
    wetted: np.ndarray | None = None   # wetted fraction of each cell's area that leaks (None: all of it)
    w_floor: float = 0.0      # the engine's closure width [m]: a face between two closed cells conducts as an
    #                           aperture of 2 w_floor (the walls in contact still pass pressure, so a closed
    #                           region's pressures stay determined); Newton's convergence test floors ||w|| there
    w_contact: np.ndarray | None = None   # width at which the walls meet, per cell (a proppant pack's: slurry.py);
    #                                       None: 0. The fluid below it does not leak (leak_fraction)


@dataclass
class NewtonWork:
    """Linear-algebra work of Newton solves (StepResult.iterations counts the iterations): factorisations
    (dense LU or the Krylov preconditioner's SuperLU) and GMRES iterations."""

    factorisations: int = 0
    gmres_iterations: int = 0


@dataclass(frozen=True)
class StepResult:
    w: np.ndarray
    p: np.ndarray
    leaked: np.ndarray        # volume leaked per cell over the step [m^3]
    iterations: int
    converged: bool
    residual: np.ndarray      # final Eq. 29 residual per cell [m^3]
    work: NewtonWork          # the step's linear-algebra work (all contact passes)
    preconditioner: Any = None   # Newton-Krylov: the last preconditioner, for a next solve on the same cells
    demand: np.ndarray | None = None   # Carter's demand per cell over the step [m^3] (leaked: its ramped part)
    contact: np.ndarray | None = None  # the step's w_contact (StepProblem)


class Elasticity:
    """C of the current active set, dense (gathered once per active set) or FFT matrix-free, and its
    self-stiffness c0 = C_PP (the pressure scale of a closed cell's unknown)."""

    def __init__(self, op: ElasticityOperator, ix: np.ndarray, iz: np.ndarray, dense: bool):
        self.op, self.ix, self.iz = op, ix, iz
        self.matrix = op.dense(ix, iz) if dense else None
        self.self_stiffness = float(op.dense(np.zeros(1, np.int64), np.zeros(1, np.int64))[0, 0])

    def apply(self, w: np.ndarray) -> np.ndarray:
        """C w (Eq. 20)."""
        return self.matrix @ w if self.matrix is not None else self.op.matvec(self.ix, self.iz, w)


def held_width(prob: StepProblem) -> np.ndarray | float:
    """Width of a cell whose unknown is its pressure: the prescribed width of a pinned cell, the contact width
    (0, or ``w_contact``)."""
    if prob.pinned is not None:
        return np.nan_to_num(prob.pinned, nan=0.0)
    return 0.0 if prob.w_contact is None else prob.w_contact


def _split(prob: StepProblem, elastic: Elasticity, x: np.ndarray, closed: np.ndarray | None):
    """(w, p) of the unknowns x: w = x, p = sigma + C w (Eq. 28) at open cells; w = held_width, p = sigma +
    c0 x at held cells (closed by contact, or pinned: x is the fluid pressure's excess over sigma in units of
    c0, i.e. metres)."""
    if closed is None or not closed.any():
        return x, prob.sigma + elastic.apply(x)
    w = np.where(closed, held_width(prob), x)
    return w, np.where(closed, prob.sigma + elastic.self_stiffness * x, prob.sigma + elastic.apply(w))


def leak_fraction(prob: StepProblem, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The fraction of a cell's Carter demand it leaks and its derivative: the positivity ramp g(w)
    (leakoff.available_fraction) times the cell's wetted fraction; with ``w_contact`` g(w - w_contact): the
    fluid held in a proppant pack does not leak."""
    g, dg = available_fraction(w if prob.w_contact is None else w - prob.w_contact, prob.w_eps)
    return (g, dg) if prob.wetted is None else (g * prob.wetted, dg * prob.wetted)


class Residual(NamedTuple):
    """Eq. 29 at one iterate and what its Jacobian reuses."""

    f: np.ndarray        # the residual, volume per cell over the step [m^3]
    w: np.ndarray        # widths (``_split``: held cells at held_width)
    p: np.ndarray        # fluid pressures
    t: np.ndarray        # the face conductances T(w) (the lubrication operator L(w): divergence_matrix)
    dt_dw: list          # their derivatives
    g: np.ndarray        # the leaked fraction of the Carter demand (leak_fraction)
    dg: np.ndarray       # and its derivative


def residual(prob: StepProblem, elastic: Elasticity, x: np.ndarray, closed: np.ndarray | None = None) -> Residual:
    """Eq. 29 residual F(x) with the widths and pressures of ``_split``, plus the conductances and the
    ramp."""
    w, p = _split(prob, elastic, x, closed)
    t, *dt_dw = conductance(prob.faces, w, prob.w_smooth)
    if closed is not None and prob.pinned is None and prob.w_floor > 0.0:   # walls in contact: an aperture
        shut = closed[prob.faces.a] & closed[prob.faces.b]                  # of 2 w_floor between closed cells
        t = np.where(shut, np.maximum(t, prob.faces.g * (2.0 * prob.w_floor) ** 3), t)
        dt_dw = [np.where(shut, 0.0, d) for d in dt_dw]
    g, dg = leak_fraction(prob, w)
    f = (prob.area * (w - prob.w_old) + prob.area * prob.demand * g - prob.dt * net_inflow(prob.faces, t, p)
         - prob.source)
    return Residual(f, w, p, t, dt_dw, g, dg)


def _conductance_jacobian(prob: StepProblem, w: np.ndarray, p: np.ndarray,
                          dt_dw: np.ndarray) -> scipy.sparse.csr_matrix:
    """D_Pk = d[L(w) p]_P / dw_k at fixed p (only the face conductances depend on w)."""
    a, b = prob.faces.a, prob.faces.b
    on_a, on_b = dt_dw
    dp = p[b] - p[a]
    rows = np.concatenate([a, a, b, b])
    cols = np.concatenate([a, b, a, b])
    vals = np.concatenate([on_a * dp, on_b * dp, -on_a * dp, -on_b * dp])
    return scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(w.size, w.size))


def dense_jacobian(prob: StepProblem, elastic: Elasticity, x: np.ndarray,
                   closed: np.ndarray | None = None) -> np.ndarray:
    """The analytic Jacobian dF/dx of Eq. 29 (with Eq. 28 eliminated) as a dense matrix."""
    closed = np.zeros(x.size, bool) if closed is None else closed
    r = residual(prob, elastic, x, closed)
    return _dense(prob, elastic, divergence_matrix(prob.faces, r.t, x.size),
                  _conductance_jacobian(prob, r.w, r.p, r.dt_dw),
                  prob.area * (1.0 + prob.demand * r.dg), closed)


def _dense(prob, elastic, lap, cond, diag, closed) -> np.ndarray:
    """J = diag(A (1 + dL g')) P_o - dt L (P_o C P_o + c0 P_c) - dt D P_o, P_o / P_c the open / closed
    selections (P_o = I without contact)."""
    c = elastic.matrix if elastic.matrix is not None else elastic.op.dense(elastic.ix, elastic.iz)
    if closed.any():
        c = c.copy()
        c[closed, :] = 0.0
        c[:, closed] = 0.0
        k = np.flatnonzero(closed)
        c[k, k] = elastic.self_stiffness
    open_ = (~closed).astype(float)
    jac = -prob.dt * (lap @ c)
    jac[np.diag_indices_from(jac)] += diag * open_
    jac -= prob.dt * (cond @ scipy.sparse.diags(open_)).toarray()
    return jac


def _krylov_update(prob, elastic, f, lap, cond, diag, rtol, closed, precond=None):
    """(dx, M, GMRES iterations): the GMRES solution of J dx = -f and the preconditioner M ~ J^-1
    (near-field SuperLU of J; ``precond``, an M of an earlier iterate of the step, is reused instead)."""
    n = f.size
    open_ = (~closed).astype(float)
    c0 = elastic.self_stiffness
    sparse_part = scipy.sparse.diags(diag * open_) - prob.dt * (cond @ scipy.sparse.diags(open_))

    def apply(v):
        return sparse_part @ v - prob.dt * (lap @ np.where(closed, c0 * v, elastic.apply(open_ * v)))

    if precond is None:
        mask = scipy.sparse.diags(open_)
        near = (mask @ elastic.op.near_field(elastic.ix, elastic.iz, NEAR_FIELD_RADIUS) @ mask
                + scipy.sparse.diags(c0 * closed))
        precond = splu_preconditioner(sparse_part - prob.dt * (lap @ near))
    op = LinearOperator((n, n), matvec=apply, dtype=float)
    result = gmres_solve(op, -f, precond, rtol=rtol, restart=60, maxiter=600)
    if not result.converged:
        raise np.linalg.LinAlgError(f"GMRES did not converge (relative residual {result.residual:.2e})")
    return result.x, precond, result.iterations


def _newton(prob: StepProblem, elastic: Elasticity, x: np.ndarray, closed: np.ndarray, tolerance: float,
            max_iterations: int, work: NewtonWork, precond=None,
            simplified_exit: bool = False) -> tuple[np.ndarray, bool, int, Any]:
    """Damped Newton on Eq. 29 for a fixed contact set (module docstring); (x, converged, iterations, the
    last Newton-Krylov preconditioner), the work done added to ``work``. ``precond``: a preconditioner of an
    earlier solve on the same cells, tried first (a new one is built where GMRES fails with it);
    ``simplified_exit``: stop on the simplified correction (module docstring).

    Jacobian reuse: the monotonicity test of an undamped update already gives the simplified Newton
    correction at the new iterate with the current factorisation, dx' = -J_k^-1 F(x + dx). When it contracts
    well, ||dx'|| <= REUSE_CONTRACTION ||dx||, the next iteration takes dx' (a chord step, no new Jacobian)
    with the dense LU; with GMRES the next iteration solves with the new Jacobian but keeps the preconditioner
    M. A chord update that fails its monotonicity test is not taken: the Jacobian is rebuilt at the same
    iterate. The convergence test is unchanged (||dx|| < eps ||x|| of the update just taken)."""
    r = residual(prob, elastic, x, closed)
    it = 0
    dense = elastic.matrix is not None
    inverse = chord = None   # the current factorisation (x -> J^-1 x or M x), the next chord step
    for it in range(1, max_iterations + 1):
        fresh = chord is None
        try:
            if not fresh:
                dx = chord
            else:
                diag = prob.area * (1.0 + prob.demand * r.dg)
                cond = _conductance_jacobian(prob, r.w, r.p, r.dt_dw)
                lap = divergence_matrix(prob.faces, r.t, x.size)
                if dense:
                    with warnings.catch_warnings():   # a singular Jacobian fails the iteration (the step is retried)
                        warnings.simplefilter("error", scipy.linalg.LinAlgWarning)
                        lu = scipy.linalg.lu_factor(_dense(prob, elastic, lap, cond, diag, closed),
                                                    check_finite=False)
                    work.factorisations += 1
                    dx = scipy.linalg.lu_solve(lu, -r.f)
                    inverse = partial(scipy.linalg.lu_solve, lu)
                else:
                    dx, precond = _gmres_update(prob, elastic, r.f, lap, cond, diag, tolerance, closed, precond,
                                                work)
                    dx = _volume_exact(prob, r, dx, closed)
                    inverse = precond.matvec
        except (np.linalg.LinAlgError, ValueError, scipy.linalg.LinAlgWarning):
            return x, False, it, precond
        if not np.all(np.isfinite(dx)):
            return x, False, it, precond
        scale = np.linalg.norm(dx) if dense else np.linalg.norm(inverse(-r.f))
        step, accepted, simplified = 1.0, False, None
        for _ in range(MONOTONICITY_HALVINGS):
            trial = residual(prob, elastic, x + step * dx, closed)
            simplified = inverse(-trial.f) if np.all(np.isfinite(trial.f)) else None
            if simplified is not None and np.linalg.norm(simplified) <= (1.0 - 0.25 * step) * scale:
                accepted = True
                break
            if not fresh:   # a chord step that does not contract is not taken
                break
            step *= 0.5
        if not accepted and not fresh:   # rebuild the Jacobian at the same iterate
            chord = None
            continue
        x = x + step * dx
        r = trial
        limit = tolerance * max(np.linalg.norm(x), prob.w_floor * np.sqrt(x.size), 1e-300)
        if np.linalg.norm(dx) < limit:   # undamped update
            return x, True, it, precond
        if simplified_exit and step == 1.0 and np.linalg.norm(simplified) < limit:
            return x + _volume_exact(prob, r, simplified, closed), True, it, precond
        reuse = (REUSE_JACOBIAN and accepted and step == 1.0
                 and np.linalg.norm(simplified) <= REUSE_CONTRACTION * scale)
        chord = _volume_exact(prob, r, simplified, closed) if reuse and dense else None
        if not reuse:
            precond = None
    return x, False, it, precond


def _volume_exact(prob: StepProblem, r: Residual, dx: np.ndarray, closed: np.ndarray) -> np.ndarray:
    """dx shifted by a uniform width at the open cells so that the update satisfies the step's volume balance
    to first order, sum_P [F + J dx]_P = 0. The lubrication terms of J have zero column sums (fluxes cancel),
    so only its diagonal A (1 + dL g') enters: an exact Newton update satisfies this, a chord update (old J)
    or an inexact GMRES solution does not, and without the shift their converged steps would lose volume at the
    level of the linear solver's tolerance instead of round-off."""
    a = np.where(closed, 0.0, prob.area * (1.0 + prob.demand * r.dg))
    total = a.sum()
    if not total > 0.0:
        return dx
    return dx - np.where(closed, 0.0, (r.f.sum() + a @ dx) / total)


#: Scalar Newton iterations of the volume-conserving shift (``_volume_conserving``; two reach round-off).
VOLUME_SHIFT_ITERATIONS = 3


def _volume_conserving(prob: StepProblem, elastic: Elasticity, x: np.ndarray, closed: np.ndarray) -> np.ndarray:
    """The converged iterate x shifted by the uniform width s at the open cells that makes the step's volume
    balance exact, sum_P F_P(x + s) = 0 to round-off. The lubrication fluxes cancel in the sum, so it is the
    scalar V(s) = sum_P F_P(x) + sum_open A (s + dL (g(w + s) - g(w))), increasing in s (V' >= A per open cell),
    solved by Newton from s = 0. An update within Newton's tolerance leaves sum F at the leak-off ramp's
    curvature over that update, A dL g'' dw^2 / 2 per cell, large where a cell's width is near the ramp's w_eps
    (cells near closure, a front held at the tip): injected - stored - leaked would collect it step by step. The
    shift is of the order of that sum over the open area, far below the tolerance's width."""
    open_ = ~closed
    if not open_.any():
        return x
    r = residual(prob, elastic, x, closed)
    f0, n = float(r.f.sum()), int(open_.sum())
    demand = np.broadcast_to(prob.demand, x.shape)
    s = 0.0
    for _ in range(VOLUME_SHIFT_ITERATIONS):
        g, dg = leak_fraction(prob, np.where(open_, r.w + s, r.w))
        volume = f0 + prob.area * (s * n + float(np.sum(np.where(open_, demand * (g - r.g), 0.0))))
        slope = prob.area * (n + float(np.sum(np.where(open_, demand * dg, 0.0))))
        if not (np.isfinite(volume) and slope > 0.0):
            return x
        s -= volume / slope
    return np.where(open_, x + s, x)


def _gmres_update(prob, elastic, f, lap, cond, diag, tolerance, closed, precond, work: NewtonWork):
    """(dx, M) by _krylov_update with M reused when given; a GMRES that fails with a reused M is rerun with
    a new one (its work added to ``work``)."""
    rtol = min(1e-3, tolerance * GMRES_TOLERANCE_FACTOR)
    if precond is not None:
        try:
            dx, precond, gm = _krylov_update(prob, elastic, f, lap, cond, diag, rtol, closed, precond)
            work.gmres_iterations += gm
            return dx, precond
        except np.linalg.LinAlgError:
            pass
    work.factorisations += 1
    dx, precond, gm = _krylov_update(prob, elastic, f, lap, cond, diag, rtol, closed)
    work.gmres_iterations += gm
    return dx, precond


def start_widths(prob: StepProblem) -> np.ndarray:
    """Newton's first iterate: w_old, except that an empty cell (a cell the front just opened) starts at half
    the mean width of its open neighbours. From w = 0 the conductance derivative times the large pressure drop
    into the empty cell dominates its Jacobian row and sends the iterate to large negative widths, where
    Newton stalls."""
    w, a, b = prob.w_old, prob.faces.a, prob.faces.b
    total = np.bincount(a, w[b], w.size) + np.bincount(b, w[a], w.size)
    count = np.bincount(a, w[b] > 0.0, w.size) + np.bincount(b, w[a] > 0.0, w.size)
    return np.where((w <= 0.0) & (count > 0), 0.5 * total / np.maximum(count, 1), w)


def drained_start(prob: StepProblem) -> np.ndarray:
    """Newton's first iterate for a step without injection: w_old scaled by the s in [0, 1] at which the volume
    the open cells lose equals what they leak, sum (1 - s) w_old = sum demand g(s w_old) (the shape kept, as a
    uniformly falling net pressure keeps it). From w_old itself, the long steps of a fracture near closure,
    whose cells lose most of their fluid in a step, took 20 damped Newton iterations."""
    w0 = np.maximum(prob.w_old, 0.0)
    share = 1.0 if prob.wetted is None else prob.wetted

    def excess(s: float) -> float:
        return float(np.sum((1.0 - s) * w0) - np.sum(prob.demand * share * available_fraction(s * w0, prob.w_eps)[0]))

    if not w0.any() or excess(1.0) >= 0.0:
        return prob.w_old.copy()
    return brentq(excess, 0.0, 1.0, xtol=1e-6) * w0


def solve_step(prob: StepProblem, elastic: Elasticity, tolerance: float, max_iterations: int,
               w_start: np.ndarray | None = None, closed_start: np.ndarray | None = None,
               preconditioner: Any = None, simplified_exit: bool = False) -> StepResult:
    """Newton iterations on Eq. 29 until ||dw|| < tolerance ||w|| (Eq. 32; with ``simplified_exit`` also once
    the simplified correction is below it, module docstring), then the contact set is updated
    (cells with w < 0 closed, closed cells whose fluid pressure exceeds sigma + C w opened) and Newton rerun
    until it settles (at most CONTACT_PASSES times; a set still moving is solved once more as it stands, so
    that the step's residual is converged); a converged iterate is then shifted to balance the step's volume
    exactly (``_volume_conserving``); never raises on failure.
    ``closed_start``: cells that start closed (the contact set of the previous step: with it, a step whose set
    does not change needs one Newton pass instead of two). ``preconditioner``: StepResult.preconditioner of an
    earlier solve on the same active cells and contact set (Newton-Krylov: its SuperLU is tried first instead
    of a new one)."""
    x = (start_widths(prob) if w_start is None else w_start).astype(float, copy=True)
    pinned = np.zeros(x.size, bool) if prob.pinned is None else np.isfinite(prob.pinned)
    closed = pinned if closed_start is None else pinned | closed_start
    if closed.any():   # a held cell's unknown starts at the elastic pressure of the start widths
        x[closed] = elastic.apply(np.where(closed, held_width(prob), x))[closed] / elastic.self_stiffness
    iterations = 0
    work = NewtonWork()
    settled = False
    for _ in range(CONTACT_PASSES):
        x, converged, it, preconditioner = _newton(prob, elastic, x, closed, tolerance, max_iterations, work,
                                                   preconditioner, simplified_exit)
        iterations += it
        if not converged:
            break
        w, p = _split(prob, elastic, x, closed)
        floor = 0.0 if prob.w_contact is None else prob.w_contact
        to_close = ~closed & (w - floor < -CONTACT_TOLERANCE * float(np.abs(w).max()))
        to_open = closed & ~pinned & (prob.sigma + elastic.apply(w) < p)
        settled = not (to_close.any() or to_open.any())
        if settled:
            break
        x = np.where(to_close, (p - prob.sigma) / elastic.self_stiffness, np.where(to_open, 0.0, x))
        closed = (closed | to_close) & ~to_open
        preconditioner = None
    if converged and not settled:   # the set still moved after the last pass: solve on the set it moved to
        x, converged, it, preconditioner = _newton(prob, elastic, x, closed, tolerance, max_iterations, work,
                                                   preconditioner, simplified_exit)
        iterations += it
    if converged:
        x = _volume_conserving(prob, elastic, x, closed)
    r = residual(prob, elastic, x, closed)
    ok = converged and bool(np.all(np.isfinite(r.f)))
    return StepResult(w=r.w, p=r.p, leaked=prob.area * prob.demand * r.g, iterations=iterations, converged=ok,
                      residual=r.f, work=work, preconditioner=preconditioner, demand=prob.area * prob.demand,
                      contact=prob.w_contact)
