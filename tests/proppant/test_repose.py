"""Angle of repose of a sand pile poured in a slot against published angles of repose of sand (issue 34,
item 3). The set-up and the measurement: bench/bed_validation.py (``pour``, ``surface``, ``flank_angles``);
the figures are printed by

    python bench/bed_validation.py repose
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
from bed_validation import PUBLISHED, collapse, flank_angles, pour, surface  # noqa: E402


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


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="no slope: the poured grains build a column one cell wide under the inlet "
                   "(surface 50 mm at 3 s, the slot's 80 mm at 8 s; flanks > 83 deg), and a released packed column "
                   "stands. No term resolves a grain's weight along a slope: the particle stress's sideways push, "
                   "bounded by the packing limiter, is stopped by bed friction (without it a released column comes to "
                   "rest at 63-65 deg) (docs/validation.md, Angle of repose)")
def test_angle_of_repose_of_a_poured_pile():
    """The poured pile's mean flank angle within 3 deg of 34 deg (Carter 1950, sand; issue 34's tolerance).
    Not met: docs/validation.md, "Angle of repose", has the measured angle and the reason measured."""
    r = pour(8.0)
    assert abs(r["angle"] - PUBLISHED["sand, Carter (1950)"]) < 3.0
