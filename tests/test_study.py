"""The speed-accuracy study's machinery (bench/study.py and its bench/_study_*.py helpers): one small case with
two settings through the table and the report, and the Pareto front of a hand-made list."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench"
sys.path.insert(0, str(BENCH))

from _study_cases import CASES, PRESETS, Knobs, apply_knobs, run_case  # noqa: E402
from _study_plan import COLUMNS, format_table, preset_knobs, table_rows  # noqa: E402
from _study_report import fitted_order, pareto_front, write_report  # noqa: E402


def test_pareto_front_keeps_exactly_the_non_dominated_points():
    points = [(1.0, 0.5), (2.0, 0.2), (3.0, 0.3), (0.5, 0.9), (4.0, 0.05), (2.0, 0.25), (5.0, 0.05),
              (1.0, 0.6), (math.nan, 0.01), (6.0, math.nan)]
    # (3, 0.3) is beaten by (2, 0.2); (2, 0.25) by (2, 0.2); (5, 0.05) by (4, 0.05); (1, 0.6) by (1, 0.5).
    assert pareto_front(points) == [3, 0, 1, 4]


def test_fitted_order_recovers_a_power_law():
    h = [4.0, 2.0, 1.0, 0.5]
    assert fitted_order(h, [3.0 * x**1.5 for x in h]) == pytest.approx(1.5, rel=1e-12)
    assert math.isnan(fitted_order([1.0], [0.1]))


def test_knobs_change_the_scene():
    case = CASES["radial_I"]
    scene = case.load(Knobs(refinement=2.0, time_step_relaxation=0.25, newton_tolerance=1e-8))
    assert (scene.mesh.dx, scene.mesh.dz) == pytest.approx((2.5, 2.5))
    assert scene.fracture.time_step_relaxation == 0.25 and scene.fracture.newton_tolerance == 1e-8
    davis = CASES["davis1982"].load(Knobs(refinement=2.0, parcels_per_cell=4, dt_max=0.5))
    assert (davis.mesh.dx, davis.mesh.dz) == pytest.approx((0.01, 0.005))   # the column stays one cell wide
    assert davis.proppant.numerics.parcels_per_cell == 4 and davis.proppant.numerics.dt_max == 0.5
    # a key the scene sets wins over the preset (davis1982.toml sets parcels_per_cell and dt_max)
    fast = preset_knobs(CASES["davis1982"], "fast")
    assert fast.parcels_per_cell is None and fast.dt_max is None and fast.c_max == PRESETS["fast"].c_max
    assert apply_knobs(davis, Knobs()).proppant.numerics.parcels_per_cell == 4


def test_study_table_and_report_on_a_small_case(tmp_path):
    case = CASES["radial_I"]
    runs = [run_case(case, Knobs(refinement=0.5, time_step_relaxation=lam), f"relax {lam}", "time")
            for lam in (1.0, 0.5)]
    rows = table_rows(runs)
    assert len(rows) == 2
    for row in rows:
        assert set(COLUMNS) <= set(row)
        assert row["cells"] > 0 and row["steps"] > 0 and row["note"] == ""
        for key in ("cpu_s", "wall_s", "error"):
            assert math.isfinite(row[key]) and row[key] >= 0.0
        assert row["error"] < 0.1          # 10 m cells: R and w(0) within a few % of Dontsov (2016)
    assert set(runs[0].parts) == {"R", "w0"}
    assert len(format_table(rows).splitlines()) == 3
    meta = dict(quick=True, backend="numpy", started="now", cpu_total=1.0, wall_total=1.0,
                load=((1.0, 1.0, 1.0), (1.0, 1.0, 1.0)), cores=2, presets=PRESETS)
    paths = write_report(runs, meta, tmp_path)
    assert all(p.is_file() for p in paths)
    text = (tmp_path / "speed-accuracy.md").read_text()
    assert "Pareto front" in text and "radial_I" in text


def test_balanced_preset_is_the_engine_defaults():
    from hfgpu.fracture.config import FractureNumerics
    from hfgpu.proppant.config import MppicNumerics

    balanced = PRESETS["balanced"]
    assert balanced.refinement == 1.0
    for name in ("time_step_relaxation", "newton_tolerance"):
        assert getattr(balanced, name) == getattr(FractureNumerics(), name), name
    for name in ("simple_tolerance", "parcels_per_cell", "particle_substeps", "c_max", "dt_max"):
        assert getattr(balanced, name) == getattr(MppicNumerics(), name), name
    assert set(PRESETS) == {"fast", "balanced", "accurate"}
