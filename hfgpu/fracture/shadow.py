"""Stress shadow: the normal stress an opening element of one fracture plane puts on a parallel plane.

A uniform opening (normal displacement discontinuity) D over the rectangle |x'| <= dx/2, |z'| <= dz/2 of the
plane y = 0 in an infinite isotropic solid changes the normal stress on the plane y (any point (x, z, y)) by

    C(x, z, y) D,   C = E' / (8 pi) [ T(x + dx/2, z + dz/2) - T(x + dx/2, z - dz/2)
                                      - T(x - dx/2, z + dz/2) + T(x - dx/2, z - dz/2) ],
    T(X, Z) = y G'(X, Z, y) - G(X, Z, y),
    G = dF/dy = -X Z (rho^2 + y^2) / (rho (X^2 + y^2) (Z^2 + y^2)),   rho = sqrt(X^2 + Z^2 + y^2),

with F = arctan(X Z / (y rho)) the corner term of the solid angle the rectangle subtends, so that the harmonic
potential phi = int int dA / R has phi_y = -sum(+-F), and C is E' / (8 pi) (phi_yy - y phi_yyy): the normal
stress of a normal displacement discontinuity (Crouch & Starfield 1983, ch. 5 and 7; Salamon 1964, for the
same potential form; the sign is the engine's: compression positive, as the closing stress sigma). At y = 0,
T = -G = rho / (X Z) and C is the in-plane kernel of elasticity.influence (Eq. 21), which this module returns
there. tests/fracture/test_shadow.py checks it against the normal stress on the axis of a pressurised penny
crack (:func:`hfgpu.reference.radial.penny_axis_stress`) and against finite differences of F.

The kernel depends only on the integer offsets of two cells of one in-plane grid and on the planes' spacing,
so between two planes it is block-Toeplitz in the in-plane offsets, as the single plane's is.
"""

from __future__ import annotations

import numpy as np
import scipy.fft

from .elasticity import influence


def _corner(x: np.ndarray, z: np.ndarray, y: float) -> np.ndarray:
    """T(X, Z) = y dG/dy - G of the module docstring, at the plane distance y != 0."""
    x2, z2, y2 = x * x, z * z, y * y
    rho2 = x2 + z2 + y2
    rho = np.sqrt(rho2)
    a, b = x2 + y2, z2 + y2
    num, den = rho2 + y2, rho * a * b
    d_num = 4.0 * y
    d_den = (y / rho) * a * b + rho * 2.0 * y * (a + b)
    g = -x * z * num / den
    dg = -x * z * (d_num * den - num * d_den) / (den * den)
    return y * dg - g


def offset_influence(offset_x, offset_z, offset_y: float, dx: float, dz: float,
                     plane_strain_modulus: float) -> np.ndarray:
    """C [Pa/m] of the module docstring: the normal stress (compression positive) at receiver-minus-source
    offsets (offset_x, offset_z) in the planes [m] and ``offset_y`` between them, per metre of the source
    element's opening. ``offset_y`` = 0 is the in-plane kernel (elasticity.influence). Broadcasts."""
    if offset_y == 0.0:
        return influence(offset_x, offset_z, dx, dz, plane_strain_modulus)
    a, b = 0.5 * dx, 0.5 * dz
    x = np.asarray(offset_x, dtype=float)
    z = np.asarray(offset_z, dtype=float)
    y = abs(float(offset_y))
    bracket = (_corner(x + a, z + b, y) - _corner(x + a, z - b, y)
               - _corner(x - a, z + b, y) + _corner(x - a, z - b, y))
    return plane_strain_modulus / (8.0 * np.pi) * bracket


def _box(cell_sets) -> tuple[int, int, int, int]:
    """(ix0, iz0, nx, nz): the bounding box of the (ix, iz) index arrays of ``cell_sets`` (none empty)."""
    ix0 = min(int(np.min(c[0])) for c in cell_sets)
    iz0 = min(int(np.min(c[1])) for c in cell_sets)
    return (ix0, iz0, max(int(np.max(c[0])) for c in cell_sets) - ix0 + 1,
            max(int(np.max(c[1])) for c in cell_sets) - iz0 + 1)


def _fft_shape(nx: int, nz: int) -> tuple[int, int]:
    """The zero-padded real FFT grid (z, x) of a linear (not circular) convolution on an nx x nz box."""
    return scipy.fft.next_fast_len(2 * nz - 1, real=True), scipy.fft.next_fast_len(2 * nx - 1, real=True)


def _transform(cells: tuple[np.ndarray, np.ndarray], w: np.ndarray, box: tuple[int, int, int, int],
               shape: tuple[int, int]) -> np.ndarray:
    """rfft2 of the openings ``w`` placed at ``cells`` = (ix, iz) of ``box`` on the FFT grid ``shape``."""
    grid = np.zeros(shape)
    grid[np.asarray(cells[1]) - box[1], np.asarray(cells[0]) - box[0]] = w
    return scipy.fft.rfft2(grid)


class PlanesOperator:
    """The elasticity of N parallel fracture planes on one in-plane grid (cells dx x dz; plane k at normal
    position ``positions[k]`` [m]): the normal stress on every active cell of every plane from the openings of
    all, sum_l C(plane k <- plane l) w_l, C the in-plane kernel for l = k and :func:`offset_influence` at the
    planes' distance otherwise.

    Each block is a 2-D convolution on the common bounding box of all planes' active cells, so ``matvec`` costs N
    forward real FFTs, N^2 spectral products (one kernel table per distinct spacing, cached) and N inverse
    FFTs, O(N^2 M + N M log M) for M cells in the box, instead of the (N M)^2 of the dense product
    (``dense``, the oracle).
    """

    def __init__(self, dx: float, dz: float, plane_strain_modulus: float, positions):
        self.dx, self.dz, self.e_prime = float(dx), float(dz), float(plane_strain_modulus)
        self.positions = np.asarray(positions, dtype=float)
        self._tables: dict[tuple[float, tuple[int, int]], np.ndarray] = {}

    def _table_hat(self, spacing: float, shape: tuple[int, int]) -> np.ndarray:
        """rfft2 of the kernel at the planes' distance ``spacing`` on an FFT grid of ``shape`` (circular order)."""
        key = (spacing, shape)
        if key not in self._tables:
            pz, px = shape
            dk = np.fft.fftfreq(pz, 1.0 / pz)
            di = np.fft.fftfreq(px, 1.0 / px)
            table = offset_influence(di[None, :] * self.dx, dk[:, None] * self.dz, spacing, self.dx, self.dz,
                                     self.e_prime)
            self._tables[key] = scipy.fft.rfft2(table)
        return self._tables[key]

    def matvec(self, cells: list[tuple[np.ndarray, np.ndarray]], w: list[np.ndarray]) -> list[np.ndarray]:
        """[sum_l C(k <- l) w_l on the cells of plane k for each k]; ``cells[k]`` = (ix, iz) integer indices
        of plane k's active cells on the shared grid, ``w[k]`` their openings [m]."""
        if len(cells) != self.positions.size or len(w) != self.positions.size:
            raise ValueError(f"PlanesOperator.matvec: {self.positions.size} planes; got {len(cells)} cell sets "
                             f"and {len(w)} opening vectors")
        every = [c for c in cells if len(c[0])]
        if not every:
            return [np.zeros(0) for _ in cells]
        box = _box(every)
        shape = _fft_shape(box[2], box[3])
        hats = [_transform(c, wk, box, shape) for c, wk in zip(cells, w)]
        return [self._received(k, range(len(cells)), hats, shape)[np.asarray(iz) - box[1], np.asarray(ix) - box[0]]
                for k, (ix, iz) in enumerate(cells)]

    def _received(self, k: int, sources, hats: list[np.ndarray], shape: tuple[int, int]) -> np.ndarray:
        """The stress on plane k's FFT grid from the planes ``sources`` (indices into ``hats``, their
        transforms): the inverse FFT of sum_m hat_m C^(k <- m) (zero without sources)."""
        total = np.zeros((shape[0], shape[1] // 2 + 1), dtype=complex)
        for m in sources:
            total += hats[m] * self._table_hat(abs(float(self.positions[k] - self.positions[m])), shape)
        return scipy.fft.irfft2(total, s=shape)

    def on_plane(self, k: int, receivers: tuple[np.ndarray, np.ndarray], cells: list[tuple[np.ndarray, np.ndarray]],
                 w: list[np.ndarray]) -> np.ndarray:
        """sum_{l != k} C(k <- l) w_l on the cells ``receivers`` = (ix, iz) of plane k: the shadow the other planes
        (``cells[l]``, ``w[l]``; plane k's own entries are not read) cast on it, by N - 1 forward FFTs, N - 1
        spectral products and one inverse FFT over the common bounding box."""
        others = [m for m in range(len(cells)) if m != k and len(cells[m][0])]
        ix, iz = np.asarray(receivers[0]), np.asarray(receivers[1])
        if not others or ix.size == 0:
            return np.zeros(ix.size)
        box = _box([cells[m] for m in others] + [(ix, iz)])
        shape = _fft_shape(box[2], box[3])
        hats = {m: _transform(cells[m], w[m], box, shape) for m in others}
        return self._received(k, others, hats, shape)[iz - box[1], ix - box[0]]

    def shadow_fields(self, box: tuple[int, int, int, int], cells: list[tuple[np.ndarray, np.ndarray]],
                      w: list[np.ndarray]) -> list[np.ndarray]:
        """[sum_{l != k} C(k <- l) w_l at every cell of ``box`` for each plane k]: the shadow the other planes cast
        on the whole box (ix0, iz0, nx, nz) of the shared grid, which holds every plane's ``cells``; (nz, nx) arrays,
        by N forward FFTs, N (N - 1) spectral products and N inverse FFTs, O(N^2 M + N M log M)."""
        shape = _fft_shape(box[2], box[3])
        hats = [_transform(c, wk, box, shape) for c, wk in zip(cells, w)]
        return [self._received(k, [m for m in range(len(cells)) if m != k], hats, shape)[:box[3], :box[2]]
                for k in range(len(cells))]

    def dense(self, cells: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
        """The block matrix [C(k <- l)] over all planes' active cells, in the order of ``cells``, from
        :func:`offset_influence` directly (the oracle of ``matvec``)."""
        ix = np.concatenate([np.asarray(c[0]) for c in cells])
        iz = np.concatenate([np.asarray(c[1]) for c in cells])
        y = np.concatenate([np.full(len(c[0]), p) for c, p in zip(cells, self.positions)])
        out = np.empty((ix.size, ix.size))
        for spacing in np.unique(np.abs(y[:, None] - y[None, :])):
            pair = np.abs(y[:, None] - y[None, :]) == spacing
            out[pair] = offset_influence(((ix[:, None] - ix[None, :]) * self.dx)[pair],
                                         ((iz[:, None] - iz[None, :]) * self.dz)[pair], float(spacing),
                                         self.dx, self.dz, self.e_prime)
        return out
