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
    """Shields number 0.8 of the critical one (aimed 0.032; measured 0.0404 over the bed against theta_cr
    0.0495): no solid flux over the middle of the slot from 0.3 to 0.8 s, and no grain of the bed's rows moving
    faster than 1e-4 m/s at 0.8 s (measured: 2.1e-5 m/s along x, next to the outlet; in the middle half 0 along
    x and <= 3.2e-6 m/s down, the bed compacting)."""
    r = measure(0.032, 0.3, 0.8, quiet=True)
    assert 0.7 * r["theta_cr"] < r["theta"] < r["theta_cr"]
    assert r["q_total"] == 0.0
    assert r["bed_speed_max"] < 1e-4


# Measured (python bench/bed_validation.py load; "grain" bed stress, 0.5-1.5 s): aimed Shields number ->
# (Shields number over the bed, q* of the bed's rows and the grains on them, q* of everything, MPM's q*)
MEASURED = {0.07: (0.0797, 0.0, 0.0, 0.0473), 0.10: (0.1037, 0.0148, 0.0148, 0.108),
            0.15: (0.0998, 1.83, 6.38, 0.0970), 0.20: (0.1478, 9.26, 12.4, 0.256)}


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="q* / MPM measured 0 / 0.14 / 19 / 36 (bed rows; total load 0 / 0.14 / "
                   "66 / 48) at Shields numbers 0.080 / 0.104 / 0.100 / 0.148: no grain moves at 1.6 theta_cr (a surface "
                   "grain's threshold of motion sees the fluid inside the bed's top cell, at most 2.7 mm/s under a "
                   "0.28 m/s flow), and once the bed's grains are carried up into the flow the whole bed slides "
                   "(docs/validation.md, Bed load)")
@pytest.mark.parametrize("shields", [0.07, 0.10, 0.15, 0.20])
def test_bed_load_within_a_factor_of_two_of_meyer_peter_mueller(shields):
    """Above the threshold, q* of the bed's rows and the grains on it within a factor of 2 of Meyer-Peter &
    Mueller's q* = 8 (theta - 0.047)^1.5 at the Shields number of the flow over the bed (issue 34's
    tolerance). Not met: MEASURED above; docs/validation.md, "Bed load", has the reasons measured."""
    r = measure(shields)
    assert r["theta"] > 1.2 * r["theta_cr"]
    assert 0.5 < r["ratio_bed"] < 2.0
