"""The fracture's grid: uniform dx x dz cells on an unbounded plane, stored on a box that grows.

Cells carry integer indices (ix, iz) relative to the injection cell, the cell that holds the injection point
(injection.x, injection.depth); cell (ix, iz) has its centre at (x_inj + ix dx, z_inj + iz dz) (z positive
downward), (x_inj, z_inj) being the injection cell's centre. Fields live on a rectangular box of cells that is
enlarged (by ``GROW`` cells on a side) whenever an active cell comes within two cells of its edge, so there is
no predefined maximum footprint. Only active cells enter the elasticity and lubrication systems.

The grid serves the layers (:func:`fit_layers`): its rows are placed so that the layer boundary nearest the
injection point, and every boundary a whole number of cells from it, lies on a cell face, and the injection
cell is the cell holding the injection point. The point source of Eq. 29 is that cell's: Q(t) delta(x - x_inj)
is injected into cell (0, 0), whose centre is then up to half a cell (dz / 2) below or above the injection
depth, z_inj = depth + shift, -dz/2 < shift <= dz/2 (an injection point on a face is in the cell below it). A
scene without layers, or whose boundaries already lie on faces of the grid centred on the injection point,
keeps that grid (shift 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

GROW = 8
#: A boundary within this fraction of dz of a face lies on it (round-off of unit conversions).
ON_FACE = 1e-6
#: The shortest cell height tried for one that puts every boundary on a face is dz / HONOURING_RANGE.
HONOURING_RANGE = 100


@dataclass(frozen=True)
class LayerFit:
    """Where the grid's rows sit among the layer boundaries (:func:`fit_layers`).

    ``shift``: z of the injection cell's centre minus the injection depth [m], -dz/2 < shift <= dz/2;
    ``anchor``: the boundary put on a face (the one nearest the injection depth; None without boundaries);
    ``off_face``: the boundaries that are not on a face, in depth order; ``honouring``: the largest cell
    height <= dz putting every boundary on a face (None when none >= dz / ``HONOURING_RANGE`` does)."""

    shift: float
    anchor: float | None
    off_face: tuple[float, ...]
    honouring: float | None


def layer_boundaries(layers) -> tuple[float, ...]:
    """The depths [m] where the layer table's properties change, sorted: every top and bottom but the
    outermost two (the outermost layers extend to +-infinity; a gap between layers has the rock's values)."""
    ordered = sorted(layers, key=lambda layer: layer.top)
    if not ordered:
        return ()
    inner = {layer.top for layer in ordered[1:]} | {layer.bottom for layer in ordered[:-1]}
    return tuple(sorted(inner))


def _phase(value: float) -> float:
    """value - round(value), in [-1/2, 1/2]."""
    return value - round(value)


def fit_layers(depth: float, dz: float, boundaries: tuple[float, ...]) -> LayerFit:
    """The grid's placement among ``boundaries`` for cells ``dz`` tall and an injection at ``depth``.

    The faces lie at z_f = depth + shift + (k + 1/2) dz. The anchor is the boundary nearest the depth (a bound
    of the injection point's layer; of two as near, the one that brings more boundaries onto faces, then the
    shallower), and shift = b - depth - dz/2 + m dz puts it on a face, with m the integer giving
    -dz/2 < shift <= dz/2; a shift within ``ON_FACE`` dz of 0 (the anchor already on a face of the grid
    centred on the injection point) is exactly 0, one within ``ON_FACE`` dz of -dz/2 is dz/2."""
    if not boundaries:
        return LayerFit(0.0, None, (), None)

    def shift_for(b: float) -> float:
        phase = _phase((b - depth) / dz - 0.5)
        if abs(phase) < ON_FACE:
            return 0.0
        if abs(abs(phase) - 0.5) < ON_FACE:
            return 0.5 * dz
        return phase * dz

    def off_face(shift: float) -> tuple[float, ...]:
        return tuple(b for b in boundaries if abs(_phase((b - depth - shift) / dz - 0.5)) >= ON_FACE)

    anchor = min(boundaries, key=lambda b: (round(abs(b - depth) / dz / ON_FACE), len(off_face(shift_for(b))), b))
    shift = shift_for(anchor)
    return LayerFit(shift, anchor, off_face(shift), _honouring(dz, boundaries))


def _honouring(dz: float, boundaries: tuple[float, ...]) -> float | None:
    """The largest h <= dz with every spacing between boundaries a whole number of h (within ``ON_FACE``):
    h = g / n for the smallest gap g, n = 1, 2, ... from the first giving h <= dz while h >= dz / HONOURING_RANGE
    (None past it)."""
    spacings = np.diff(boundaries)
    if spacings.size == 0:
        return dz
    gap, spans = float(spacings.min()), np.asarray(boundaries) - boundaries[0]
    first = max(math.ceil(gap / dz * (1.0 - ON_FACE)), 1)
    for n in range(first, math.floor(gap / dz * HONOURING_RANGE * (1.0 + ON_FACE)) + 1):
        h = gap / n
        if np.all(np.abs(spans / h - np.round(spans / h)) < ON_FACE):
            return h
    return None


def injection_cell_centre(scene) -> tuple[float, float]:
    """(x, z) [m] of the fracture's injection cell's centre: (injection.x, injection.depth + shift), the shift of
    :func:`scene_layer_fit` (0 without layers). Coarsening keeps it (coarsen.py centres a coarse cell on it)."""
    return scene.injection.x, scene.injection.depth + scene_layer_fit(scene).shift


def scene_layer_fit(scene) -> LayerFit:
    """:func:`fit_layers` of a scene: its layer table, injection depth and cell height in use (a scene without
    ``[rock]`` layers: shift 0)."""
    layers = scene.rock.layers if scene.rock is not None else ()
    return fit_layers(scene.injection.depth, scene.mesh.dz, layer_boundaries(layers))


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
        """A (2 half + 1)^2 box centred on the injection cell, whose centre is (x_inj, z_inj) (module docstring:
        the injection depth + :attr:`LayerFit.shift`), all fields at their empty values."""
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
        """(x - x_inj, z - z_inj) of every box cell, each (nz, nx): offsets from the injection cell's centre."""
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

    def unsolved(self, t: float) -> np.ndarray:
        """Active cells the front criterion opened at time t (or later) that no solve has seen yet: width 0."""
        return self.fields["active"] & (self.fields["w"] <= 0.0) & (self.fields["opened"] >= t)

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
