"""Threshold of motion on a bed surface (MppicParams.shields_deposition): Soulsby & Whitehouse's (1997)
critical Shields number, the bed shear stress of the gap-averaged flow, and the push (both backends): a grain
on the floor stays put below the critical Shields number and is entrained above it; grains off the bed or
inside a dense cell move as without the rule."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu.kernels.closures import bed
from hfgpu.kernels.closures.wall_friction import wall_friction_code, wall_friction_factor_numpy
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

from ..kernels.engine_step import MU, RHO_F, G, particle_step

RHO_P = 2550.0


def test_critical_shields_number_of_sand_in_water():
    """D* = d ((s - 1) g / nu^2)^(1/3): 0.3 mm sand (s = 2.55) in water at 1 cP has D* = 7.43 and
    theta_cr = 0.30 / (1 + 1.2 D*) + 0.055 (1 - exp(-0.02 D*)) = 0.0378 (Soulsby 1997, eq. 77); the curve
    falls from 0.30 (D* -> 0, viscous) to 0.055 (D* -> inf, Shields' rough-turbulent plateau) and is near
    0.03 at its minimum around D* = 10-30 (the dip of the Shields diagram)."""
    d_star = 0.3e-3 * ((RHO_P / RHO_F - 1.0) * G / (MU / RHO_F) ** 2) ** (1.0 / 3.0)
    assert d_star == pytest.approx(7.43, abs=0.01)
    assert bed.critical_shields_number_numpy(0.3e-3, RHO_P, RHO_F, MU, G) == pytest.approx(0.0378, abs=2e-4)
    tiny, huge = bed.critical_shields_number_numpy(np.array([1e-8, 1.0]), RHO_P, RHO_F, MU, G)
    assert tiny == pytest.approx(0.30, rel=1e-3) and huge == pytest.approx(0.055, rel=1e-3)
    d = np.geomspace(0.1e-3, 10e-3, 200)
    curve = bed.critical_shields_number_numpy(d, RHO_P, RHO_F, MU, G)
    assert 0.028 < curve.min() < 0.032


@pytest.mark.parametrize("law", ["laminar", "dean"])
def test_bed_shear_stress_is_the_surface_stress_of_the_gap_averaged_flow(law):
    """tau_b = f_t sqrt(12) mu U / w: the surface gradient mu U sqrt(12) / w of the Brinkman boundary layer
    U (1 - exp(-sqrt(12) y / w)) of the gap-averaged flow, times the fluid's wall-friction factor f_t (1
    laminar; Dean's c_f Re / 12 past Re = 899)."""
    w = 7.62e-3
    speed = np.array([0.05, 0.2, 0.5])
    lam = np.sqrt(12.0) * MU * speed / w
    tau = bed.bed_shear_stress_numpy(-speed, w, RHO_F, MU, wall_friction_code(law))
    f_t = wall_friction_factor_numpy(speed, w, MU, RHO_F, wall_friction_code(law))
    np.testing.assert_allclose(tau, lam * f_t, rtol=1e-14)
    y = np.linspace(0.0, 1e-6, 3)
    profile = 1.0 - np.exp(-np.sqrt(12.0) * y / w)  # per unit outer velocity
    slope = MU * np.gradient(profile, y)[0]
    laminar = bed.bed_shear_stress_numpy(0.2, w, RHO_F, MU, wall_friction_code("laminar"))
    assert slope * 0.2 == pytest.approx(laminar, rel=1e-3)
    if law == "dean":  # Re = 1000 x 0.5 x 7.62e-3 / 1e-3 = 3810: turbulent, 0.073/12 Re^0.75 = 2.92
        assert tau[2] / lam[2] == pytest.approx(0.073 / 12.0 * 3810.0 ** 0.75, rel=1e-12)
        assert tau[0] == lam[0]  # Re 381: laminar


def floor_case(speed, theta_cell, n=64, law="laminar"):
    """A 3 x 4 slot of 1 cm cells, gap 7.62 mm, uniform fluid velocity ``speed`` along x; n grains of 0.3 mm
    at rest on the floor (within one radius of it) in the bottom row, whose theta_p is about ``theta_cell``."""
    d, w, r = 0.01, 7.62e-3, 0.15e-3
    frame = GridFrame(d, d, d / 2, d / 2)
    width = np.full((3, 4), w)
    x = np.linspace(1.2 * d, 2.8 * d, n)
    z = np.full(n, 3.0 * d - r)
    per = theta_cell * 2 * d * d * w / (4 / 3 * np.pi * r ** 3) / n
    parcels = Parcels.create(x, z, radius=r, density=RHO_P, particles=per)
    fluid_u = np.full((3, 5), speed)
    fluid_u[:, [0, -1]] = 0.0
    params = MppicParams(shields_deposition=True, wall_friction=law)
    return frame, width, parcels, fluid_u, params


def push_once(backend_name, frame, width, parcels, fluid_u, params, dt=1e-3):
    """One particle sub-step of the engine in the fluid velocity fluid_u along x."""
    fluid = dict(u=fluid_u, v=np.zeros((4, 4)), pressure=np.zeros((3, 4)))
    particle_step(backend_name, frame, width, parcels, fluid, params, dt=dt)


def threshold_speed(law):
    """The fluid speed at which a 0.3 mm grain in the 7.62 mm gap is at the critical Shields number."""
    from scipy.optimize import brentq

    critical = bed.critical_shields_number_numpy(0.3e-3, RHO_P, RHO_F, MU, G)
    code = wall_friction_code(law)
    return brentq(lambda s: bed.shields_number_numpy(bed.bed_shear_stress_numpy(s, 7.62e-3, RHO_F, MU, code),
                                                     0.3e-3, RHO_P, RHO_F, G) - critical, 1e-3, 2.0)


@pytest.mark.parametrize("backend_name", ["numpy", "taichi"])
@pytest.mark.parametrize("law", ["laminar", "dean"])
def test_floor_grains_stay_below_the_threshold_and_move_above_it(backend_name, law):
    """Grains on the floor (loose bottom row, theta_p ~ 0.1) stop along x at 0.95 x the speed of the critical
    Shields number (0.38 m/s laminar, 0.23 m/s with Dean's friction for 0.3 mm sand in 7.62 mm) and slide
    at 1.05 x it, as fast as without the rule (it only stops; bed friction alone slows)."""
    u_c = threshold_speed(law)
    assert u_c == pytest.approx(0.381 if law == "laminar" else 0.230, rel=0.01)
    for factor, stays in ((0.95, True), (1.05, False)):
        frame, width, parcels, fluid_u, params = floor_case(factor * u_c, 0.1, law=law)
        without = parcels.copy()
        start = parcels.x.copy()
        push_once(backend_name, frame, width, parcels, fluid_u, params)
        push_once(backend_name, frame, width, without, fluid_u,
                  MppicParams(shields_deposition=False, wall_friction=law))
        if stays:
            assert np.all(parcels.u == 0.0) and np.all(without.u > 0.0)
            np.testing.assert_array_equal(parcels.x, start)
        else:
            assert np.all(parcels.u > 0.0)
            np.testing.assert_array_equal(parcels.u, without.u)


@pytest.mark.parametrize("backend_name", ["numpy", "taichi"])
def test_rule_leaves_suspended_and_buried_grains_alone(backend_name):
    """Grains 2 diameters and more above the floor in a loose cell (suspended) and grains in a dense bottom row
    (theta_p ~ 0.55 >= friction_volume_fraction: inside the bed, where bed friction and the packing cap act)
    move exactly as without the rule, in a flow slow enough to hold a surface grain."""
    for theta_cell, lift in ((0.1, 6 * 0.15e-3), (0.55, 0.0)):
        frame, width, parcels, fluid_u, params = floor_case(0.1, theta_cell)
        parcels.z[:] -= lift
        without = parcels.copy()
        push_once(backend_name, frame, width, parcels, fluid_u, params)
        push_once(backend_name, frame, width, without, fluid_u, MppicParams())
        for name in ("x", "z", "u", "v"):
            np.testing.assert_array_equal(getattr(parcels, name), getattr(without, name))
        assert np.all(parcels.u > 0.0)
