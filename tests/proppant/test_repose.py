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
    beside it at 3 s (measured: 52.0-56.4 mm from 59.4-59.9); without it, it spreads to a peak under 50 mm
    (46.8) and stops by 10 s (its surface moved 0.011 mm from 7 to 10 s), its flanks steeper than 55 deg (a
    cliff within one cell): without bed_slope no term resolves a grain's weight along a slope, the spreading is
    the particle stress's and the packing limiter's (docs/validation.md, "Angle of repose")."""
    held = collapse(3.0, quiet=True)
    start = held["before"] > 0
    assert np.all(held["heights"][~start] == 0.0)
    assert np.abs(held["heights"][start] - held["before"][start]).max() < 8e-3
    free = collapse(10.0, extra="bed_friction = 0", quiet=True, since=7.0)
    assert free["peak"] < 50e-3 and free["left"] > 55.0 and free["right"] > 55.0
    assert free["moved"] < 1e-4 and free["speed_max"] < 1e-4


@pytest.mark.parametrize("mu_b", [0.543, 0.364, 0.700])
def test_a_released_column_slumps_no_steeper_than_the_coulomb_angle_with_the_slope(mu_b):
    """With bed_slope the same column slumps and comes to rest (its surface moves less than 1 mm from 9 to 12 s)
    with no flank steeper than atan(mu_b) + 2 deg, the Coulomb (infinite-slope) angle of repose of a cohesionless
    material (Terzaghi 1943; Nedderman 1992). A collapse runs out past the static angle, by an amount that
    depends on the column's aspect ratio and the fluid (Lube et al. 2005; Rondon et al. 2011) and has no closed
    form here: below, the flanks are only held within 8 deg of it (a slope stands). Measured at 12 s: 26.2 / 27.3
    deg at mu_b = 0.543 (28.5 deg), 12.9 / 16.1 at 0.364 (20.0), 30.3 / 30.2 at 0.700 (35.0); the surface moved
    0.03 / 0.16 / 0.00 mm from 9 s (at 0.364 it still moved 1.06 mm from 6 to 9 s; docs/validation.md, "Angle of
    repose")."""
    r = collapse(12.0, extra=f"bed_slope = true\nbed_friction = {mu_b}", quiet=True, since=9.0)
    coulomb = np.degrees(np.arctan(mu_b))
    for angle in (r["left"], r["right"]):
        assert coulomb - 8.0 < angle < coulomb + 2.0
    assert r["moved"] < 1e-3


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="poured with bed_slope, the flanks stand at 27.1 / 22.7 deg after 4 s at rest, "
                   "still moving, a staircase with a 15 mm step on the right flank (27.8 / 22.4 after 20 s; 31.0 / "
                   "29.9 with grain_pressure 'last' and damping_scheme 'implicit'), not within 3 deg of atan(mu_b) = "
                   "28.5 deg; the reason is not established (docs/validation.md, Angle of repose)")
def test_angle_of_repose_of_a_poured_pile():
    """The poured pile (8 s of pouring, 4 s at rest, bed_slope) with each flank within 3 deg of atan(mu_b) =
    28.5 deg, which is within 3 deg of no published angle of sand above (25 / 34 / 40 deg) but between them.
    Not met (27.1 / 22.7 deg): docs/validation.md, "Angle of repose", has the angles."""
    r = pour(8.0, extra="bed_slope = true", rest=4.0)
    coulomb = np.degrees(np.arctan(0.543))
    assert abs(r["left"] - coulomb) < 3.0 and abs(r["right"] - coulomb) < 3.0
