"""The field case on a coarse (5 m) and a medium (2.5 m) proppant grid, to 1800 s (600 s of slurry), as
``demos/grid_study.py`` runs it: the propped-area change between the grids within the band the study measured
(docs/field-case.md, "Convergence with the proppant grid"), and the physical invariants on both grids."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from hfgpu import open_results, run
from hfgpu.kernels.stencil_numpy import owning_cell
from hfgpu.proppant.particle_ops_numpy import on_bed
from hfgpu.propped import shields_ratio

ROOT = Path(__file__).resolve().parents[1]
END = 1800.0
#: Propped area at 1800 s, 2.5 m grid over 5 m grid, minus 1: the study measured +2.8 % (7950 -> 8169 m^2,
#: docs/field-case.md); a second seed moves the 5 m value by 0.3 %, and a different thread count changes the
#: deposits' summation order and so the parcels' paths, so the band is +-5 points around it.
PROPPED_CHANGE = (-0.022, 0.078)


@pytest.fixture(scope="module")
def grids(tmp_path_factory):
    sys.path.insert(0, str(ROOT / "demos"))
    from grid_study import scene_for

    folder = tmp_path_factory.mktemp("field_grid")
    out = {}
    for cells in (5.0, 2.5):
        path = folder / f"cells_{cells:g}.h5"
        run(scene_for(cells, END, None), path, progress=False)
        out[cells] = open_results(path)
    return out


@pytest.mark.slow
def test_propped_area_changes_with_the_grid_within_the_measured_band(grids):
    sys.path.insert(0, str(ROOT / "demos"))
    from grid_study import measure

    coarse, medium = (measure(grids[c].path, END) for c in (5.0, 2.5))
    assert coarse["propped"] > 0.0
    assert PROPPED_CHANGE[0] <= medium["propped"] / coarse["propped"] - 1.0 <= PROPPED_CHANGE[1]
    assert medium["parcels"] > 3.0 * coarse["parcels"]  # parcels per cell held: ~4x the parcels


@pytest.mark.slow
@pytest.mark.parametrize("cells", [5.0, 2.5])
def test_solids_exact_and_packing_bounded(grids, cells):
    r = grids[cells]
    assert r.status == "complete"
    b = r.proppant_balance
    np.testing.assert_allclose(b["injected"], b["in_domain"] + b["outflow"] + b["screened_out"], rtol=1e-12,
                               atol=1e-15)
    theta_cp = r.scene.proppant.params.theta_cp
    for snap in r.proppant_snapshots:
        assert np.max(snap.grid["volume_fraction"]) <= 1.05 * theta_cp


@pytest.mark.slow
@pytest.mark.parametrize("cells", [5.0, 2.5])
def test_bed_surface_grains_below_the_threshold_of_motion_do_not_slide(grids, cells):
    """Grains on a bed surface (on a floor or above a dense cell, their own cell loose) whose Shields number
    is below the critical one do not move along the bed (shields_deposition, on by default). Judged from the
    snapshot's fields (the push uses its sub-step's scatter and Eq. 40's interpolation), so a small share of
    parcels near the threshold may differ."""
    r = grids[cells]
    scene, snap = r.scene, r.proppant_snapshots[-1]
    params, f = scene.proppant.params, snap.frame
    p = {k: np.asarray(v) for k, v in snap.parcels.items()}
    width, theta = np.asarray(snap.grid["width"]), np.asarray(snap.grid["volume_fraction"])
    k, i, _ = owning_cell(p["x"], p["z"], f, width.shape)
    surface = on_bed(p["x"], p["z"], p["radius"], f, width, theta, params) \
        & (theta[k, i] < params.friction_volume_fraction) & (p["state"] == 0)
    below = surface & (shields_ratio(snap, scene.proppant, scene.fluid.density, scene.fluid.viscosity) < 0.5)
    assert below.sum() > 0
    assert np.mean(np.abs(p["u"][below]) < 1e-3) >= 0.9  # 1.00 on 5 m cells; 0.11 with the rule off
