"""The footprint's size (geometry.py): area, equal-area radius, length and height with tip cells counted by
their filled fraction, against a fully open rectangle (to round-off) and a prescribed circular front (second
order in the cell size); the fractions of both front modes; and the values a run reports."""

import math

import numpy as np
import pytest

from hfgpu.fracture.geometry import filled_fraction, footprint
from hfgpu.fracture.simulator import simulate
from hfgpu.fracture.tip_cells import wetted_fraction
from hfgpu.records import MemorySink

from .helpers import scene


@pytest.mark.parametrize("mode", ["cells", "subgrid"])
def test_fully_open_rectangle_to_round_off(mode):
    dx, dz, nx, nz = 0.3, 0.7, 11, 7
    active = np.zeros((nz + 4, nx + 6), bool)
    active[2:2 + nz, 3:3 + nx] = True
    opened = np.where(active, 1.0, np.nan)
    fraction = filled_fraction(mode, active, np.where(active, 1.0, 0.0), opened, opened + 2.0, 5.0)
    size = footprint(fraction, dx, dz)
    assert size["area"] == pytest.approx(nx * nz * dx * dz, rel=1e-15)
    assert size["length"] == pytest.approx(nx * dx, rel=1e-15)
    assert size["height"] == pytest.approx(nz * dz, rel=1e-15)
    assert size["area_radius"] == pytest.approx(math.sqrt(nx * nz * dx * dz / math.pi), rel=1e-15)


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


def test_cells_front_counts_a_tip_cell_by_the_time_the_front_takes_to_cross_it():
    active = np.array([[True, True, True, False]])
    opened = np.array([[0.0, 4.0, 10.0, np.nan]])
    filled = np.array([[0.0, 8.0, 14.0, np.nan]])   # the first: the starting fracture (filled = opened)
    fraction = filled_fraction("cells", active, np.zeros((1, 4)), opened, filled, 11.0)
    np.testing.assert_allclose(fraction, [[1.0, 1.0, 0.25, 0.0]], rtol=1e-15)


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
    areas = [float(s.extras["area"]) for s in sink.fracture_snapshots]
    assert areas == sorted(areas)
