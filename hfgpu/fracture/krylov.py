"""Preconditioned GMRES for the Newton step of Eq. 30, with C applied by FFT (elasticity.py).

The Jacobian of Eq. 28-29 is the block matrix

    J = [[ J_rd,        J_rd<-ff ],      J_rd = C (dense; applied by FFT in O(N log N)),
         [ J_ff<-rd,    J_ff     ]]      the other three blocks sparse (lubrication stencil, diagonals).

It is solved matrix-free by restarted GMRES (scipy.sparse.linalg.gmres, Saad & Schultz 1986), left-
preconditioned by a sparse LU (SuperLU, scipy.sparse.linalg.splu) of the same block matrix in which C is
replaced by its near field (``ElasticityOperator.near_field``: C truncated to offsets |di|, |dk| <= radius).
The near field holds the singular, dominant part of the hypersingular kernel (C_ij decays like r^-3).
Measured on radial sets, C alone, rtol 1e-10 (bench/bench_elasticity.py, one core): GMRES iterations for
N = 1e3, 1e4, 1e5 are 27, 48, 86 unpreconditioned and 12, 23, 42 with the radius-1 (3x3) near field
(9, 17, 34 at radius 2); the count still grows about like N^0.25. For C alone the FFT matvec is so cheap
(7 ms at N = 1e5) that halving the iterations does not pay for the factorisation (N = 1e5: 0.9 s plain,
2.6 s preconditioned in all); the preconditioner earns its keep in the coupled system, where the sparse
lubrication blocks (exact in the preconditioner) carry the bad scaling (tests/fracture/test_operator.py:
26 iterations with C_near = 0, 12 at radius 1, 9 at radius 2, on an Eq. 30-shaped system of 2 x 600).

Public API (used by the fracture engine; kept stable):

* ``gmres_solve(A, b, preconditioner=None, *, rtol=1e-10, restart=60, maxiter=2000, x0=None)
  -> KrylovResult(x, iterations, residual, converged)``; ``residual`` is the true relative residual
  ||b - A x|| / ||b|| (not the preconditioned one).
* ``splu_preconditioner(approximation, *, symmetric=False) -> LinearOperator``: x -> approximation^{-1} x
  by SuperLU.
* ``elasticity_preconditioner(op, ix, iz, radius=1)``: the above for C alone (radius 1, the 3x3 stencil,
  is the fastest preconditioned variant in bench/bench_elasticity.py: fewer iterations at radius 2-3 do not
  pay for the extra fill of the factorisation).
* ``coupled_operator(c, upper_right, lower_left, lower_right) -> LinearOperator`` of [[C, B], [D, F]],
  with ``c`` a LinearOperator (e.g. ``op.linear_operator(ix, iz)``) and B, D, F sparse.
* ``coupled_preconditioner(c_near, upper_right, lower_left, lower_right) -> LinearOperator``: SuperLU of
  [[C_near, B], [D, F]], all sparse (``c_near = op.near_field(ix, iz, radius)``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse
from scipy.sparse.linalg import LinearOperator, gmres, splu

from .elasticity import ElasticityOperator


@dataclass(frozen=True)
class KrylovResult:
    """Outcome of a GMRES solve: solution, inner iterations used, true relative residual, convergence."""

    x: np.ndarray
    iterations: int
    residual: float
    converged: bool


def gmres_solve(A: LinearOperator, b: np.ndarray, preconditioner: LinearOperator | None = None, *,
                rtol: float = 1e-10, restart: int = 60, maxiter: int = 2000,
                x0: np.ndarray | None = None) -> KrylovResult:
    """Solve A x = b (the Newton correction of Eq. 30) by restarted GMRES, left-preconditioned.

    ``maxiter`` bounds the total number of inner iterations (rounded up to whole restart cycles);
    convergence means ||b - A x|| <= rtol ||b|| (scipy checks the true residual at each restart). Never
    raises on non-convergence: the caller reads ``converged`` (and retries, e.g. with a smaller step).
    """
    b = np.asarray(b, dtype=float)
    if b.ndim != 1 or A.shape != (b.size, b.size):
        raise ValueError(f"gmres_solve: A has shape {A.shape} and b {b.shape}; need A (n, n), b (n,)")
    if not (0.0 < rtol < 1.0):
        raise ValueError(f"gmres_solve: rtol = {rtol!r}; must lie in (0, 1)")
    if restart < 1 or maxiter < 1:
        raise ValueError(f"gmres_solve: restart = {restart!r}, maxiter = {maxiter!r}; both must be >= 1")
    norm_b = np.linalg.norm(b)
    if norm_b == 0.0:
        return KrylovResult(np.zeros_like(b), 0, 0.0, True)
    counter = [0]

    def count(_residual: float) -> None:
        counter[0] += 1

    x, info = gmres(A, b, x0=x0, M=preconditioner, rtol=rtol, atol=0.0, restart=restart,
                 maxiter=max(1, -(-maxiter // restart)), callback=count, callback_type="pr_norm")
    residual = float(np.linalg.norm(b - A @ x) / norm_b)
    return KrylovResult(x, counter[0], residual, info == 0)


def splu_preconditioner(approximation: scipy.sparse.spmatrix, *, symmetric: bool = False) -> LinearOperator:
    """M = approximation^{-1} as a LinearOperator, by a sparse LU factorisation (SuperLU).

    ``symmetric=True`` (for C's near field alone, an M-matrix: positive diagonal, negative off-diagonals,
    positive row sums since the omitted far field of a row sums to a negative number) orders by minimum
    degree on A^T + A and pivots on the diagonal, about 3x faster and with half the fill of the general
    path (COLAMD with partial pivoting), which any other matrix must use.
    """
    matrix = scipy.sparse.csc_matrix(approximation, dtype=float)
    if symmetric:
        lu = splu(matrix, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                  options={"SymmetricMode": True})
    else:
        lu = splu(matrix)
    n = matrix.shape[0]
    return LinearOperator((n, n), matvec=lu.solve, dtype=float)


def elasticity_preconditioner(op: ElasticityOperator, ix: np.ndarray, iz: np.ndarray,
                              radius: int = 1) -> LinearOperator:
    """Preconditioner for C alone (Eq. 20): SuperLU of C's (2 radius + 1)^2 near-field stencil."""
    return splu_preconditioner(op.near_field(ix, iz, radius), symmetric=True)


def coupled_operator(c: LinearOperator, upper_right: scipy.sparse.spmatrix,
                     lower_left: scipy.sparse.spmatrix, lower_right: scipy.sparse.spmatrix) -> LinearOperator:
    """The Jacobian of Eq. 30, [[C, J_rd<-ff], [J_ff<-rd, J_ff]], with C matrix-free (x = [dw, dp])."""
    n = c.shape[0]
    m = lower_right.shape[0]
    if upper_right.shape != (n, m) or lower_left.shape != (m, n) or lower_right.shape != (m, m):
        raise ValueError(f"coupled_operator: block shapes C {c.shape}, upper_right {upper_right.shape}, "
                         f"lower_left {lower_left.shape}, lower_right {lower_right.shape} do not fit "
                         f"[[({n}, {n}), ({n}, {m})], [({m}, {n}), ({m}, {m})]]")

    def apply(x: np.ndarray) -> np.ndarray:
        x = np.ravel(x)
        w, p = x[:n], x[n:]
        return np.concatenate([c @ w + upper_right @ p, lower_left @ w + lower_right @ p])

    return LinearOperator((n + m, n + m), matvec=apply, dtype=float)


def coupled_preconditioner(c_near: scipy.sparse.spmatrix, upper_right: scipy.sparse.spmatrix,
                           lower_left: scipy.sparse.spmatrix,
                           lower_right: scipy.sparse.spmatrix) -> LinearOperator:
    """SuperLU of [[C_near, J_rd<-ff], [J_ff<-rd, J_ff]]: the Eq. 30 Jacobian with C cut to its near field."""
    return splu_preconditioner(scipy.sparse.bmat([[c_near, upper_right], [lower_left, lower_right]],
                                                 format="csc"))
