"""MP-PIC closures against check values evaluated independently from their sources (Snider 2001, Gidaspow 1994
as in MFIX, Harris & Crighton 1994, O'Rourke & Snider 2010) and closed-form limits."""

import numpy as np
import pytest

from hfgpu.errors import SceneError
from hfgpu.proppant import closures
from hfgpu.proppant.params import MppicParams

# Check case (values evaluated independently from each source's formula): d = 0.45 mm, rho_p = 2550,
# rho_f = 1000, mu = 1 mPa s, |du| = 0.05 m/s
D, RHO_P, RHO_F, MU, SLIP = 0.45e-3, 2550.0, 1000.0, 1e-3, 0.05
THETA_F = np.array([0.99, 0.90, 0.80, 0.70, 0.60])


def test_reynolds_of_check_case():
    assert closures.reynolds(SLIP, D / 2, RHO_F, MU) == pytest.approx(22.5, rel=1e-12)


def test_snider_drag_table():
    """Snider (2001) C_d and D_p at the check case (4-5 significant digits)."""
    params = MppicParams(drag_law="snider")
    cd = closures.drag_coefficient(22.5, THETA_F, params)
    np.testing.assert_allclose(cd, [2.5379, 3.1194, 4.0346, 5.4182, 7.6472], rtol=1e-4)
    dp = closures.drag_rate(SLIP, D / 2, RHO_P, 1.0 - THETA_F, RHO_F, MU, params)
    np.testing.assert_allclose(dp, [82.94, 101.94, 131.85, 177.07, 249.91], rtol=2e-4)


def test_wen_yu_factor_reproduces_gidaspow_dilute_branch():
    """Eq. 14's factor (coefficient 0.15) with Gidaspow's Reynolds number theta_f Re gives Gidaspow's
    D_p = beta / (theta_s rho_p) for theta_f >= 0.8 (Gidaspow 1994 in MFIX's convention, evaluated independently)."""
    params = MppicParams()
    tf = THETA_F[:3]
    dp = 4.5 * MU / (RHO_P * (D / 2) ** 2) * closures.drag_factor(tf * 22.5, tf, params)
    np.testing.assert_allclose(dp, [81.08, 100.68, 131.77], rtol=2e-4)


def test_drag_stokes_limit_and_newton_branch():
    """Re -> 0: D_p -> 18 mu / (rho_p d^2) (Stokes); Re >= 1000: C_d = 0.44 theta_f^-2.65."""
    params = MppicParams()
    np.testing.assert_allclose(closures.drag_rate(0.0, D / 2, RHO_P, 0.0, RHO_F, MU, params),
                               18 * MU / (RHO_P * D ** 2), rtol=1e-14)
    np.testing.assert_allclose(closures.drag_coefficient(2000.0, 0.8, params), 0.44 * 0.8 ** -2.65, rtol=1e-14)
    paper = MppicParams(drag_re_coefficient=0.5)
    assert closures.drag_coefficient(10.0, 1.0, paper) == pytest.approx(2.4 * (1 + 0.5 * 10 ** 0.687))


def test_harris_crighton_check_values():
    """Harris & Crighton (1994) as in OpenFOAM's HarrisCrighton model: P_s = 100 Pa, beta = 3, theta_cp = 0.6,
    eps = 1e-7."""
    params = MppicParams(P_s=100.0, beta=3.0)
    tau = closures.particle_stress([0.1, 0.3, 0.5, 0.55, 0.59, 0.60], params)
    np.testing.assert_allclose(tau, [0.2, 9.0, 125.0, 332.75, 2053.8, 5.4e8], rtol=1e-4)


@pytest.mark.parametrize("theta", [0.0, 0.05, 0.3, 0.59, 0.599999])
def test_stress_derivative_matches_finite_difference(theta):
    params = MppicParams(P_s=100.0, beta=3.0)
    h = 1e-9
    fd = (closures.particle_stress(theta + h, params) - closures.particle_stress(theta - h, params)) / (2 * h) \
        if theta > 0 else 0.0
    assert closures.particle_stress_derivative(theta, params) == pytest.approx(fd, rel=1e-5, abs=1e-9)


def test_damping_check_values():
    """O'Rourke & Snider (2010) eq. 48: theta_cp = 0.6, r32 = 0.225 mm."""
    r32 = 0.225e-3
    cases = [(0.3, 0.01, 0.9, 6.60), (0.5, 0.01, 0.9, 33.0), (0.55, 0.05, 0.85, 530.3)]
    for theta, sigma, e, expected in cases:
        params = MppicParams(restitution=e, damping_threshold=0.0)
        rate = closures.damping_rate(theta, sigma ** 2, r32, params)
        assert rate == pytest.approx(expected, rel=2e-3)


def test_damping_only_near_close_packing():
    params = MppicParams(damping_threshold=0.9)
    rates = closures.damping_rate(np.array([0.3, 0.55]), 1e-4, 2e-4, params)
    assert rates[0] == 0.0 and rates[1] > 0.0
    assert closures.damping_rate(0.55, 1e-4, 2e-4, MppicParams(damping=False)) == 0.0


def test_slurry_viscosity_limits():
    """Clean fluid at theta = 0; Krieger-Dougherty's dilute slope is Einstein's 2.5 (Einstein 1906);
    the power law is Eq. 10."""
    kd = MppicParams(viscosity_law="krieger-dougherty")
    assert closures.slurry_viscosity(0.0, 2e-3, kd) == pytest.approx(2e-3, rel=1e-15)
    h = 1e-7
    slope = (closures.slurry_viscosity(h, 1.0, kd) - 1.0) / h
    assert slope == pytest.approx(2.5, rel=1e-5)
    assert closures.slurry_viscosity(0.3, 1e-3, MppicParams()) == pytest.approx(1e-3 * 0.5 ** -1.82, rel=1e-14)
    assert np.isfinite(closures.slurry_viscosity(0.7, 1e-3, MppicParams()))


@pytest.mark.parametrize("field, value", [("theta_cp", 1.2), ("drag_law", "stokes"), ("drag_iterations", 0),
                                          ("restitution", -0.1), ("viscosity_law", "linear"), ("P_s", 0.0),
                                          ("bed_friction", -0.5), ("friction_volume_fraction", 0.0),
                                          ("friction_volume_fraction", 1.0)])
def test_params_reject_bad_values_naming_the_field(field, value):
    with pytest.raises(SceneError, match=f"mppic.{field}"):
        MppicParams(**{field: value})


def test_slurry_viscosity_cap():
    """max_relative_viscosity caps mu_f / mu_0 of both laws; below the cap Eq. 10 is untouched."""
    params = MppicParams(max_relative_viscosity=1000.0)
    theta = np.array([0.3, 0.59, 0.6, 0.65])
    mu = closures.slurry_viscosity(theta, 1e-3, params)
    assert mu[0] == pytest.approx(1e-3 * 0.5 ** -1.82, rel=1e-14)
    assert mu[1:] == pytest.approx(1.0, rel=1e-12)  # (1 - 0.59/0.6)^-1.82 = 1.7e3 > 1000
    kd = MppicParams(viscosity_law="krieger-dougherty", max_relative_viscosity=50.0)
    assert closures.slurry_viscosity(0.6, 1e-3, kd) == pytest.approx(0.05, rel=1e-12)
    with pytest.raises(Exception, match="mppic.max_relative_viscosity"):
        MppicParams(max_relative_viscosity=0.5)


def test_slurry_viscosity_laws_are_named_once():
    """Each law of MppicParams.viscosity_law is one of the family's names; another name is refused."""
    from hfgpu.kernels.closures import slurry_viscosity

    assert slurry_viscosity.VISCOSITY_LAWS == ("power", "krieger-dougherty")
    with pytest.raises(ValueError, match="viscosity_law"):
        slurry_viscosity.exponent("einstein", -1.82, 0.6)
