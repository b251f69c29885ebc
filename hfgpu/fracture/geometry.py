"""The fracture's size from its footprint: area, length, height and the radius of the equal-area disc.

Every cell of the footprint counts by its filled fraction f in [0, 1], the part of the cell behind the front
(1 in the channel, between 0 and 1 in a tip cell the front crosses), so with cells of dx x dz

    A = dx dz sum_cells f,    R_A = sqrt(A / pi),
    L = max_rows dx sum_row f,    H = max_columns dz sum_column f,

i.e. the length is the longest row's wetted length (tip to tip along x) and the height the tallest column's
(along z). A fully open rectangle gives its own area, length and height; a disc gives A = pi R^2 (to the
accuracy of the fractions) and L = H = its mean chord over the central column, 2 R - O(h^2 / R).

How each front gives f (``filled_fraction``):

- ``front_tracking = "subgrid"``: the tip cells' wetted fraction, the exact part of the cell behind the
  level set's plane front (tip_cells.wetted_fraction, grid field ``fill``); 1 in the channel.
- ``front_tracking = "cells"``: the front reconstructed from the widths. An edge cell (an open cell with a
  closed 4-neighbour) is a tip element: the tip asymptote inverted at its width (front.front_distances, the
  inverse of Eq. 33) puts the front at a distance s from its centre, s the largest over the sides it faces
  closed cells (capped at one cell, as the front summary). Its f is the exact part of the cell behind the
  straight front at distance s along the outward normal n, n the normalised sum of the directions of those
  sides (tip_cells.wetted_fraction: f = 1/2 + s / h on a side of a straight front, the diagonal cut in a
  corner); where those directions cancel (closed cells on opposite sides only: a strip one cell across), the
  front runs at +-s about the centre and f = min(2 s / h, 1) across the strip (the product of both axes for a
  cell closed all round); f = 1 in cells with no closed neighbour. A fully open rectangle (s >= one cell at its edges)
  gives exactly its own area. The same inverted distances give the front summary's radius, so the area and
  the front agree (``python bench/bench_fracture.py --cases long`` prints both radii's errors).

Cells that contact holds shut (width 0 after their opening, newton.py) hold no fluid and count 0 in either
mode: a barrier row that the front opened and the stress closed again is not fracture area. With whole cells,
a cell the criterion has just opened in higher-stress rock that its neighbours' fluid pressure cannot open is
left out of the footprint too (front_cells.CellFront.held).

The fluid volume of the footprint is V = dx dz sum_cells w: a tip cell's width is its cell mean (the tip
asymptote's mean over the wetted part with the sub-grid front), so V is the stored volume of the balance.
"""

from __future__ import annotations

import math

import numpy as np

from .front import DIRECTIONS
from .tip_cells import wetted_fraction


def filled_fraction(mode: str, active: np.ndarray, fill: np.ndarray, distances: list[np.ndarray] | None,
                    dx: float, dz: float, shut: np.ndarray | None = None) -> np.ndarray:
    """Filled fraction f of every box cell (module docstring), 0 outside the footprint ``active`` and in the
    cells ``shut`` (held closed by contact: no fluid, not part of the fracture's area); ``mode`` is
    ``front_tracking``; ``fill``: the sub-grid front's wetted fractions; ``distances``: with cells, the front's
    distance from each edge cell's centre per side facing a closed cell (front.front_distances, in the order
    of front.DIRECTIONS; NaN elsewhere)."""
    if shut is not None:
        active = active & ~shut
    if mode == "subgrid":
        return np.where(active, np.clip(fill, 0.0, 1.0), 0.0)
    nx, nz = np.zeros(active.shape), np.zeros(active.shape)
    across_x, across_z = np.zeros(active.shape, bool), np.zeros(active.shape, bool)
    reach = np.full(active.shape, np.nan)
    for (dk, di), s in zip(DIRECTIONS, distances):
        faces = np.isfinite(s) & active
        nx, nz = nx + di * faces, nz + dk * faces
        across_x, across_z = (across_x | faces, across_z) if di else (across_x, across_z | faces)
        reach = np.fmax(reach, np.where(faces, s, np.nan))
    edge = np.isfinite(reach)
    strip = edge & (nx == 0.0) & (nz == 0.0)   # the front on opposite sides only: a strip one cell across
    norm = np.where(edge & ~strip, np.hypot(nx, nz), 1.0)
    advance = np.where(edge, np.clip(reach, 0.0, max(dx, dz)), 0.0)
    edge_fraction = wetted_fraction(advance, np.where(strip, 1.0, nx / norm), nz / norm, dx, dz)
    across = (np.where(across_x, np.minimum(2.0 * advance / dx, 1.0), 1.0)
              * np.where(across_z, np.minimum(2.0 * advance / dz, 1.0), 1.0))   # the strip: +-s about the centre
    return np.where(strip, across, np.where(edge, edge_fraction, np.where(active, 1.0, 0.0)))


def footprint(fraction: np.ndarray, dx: float, dz: float) -> dict[str, float]:
    """{area [m^2], area_radius [m], length [m], height [m]} of filled fractions on (nz, nx) cells of
    dx x dz (module docstring)."""
    area = float(fraction.sum()) * dx * dz
    return dict(area=area, area_radius=math.sqrt(area / math.pi),
                length=float(fraction.sum(axis=1).max(initial=0.0)) * dx,
                height=float(fraction.sum(axis=0).max(initial=0.0)) * dz)
