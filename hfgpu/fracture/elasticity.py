"""Elasticity of a planar crack by piecewise-constant displacement discontinuities (Eq. 20-21).

Uniform rectangular elements of size dx x dz; the opening w_j of element j changes the normal traction at
the centre of element i by C_ij w_j, with (Crouch & Starfield 1983, Eq. 21 of the paper, written with
the sign that makes the self-influence positive)

    C_ij = E' / (8 pi) [ sqrt(X^2 + Z^2) / (X Z) ]  evaluated at X = x_i - x_j -+ dx/2, Z = z_i - z_j -+ dz/2

(the bracket is the double difference F(X+, Z+) - F(X+, Z-) - F(X-, Z+) + F(X-, Z-) over the corners),
so that p_i - sigma_i = sum_j C_ij w_j (Eq. 20). The kernel depends only on the integer offset between
cells, so on a uniform grid the operator is block-Toeplitz.

Public API (used by the fracture engine; kept stable):

* ``influence(offset_x, offset_z, dx, dz, E')`` -- C for centre offsets in metres (Eq. 21).
* ``dense_matrix(ix, iz, dx, dz, E')`` -- the dense C of the active cells, straight from Eq. 21 (the oracle).
* ``ElasticityOperator(dx, dz, E')`` -- the same operator on an unbounded uniform grid whose active cells
  are given by integer indices ``(ix, iz)`` (any sign; cell centre at ``(ix dx, iz dz)`` relative to an
  origin the caller chooses):

  - ``op.matvec(ix, iz, w) -> C @ w`` in O(N log N) time and O(N) memory by a zero-padded real 2-D FFT of
    the active set's bounding box (``w`` of shape (N,) or (N, m) for m right-hand sides);
  - ``op.dense(ix, iz) -> C`` (N x N, gathered from the cached kernel table);
  - ``op.diagonal(n) -> C_ii`` (all equal on a uniform grid), ``op.self_influence`` (the scalar);
  - ``op.near_field(ix, iz, radius) -> scipy.sparse.csr_matrix`` -- C truncated to offsets
    |di|, |dk| <= radius (the preconditioner's approximation, see ``krylov.py``);
  - ``op.linear_operator(ix, iz) -> scipy.sparse.linalg.LinearOperator`` wrapping ``matvec``.

  The kernel table and its FFT are computed once per box capacity and grown (capacity by a factor 1.5,
  FFT size the next fast length >= 2 capacity - 1) when the active set's bounding box outgrows them, so a
  growing fracture recomputes them O(log N) times in all; memory is a few (Pz x Px) float64 arrays,
  O(N) (N = 1e5 radial: FFT 720 x 720, 8 MB cache, 17 MB peak per matvec).
"""

from __future__ import annotations

import numpy as np
import scipy.fft
import scipy.sparse
from scipy.sparse.linalg import LinearOperator

_GROWTH = 1.5
_DENSE_ROWS = 256


def _corner(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    return np.sqrt(x * x + z * z) / (x * z)


def influence(offset_x: np.ndarray, offset_z: np.ndarray, dx: float, dz: float,
              plane_strain_modulus: float) -> np.ndarray:
    """C for receiver-minus-source centre offsets (metres), Eq. 21. Broadcasts its arguments."""
    a, b = 0.5 * dx, 0.5 * dz
    x = np.asarray(offset_x, dtype=float)
    z = np.asarray(offset_z, dtype=float)
    bracket = (_corner(x + a, z + b) - _corner(x + a, z - b)
               - _corner(x - a, z + b) + _corner(x - a, z - b))
    return plane_strain_modulus / (8.0 * np.pi) * bracket


def dense_matrix(ix: np.ndarray, iz: np.ndarray, dx: float, dz: float,
                 plane_strain_modulus: float) -> np.ndarray:
    """The dense N x N matrix C_ij of Eq. 20 for active cells at integer indices (ix, iz): the oracle."""
    ix = np.asarray(ix)
    iz = np.asarray(iz)
    offset_x = (ix[:, None] - ix[None, :]) * dx
    offset_z = (iz[:, None] - iz[None, :]) * dz
    return influence(offset_x, offset_z, dx, dz, plane_strain_modulus)


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not np.isfinite(value) or value <= 0.0:
        raise ValueError(f"ElasticityOperator: {name} = {value!r}; must be a finite number > 0")
    return value


def _cell_indices(ix: np.ndarray, iz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Validate active-cell indices: equal-length 1-D integer arrays with no repeated cell."""
    ix = np.asarray(ix)
    iz = np.asarray(iz)
    if ix.ndim != 1 or iz.shape != ix.shape:
        raise ValueError(f"active cells: ix and iz must be 1-D of equal length; got shapes {ix.shape} "
                         f"and {iz.shape}")
    if ix.size and not (np.issubdtype(ix.dtype, np.integer) and np.issubdtype(iz.dtype, np.integer)):
        raise ValueError(f"active cells: ix and iz must be integer arrays; got {ix.dtype} and {iz.dtype}")
    return ix.astype(np.int64, copy=False), iz.astype(np.int64, copy=False)


class ElasticityOperator:
    """C of Eq. 20-21 on an unbounded uniform grid, applied by FFT over the active cells' bounding box.

    ``dx``, ``dz``: element size (m) along x (length) and z (height); ``plane_strain_modulus``: E' (Pa).
    See the module docstring for the methods. Not thread-safe (the kernel cache grows in place).
    """

    def __init__(self, dx: float, dz: float, plane_strain_modulus: float):
        self.dx = _positive("dx", dx)
        self.dz = _positive("dz", dz)
        self.plane_strain_modulus = _positive("plane_strain_modulus", plane_strain_modulus)
        self.self_influence = float(influence(0.0, 0.0, self.dx, self.dz, self.plane_strain_modulus))
        self._capacity = (0, 0)          # (nz, nx) box the cached tables serve
        self._shape = (0, 0)             # FFT size (Pz, Px) >= 2 * capacity - 1
        self._table = np.zeros((0, 0))   # C at offset (dk mod Pz, di mod Px)
        self._table_hat = np.zeros((0, 0), dtype=complex)

    @property
    def capacity(self) -> tuple[int, int]:
        """(nz, nx): the largest box of cells the cached kernel table serves. The FFT size, hence the round-off
        of every product, follows from it, so a restored run reserves the capacity it had (``reserve``)."""
        return self._capacity

    def reserve(self, nz: int, nx: int) -> None:
        """Grow the kernel table and its rfft2 so that a box of nz x nx cells fits (Eq. 21 tabulated); the
        capacity grows by _GROWTH at least, so a growing fracture rebuilds the table a few times only."""
        cz, cx = self._capacity
        if nz <= cz and nx <= cx:
            return
        cz = max(nz, int(np.ceil(_GROWTH * cz)) if nz > cz else cz)
        cx = max(nx, int(np.ceil(_GROWTH * cx)) if nx > cx else cx)
        pz = scipy.fft.next_fast_len(2 * cz - 1, real=True)
        px = scipy.fft.next_fast_len(2 * cx - 1, real=True)
        # Offsets in FFT (circular) order: 0, 1, ..., P/2, -(P - P/2 - 1), ..., -1; all |offset| < P.
        dk = np.fft.fftfreq(pz, 1.0 / pz)
        di = np.fft.fftfreq(px, 1.0 / px)
        table = influence(di[None, :] * self.dx, dk[:, None] * self.dz, self.dx, self.dz,
                          self.plane_strain_modulus)
        self._capacity = (cz, cx)
        self._shape = (pz, px)
        self._table = table
        self._table_hat = scipy.fft.rfft2(table)

    def _box(self, ix: np.ndarray, iz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Local (row, column) of each active cell in its bounding box, after growing the cache to fit."""
        if ix.size == 0:
            return ix, iz
        col = ix - ix.min()
        row = iz - iz.min()
        self.reserve(int(row.max()) + 1, int(col.max()) + 1)
        return row, col

    def matvec(self, ix: np.ndarray, iz: np.ndarray, w: np.ndarray) -> np.ndarray:
        """sum_j C_ij w_j (Eq. 20) for active cells (ix, iz), by zero-padded FFT convolution.

        ``w`` has shape (N,) or (N, m); the result has the same shape.
        """
        ix, iz = _cell_indices(ix, iz)
        w = np.asarray(w, dtype=float)
        if w.shape[:1] != ix.shape or w.ndim > 2:
            raise ValueError(f"matvec: w must have shape ({ix.size},) or ({ix.size}, m); got {w.shape}")
        if ix.size == 0:
            return np.zeros_like(w)
        row, col = self._box(ix, iz)
        pz, px = self._shape
        grid = np.zeros((pz, px) + w.shape[1:])
        grid[row, col] = w
        hat = scipy.fft.rfft2(grid, axes=(0, 1))
        kernel = self._table_hat if w.ndim == 1 else self._table_hat[:, :, None]
        out = scipy.fft.irfft2(hat * kernel, s=(pz, px), axes=(0, 1))
        return out[row, col]

    def dense(self, ix: np.ndarray, iz: np.ndarray) -> np.ndarray:
        """The dense N x N C of Eq. 20-21 for active cells (ix, iz), gathered from the kernel table."""
        ix, iz = _cell_indices(ix, iz)
        row, col = self._box(ix, iz)
        pz, px = self._shape
        out = np.empty((ix.size, ix.size))
        for start in range(0, ix.size, _DENSE_ROWS):       # in row blocks: no N x N index temporaries
            block = slice(start, start + _DENSE_ROWS)
            out[block] = self._table[(row[block, None] - row[None, :]) % pz,
                                     (col[block, None] - col[None, :]) % px]
        return out

    def diagonal(self, n: int) -> np.ndarray:
        """C_ii for n cells: the self-influence E' sqrt(dx^2 + dz^2) / (pi dx dz) of Eq. 21 (all equal)."""
        return np.full(int(n), self.self_influence)

    def near_field(self, ix: np.ndarray, iz: np.ndarray, radius: int = 1) -> scipy.sparse.csr_matrix:
        """C of Eq. 21 truncated to pairs with |ix_i - ix_j| <= radius and |iz_i - iz_j| <= radius (CSR)."""
        ix, iz = _cell_indices(ix, iz)
        if int(radius) != radius or radius < 0:
            raise ValueError(f"near_field: radius = {radius!r}; must be an integer >= 0")
        radius = int(radius)
        n = ix.size
        if n == 0:
            return scipy.sparse.csr_matrix((0, 0))
        row, col = self._box(ix, iz)
        pz, px = self._shape
        # Index of each box cell (padded by `radius` on every side), -1 where inactive.
        rz, rx = min(radius, int(row.max())), min(radius, int(col.max()))   # no pair is farther apart
        lookup = np.full((row.max() + 1 + 2 * rz, col.max() + 1 + 2 * rx), -1, dtype=np.int64)
        lookup[row + rz, col + rx] = np.arange(n)
        receivers, sources, values = [], [], []
        for dk in range(-rz, rz + 1):
            for di in range(-rx, rx + 1):
                source = lookup[row + rz - dk, col + rx - di]   # the cell at offset (-dk, -di)
                hit = source >= 0
                receivers.append(np.flatnonzero(hit))
                sources.append(source[hit])
                values.append(np.full(hit.sum(), self._table[dk % pz, di % px]))
        return scipy.sparse.csr_matrix(
            (np.concatenate(values), (np.concatenate(receivers), np.concatenate(sources))), shape=(n, n))

    def linear_operator(self, ix: np.ndarray, iz: np.ndarray) -> LinearOperator:
        """C of the active cells as a scipy LinearOperator (FFT matvec; C is symmetric)."""
        ix, iz = _cell_indices(ix, iz)
        n = ix.size
        return LinearOperator((n, n), matvec=lambda v: self.matvec(ix, iz, v),
                              rmatvec=lambda v: self.matvec(ix, iz, v),
                              matmat=lambda v: self.matvec(ix, iz, v), dtype=float)
