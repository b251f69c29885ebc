"""Radial-fracture oracles against published constants, conservation and tables evaluated independently of
hfgpu: the vertex closed forms of Savitski & Detournay (2002) and Madyarova (2003), and a separate Python port of
Dontsov's (2016) algorithm (the author's egordontsov/Radial-HF-rapid-solution).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from hfgpu.reference import radial as r

Q0 = 1e-3


def groups(K_Ic, mu, C_L, E=30e9, nu=0.25):
    p = r.scaled_parameters(E, nu, K_Ic, mu, C_L)
    return p.E_prime, p.K_prime, p.mu_prime, p.C_prime


def test_scaled_parameters_eq1():
    p = r.scaled_parameters(30e9, 0.25, 1e6, 1e-3, 1e-5)
    assert p.E_prime == pytest.approx(3.2e10, rel=1e-12)
    assert p.K_prime == pytest.approx(3.1915e6, rel=1e-4)          # (32/pi)^{1/2} K_Ic
    assert p.mu_prime == pytest.approx(12e-3, rel=1e-12)
    assert p.C_prime == pytest.approx(2e-5, rel=1e-12)


def test_closed_form_prefactors_match_published_values():
    # GEOS pennyFracToughnessDominated Example.rst (0.8546, 0.6537, 0.3004), Dontsov RadialVertexSolutions.m (0.4744)
    assert r.K_RADIUS == pytest.approx(0.8546, abs=1e-4)
    assert r.K_OPENING == pytest.approx(0.6537, abs=1e-4)
    assert r.K_PRESSURE == pytest.approx(0.3004, abs=1e-4)
    assert r.LEAKOFF_RADIUS == pytest.approx(0.4502, abs=1e-4)
    assert r.KT_OPENING == pytest.approx(0.4744, abs=1e-4)
    assert r.KT_PRESSURE == pytest.approx(0.41387, abs=1e-5)


def test_m_vertex_prefactor_variants_agree_within_one_percent():
    E, K, mu, C = groups(0.1e6, 1.0, 1e-9)
    m = r.m_vertex(E, mu, Q0, 10.0)
    scale_R = (E * Q0**3 * 10.0**4 / mu) ** (1 / 9)
    scale_w = (mu**2 * Q0**3 * 10.0 / E**2) ** (1 / 9)
    for pref in (0.6955, 0.6976, 0.6944):        # S&D/GEOS, PyFrac, Dontsov
        assert float(m.R) == pytest.approx(pref * scale_R, rel=0.01)
    for pref in (1.1977, 1.1953, 1.1901):        # GEOS, PyFrac polynomial, Dontsov fit
        assert float(m.w0) == pytest.approx(pref * scale_w, rel=0.01)


def test_m_vertex_profile_conserves_injected_volume():
    """int_0^R w 2 pi r dr = Q0 t (no leak-off): 2 pi gamma^2 int Omega_m0 rho drho = 1."""
    E, K, mu, C = groups(0.1e6, 1.0, 1e-9)
    t = 50.0
    R = float(r.m_vertex(E, mu, Q0, t).R)
    vol = quad(lambda rho: r.m_vertex_profile(E, mu, Q0, t, rho)[0] * 2 * np.pi * rho * R**2, 1e-9, 1 - 1e-9)[0]
    assert vol == pytest.approx(Q0 * t, rel=2e-3)


def test_m_vertex_pressure_profile():
    # Pi_m0 of Savitski & Detournay (2002) evaluated independently; PyFrac's fit within 2 % for rho <= 0.75
    E, K, mu, C = groups(0.1e6, 1.0, 1e-9)
    rho = np.array([0.10, 0.25, 0.50, 0.75, 0.90])
    t = 10.0
    w, p = r.m_vertex_profile(E, mu, Q0, t, rho)
    Pi = p / (mu * E**2 / t) ** (1 / 3)
    np.testing.assert_allclose(Pi, [0.8254, 0.7250, 0.6228, 0.5070, 0.3547], atol=1e-4)
    np.testing.assert_allclose(Pi[:4], [0.8234, 0.7233, 0.6201, 0.4999], rtol=0.02)
    assert w[0] < float(r.m_vertex(E, mu, Q0, t).w0)
    with pytest.raises(ValueError, match="rho"):
        r.m_vertex_profile(E, mu, Q0, t, [0.0, 0.5])


def test_k_vertex_is_a_sneddon_crack_at_toughness_holding_the_injected_volume():
    """Sneddon (1946): w0 = 8 p R/(pi E'), K_I = 2 p (R/pi)^{1/2}; volume 2 pi R^2 w0/3 = Q0 t."""
    E, K, mu, C = groups(2e6, 1e-6, 1e-12)
    t = np.array([1.0, 10.0, 100.0])
    s = r.k_vertex(E, K, Q0, t)
    K_Ic = K / np.sqrt(32 / np.pi)
    np.testing.assert_allclose(s.w0, 8 * s.net_pressure * s.R / (np.pi * E), rtol=1e-12)
    np.testing.assert_allclose(2 * s.net_pressure * np.sqrt(s.R / np.pi), K_Ic, rtol=1e-12)
    np.testing.assert_allclose(2 * np.pi * s.R**2 * s.w0 / 3, Q0 * t, rtol=1e-12)


def test_leakoff_vertices_lose_all_injected_fluid_and_kt_is_at_toughness():
    """Carter leak-off of a front R ~ t^{1/4}: int_0^R 2 C' (t - t0(r))^{1/2} 2 pi r dr = Q0 t, t0 = t (r/R)^4."""
    E, K, mu, C = groups(2e6, 1e-6, 1e-3)
    t = 30.0
    kt = r.kt_vertex(E, K, C, Q0, t)
    R = float(kt.R)
    lost = quad(lambda x: 2 * C * np.sqrt(t - t * (x / R) ** 4) * 2 * np.pi * x, 0, R)[0]
    assert lost == pytest.approx(Q0 * t, rel=1e-8)
    assert float(r.mt_vertex(E, mu, C, Q0, t).R) == pytest.approx(R, rel=1e-14)
    K_Ic = K / np.sqrt(32 / np.pi)
    assert 2 * float(kt.net_pressure) * np.sqrt(R / np.pi) == pytest.approx(K_Ic, rel=1e-12)
    assert float(kt.w0) == pytest.approx(8 * float(kt.net_pressure) * R / (np.pi * E), rel=1e-12)


# Evaluated independently (E' 3.2e10 Pa, Q0 1e-3 m^3/s): (K_Ic, mu, C_L) and rows t: (R vertex, w0 vertex, p vertex, R Dontsov, w0 Dontsov, eta)
TABLES = {
    "M": ((0.1e6, 1.0, 1e-9), {10: (2.1581, 1.2439e-3, 6.6702e6, 2.1538, 1.2357e-3, 1.000),
                               50: (4.4129, 1.4875e-3, 3.9008e6, 4.4044, 1.4777e-3, 1.000),
                               100: (6.0050, 1.6066e-3, 3.0960e6, 5.9933, 1.5960e-3, 1.000)}),
    "K": ((2e6, 1e-6, 1e-12), {10: (4.0908, 2.8529e-4, 8.7641e5, 4.0907, 2.8533e-4, 1.000),
                               50: (7.7875, 3.9362e-4, 6.3520e5, 7.7870, 3.9364e-4, 1.000),
                               100: (10.276, 4.5215e-4, 5.5298e5, 10.275, 4.5215e-4, 1.000)}),
    "Mt": ((0.1e6, 1.0, 1e-3), {10: (0.56610, 8.6952e-4, 1.8123e7, 0.55441, 8.7184e-4, 0.047),
                                50: (0.84651, 9.6153e-4, 1.3402e7, 0.83768, 9.6647e-4, 0.024),
                                100: (1.0067, 1.0041e-3, 1.1769e7, 0.99901, 1.0102e-3, 0.018)}),
    "Kt": ((2e6, 1e-6, 1e-3), {10: (0.56610, 1.0611e-4, 2.3559e6, 0.56428, 1.0610e-4, 0.007),
                               50: (0.84651, 1.2976e-4, 1.9265e6, 0.84499, 1.2977e-4, 0.004),
                               100: (1.0067, 1.4150e-4, 1.7667e6, 1.0053, 1.4153e-4, 0.003)}),
}


def vertex(name, E, K, mu, C, t):
    return {"M": lambda: r.m_vertex(E, mu, Q0, t), "K": lambda: r.k_vertex(E, K, Q0, t),
            "Mt": lambda: r.mt_vertex(E, mu, C, Q0, t), "Kt": lambda: r.kt_vertex(E, K, C, Q0, t)}[name]()


@pytest.mark.parametrize("name", TABLES)
def test_vertex_columns_of_reference_table(name):
    (K_Ic, mu, C_L), rows = TABLES[name]
    E, K, mu_p, C = groups(K_Ic, mu, C_L)
    t = np.array(sorted(rows), dtype=float)
    ref = np.array([rows[k] for k in sorted(rows)])
    s = vertex(name, E, K, mu_p, C, t)
    np.testing.assert_allclose(s.R, ref[:, 0], rtol=2e-4)
    np.testing.assert_allclose(s.w0, ref[:, 1], rtol=3e-4)
    if name in ("K", "Kt"):
        p = s.net_pressure
    elif name == "M":
        p = np.array([r.m_vertex_profile(E, mu_p, Q0, tk, 0.5)[1] for tk in t])
    else:
        p = r.mt_pressure_scale(E, mu_p, C, Q0, t) * 0.8594     # Pi_mt(0.5), PyFrac's Mt_vertex_solution fit
    np.testing.assert_allclose(p, ref[:, 2], rtol=3e-4)


@pytest.mark.parametrize("name", TABLES)
def test_dontsov_columns_of_reference_table(name):
    (K_Ic, mu, C_L), rows = TABLES[name]
    t = np.linspace(1.0, 100.0, 100)                # "100 time steps to 100 s"
    s = r.dontsov_radial(*groups(K_Ic, mu, C_L), Q0, t)
    idx = [9, 49, 99]
    ref = np.array([rows[k] for k in (10, 50, 100)])
    np.testing.assert_allclose(s.R[idx], ref[:, 3], rtol=5e-3)
    np.testing.assert_allclose(s.w0[idx], ref[:, 4], rtol=5e-3)
    np.testing.assert_allclose(s.efficiency[idx], ref[:, 5], atol=2e-3)


@pytest.mark.parametrize("E,nu,K_Ic,mu,C_L,times,R,w0,eta", [
    # egordontsov Radial_main.m defaults, solved by a separate port of Dontsov (2016)
    (20e9, 0.2, 1e6, 0.01, 1e-6, (100, 500, 1000), (9.018, 17.72, 23.54), (0.640e-3, 0.771e-3, 0.837e-3),
     (0.929, 0.876, 0.844)),
    # PhiPsi PC_analytical_solution.m example
    (30e9, 0.35, 0.5e6, 1e-3, 0.5e-6, (50, 250, 500), (9.278, 18.52, 24.84), (0.3135e-3, 0.3742e-3, 0.4035e-3),
     (0.947, 0.905, 0.878)),
])
def test_dontsov_mixed_regime_cases(E, nu, K_Ic, mu, C_L, times, R, w0, eta):
    t = np.linspace(times[-1] / 100, times[-1], 100)
    s = r.dontsov_radial(*groups(K_Ic, mu, C_L, E=E, nu=nu), Q0, t)
    idx = [int(round(tk / t[0])) - 1 for tk in times]
    np.testing.assert_allclose(s.R[idx], R, rtol=5e-3)
    np.testing.assert_allclose(s.w0[idx], w0, rtol=5e-3)
    np.testing.assert_allclose(s.efficiency[idx], eta, atol=2e-3)


def test_regime_numbers_of_mixed_cases():
    E, K, mu, C = groups(1e6, 0.01, 1e-6, E=20e9, nu=0.2)
    assert float(r.t_mk(E, K, mu, Q0)) == pytest.approx(54.19, rel=1e-3)
    assert float(r.tau(E, K, mu, Q0, 1000.0)) == pytest.approx(18.46, rel=1e-3)
    assert float(r.phi(E, K, mu, C, Q0)) == pytest.approx(7.80e-7, rel=2e-3)
    E, K, mu, C = groups(0.5e6, 1e-3, 0.5e-6, E=30e9, nu=0.35)
    assert float(r.t_mk(E, K, mu, Q0)) == pytest.approx(2195, rel=1e-3)
    assert float(r.phi(E, K, mu, C, Q0)) == pytest.approx(1.86e-4, rel=3e-3)
    assert r.regime(E, K, mu, C, Q0, 250.0) == "transition"


def test_transition_times():
    # Dontsov (2016) t_mk and its transition times evaluated independently: M case t_mk = 8.8e16 s, t_mm~ = 2.6e14 s; Mt case t_mm~ = 0.0961 s; Kt case t_kk~ = 1.35e-3 s
    ct = r.transition_times(*groups(0.1e6, 1.0, 1e-9), Q0)
    assert ct.t_mk == pytest.approx(8.8e16, rel=0.01)
    assert ct.t_mmt == pytest.approx(2.6e14, rel=0.02)
    assert r.transition_times(*groups(0.1e6, 1.0, 1e-3), Q0).t_mmt == pytest.approx(0.0961, rel=1e-3)
    E, K, mu, C = groups(2e6, 1e-6, 1e-3)
    ct = r.transition_times(E, K, mu, C, Q0)
    assert ct.t_kkt == pytest.approx(1.35e-3, rel=5e-3)
    # closed forms of the derived times
    assert ct.t_mmt == pytest.approx((mu**4 * Q0**6 / (E**4 * C**18)) ** (1 / 7), rel=1e-10)
    assert ct.t_kkt == pytest.approx((K**8 * Q0**2 / (E**8 * C**10)) ** (1 / 3), rel=1e-10)
    assert ct.t_mtkt == pytest.approx(mu**4 * E**12 * C**2 * Q0**2 / K**16, rel=1e-10)


# Parameters deep inside each vertex's validity zone over the whole time range.
DEEP = {"M": (0.01e6, 1.0, 1e-12, (1.0, 100.0)), "K": (3e6, 1e-7, 1e-14, (1.0, 100.0)),
        "Mt": (0.01e6, 10.0, 1e-2, (10.0, 1000.0)), "Kt": (3e6, 1e-7, 1e-2, (10.0, 1000.0))}
# w0: Dontsov's fits of the M and Mt openings differ from the vertex constants by 0.6 % and 0.8 %.
DEEP_W0_TOL = {"M": 0.01, "K": 0.005, "Mt": 0.01, "Kt": 0.005}


@pytest.mark.parametrize("name", DEEP)
def test_dontsov_approaches_each_vertex_deep_in_its_zone(name):
    K_Ic, mu, C_L, (t0, t1) = DEEP[name]
    E, K, mu_p, C = groups(K_Ic, mu, C_L)
    t = np.geomspace(t0, t1, 50)
    assert set(r.regime(E, K, mu_p, C, Q0, t)) == {name}
    s = r.dontsov_radial(E, K, mu_p, C, Q0, t)
    v = vertex(name, E, K, mu_p, C, t)
    np.testing.assert_allclose(s.R, v.R, rtol=5e-3)
    np.testing.assert_allclose(s.w0, v.w0, rtol=DEEP_W0_TOL[name])
    tip = {"M": 2 / 3, "K": 1 / 2, "Mt": 5 / 8, "Kt": 1 / 2}[name]     # w ~ (1 - rho)^delta near the front
    np.testing.assert_allclose(s.delta, tip, atol=1e-3)
    if name in ("Mt", "Kt"):
        assert np.all(s.efficiency < 0.01)
    else:
        assert np.all(s.efficiency > 0.99)


def test_dontsov_profile_and_scalar_time():
    E, K, mu, C = groups(1e6, 0.01, 1e-6, E=20e9, nu=0.2)
    s = r.dontsov_radial(E, K, mu, C, Q0, 1000.0)
    assert s.R.shape == (1,)
    assert float(s.R[0]) == pytest.approx(23.54, rel=5e-3)
    w = s.opening([0.0, 0.5, 1.0])
    assert w[0, 0] == pytest.approx(float(s.w0[0]), rel=1e-14)
    assert w[0, 2] == 0.0 and 0 < w[0, 1] < w[0, 0]


def test_paper_table2_cases_fall_in_the_regimes_the_paper_names():
    # hfgpu paper, Table 2 and section 5.1.1: cases I-IV are M, Mt, K, Kt
    cases = {"M": (40e9, 0.15, 1e6, 0.08, 0.053, 370.0, 2e-7), "Mt": (40e9, 0.15, 1e6, 0.08, 0.053, 370.0, 4e-3),
             "K": (5e9, 0.42, 1.27e6, 1e-3, 3e-5, 405.8, 1e-7), "Kt": (5e9, 0.42, 1.27e6, 1e-3, 3e-5, 407.0, 4e-4)}
    for name, (E, nu, K_Ic, mu, Q, t, C_L) in cases.items():
        Ep, Kp, mup, Cp = groups(K_Ic, mu, C_L, E=E, nu=nu)
        assert r.regime(Ep, Kp, mup, Cp, Q, t) == name


def test_zero_leakoff_is_allowed():
    E, K, mu, _ = groups(2e6, 1e-6, 0.0)
    t = np.geomspace(1.0, 100.0, 20)
    assert set(r.regime(E, K, mu, 0.0, Q0, t)) == {"K"}
    s = r.dontsov_radial(E, K, mu, 0.0, Q0, t)
    np.testing.assert_allclose(s.R, r.k_vertex(E, K, Q0, t).R, rtol=5e-3)
    np.testing.assert_allclose(s.efficiency, 1.0, atol=1e-3)   # phi floored at 1e-30 as in the reference code


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="E_prime"):
        r.m_vertex(-1.0, 1.0, 1e-3, 1.0)
    with pytest.raises(ValueError, match="nu"):
        r.scaled_parameters(1e9, 0.5, 1e6, 1e-3, 0.0)
    with pytest.raises(ValueError, match="C_prime"):
        r.dontsov_radial(1e10, 1e6, 1.0, -1.0, 1e-3, np.linspace(1, 10, 10))
    with pytest.raises(ValueError, match="t: "):
        r.dontsov_radial(1e10, 1e6, 1.0, 1e-3, 1e-3, np.array([1.0, 2.0, 3.0]))
