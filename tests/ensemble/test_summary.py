"""Summary tables: percentiles, the propped-cell probability maps on a common grid, and a sweep of coupled
members (proppant) through to its propped maps figure."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

import hfgpu
from hfgpu.ensemble.plots import plot_ensemble
from hfgpu.ensemble.summary import (columns, common_fraction, percentiles, read_csv, read_ensemble, write_csv,
                                    write_ensemble)
from hfgpu.ensemble.table_units import ColumnUnits, column_kinds
from hfgpu.records import GridFrame

ROOT = Path(__file__).resolve().parents[2]


def test_percentiles_skip_failed_members_and_nan():
    rows = [{"status": "complete", "m": v} for v in (1.0, 2.0, 3.0, 4.0, float("nan"))]
    rows.append({"status": "failed: Newton", "m": 100.0})
    np.testing.assert_array_equal(percentiles(rows, "m"), np.percentile([1.0, 2.0, 3.0, 4.0], [10, 50, 90]))
    assert np.isnan(percentiles([{"status": "complete", "m": float("nan")}], "m")).all()


def test_tables_round_trip_numbers_nan_and_text(tmp_path):
    header = columns(["proppant[0].size", "rock.min_stress"], ["propped_area"])
    rows = [{"id": "0000", "status": "complete", "proppant[0].size": "40/70", "rock.min_stress": 6.1e7,
             "propped_area": 123.456789012345, "wall_seconds": 1.5},
            {"id": "0001", "status": "failed: Newton, after 3 retries", "proppant[0].size": "100 mesh",
             "rock.min_stress": 6.2e7, "propped_area": float("nan"), "wall_seconds": 0.25}]
    units = ColumnUnits(column_kinds({"proppant[0].size": "", "rock.min_stress": "pressure"}, ["propped_area"]),
                        "SI", stored=True)
    write_csv(tmp_path / "summary.csv", header, rows, units)
    write_ensemble(tmp_path / "ensemble.h5", "seed = 1", header, rows, ["propped_area"], None, units)
    for back in (read_csv(tmp_path / "summary.csv"), read_ensemble(tmp_path / "ensemble.h5")["rows"]):
        assert [list(r) for r in back] == [header, header]
        assert back[0] == rows[0]
        assert back[1]["status"] == rows[1]["status"] and np.isnan(back[1]["propped_area"])
        assert back[1]["proppant[0].size"] == "100 mesh"
    assert read_ensemble(tmp_path / "ensemble.h5")["inputs"] == ["proppant[0].size", "rock.min_stress"]


def test_common_grid_takes_the_finest_cells_and_the_union_of_frames():
    coarse = (GridFrame(dx=2.0, dz=2.0, x0=1.0, z0=1.0), np.array([[True, False], [True, True]]))   # [0, 4]^2
    fine = (GridFrame(dx=1.0, dz=1.0, x0=2.5, z0=0.5), np.ones((1, 3), dtype=bool))               # x [2, 5], z [0, 1]
    frame, fraction = common_fraction([coarse, fine])
    assert frame == GridFrame(dx=1.0, dz=1.0, x0=0.5, z0=0.5)
    # row 0: the coarse map propped at x < 2, the fine one at x > 2; x > 4 lies outside the coarse frame
    np.testing.assert_array_equal(fraction, np.array([[0.5, 0.5, 0.5, 0.5, 0.5],
                                                      [0.5, 0.5, 0.0, 0.0, 0.0],
                                                      [0.5, 0.5, 0.5, 0.5, 0.0],
                                                      [0.5, 0.5, 0.5, 0.5, 0.0]]))


def test_coupled_members_give_propped_maps(tmp_path, scheduler):
    shutil.copy(ROOT / "tests" / "scenes" / "tiny_coupled.toml", tmp_path / "base.toml")
    (tmp_path / "sweep.toml").write_text('scene = "base.toml"\ndesign = "grid"\n[[vary]]\n'
                                         'key = "rock.leakoff_coefficient"\n'
                                         'values = ["1e-6 m/s**0.5", "3e-6 m/s**0.5"]\n'
                                         '[metrics]\nnames = ["propped_area", "propped_fraction", "screened_out", '
                                         '"fracture_height"]\n', encoding="utf-8")
    rows = hfgpu.sweep(tmp_path / "sweep.toml", tmp_path / "out", scheduler=scheduler, progress=False)
    assert [r["status"] for r in rows] == ["complete", "complete"]
    assert all(np.isfinite([r["propped_area"], r["propped_fraction"], r["fracture_height"]]).all() for r in rows)
    assert all(r["screened_out"] in (0.0, 1.0) for r in rows)
    assert "efficiency" not in rows[0]
    data = read_ensemble(tmp_path / "out" / "ensemble.h5")
    propped = data["propped"]
    assert propped["members"] == 2
    assert set(np.unique(propped["fraction"])) <= {0.0, 0.5, 1.0}
    names = [p.name for p in plot_ensemble(tmp_path / "out", tmp_path / "figs")]
    assert "propped_maps.png" in names and "tornado.png" in names
