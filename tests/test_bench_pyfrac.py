"""bench/bench_pyfrac.py without PyFrac: the errors of a run's records against a closed form (end and largest over
the late times), the PKN case's errors from synthetic records, and the table row of a saved record."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))

import bench_pyfrac as bp  # noqa: E402


def test_run_errors_end_and_signed_largest_over_late_times():
    t = np.array([1.0, 2.0, 5.0, 10.0, 20.0, 50.0])
    ref = 3.0 * t**0.8
    err = np.array([0.9, -0.5, 0.02, -0.04, 0.03, 0.01])   # the early 0.9 and -0.5 fall before t_from
    end, worst = bp.run_errors(t, ref * (1.0 + err), ref, t_from=5.0)
    assert end == pytest.approx(0.01, abs=1e-12)
    assert worst == pytest.approx(-0.04, abs=1e-12)
    values = ref * (1.0 + err)
    values[3] = math.nan                                     # a missing value is skipped
    assert bp.run_errors(t, values, ref, t_from=5.0)[1] == pytest.approx(0.03, abs=1e-12)
    assert math.isnan(bp.run_errors(t, ref, ref, t_from=100.0)[1])


def test_height_case_errors_from_synthetic_records():
    t = np.linspace(1.0, 145.0, 300)
    length, w0 = bp.height_reference(t)
    size = length * np.where(t < bp.PKN_FROM, 1.5, 1.0 + 0.05 * t / 145.0)   # large early, 5 % at the end
    e = bp.case_errors("height", {"time": t, "size": size, "w0": w0 * 0.9})
    assert e["size_end"] == pytest.approx(0.05, rel=1e-9)
    assert e["size_max"] == pytest.approx(0.05, rel=1e-9)
    assert e["w0_end"] == pytest.approx(-0.1, rel=1e-9) and e["w0_max"] == pytest.approx(-0.1, rel=1e-9)
    assert e["from"] == bp.PKN_FROM


def test_radial_case_errors_from_area_and_window(monkeypatch):
    """R_A = sqrt(A / pi); the max is over t >= 10x the first time. A power law stands in for Dontsov's
    solution (its own tests are in tests/reference)."""
    monkeypatch.setattr(bp, "radial_reference", lambda t: (0.5 * np.asarray(t) ** 0.4, 1e-3 * np.asarray(t) ** 0.2))
    t = np.geomspace(0.01, 1e5, 50)
    r = 0.5 * t**0.4 * np.where(t < 0.1, 1.3, 1.02)
    record = {"series": {"time": t, "area": math.pi * r**2, "w0": 1e-3 * t**0.2, "half_length": r}}
    e = bp.case_errors("radial", bp.size_series("radial", record))
    assert e["from"] == pytest.approx(0.1)
    assert e["size_end"] == pytest.approx(0.02, rel=1e-9) and e["size_max"] == pytest.approx(0.02, rel=1e-9)
    assert e["w0_end"] == pytest.approx(0.0, abs=1e-12)


def test_a_saved_record_makes_a_row_with_the_wall_ratio():
    t = np.linspace(1.0, 145.0, 50)
    length, w0 = bp.height_reference(t)
    record = {"code": "PyFrac", "threads": "one", "wall_s": 300.0, "cpu_s": 290.0, "steps": 400, "cells": 1234,
              "series": {"time": list(t), "area": list(t), "half_length": list(length * 1.1), "w0": list(w0)}}
    line = bp.row("height", record, hfgpu_wall=30.0)
    assert "+10.00%" in line and line.rstrip().endswith("10.00") and "PyFrac" in line


def test_thread_settings():
    one = bp.thread_env("one")
    assert all(one[k] == "1" for k in bp.THREAD_VARS)
    assert not any(k in bp.thread_env("default") for k in bp.THREAD_VARS)
    with pytest.raises(SystemExit):
        bp.thread_env("two")
