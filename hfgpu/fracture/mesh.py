"""The fracture's grid: uniform dx x dz cells on an unbounded plane, stored on a box that grows.

Cells carry integer indices (ix, iz) relative to the injection cell, whose centre sits at
(injection.x, injection.depth); cell (ix, iz) has its centre at (x_inj + ix dx, z_inj + iz dz) (z positive
downward). Fields live on a rectangular box of cells that is enlarged (by ``GROW`` cells on a side) whenever
an active cell comes within two cells of its edge, so there is no predefined maximum footprint. Only active
cells enter the elasticity and lubrication systems.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

GROW = 8


@dataclass
class Grid:
    """Box of cells: ``fields`` maps names to (nz, nx) arrays; box cell [0, 0] has indices (ix0, iz0)."""

    dx: float
    dz: float
    x_inj: float
    z_inj: float
    ix0: int
    iz0: int
    fields: dict[str, np.ndarray] = field(default_factory=dict)

    FILL = {"active": False, "w": 0.0, "opened": np.nan, "filled": np.nan, "reached": np.nan, "leak_rate": 0.0, "p": 0.0,
            "leaked": 0.0, "fill": 0.0,
            "advance": np.nan, "w_rate": 0.0}

    @classmethod
    def around_injection(cls, dx: float, dz: float, x_inj: float, z_inj: float, half: int) -> "Grid":
        """A (2 half + 1)^2 box centred on the injection cell, all fields at their empty values."""
        n = 2 * half + 1
        grid = cls(dx, dz, x_inj, z_inj, -half, -half)
        for name, fill in cls.FILL.items():
            grid.fields[name] = np.full((n, n), fill)
        return grid

    def copy(self) -> "Grid":
        """An independent copy (every field array copied)."""
        return Grid(self.dx, self.dz, self.x_inj, self.z_inj, self.ix0, self.iz0,
                    {name: array.copy() for name, array in self.fields.items()})

    @property
    def shape(self) -> tuple[int, int]:
        return self.fields["active"].shape

    def __getitem__(self, name: str) -> np.ndarray:
        return self.fields[name]

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, z) of every box cell, each (nz, nx)."""
        nz, nx = self.shape
        x = self.x_inj + (self.ix0 + np.arange(nx)) * self.dx
        z = self.z_inj + (self.iz0 + np.arange(nz)) * self.dz
        return np.meshgrid(x, z)

    def offsets(self) -> tuple[np.ndarray, np.ndarray]:
        """(x - x_inj, z - z_inj) of every box cell, each (nz, nx)."""
        x, z = self.centres()
        return x - self.x_inj, z - self.z_inj

    def active_indices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Box (row, column) and grid (ix, iz) of the active cells, in row-major order."""
        rows, cols = np.nonzero(self.fields["active"])
        return rows, cols, cols + self.ix0, rows + self.iz0

    def shut(self, t: float) -> np.ndarray:
        """Active cells held closed by contact at time t: width 0 after their opening (a cell opened at t itself
        has not been solved yet). They start a step closed (newton.solve_step) and count no area (geometry.py)."""
        return self.fields["active"] & (self.fields["w"] <= 0.0) & (self.fields["opened"] < t)

    def ensure_margin(self, margin: int = 2) -> None:
        """Grow the box by GROW cells on every side an active cell comes within ``margin`` cells of."""
        rows, cols = np.nonzero(self.fields["active"])
        if rows.size == 0:
            return
        nz, nx = self.shape
        pad = ((GROW if rows.min() < margin else 0, GROW if rows.max() >= nz - margin else 0),
               (GROW if cols.min() < margin else 0, GROW if cols.max() >= nx - margin else 0))
        if not any(any(p) for p in pad):
            return
        for name, fill in self.FILL.items():
            self.fields[name] = np.pad(self.fields[name], pad, constant_values=fill)
        self.iz0 -= pad[0][0]
        self.ix0 -= pad[1][0]

    def bounding_box(self, margin: int = 1) -> tuple[slice, slice]:
        """Slices of the active cells' bounding box plus ``margin`` cells (clipped to the box)."""
        rows, cols = np.nonzero(self.fields["active"])
        nz, nx = self.shape
        return (slice(max(rows.min() - margin, 0), min(rows.max() + margin + 1, nz)),
                slice(max(cols.min() - margin, 0), min(cols.max() + margin + 1, nx)))
