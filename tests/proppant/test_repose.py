"""Angle of repose of sand in a slot (issue 34, item 3): a released packed column and a poured pile, with
bed_slope, against the Coulomb angle atan(mu_b) (Terzaghi 1943; Nedderman 1992) and beside published angles of
repose of sand. The set-ups and the measurement: bench/bed_validation.py (``collapse``, ``pour``, ``surface``,
``flank_angles``); the figures are printed by

    python bench/bed_validation.py collapse --end 6 --set bed_slope=true
    python bench/bed_validation.py repose --rest 4 --set bed_slope=true
    pytest -m slow tests/proppant/test_repose.py -s

References: Carter (1950), U.S. Bureau of Reclamation Hydraulic Laboratory memorandum HYD-299, "Angle of repose
of noncohesive material": 34 deg typical of dry sand, lower for submerged sand; Kleinhans et al. (2011), J.
Geophys. Res. 116, E11004: about 25 deg for rounded grains and 40 deg for angular ones, in air or water.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from bed_validation import collapse, flank_angles, pour, surface  # noqa: E402


def test_surface_and_flank_angles_of_a_drawn_pile():
    """The measurement itself on a pile drawn at 30 deg with theta_p falling linearly across the surface cell:
    the surface where theta_p crosses 0.3 within 0.5 mm, the flank angles within 1 deg."""
    dz, nz, nx = 5e-3, 16, 32
    x = (np.arange(nx) + 0.5) * dz
    height = np.maximum(0.05 - np.tan(np.radians(30.0)) * np.abs(x - 0.08), 0.0)
    centres = (nz - 1 - np.arange(nz) + 0.5) * dz  # row 0 at the top
    theta = np.clip(0.3 + 0.6 * (height[None, :] - centres[:, None]) / dz, 0.0, 0.58)
    h = surface(theta, 0.3, dz)
    inside = height > dz
    assert np.abs(h[inside] - height[inside]).max() < 5e-4
    _, left, right = flank_angles(h, dz)
    assert left == pytest.approx(30.0, abs=1.0) and right == pytest.approx(30.0, abs=1.0)


def test_a_released_column_stands_with_bed_friction_and_spreads_without():
    """A packed column 4 cells wide and 60 mm high released in still water (bench/bed_validation.py collapse):
    with bed friction (default) it stands, every column's surface within 8 mm of where it started and none
    beside it at 3 s (measured: 52.8-57.1 mm from 59.4-59.9); without it, it spreads and stops at 10 s with
    flanks of 55-75 deg (measured 65.2 / 63.2) and a peak under 45 mm (36.0): the slope is set by the particle
    stress and the packing limiter, not by a Coulomb balance (docs/validation.md, "Angle of repose")."""
    held = collapse(3.0, quiet=True)
    start = held["before"] > 0
    assert np.all(held["heights"][~start] == 0.0)
    assert np.abs(held["heights"][start] - held["before"][start]).max() < 8e-3
    free = collapse(10.0, extra="bed_friction = 0", quiet=True)
    assert free["peak"] < 45e-3 and 55.0 < free["left"] < 75.0 and 55.0 < free["right"] < 75.0
    assert free["speed_max"] < 1e-4


@pytest.mark.parametrize("mu_b", [0.543, 0.364, 0.700])
def test_a_released_column_slumps_no_steeper_than_the_coulomb_angle_with_the_slope(mu_b):
    """With bed_slope the same column slumps and comes to rest with no flank steeper than atan(mu_b) + 2 deg, the
    Coulomb (infinite-slope) angle of repose of a cohesionless material (Terzaghi 1943; Nedderman 1992), and none
    below it by more than 5 deg (a collapse runs out past the static angle), the fastest grain under 2 mm/s at
    6 s. Measured: 28.2 / 27.8 deg at mu_b = 0.543 (28.5 deg), 15.8 / 19.8 at 0.364 (20.0), 31.5 / 31.5 at 0.700
    (35.0) (docs/validation.md, "Angle of repose")."""
    r = collapse(6.0, extra=f"bed_slope = true\nbed_friction = {mu_b}", quiet=True)
    coulomb = np.degrees(np.arctan(mu_b))
    for angle in (r["left"], r["right"]):
        assert coulomb - 5.0 < angle < coulomb + 2.0
    assert r["speed_max"] < 2e-3


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="poured with bed_slope, the flanks stand at 32.5 / 31.4 deg after 4 s at rest "
                   "(31.0 / 31.5 after 8 s; 32.2 / 35.2 on 2.5 mm cells), steeper than atan(mu_b) = 28.5 deg; the "
                   "reason is not established (docs/validation.md, Angle of repose)")
def test_angle_of_repose_of_a_poured_pile():
    """The poured pile (8 s of pouring, 4 s at rest, bed_slope) with each flank within 3 deg of atan(mu_b) =
    28.5 deg, which is within 3 deg of no published angle of sand above (25 / 34 / 40 deg) but between them.
    Not met (32.5 / 31.4 deg): docs/validation.md, "Angle of repose", has the angles."""
    r = pour(8.0, extra="bed_slope = true", rest=4.0)
    coulomb = np.degrees(np.arctan(0.543))
    assert abs(r["left"] - coulomb) < 3.0 and abs(r["right"] - coulomb) < 3.0
