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
- ``front_tracking = "cells"``: a cell opens when the front reaches its edge (time ``opened``) and the front
  crosses it by the time ``filled`` (its parent's crossing time, Eq. 34; the same spread of opening times
  the partially filled tip cells' Carter leak-off averages over, leakoff.carter_cumulative), so at time t
  f = (t - opened) / (filled - opened), clipped to [0, 1] (1 where filled <= opened: the starting fracture).

The fluid volume of the footprint is V = dx dz sum_cells w: a tip cell's width is its cell mean (the tip
asymptote's mean over the wetted part with the sub-grid front), so V is the stored volume of the balance.
"""

from __future__ import annotations

import math

import numpy as np


def filled_fraction(mode: str, active: np.ndarray, fill: np.ndarray, opened: np.ndarray, filled: np.ndarray,
                    t: float) -> np.ndarray:
    """Filled fraction f of every box cell at time t (module docstring), 0 outside the footprint ``active``;
    ``mode`` is ``front_tracking``."""
    if mode == "subgrid":
        return np.where(active, np.clip(fill, 0.0, 1.0), 0.0)
    span = np.where(active, filled - opened, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        ramp = np.clip((t - opened) / np.where(span > 0.0, span, 1.0), 0.0, 1.0)
    return np.where(active, np.where(span > 0.0, ramp, 1.0), 0.0)


def footprint(fraction: np.ndarray, dx: float, dz: float) -> dict[str, float]:
    """{area [m^2], area_radius [m], length [m], height [m]} of filled fractions on (nz, nx) cells of
    dx x dz (module docstring)."""
    area = float(fraction.sum()) * dx * dz
    return dict(area=area, area_radius=math.sqrt(area / math.pi),
                length=float(fraction.sum(axis=1).max(initial=0.0)) * dx,
                height=float(fraction.sum(axis=0).max(initial=0.0)) * dz)
