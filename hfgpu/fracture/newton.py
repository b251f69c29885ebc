"""Newton-Raphson for one implicit time step of the coupled elasticity-lubrication system (Eq. 28-32).

The pressure is eliminated with the elasticity residual Eq. 28 taken exactly, p = sigma + C w, so the
unknowns are the N widths of the active cells and the residual is Eq. 29 (volume per cell over the step):

    F_P(w) = A (w_P - w_P^o) + A dL_P g(w_P) - dt [L(w) (sigma + C w)]_P - S_P,

with A = dx dz, L(w) the lubrication operator of :mod:`lubrication`, dL the Carter demand of the step and
g the positivity ramp of :mod:`leakoff`, S the injected volume. Its analytic Jacobian is

    J = diag(A (1 + dL g')) - dt L(w) C - dt D(w),   D = d(L(w) p)/dw at fixed p (conductance derivative).

Each Newton update solves J dw = -F, either directly (dense LU, numpy.linalg.solve) or, for large N,
matrix-free by GMRES (``krylov.gmres_solve``) with C applied by FFT and a SuperLU preconditioner of J with C
cut to its near field. The update is damped by backtracking (halving the step until ||F|| decreases,
at most LINE_SEARCH_HALVINGS times): the conductance's kink at w = 0 otherwise makes Newton cycle. Convergence is the relative update norm of Eq. 32, ||dw|| < eps ||w||.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse
from scipy.sparse.linalg import LinearOperator

from .elasticity import ElasticityOperator
from .krylov import gmres_solve, splu_preconditioner
from .leakoff import available_fraction
from .lubrication import Faces, conductance, divergence_matrix

LINE_SEARCH_HALVINGS = 8


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


@dataclass(frozen=True)
class StepResult:
    w: np.ndarray
    p: np.ndarray
    leaked: np.ndarray        # volume leaked per cell over the step [m^3]
    iterations: int
    converged: bool
    residual: np.ndarray      # final Eq. 29 residual per cell [m^3]


class Elasticity:
    """C of the current active set, dense (gathered once per active set) or FFT matrix-free."""

    def __init__(self, op: ElasticityOperator, ix: np.ndarray, iz: np.ndarray, dense: bool):
        self.op, self.ix, self.iz = op, ix, iz
        self.matrix = op.dense(ix, iz) if dense else None

    def apply(self, w: np.ndarray) -> np.ndarray:
        """C w (Eq. 20)."""
        return self.matrix @ w if self.matrix is not None else self.op.matvec(self.ix, self.iz, w)


def residual(prob: StepProblem, elastic: Elasticity, w: np.ndarray):
    """Eq. 29 residual F(w) with p = sigma + C w (Eq. 28), plus p, the conductances and the ramp."""
    p = prob.sigma + elastic.apply(w)
    t, *dt_dw = conductance(prob.faces, w, prob.w_smooth)
    lap = divergence_matrix(prob.faces, t, w.size)
    g, dg = available_fraction(w, prob.w_eps)
    f = (prob.area * (w - prob.w_old) + prob.area * prob.demand * g - prob.dt * (lap @ p) - prob.source)
    return f, p, lap, dt_dw, dg


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


def dense_jacobian(prob: StepProblem, elastic: Elasticity, w: np.ndarray) -> np.ndarray:
    """The analytic Jacobian dF/dw of Eq. 29 (with Eq. 28 eliminated) as a dense matrix."""
    _, p, lap, dt_dw, dg = residual(prob, elastic, w)
    return _dense(prob, elastic, lap, _conductance_jacobian(prob, w, p, dt_dw),
                  prob.area * (1.0 + prob.demand * dg))


def _dense(prob, elastic, lap, cond, diag) -> np.ndarray:
    c = elastic.matrix if elastic.matrix is not None else elastic.op.dense(elastic.ix, elastic.iz)
    jac = -prob.dt * (lap @ c)
    jac[np.diag_indices_from(jac)] += diag
    jac -= prob.dt * cond.toarray()
    return jac


def _krylov_update(prob, elastic, f, lap, cond, diag, rtol) -> np.ndarray:
    n = f.size
    sparse_part = scipy.sparse.diags(diag) - prob.dt * cond

    def apply(v):
        return sparse_part @ v - prob.dt * (lap @ elastic.apply(v))

    near = elastic.op.near_field(elastic.ix, elastic.iz, 2)
    precond = splu_preconditioner(sparse_part - prob.dt * (lap @ near))
    op = LinearOperator((n, n), matvec=apply, dtype=float)
    result = gmres_solve(op, -f, precond, rtol=rtol, restart=60, maxiter=600)
    if not result.converged:
        raise np.linalg.LinAlgError(f"GMRES did not converge (relative residual {result.residual:.2e})")
    return result.x


def solve_step(prob: StepProblem, elastic: Elasticity, tolerance: float, max_iterations: int,
               w_start: np.ndarray | None = None) -> StepResult:
    """Newton iterations on Eq. 29 until ||dw|| < tolerance ||w|| (Eq. 32); never raises on failure."""
    w = (prob.w_old if w_start is None else w_start).astype(float, copy=True)
    converged = False
    it = 0
    f, p, lap, dt_dw, dg = residual(prob, elastic, w)
    norm = np.linalg.norm(f)
    for it in range(1, max_iterations + 1):
        diag = prob.area * (1.0 + prob.demand * dg)
        cond = _conductance_jacobian(prob, w, p, dt_dw)
        try:
            if elastic.matrix is not None:
                dw = np.linalg.solve(_dense(prob, elastic, lap, cond, diag), -f)
            else:
                dw = _krylov_update(prob, elastic, f, lap, cond, diag, rtol=min(1e-3, tolerance * 1e-1))
        except np.linalg.LinAlgError:
            break
        if not np.all(np.isfinite(dw)):
            break
        step = 1.0
        for _ in range(LINE_SEARCH_HALVINGS):
            trial = residual(prob, elastic, w + step * dw)
            trial_norm = np.linalg.norm(trial[0])
            if trial_norm < norm or not np.isfinite(norm):
                break
            step *= 0.5
        w = w + step * dw
        f, p, lap, dt_dw, dg = trial
        norm = trial_norm
        if np.linalg.norm(dw) < tolerance * max(np.linalg.norm(w), 1e-300):   # undamped update
            converged = True
            break
    f, p, *_ = residual(prob, elastic, w)
    g, _ = available_fraction(w, prob.w_eps)
    ok = converged and bool(np.all(np.isfinite(f)))
    return StepResult(w=w, p=p, leaked=prob.area * prob.demand * g, iterations=it, converged=ok, residual=f)
