"""Coarsening of the fracture grid: merge factor x factor cells (3 x 3 by default) into one.

When the fracture outgrows the cell budget the engine continues on a grid ``factor`` times coarser. The
merge works on the integer-index representation of the active cells and keeps the injection (source) cell
at the centre of its coarse cell, so the point source of Eq. 29 stays a cell-centred source:

* the merge factor is odd (3 by default); a 2 x 2 merge cannot keep the source centred (its coarse centre
  falls on a fine-grid vertex), a 3 x 3 merge does so trivially;
* blocks are aligned on the source cell ``(cx, cz)``: coarse cell ``(K, L)`` holds the fine cells
  ``cx + f K - h .. cx + f K + h`` by ``cz + f L - h .. cz + f L + h`` (h = (f - 1) / 2), so it is centred
  on fine cell ``(cx + f K, cz + f L)`` and the source's coarse index is ``(0, 0)``; with the source at fine
  index (0, 0) both grids share their origin and coarse centres lie at ``(K f dx, L f dz)``;
* a coarse cell is active when any of its children is (no fluid is dropped).

Per-cell fields are carried by stated rules (``Coarsening`` methods):

* ``width(w)``: w_coarse = (sum of the children's widths) / f^2, inactive children counting as zero
  opening, so the fluid volume sum w dA is unchanged (to round-off);
* ``total(q)``: sum over children, for extensive per-cell quantities (volumes, masses);
* ``mean(p)``: area-weighted mean over the active children (pressure; all children have equal area);
* ``earliest(t)``: minimum over the active children (opening time tau of the Carter leak-off term of
  Eq. 29 and activation times of Eq. 34);
* ``fill``: number of active children / f^2 per coarse cell (1 inside, < 1 at the front).

Public API: ``coarsen(ix, iz, source=(0, 0), factor=3) -> Coarsening``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Coarsening:
    """Fine-to-coarse map: coarse active cells (ix, iz), and for each fine cell the index of its parent."""

    factor: int
    ix: np.ndarray
    iz: np.ndarray
    parent: np.ndarray
    fill: np.ndarray

    def total(self, values: np.ndarray) -> np.ndarray:
        """Sum over each coarse cell's active children (extensive quantities)."""
        return np.bincount(self.parent, weights=self._checked(values), minlength=self.ix.size)

    def width(self, w: np.ndarray) -> np.ndarray:
        """Coarse opening conserving fluid volume: sum(children w) dA / (f^2 dA) (inactive children: 0)."""
        return self.total(w) / self.factor**2

    def mean(self, values: np.ndarray) -> np.ndarray:
        """Area-weighted (equal areas: arithmetic) mean over each coarse cell's active children (pressure)."""
        return self.total(values) / (self.fill * self.factor**2)

    def earliest(self, times: np.ndarray) -> np.ndarray:
        """Minimum over each coarse cell's active children (opening and activation times)."""
        out = np.full(self.ix.size, np.inf)
        np.minimum.at(out, self.parent, self._checked(times))
        return out

    def _checked(self, values: np.ndarray) -> np.ndarray:
        values = np.asarray(values, dtype=float)
        if values.shape != self.parent.shape:
            raise ValueError(f"Coarsening: a per-cell field must have shape {self.parent.shape} (one value "
                             f"per fine active cell); got {values.shape}")
        return values


def coarsen(ix: np.ndarray, iz: np.ndarray, source: tuple[int, int] = (0, 0), factor: int = 3) -> Coarsening:
    """Merge factor x factor blocks of fine cells, blocks aligned so the source cell is a coarse centre.

    ``ix``, ``iz``: fine active-cell indices (distinct cells); ``source``: the injection cell's fine index.
    Coarse index K = floor((ix - cx + h) / f), h = (f - 1) / 2 (module docstring).
    """
    ix = np.asarray(ix)
    iz = np.asarray(iz)
    if ix.ndim != 1 or iz.shape != ix.shape or ix.size == 0:
        raise ValueError(f"coarsen: ix and iz must be non-empty 1-D arrays of equal length; got shapes "
                         f"{ix.shape} and {iz.shape}")
    if not (np.issubdtype(ix.dtype, np.integer) and np.issubdtype(iz.dtype, np.integer)):
        raise ValueError(f"coarsen: ix and iz must be integer arrays; got {ix.dtype} and {iz.dtype}")
    if not (isinstance(factor, (int, np.integer)) and factor >= 3 and factor % 2 == 1):
        raise ValueError(f"coarsen: factor = {factor!r}; must be an odd integer >= 3 (an even merge cannot "
                         "keep the source cell at a coarse cell centre)")
    cx, cz = (int(v) for v in source)
    half = (factor - 1) // 2
    big_k = np.floor_divide(ix.astype(np.int64) - cx + half, factor)
    big_l = np.floor_divide(iz.astype(np.int64) - cz + half, factor)
    fine_key = (iz.astype(np.int64) - iz.min()) * (int(ix.max() - ix.min()) + 1) + (ix - ix.min())
    if np.unique(fine_key).size != ix.size:
        raise ValueError("coarsen: the active cells (ix, iz) contain repeated cells")
    span = int(big_k.max() - big_k.min()) + 1
    key = (big_l - big_l.min()) * span + (big_k - big_k.min())
    unique_key, first, parent = np.unique(key, return_index=True, return_inverse=True)
    children = np.bincount(parent, minlength=unique_key.size)
    return Coarsening(factor=int(factor), ix=big_k[first], iz=big_l[first], parent=parent.ravel(),
                      fill=children / factor**2)
