"""Coarsening of the fracture grid: continue on cells ``factor`` times larger (3 x 3 merges by default, or 2x).

When the fracture outgrows the cell budget the engine continues on a grid ``factor`` times coarser, its
cells centred on the injection (source) cell, so the point source of Eq. 29 stays in the coarse cell (0, 0)
(it sits up to half a fine cell from that cell's centre where the grid is placed on layer boundaries, mesh.py;
a boundary on a fine face is on a coarse face only where the merge's faces fall on it).
The map works on the integer-index representation of the active cells as (child, parent, share) triples:
fine cell ``child`` covers the part ``share`` of its area in coarse cell ``parent``.

* Odd factor f (3 by default): blocks are aligned on the source cell ``(cx, cz)``: coarse cell ``(K, L)``
  holds the fine cells ``cx + f K - h .. cx + f K + h`` by ``cz + f L - h .. cz + f L + h`` (h = (f - 1) / 2),
  whole (share 1), so it is centred on fine cell ``(cx + f K, cz + f L)`` and the source's coarse index is
  ``(0, 0)``.
* f = 2: coarse cell ``(K, L)`` spans fine offsets ``2K - 1 .. 2K + 1`` from the source along x (and the
  same along z): the fine cell at an even offset lies inside it, one at an odd offset is cut in half between
  two coarse cells (share 1/2 per axis, 1/4 at a corner). The coarse cells do not nest the fine ones, but they
  stay centred on the source (PyFrac's remeshing by 2); the fields are carried by area overlap.

A coarse cell is active when any active fine cell overlaps it (no fluid is dropped). Per-cell fields are
carried by stated rules (``Coarsening`` methods):

* ``width(w)``: w_coarse = sum(share x w) / f^2, inactive fine cells counting as zero opening, so the fluid
  volume sum w dA is unchanged (to round-off);
* ``total(q)``: sum of share x q, for extensive per-cell quantities (volumes, masses);
* ``mean(p)``: area-weighted mean over the overlapping active fine cells (pressure);
* ``earliest(t)``: minimum over the overlapping active fine cells (opening time tau of the Carter leak-off term
  of Eq. 29 and activation times of Eq. 34);
* ``fill``: the part of the coarse cell the active fine cells cover (1 inside, < 1 at the front).

The sub-grid front crosses the merge too (``coarse_front``): a coarse cell's wetted fraction is the
area-weighted mean of its fine cells' (inactive ones 0), so the wetted area sum f dA is carried exactly; a
coarse cell not wholly wetted is a tip cell, its front normal the share-weighted sum of its fine tip cells'
normals (where it has none, minus the sum of its fine cells' offsets from its centre weighted by their wetted
areas: the direction of its dry part), and its advance the one whose plane front wets that fraction
(tip_cells.advance_for_fill).

The engine's fields move onto the coarse grid by ``coarse_grid`` (widths and rates by ``width``, the leaked
volumes by ``total / f^2``, pressure by ``mean``, opening and arrival times by ``earliest``, the time the front
crosses a cell by the latest fine cell's), with the front's ``fill`` and ``advance`` from ``coarse_front`` or,
where no sub-grid front is carried, ``channel_front``.

Public API: ``coarsen(ix, iz, source=(0, 0), factor=3) -> Coarsening``, ``coarse_front``, ``channel_front``,
``coarse_grid``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .mesh import GROW, Grid
from .tip_cells import advance_for_fill


@dataclass(frozen=True)
class Coarsening:
    """Fine-to-coarse map: coarse active cells (ix, iz) and the (child, parent, share) triples of the overlap
    (module docstring; with an odd factor ``child`` is every fine cell once, in order, and ``share`` 1)."""

    factor: int
    ix: np.ndarray
    iz: np.ndarray
    child: np.ndarray
    parent: np.ndarray
    share: np.ndarray
    fill: np.ndarray

    def total(self, values: np.ndarray) -> np.ndarray:
        """Sum of share x value over each coarse cell's overlapping active fine cells (extensive quantities)."""
        return np.bincount(self.parent, weights=self.share * self._checked(values)[self.child],
                           minlength=self.ix.size)

    def width(self, w: np.ndarray) -> np.ndarray:
        """Coarse opening conserving fluid volume: sum(share w) dA / (f^2 dA) (inactive fine cells: 0)."""
        return self.total(w) / self.factor**2

    def mean(self, values: np.ndarray) -> np.ndarray:
        """Area-weighted mean over each coarse cell's overlapping active fine cells (pressure)."""
        return self.total(values) / (self.fill * self.factor**2)

    def earliest(self, times: np.ndarray) -> np.ndarray:
        """Minimum over each coarse cell's overlapping active fine cells (opening and activation times)."""
        out = np.full(self.ix.size, np.inf)
        np.minimum.at(out, self.parent, self._checked(times)[self.child])
        return out

    def _checked(self, values: np.ndarray) -> np.ndarray:
        values = np.asarray(values, dtype=float)
        fine = int(self.child.max()) + 1
        if values.shape != (fine,):
            raise ValueError(f"Coarsening: a per-cell field must have shape ({fine},) (one value per fine active "
                             f"cell); got {values.shape}")
        return values


def _axis(offset: np.ndarray, factor: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """(coarse index, share) pairs of fine cells at integer ``offset`` from the source along one axis."""
    if factor % 2:
        return [(np.floor_divide(offset + (factor - 1) // 2, factor), np.ones(offset.size))]
    odd = offset % 2 == 1
    half = np.where(odd, 0.5, 1.0)
    return [(np.floor_divide(offset, 2), half), (np.floor_divide(offset + 1, 2), np.where(odd, 0.5, 0.0))]


def coarsen(ix: np.ndarray, iz: np.ndarray, source: tuple[int, int] = (0, 0), factor: int = 3) -> Coarsening:
    """The map onto cells ``factor`` times larger centred on the source cell (module docstring).

    ``ix``, ``iz``: fine active-cell indices (distinct cells); ``source``: the injection cell's fine index;
    ``factor``: 2 or an odd integer >= 3.
    """
    ix = np.asarray(ix)
    iz = np.asarray(iz)
    if ix.ndim != 1 or iz.shape != ix.shape or ix.size == 0:
        raise ValueError(f"coarsen: ix and iz must be non-empty 1-D arrays of equal length; got shapes "
                         f"{ix.shape} and {iz.shape}")
    if not (np.issubdtype(ix.dtype, np.integer) and np.issubdtype(iz.dtype, np.integer)):
        raise ValueError(f"coarsen: ix and iz must be integer arrays; got {ix.dtype} and {iz.dtype}")
    if not (isinstance(factor, (int, np.integer)) and (factor == 2 or (factor >= 3 and factor % 2 == 1))):
        raise ValueError(f"coarsen: factor = {factor!r}; must be 2 or an odd integer >= 3 (the coarse cells "
                         "must stay centred on the source cell)")
    cx, cz = (int(v) for v in source)
    fine_key = (iz.astype(np.int64) - iz.min()) * (int(ix.max() - ix.min()) + 1) + (ix - ix.min())
    if np.unique(fine_key).size != ix.size:
        raise ValueError("coarsen: the active cells (ix, iz) contain repeated cells")
    cells = np.arange(ix.size)
    triples = [(cells, big_k, big_l, share_x * share_z)
               for big_k, share_x in _axis(ix.astype(np.int64) - cx, factor)
               for big_l, share_z in _axis(iz.astype(np.int64) - cz, factor)]
    child, big_k, big_l, share = (np.concatenate(parts) for parts in zip(*triples))
    keep = share > 0.0
    child, big_k, big_l, share = child[keep], big_k[keep], big_l[keep], share[keep]
    span = int(big_k.max() - big_k.min()) + 1
    key = (big_l - big_l.min()) * span + (big_k - big_k.min())
    unique_key, first, parent = np.unique(key, return_index=True, return_inverse=True)
    covered = np.bincount(parent.ravel(), weights=share, minlength=unique_key.size)
    return Coarsening(factor=int(factor), ix=big_k[first], iz=big_l[first], child=child, parent=parent.ravel(),
                      share=share, fill=covered / factor**2)


def coarse_front(c: Coarsening, ix: np.ndarray, iz: np.ndarray, fill: np.ndarray, nx: np.ndarray,
                 nz: np.ndarray, dx: float, dz: float) -> tuple[np.ndarray, np.ndarray]:
    """(fill, advance) of the coarse cells of ``c`` from the sub-grid front on the fine grid (module
    docstring): ``ix``, ``iz`` the fine active cells given to ``coarsen`` (source at (0, 0)), ``fill`` their
    wetted fractions, ``nx``, ``nz`` the front's unit normal at the fine tip cells (0 elsewhere), dx, dz the
    fine cell. advance is NaN at the wholly wetted (channel) coarse cells."""
    f = c.factor
    wet = np.clip(fill, 0.0, 1.0)
    fill_c = c.total(wet) / f**2
    gx, gz = c.total(nx), c.total(nz)
    # the share-weighted offsets of a coarse cell's fine cells sum to zero over the whole cell, so the sum of
    # (1 - fill) x offset is minus that of fill x offset over the active ones
    ox = -np.bincount(c.parent, weights=c.share * wet[c.child] * (ix[c.child] - f * c.ix[c.parent]) * dx,
                      minlength=c.ix.size)
    oz = -np.bincount(c.parent, weights=c.share * wet[c.child] * (iz[c.child] - f * c.iz[c.parent]) * dz,
                      minlength=c.ix.size)
    from_tips = np.hypot(gx, gz) > 0.0
    vx, vz = np.where(from_tips, gx, ox), np.where(from_tips, gz, oz)
    norm = np.hypot(vx, vz)
    vx = np.where(norm > 0.0, vx / np.where(norm > 0.0, norm, 1.0), 1.0)
    vz = np.where(norm > 0.0, vz / np.where(norm > 0.0, norm, 1.0), 0.0)
    tip = fill_c < 1.0
    advance = np.full(fill_c.shape, np.nan)
    advance[tip] = advance_for_fill(fill_c[tip], vx[tip], vz[tip], f * dx, f * dz)
    return np.where(tip, fill_c, 1.0), advance


def channel_front(c: Coarsening) -> tuple[np.ndarray, np.ndarray]:
    """(fill, advance) of coarse cells that carry no sub-grid front: every cell wholly wetted (a channel cell)
    and its advance unknown (NaN) until the next step places the front."""
    return np.ones(c.ix.size), np.full(c.ix.size, np.nan)


def coarse_grid(grid: Grid, c: Coarsening, rows: np.ndarray, cols: np.ndarray, fill: np.ndarray,
                advance: np.ndarray) -> Grid:
    """The grid of the coarse cells of ``c`` (cells ``c.factor`` times larger around the same injection point,
    GROW cells of margin) holding ``grid``'s fields carried by the module docstring's rules; ``rows``, ``cols``:
    the fine active cells' box indices, in the order given to ``coarsen``; ``fill``, ``advance``: the coarse
    cells' front (``coarse_front`` or ``channel_front``). Volumes (w, leaked, w_rate) are carried exactly."""
    f, sel = c.factor, (rows, cols)
    half = int(max(np.abs(c.ix).max(), np.abs(c.iz).max())) + GROW
    new = Grid.around_injection(f * grid.dx, f * grid.dz, grid.x_inj, grid.z_inj, half)
    at = (c.iz + half, c.ix + half)
    new["active"][at] = True
    new["w"][at] = c.width(grid["w"][sel])
    new["p"][at] = c.mean(grid["p"][sel])
    new["leak_rate"][at] = c.total(grid["leak_rate"][sel]) / f**2
    new["leaked"][at] = c.total(grid["leaked"][sel]) / f**2
    new["opened"][at] = c.earliest(grid["opened"][sel])
    new["reached"][at] = c.earliest(grid["reached"][sel])
    new["filled"][at] = -c.earliest(-grid["filled"][sel])
    new["fill"][at] = fill
    new["advance"][at] = advance
    new["w_rate"][at] = c.width(grid["w_rate"][sel])
    return new
