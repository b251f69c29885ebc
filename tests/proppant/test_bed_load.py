"""Bed load over a settled bed against Meyer-Peter & Mueller (1948), and a bed at rest below the threshold of
motion (issue 34, item 3). The set-up and how each figure is measured: bench/bed_validation.py (``measure``);
the figures are printed by

    python bench/bed_validation.py load                 # aimed Shields numbers 0.07 0.10 0.15 0.20
    pytest -m slow tests/proppant/test_bed_load.py -s
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from bed_validation import measure  # noqa: E402


def test_bed_at_rest_below_the_threshold():
    """Shields number 0.7-1 of the critical one (aimed 0.032; measured 0.0368 over the bed against theta_cr
    0.0495): no solid flux over the middle of the slot from 0.3 to 0.8 s, and no grain of the bed's rows moving
    faster than 1e-4 m/s at 0.8 s (measured: every one at rest, 0 m/s)."""
    r = measure(0.032, 0.3, 0.8, quiet=True)
    assert 0.7 * r["theta_cr"] < r["theta"] < r["theta_cr"]
    assert r["q_total"] == 0.0
    assert r["bed_speed_max"] < 1e-4


# Measured (python bench/bed_validation.py load; "grain" bed stress, 0.5-1.5 s): aimed Shields number ->
# (Shields number over the bed, q* of the bed's rows and the grains on them, q* of everything, MPM's q*)
MEASURED = {0.07: (0.0739, 0.0, 0.0, 0.0352), 0.10: (0.1005, 0.0609, 0.0609, 0.0990),
            0.15: (0.1275, 0.612, 0.960, 0.183), 0.20: (0.2016, 1.272, 1.411, 0.486)}
NOT_MET = {0.07: "no grain moves at 1.5 theta_cr (q* 0; a surface grain's threshold of motion sees the fluid inside "
                 "the bed's top cell)",
           0.15: "q* of the bed rows 3.35 x MPM's at Shields number 0.128, most of it in the row of grains on the bed",
           0.20: "q* of the bed rows 2.62 x MPM's at Shields number 0.202, most of it in the row of grains on the bed"}


@pytest.mark.slow
@pytest.mark.parametrize("shields", [
    pytest.param(a, marks=pytest.mark.xfail(strict=True, reason=NOT_MET[a] + " (docs/validation.md, Bed load)"))
    if a in NOT_MET else a for a in MEASURED])
def test_bed_load_within_a_factor_of_two_of_meyer_peter_mueller(shields):
    """Above the threshold, q* of the bed's rows and the grains on it within a factor of 2 of Meyer-Peter &
    Mueller's q* = 8 (theta - 0.047)^1.5 at the Shields number of the flow over the bed (issue 34's
    tolerance). Met at aimed 0.10 (0.62 x MPM), not at 0.07, 0.15 and 0.20 (0, 3.35 and 2.62): MEASURED above;
    docs/validation.md, "Bed load"."""
    r = measure(shields)
    assert r["theta"] > 1.2 * r["theta_cr"]
    assert 0.5 < r["ratio_bed"] < 2.0
