"""The footprint's size (geometry.py): area, equal-area radius, length and height with tip cells counted by
their filled fraction, against a fully open rectangle (to round-off) and a prescribed circular front (second
order in the cell size); the fractions of both front modes; and the values a run reports."""

import math

import numpy as np
import pytest

from hfgpu.fracture.front import DIRECTIONS, shift
from hfgpu.fracture.geometry import filled_fraction, footprint
from hfgpu.fracture.simulator import simulate
from hfgpu.fracture.tip_cells import wetted_fraction
from hfgpu.records import MemorySink

from .helpers import scene


def _edge_distances(active: np.ndarray, s: float) -> list[np.ndarray]:
    """front.front_distances' layout with the same distance s at every side that faces a closed cell."""
    return [np.where(active & ~shift(active, -dk, -di, False), s, np.nan) for dk, di in DIRECTIONS]


@pytest.mark.parametrize("mode", ["cells", "subgrid"])
def test_fully_open_rectangle_to_round_off(mode):
    dx, dz, nx, nz = 0.3, 0.7, 11, 7
    active = np.zeros((nz + 4, nx + 6), bool)
    active[2:2 + nz, 3:3 + nx] = True
    # cells: the front one cell past every edge cell's centre (the cap), i.e. at or past its outer faces
    fraction = filled_fraction(mode, active, np.where(active, 1.0, 0.0), _edge_distances(active, 0.7), dx, dz)
    size = footprint(fraction, dx, dz)
    assert size["area"] == pytest.approx(nx * nz * dx * dz, rel=1e-15)
    assert size["length"] == pytest.approx(nx * dx, rel=1e-15)
    assert size["height"] == pytest.approx(nz * dz, rel=1e-15)
    assert size["area_radius"] == pytest.approx(math.sqrt(nx * nz * dx * dz / math.pi), rel=1e-15)


def test_cells_front_fraction_is_the_part_behind_the_reconstructed_front():
    dx, dz = 2.0, 1.0
    active = np.zeros((5, 7), bool)
    active[1:4, 1:6] = True
    fraction = filled_fraction("cells", active, np.zeros(active.shape), _edge_distances(active, 0.25), dx, dz)
    # a side cell: 1/2 + s / h across its facing side; a corner: the diagonal cut (normal (1, 1)/sqrt 2) at
    # s = 0.25 past the centre, tip_cells.wetted_fraction; inside 1, outside 0
    assert fraction[2, 1] == pytest.approx(0.5 + 0.25 / dx, rel=1e-6)
    assert fraction[1, 3] == pytest.approx(0.5 + 0.25 / dz, rel=1e-6)
    n = 1.0 / math.sqrt(2.0)
    corner = float(wetted_fraction(np.array([0.25]), np.array([-n]), np.array([-n]), dx, dz)[0])
    assert fraction[1, 1] == pytest.approx(corner, rel=1e-12) and 0.5 < corner < 1.0
    assert fraction[2, 3] == 1.0 and fraction[0].sum() == 0.0 and fraction[:, 0].sum() == 0.0
    # a cell held shut by contact holds no fluid: it counts 0, in either mode
    shut = np.zeros(active.shape, bool)
    shut[2, 1] = True
    for mode in ("cells", "subgrid"):
        held = filled_fraction(mode, active, np.ones(active.shape), _edge_distances(active, 0.25), dx, dz, shut)
        assert held[2, 1] == 0.0 and held[2, 3] == 1.0


def _circle(cells_per_radius: int, radius: float = 10.0):
    """Filled fractions of a circular front on square cells: the exact part of each cell behind the plane
    tangent to the circle at the cell's nearest point (tip_cells.wetted_fraction), as the sub-grid front
    places it."""
    h = radius / cells_per_radius
    n = 2 * cells_per_radius + 6
    x, z = np.meshgrid(*(2 * [(np.arange(n) - n // 2) * h]))
    r = np.hypot(x, z)
    safe = np.where(r > 0.0, r, 1.0)
    return footprint(wetted_fraction(radius - r, x / safe, z / safe, h, h), h, h)


def test_circular_front_converges_at_second_order():
    # measured area errors +2.3e-3 / +6.4e-4 / +1.5e-4 at 6 / 12 / 24 cells per radius
    errors = np.array([_circle(m)["area"] / (math.pi * 100.0) - 1.0 for m in (6, 12, 24)])
    assert np.all(np.abs(errors) < [3e-3, 1e-3, 2.5e-4]), errors
    order = -np.polyfit(np.log([6, 12, 24]), np.log(np.abs(errors)), 1)[0]
    assert order > 1.8, (order, errors)
    size = _circle(12)
    assert size["area_radius"] == pytest.approx(10.0, rel=5e-4)
    assert size["length"] == pytest.approx(20.0, rel=1e-12) and size["height"] == pytest.approx(20.0, rel=1e-12)


@pytest.mark.parametrize("front", ["cells", "subgrid"])
def test_a_run_reports_its_footprint_in_the_summary_and_every_snapshot(front):
    sc = scene(end_time="100 s", cell="1 m", every="25 s", fracture=f'[fracture]\nfront_tracking = "{front}"')
    sink = MemorySink()
    out = simulate(sc, sink)
    last = sink.fracture_snapshots[-1]
    for key in ("area", "area_radius", "length", "height"):
        assert float(last.extras[key]) == out[key], key
    assert out["area_radius"] == pytest.approx(math.sqrt(out["area"] / math.pi), rel=1e-15)
    # radial: length and height close to the diameter, the area below the whole open cells'
    assert out["length"] == pytest.approx(2.0 * out["area_radius"], rel=0.1)
    assert out["height"] == pytest.approx(out["length"], rel=1e-9)
    assert out["area"] <= out["cells"] * 1.0
    if front == "cells":   # the area comes from the same reconstructed front as the front summary
        assert out["area_radius"] == pytest.approx(out["radius"], rel=0.02)
    areas = [float(s.extras["area"]) for s in sink.fracture_snapshots]
    assert areas == sorted(areas)


def test_a_strip_one_cell_across_has_a_finite_footprint():
    """Closed cells above and below a row (a fracture closed onto a one-row pack): the front runs at +-s about
    each cell's centre, f = 2 s / h across the strip (the normals of the two sides cancel)."""
    active = np.zeros((5, 5), bool)
    active[2, :] = True
    distances = [np.full((5, 5), np.nan) for _ in range(4)]   # +x, -x, +z, -z (front.DIRECTIONS)
    for side in (2, 3):
        distances[side][2, :] = 0.3
    f = filled_fraction("cells", active, np.zeros((5, 5)), distances, 1.0, 1.0)
    np.testing.assert_allclose(f[2], 0.6)
    assert np.all(f[[0, 1, 3, 4]] == 0.0)
