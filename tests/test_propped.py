"""Propped-area analysis (hfgpu/propped.py) on synthetic snapshots whose answer is known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from types import SimpleNamespace

from hfgpu.io.results import ResultsWriter
from hfgpu.kernels.closures import bed
from hfgpu.proppant.params import MppicParams
from hfgpu.propped import (area_history, areal_solid, created_area, fracture_area_history, packed_fraction,
                           packed_history, parcel_groups, propped_cells, propped_summary)
from hfgpu.records import FractureSnapshot, GridFrame, ProppantSnapshot

FRAME = GridFrame(dx=2.0, dz=1.0, x0=10.0, z0=100.0)
THETA_CP = 0.6
D = 4e-4  # grain diameter [m]
LAYER = THETA_CP * D  # areal solid volume of one packed grain layer [m^3/m^2]


def _parcels(cells, layers, speeds, state=None):
    """One parcel per entry: in cell (k, i), holding ``layers`` packed grain layers' worth of solid."""
    k, i = np.array(cells).T
    particle = 4.0 / 3.0 * np.pi * (D / 2) ** 3
    n = np.asarray(layers) * LAYER * FRAME.dx * FRAME.dz / particle
    m = len(cells)
    return dict(x=FRAME.x0 + i * FRAME.dx + 0.3, z=FRAME.z0 + k * FRAME.dz - 0.2, u=np.asarray(speeds, float),
                v=np.zeros(m), radius=np.full(m, D / 2), density=np.full(m, 2650.0), particles=n,
                state=np.zeros(m, np.int32) if state is None else np.asarray(state, np.int32),
                class_id=np.zeros(m, np.int32))


def _snapshot(t, parcels, width=None):
    if width is None:
        width = np.full((3, 4), 5e-3)
        width[:, 3] = 0.0  # column 3 closed
    z = np.zeros((3, 4))
    return ProppantSnapshot(time=t, frame=FRAME, parcels=parcels,
                            grid=dict(width=width, volume_fraction=z, pressure=z, fluid_u=np.zeros((3, 5)),
                                      fluid_v=np.zeros((4, 4))))


def test_areal_solid_and_propped_cells_match_the_construction():
    # cell (0,0): 0.6 + 0.6 layers; (1,1): 0.99 layers; (2,2): 1.01; (0,3): closed cell with 5 layers
    parcels = _parcels([(0, 0), (0, 0), (1, 1), (2, 2), (0, 3)], [0.6, 0.6, 0.99, 1.01, 5.0], [0, 0, 0, 0, 0])
    snap = _snapshot(1.0, parcels)
    solid, diameter = areal_solid(snap)
    assert solid[0, 0] == pytest.approx(1.2 * LAYER, rel=1e-12)
    assert diameter[0, 0] == pytest.approx(D, rel=1e-12) and diameter[1, 0] == 0.0
    expected = np.zeros((3, 4), bool)
    expected[0, 0] = expected[2, 2] = True
    np.testing.assert_array_equal(propped_cells(snap, THETA_CP), expected)
    two = np.zeros((3, 4), bool)  # two layers: nothing qualifies but the closed cell (excluded)
    np.testing.assert_array_equal(propped_cells(snap, THETA_CP, layers=2.0), two)
    assert created_area(snap) == pytest.approx(9 * FRAME.dx * FRAME.dz)
    with pytest.raises(ValueError, match="theta_cp"):
        propped_cells(snap, 1.2)


def test_parcel_groups_sort_parcels_by_the_bed_rule_and_the_threshold_of_motion():
    """Six parcels placed by hand: a floor parcel at rest, one resting on a dense cell and moving under a
    sub-critical fluid, one on a floor under a super-critical fluid, two suspended, one bridged."""
    parcels = _parcels([(2, 0), (1, 1), (2, 2), (0, 0), (0, 2), (1, 0)], [0.1] * 6,
                       [0.0, 0.05, 0.2, 0.1, 2e-4, 0.0], state=[0, 0, 0, 0, 0, 1])
    parcels["z"] = parcels["z"].copy()
    parcels["z"][[0, 2]] = FRAME.z0 + 2.5 * FRAME.dz - 1e-4  # within one diameter of the grid's floor
    snap = _snapshot(1.0, parcels)
    snap.grid["volume_fraction"][2, 1] = 0.55  # the dense cell under parcel 1
    snap.grid["fluid_u"][1, :] = 0.1  # row 1: 0.1 m/s, row 2: 1 m/s
    snap.grid["fluid_u"][2, :] = 1.0
    setup = SimpleNamespace(params=MppicParams(), numerics=SimpleNamespace(gravity=9.81),
                            classes=(SimpleNamespace(name="sand"),))
    # the critical speed of these grains in water over a 5 mm gap lies between the two rows' speeds
    u_cr = bed.critical_shields_number_numpy(D, 2650.0, 1000.0, 1e-3, 9.81) * 1650.0 * 9.81 * D * 5e-3 \
        / (np.sqrt(12.0) * 1e-3)
    assert 0.1 < u_cr < 1.0
    g = parcel_groups(snap, setup, 1000.0, 1e-3)["sand"]
    assert g["all"]["count"] == 6
    assert {name: g[name]["count"] for name in ("suspended", "moving bed", "bed at rest", "bridged")} \
        == {"suspended": 2, "moving bed": 2, "bed at rest": 1, "bridged": 1}
    assert g["moving bed"]["subcritical"] == pytest.approx(0.5)  # parcel 1 below, parcel 2 above
    assert g["bed at rest"]["subcritical"] == 0.0  # on the floor of row 2 (1 m/s)
    assert g["moving bed"]["median_speed"] == pytest.approx(0.125)
    assert g["suspended"]["share"] == pytest.approx(2 / 6) and np.isnan(g["suspended"]["subcritical"])


def test_packed_fraction_counts_slow_and_bridged_parcels():
    parcels = _parcels([(0, 0)] * 5, [0.1] * 5, [0.0, 5e-4, 2e-3, 0.1, 0.2], state=[0, 0, 0, 0, 1])
    assert packed_fraction(parcels) == pytest.approx(3 / 5)
    assert packed_fraction(parcels, speed_threshold=0.05) == pytest.approx(4 / 5)
    assert np.isnan(packed_fraction(_parcels([(0, 0)], [1.0], [0.0]) | dict(u=np.zeros(0), v=np.zeros(0),
                                                                             state=np.zeros(0))))


def test_histories_from_a_results_file(tmp_path):
    path = tmp_path / "r.h5"
    with ResultsWriter(path, scene=None) as w:
        for t, open_cells in ((5.0, 2), (10.0, 6)):
            width = np.zeros((4, 4))
            width.flat[:open_cells] = 1e-3
            w.fracture_snapshot(FractureSnapshot(t, FRAME, width, width * 0, width * 0,
                                                 np.where(width > 0, 0.0, np.nan)))
        w.proppant_snapshot(_snapshot(10.0, _parcels([(0, 0)], [0.5], [0.1])))
        later = _snapshot(20.0, _parcels([(0, 0), (1, 2), (2, 1)], [2.0, 1.5, 0.2], [0.0, 0.0, 0.3]))
        w.proppant_snapshot(later)
    a = area_history(path, theta_cp=THETA_CP)
    np.testing.assert_allclose(a["time"], [10.0, 20.0])
    np.testing.assert_allclose(a["created"], [18.0, 18.0])
    np.testing.assert_allclose(a["propped"], [0.0, 4.0])
    np.testing.assert_allclose(a["fraction"], [0.0, 4.0 / 18.0])
    f = fracture_area_history(path)
    np.testing.assert_allclose(f["area"], [4.0, 12.0])
    assert packed_history(path, times=(9.0, 30.0)) == [(10.0, 0.0), (20.0, pytest.approx(2 / 3))]
    s = propped_summary(path, theta_cp=THETA_CP)
    assert s["propped_area"] == 4.0 and s["screen_out_cells"] == 0 and s["time"] == 20.0


def test_equivalent_times_are_the_papers_for_the_base_case_and_scale_with_the_slurry_period():
    from hfgpu.propped import PAPER_TIMES, equivalent_times

    assert equivalent_times(1200.0, 3600.0) == pytest.approx(PAPER_TIMES)
    assert equivalent_times(30.0, 90.0) == pytest.approx((31.5, 45.0, 90.0))
