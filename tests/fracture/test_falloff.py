"""The fall-off read with Nolte's G-function (hfgpu.fracture.falloff): g against its closed forms and its integral
definition, G dP/dG of exact lines, the closure pick against constructed kinks, the efficiency relation, and the
leak-off coefficient against Carter's law integrated independently over a constant-area fracture."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from hfgpu.fracture.falloff import (NO_DEPARTURE, NO_LINE, TOO_SHORT, G_function, closure_pick,
                                    efficiency_at_closure, falloff_analysis, fracture_stiffness, g0, g_function,
                                    leakoff_coefficient, superposition_derivative)

DTD = np.concatenate([[0.0], np.geomspace(1e-6, 1e3, 60)])


def test_g_closed_forms_match_the_hypergeometric_form():
    half = (1 + DTD) * np.arcsin((1 + DTD) ** -0.5) + DTD ** 0.5
    one = 4.0 / 3.0 * ((1 + DTD) ** 1.5 - DTD ** 1.5)
    np.testing.assert_allclose(g_function(DTD, 0.5), half, rtol=1e-12, atol=0)
    np.testing.assert_allclose(g_function(DTD, 1.0), one, rtol=1e-12, atol=0)
    assert g0(0.5) == pytest.approx(math.pi / 2, rel=1e-12, abs=0)
    assert g0(1.0) == pytest.approx(4.0 / 3.0, rel=1e-12, abs=0)


@pytest.mark.parametrize("alpha", [0.5, 2.0 / 3.0, 0.8, 8.0 / 9.0, 1.0])
def test_g_is_twice_the_carter_integral_over_the_opening_times(alpha):
    """g(dt_D) = 2 int_0^1 sqrt(1 + dt_D - s^(1/alpha)) ds: the area share s opened at tau = t_p s^(1/alpha)."""
    for d in (0.0, 0.01, 0.3, 2.0, 50.0):
        integral = quad(lambda s: math.sqrt(1 + d - s ** (1 / alpha)), 0, 1, epsabs=0, epsrel=1e-13)[0]
        assert g_function(d, alpha) == pytest.approx(2 * integral, rel=1e-10, abs=0)


def test_G_is_zero_at_shut_in_and_rises():
    for alpha in (0.5, 1.0):
        G = G_function(DTD, alpha)
        assert G[0] == 0.0 and np.all(np.diff(G) > 0)
    # the alpha = 1 form at dt_D = 1
    assert G_function(1.0, 1.0) == pytest.approx(4 / math.pi * 4 / 3 * (2 ** 1.5 - 1 - 1), rel=1e-12)


def test_an_exact_line_gives_m_G_and_no_closure():
    t_p, m = 600.0, 2.0e5
    t = t_p + np.geomspace(1.0, 6000.0, 200)
    G = G_function((t - t_p) / t_p)
    p = 30e6 - m * G
    np.testing.assert_allclose(superposition_derivative(G, p), m * G, rtol=1e-9)
    assert closure_pick(G, p, t) is None
    out = falloff_analysis(np.concatenate([np.linspace(0, t_p, 20), t]), np.concatenate([np.full(20, 31e6), p]),
                           t_p, 25e6)
    assert out.closure is None and out.G_c is None and out.efficiency is None and out.note == NO_DEPARTURE
    assert out.isip == p[0] and out.slope == pytest.approx(m, rel=1e-9)


@pytest.mark.parametrize("ratio", [0.4, 0.7, 1.6])
@pytest.mark.parametrize("alpha", [0.5, 1.0])
def test_the_pick_finds_a_kink_within_two_percent(ratio, alpha):
    """Linear in G until G_c, then a slope ``ratio`` times as steep: the pick within 2 % of G_c."""
    t_p, m = 900.0, 1.5e5
    t = t_p + np.linspace(2.0, 20 * t_p, 500)
    G = G_function((t - t_p) / t_p, alpha)
    G_c = 0.45 * G[-1]
    p = 40e6 - m * G - (ratio - 1) * m * np.clip(G - G_c, 0, None)
    pick = closure_pick(G, p, t)
    assert pick is not None and pick.G == pytest.approx(G_c, rel=0.02)
    assert pick.side == ("below" if ratio < 1 else "above")
    assert pick.slope == pytest.approx(m, rel=1e-6)
    assert pick.pressure == pytest.approx(40e6 - m * pick.G, rel=1e-12)
    assert pick.time == t[pick.index]


def test_no_pick_without_a_straight_early_part_or_enough_records():
    """A decline like p0 - c sqrt(G) (G dP/dG ~ sqrt(G), never a line through the origin) on the 8 coarse records
    of a short shut-in: no pick, and the analysis says why; 7 records are too few."""
    t_p = 40.0
    t = np.array([45.6, 54.0, 61.1, 71.6, 82.1, 96.2, 117.3, 120.0])
    G = G_function((t - t_p) / t_p)
    p = 11.2e6 - 3e5 * np.sqrt(G)
    assert closure_pick(G, p, t) is None
    out = falloff_analysis(np.concatenate([[t_p], t]), np.concatenate([[11.5e6], p]), t_p, 10e6)
    assert out.closure is None and out.note == NO_LINE and math.isnan(out.slope)
    assert falloff_analysis(t[:7], p[:7], t_p, 10e6).note == TOO_SHORT


def test_efficiency_relation():
    # alpha = 1/2: 4 g0 / pi = 2, eta = G_c / (2 + G_c); alpha = 1: 4 g0 / pi = 16 / (3 pi)
    assert efficiency_at_closure(2.0, 0.5) == pytest.approx(0.5, rel=1e-12)
    assert efficiency_at_closure(6.0, 0.5) == pytest.approx(0.75, rel=1e-12)
    assert efficiency_at_closure(16 / (3 * math.pi), 1.0) == pytest.approx(0.5, rel=1e-12)
    assert efficiency_at_closure(1.0, 1.0) == pytest.approx(1 / (1 + 16 / (3 * math.pi)), rel=1e-12)


def test_no_shut_in_raises():
    t = np.linspace(0, 100, 11)
    with pytest.raises(ValueError, match="no fall-off"):
        falloff_analysis(t, np.full(11, 1e7), 100.0, 5e6)
    with pytest.raises(ValueError, match="no fall-off"):
        falloff_analysis(t, np.full(11, 1e7), None, 5e6)


def test_compliances_are_the_sneddon_mean_widths():
    """Mean width / net pressure of the crack openings under a uniform net pressure (Sneddon: 4 p / E' sqrt(a^2 - x^2)
    across a plane-strain crack of half-size a; the penny-shaped crack 8 p R / (pi E') sqrt(1 - r^2 / R^2))."""
    E, p, h, x_f, R = 20e9, 1e6, 30.0, 50.0, 40.0
    pkn = quad(lambda z: 4 * p / E * math.sqrt(h * h / 4 - z * z), -h / 2, h / 2)[0] / h   # plane-strain ellipse
    kgd = quad(lambda x: 4 * p / E * math.sqrt(x_f * x_f - x * x), -x_f, x_f)[0] / (2 * x_f)
    radial = quad(lambda r: 2 * math.pi * r * 8 * p * R / (math.pi * E) * math.sqrt(1 - (r / R) ** 2), 0, R)[0] \
        / (math.pi * R * R)
    assert fracture_stiffness("pkn", E, h) == pytest.approx(p / pkn, rel=1e-9)
    assert fracture_stiffness("kgd", E, x_f) == pytest.approx(p / kgd, rel=1e-9)
    assert fracture_stiffness("radial", E, R) == pytest.approx(p / radial, rel=1e-9)


@pytest.mark.parametrize("alpha", [0.5, 1.0])
def test_carter_leakoff_of_a_constant_area_fracture_gives_the_G_slope(alpha):
    """An area that grew as A_e (t/t_p)^alpha, constant after shut-in, leaking 2 C_L / sqrt(t - tau) over its
    permeable share r_p: the volume leaked after shut-in, integrated numerically, drawn from the stored volume
    A_e p_net / S_f, makes p exactly linear in G(alpha); its slope gives back C_L by eq. (3)."""
    C_L, t_p, A_e, r_p = 5e-5, 1200.0, 2.0e4, 0.6
    S_f = fracture_stiffness("radial", 25e9, 80.0)
    isip = 32e6

    def leaked_after(t):   # per unit area: int_0^1 2 C_L int_{t_p}^{t} dt' / sqrt(t' - tau(s)) ds
        def rate(s):
            tau = t_p * s ** (1 / alpha)
            return 4 * C_L * (math.sqrt(t - tau) - math.sqrt(t_p - tau))

        return quad(rate, 0, 1, epsabs=0, epsrel=1e-12, limit=200)[0]

    t = t_p + np.geomspace(5.0, 3 * t_p, 40)
    p = np.array([isip - r_p * A_e * leaked_after(ti) / (A_e / S_f) for ti in t])
    G = G_function((t - t_p) / t_p, alpha)
    slope, intercept = np.polyfit(G, p, 1)
    assert np.max(np.abs(p - (intercept + slope * G))) < 1e-8 * isip      # linear in G
    assert intercept == pytest.approx(isip, rel=1e-10)
    assert leakoff_coefficient(-slope, t_p, S_f, r_p) == pytest.approx(C_L, rel=1e-8)
    out = falloff_analysis(np.concatenate([[t_p], t]), np.concatenate([[isip], p]), t_p, 30e6,
                           alpha=alpha, stiffness=S_f, permeable_fraction=r_p)
    assert out.closure is None and out.leakoff_coefficient == pytest.approx(C_L, rel=1e-6)


def test_a_curve_that_bends_from_the_start_is_picked_where_it_turns_down():
    """A fracture still extending after shut-in: G dP/dG = a sqrt(G) (no straight part through the origin) up to
    G_c = 4, then a fast decline; the pick is the peak, within 2 % of G_c, its slope dP/dG there."""
    G = np.linspace(0.02, 8.0, 400)  # noqa: N806
    a, g_c = 10.0, 4.0
    dpdg = np.where(G <= g_c, -a / np.sqrt(G), -0.2 * a / np.sqrt(G))
    p = 1e7 + np.concatenate([[0.0], np.cumsum(0.5 * (dpdg[1:] + dpdg[:-1]) * np.diff(G))])
    pick = closure_pick(G, p)
    assert pick is not None and pick.side == "peak" and pick.G == pytest.approx(g_c, rel=0.02)
    assert pick.slope == pytest.approx(superposition_derivative(G, p)[pick.index] / pick.G, rel=1e-12)
