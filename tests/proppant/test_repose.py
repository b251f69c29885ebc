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
from bed_validation import PUBLISHED, flank_angles, pour, surface  # noqa: E402


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


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="no slope: the poured grains build a column one cell wide under the inlet "
                   "(surface 50 mm at 3 s, the slot's 80 mm at 8 s; flanks > 83 deg). Nothing in the push turns a "
                   "grain's weight into motion along x: bed friction resists it, the packing cap stops a grain on a "
                   "full cell, the packing limiter bounds the stress's push to the velocity relative to the cell's "
                   "mean, 0 at rest (docs/validation.md, Angle of repose)")
def test_angle_of_repose_of_a_poured_pile():
    """The poured pile's mean flank angle within 3 deg of 34 deg (Carter 1950, sand; issue 34's tolerance).
    Not met: docs/validation.md, "Angle of repose", has the measured angle and the reason measured."""
    r = pour(8.0)
    assert abs(r["angle"] - PUBLISHED["sand, Carter (1950)"]) < 3.0
