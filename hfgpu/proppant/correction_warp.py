"""The pressure-correction solve of :mod:`hfgpu.proppant.fluid` on a Warp device (GPU role of warp-lang).

Each pass of the SIMPLE loop solves A p' = b, A the 5-point correction matrix of
:func:`hfgpu.proppant.fluid._correction_matrix` (symmetric positive definite: sum_f a_f (p'_P - p'_nb) on the
unknown cells, a_f > 0), b = -imbalance. Method: conjugate gradients (Hestenes & Stiefel 1952; Saad 2003,
Algorithm 9.1) with the diagonal (Jacobi) preconditioner M^-1 = diag(A)^-1, as ``warp.optim.linear.CG`` and
``warp.optim.linear.preconditioner(A, "diag")`` (NVIDIA Warp documentation, warp.optim.linear and
warp.sparse). A lives on the device as a ``warp.sparse`` BSR matrix of 1x1 float64 blocks; it, b, x and the
CG work vectors stay allocated across steps while the sparsity pattern is unchanged (only the values are
copied in). On CUDA, with conditional graphs, CG checks convergence on the device (``check_every=0``), so the
whole iteration is one captured CUDA graph; without them the host checks it every 10 iterations, on the CPU
device every iteration.

Tolerance, as :class:`hfgpu.proppant.fluid._CorrectionSolver`: ||b - A p'|| <= rtol ||b_1||, b_1 the step's
first right-hand side (later passes of the loop only remove what is left of it). CG runs on b / ||b_1|| with
an absolute tolerance rtol, which is the same criterion and keeps the captured solver independent of the
step. CG starts from x0 = 0: a warm start from the previous step's correction, scaled to minimise the A-norm
error along it (alpha = g.b / g.A g), saved under 1 % of the iterations (2623 against 2635 over 30 steps of
slot start-up, 1657 against 1661 over 15 steps of a changing suspension; rtol 1e-10), since the tolerance is
relative to each step's own right-hand side. So nothing carries over between steps but device memory.

warp is imported here only, on first use (:func:`import_warp`): the rest of hfgpu runs without it.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ..errors import SimulationError

INSTALL_HINT = "pip install 'hfgpu[gpu]'"
CUDA_CHECK_EVERY = 10   # CG iterations between the host's convergence checks on CUDA without conditional graphs


def import_warp():
    """The ``warp`` module with ``warp.sparse`` and ``warp.optim.linear`` loaded and its info log (module
    loads) silenced; ImportError saying how to install it when absent."""
    try:
        import warp
        import warp.optim.linear
        import warp.sparse
    except ImportError as error:
        raise ImportError(f"the Warp pressure-correction solver needs warp-lang: {INSTALL_HINT}") from error
    warp.config.log_level = warp.LOG_WARNING
    return warp


def cuda_available() -> bool:
    """Whether warp is installed and sees a CUDA device."""
    try:
        warp = import_warp()
    except ImportError:
        return False
    return bool(warp.is_cuda_available())


class WarpCorrectionSolver:
    """Solves the pressure-correction systems of successive steps by Jacobi-preconditioned CG on a Warp
    device ("cuda", "cuda:1", "cpu"; see the module docstring). Same interface as
    :class:`hfgpu.proppant.fluid._CorrectionSolver`: begin(matrix, unknown), solve(rhs), state(),
    restore(state), ``factorisations`` (always 0: nothing is factorised); ``iterations`` counts the CG
    iterations of all solves (on CUDA without conditional graphs, in whole multiples of 10).
    ``max_iterations``: CG iterations before :class:`SimulationError` (default max(2 n, 200), n unknowns)."""

    def __init__(self, rtol: float, device: str = "cuda", max_iterations: int | None = None):
        self.warp = import_warp()
        self.rtol = rtol
        self.device = self.warp.get_device(device)
        self.max_iterations = max_iterations
        self.factorisations = 0
        self.iterations = 0
        self.scale: float | None = None
        self._pattern: tuple[np.ndarray, np.ndarray] | None = None
        if self.device.is_cuda:   # 0: convergence checked on the device, no host synchronisation
            self._check_every = 0 if self.warp.is_conditional_graph_supported() else CUDA_CHECK_EVERY
        else:   # the residual is in host memory already: check every iteration
            self._check_every = 1

    def begin(self, matrix: sp.spmatrix, unknown: np.ndarray) -> None:
        """A new step's matrix (its unknown-cell mask ``unknown`` is not needed: the sparsity pattern says
        when the device arrays must be allocated anew), copied into the device matrix; its Jacobi
        preconditioner rebuilt."""
        csr = matrix.tocsr()
        csr.sum_duplicates()   # canonical: sorted columns, the order of warp's BSR blocks
        if (self._pattern is None or not np.array_equal(self._pattern[0], csr.indptr)
                or not np.array_equal(self._pattern[1], csr.indices)):
            self._allocate(csr)
        else:
            self._values.assign(csr.data)
            self._precondition = self.warp.optim.linear.preconditioner(self._a, "diag")
        self.scale = None

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """The correction p' for right-hand side ``rhs``, to a residual of rtol x the norm of the step's first
        right-hand side."""
        if self.scale is None:
            self.scale = float(np.sqrt(np.sum(rhs * rhs)))
        if self.scale == 0.0:
            return np.zeros_like(rhs)
        self._b.assign(rhs / self.scale)
        self._x.zero_()
        done, residual, limit = self._cg(M=self._precondition)
        if self._check_every == 0:   # device-side arrays: iteration count, squared norms
            done = int(done.numpy()[0])
            residual, limit = math.sqrt(float(residual.numpy().max())), math.sqrt(float(limit.numpy().max()))
        self.iterations += int(done)
        if not residual <= limit:
            raise SimulationError(f"Warp CG on {self.device} did not reach the pressure-correction tolerance "
                                  f"in {done} iterations", residual=residual * self.scale)
        return self._x.numpy() * self.scale

    def _allocate(self, csr: sp.csr_matrix) -> None:
        """Device matrix, vectors and CG work space for the pattern of ``csr`` (canonical CSR)."""
        warp, device = self.warp, self.device
        n = csr.shape[0]
        rows = np.repeat(np.arange(n, dtype=np.int32), np.diff(csr.indptr))
        a = warp.sparse.bsr_zeros(n, n, block_type=warp.float64, device=device)
        warp.sparse.bsr_set_from_triplets(a, warp.array(rows, dtype=warp.int32, device=device),
                                          warp.array(csr.indices, dtype=warp.int32, device=device),
                                          warp.array(csr.data, dtype=warp.float64, device=device))
        if not (np.array_equal(a.offsets.numpy()[:n + 1], csr.indptr)
                and np.array_equal(a.columns.numpy()[:csr.nnz], csr.indices)):
            raise RuntimeError("warp.sparse did not keep the CSR block order the value updates rely on")
        self._a, self._values = a, a.values[:csr.nnz]
        self._b = warp.zeros(n, dtype=warp.float64, device=device)
        self._x = warp.zeros(n, dtype=warp.float64, device=device)
        self._precondition = warp.optim.linear.preconditioner(a, "diag")
        self._cg = warp.optim.linear.CG(a, self._b, self._x, tol=0.0, atol=self.rtol,
                                        maxiter=self.max_iterations or max(2 * n, 200), M=self._precondition,
                                        check_every=self._check_every, use_cuda_graph=True)
        self._pattern = (csr.indptr.copy(), csr.indices.copy())

    def state(self) -> dict:
        """What later steps reuse (a checkpoint): nothing, each step's solve depends on its matrix and
        right-hand sides alone."""
        return {}

    def restore(self, state: dict) -> None:
        """Back to a :meth:`state` (of this solver or of :class:`hfgpu.proppant.fluid._CorrectionSolver`, whose
        LU factors it does not use): nothing to restore."""
