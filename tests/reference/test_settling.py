"""Settling oracles against their closed forms evaluated independently (Stokes, Schiller-Naumann, Snider 2001,
Richardson & Zaki 1954, Masliyah 1979 / Lockett & Bassoon 1979 and the Davis et al. 1982 batch test with the
hfgpu paper's parameters)."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu.reference import settling as s

# proppant in water
D = np.array([0.150, 0.212, 0.300, 0.450, 0.600]) * 1e-3
RHO_P, RHO_F, MU = 2550.0, 1000.0, 1e-3

# Davis et al. (1982) as in the hfgpu paper, section 5.2.1
HEAVY = (99e-6, 2990.0, 0.01)
LIGHT = (68.75e-6, 2440.0, 0.03)
DAVIS_FLUID = (992.0, 0.0667)


def test_stokes_velocity_table():
    np.testing.assert_allclose(s.stokes_velocity(D, RHO_P, RHO_F, MU), [0.0190, 0.0380, 0.0760, 0.1711, 0.3041],
                               rtol=3e-3)


def test_terminal_velocity_schiller_naumann_table_and_force_balance():
    ut = s.terminal_velocity(D, RHO_P, RHO_F, MU)
    np.testing.assert_allclose(ut, [0.0151, 0.0257, 0.0412, 0.0669, 0.0910], rtol=4e-3)
    Re = RHO_F * ut * D / MU
    np.testing.assert_allclose(Re, [2.26, 5.44, 12.4, 30.1, 54.6], rtol=4e-3)
    # weight - buoyancy = drag, evaluated independently
    drag = s.paper_drag_coefficient(Re) * 0.5 * RHO_F * ut**2 * np.pi * D**2 / 4
    np.testing.assert_allclose(drag, np.pi / 6 * D**3 * (RHO_P - RHO_F) * 9.81, rtol=1e-10)
    np.testing.assert_allclose(s.richardson_zaki_exponent(Re), [4.10, 3.76, 3.46, 3.17, 2.98], atol=6e-3)


def test_terminal_velocity_snider_drag_table():
    ut = s.terminal_velocity(D, RHO_P, RHO_F, MU, drag=s.snider_drag_coefficient)
    np.testing.assert_allclose(ut, [0.0148, 0.0252, 0.0404, 0.0659, 0.0900], rtol=4e-3)


def test_terminal_velocity_tends_to_stokes_at_low_re():
    d = 5e-6
    assert float(s.terminal_velocity(d, RHO_P, RHO_F, MU)) == pytest.approx(
        float(s.stokes_velocity(d, RHO_P, RHO_F, MU)), rel=2e-3)


def test_paper_drag_branches_and_coefficient_parameter():
    assert float(s.paper_drag_coefficient(2000.0)) == pytest.approx(0.44, rel=1e-14)
    assert float(s.paper_drag_coefficient(2000.0, theta_f=0.8)) == pytest.approx(0.44 * 0.8**-2.65, rel=1e-14)
    assert float(s.paper_drag_coefficient(10.0, coefficient=0.5)) == pytest.approx(2.4 * (1 + 0.5 * 10**0.687))
    # Snider at theta_f = 1: 24/Re (1 + Re^{2/3}/6); check value at theta_f = 0.9, Re = 22.5 evaluated independently
    assert float(s.snider_drag_coefficient(22.5, 0.9)) == pytest.approx(3.1194, abs=1e-4)


def test_richardson_zaki_correlations():
    assert float(s.richardson_zaki_exponent(0.01)) == pytest.approx(4.65)
    assert float(s.richardson_zaki_exponent(0.01, d_over_D=0.004)) == pytest.approx(4.728)
    assert float(s.richardson_zaki_exponent(1000.0)) == pytest.approx(2.39)
    assert float(s.rowe_exponent(0.0)) == pytest.approx(4.7)
    assert float(s.rowe_exponent(1e8)) == pytest.approx(0.41 / 0.175, rel=1e-3)
    assert float(s.garside_al_dibouni_exponent(0.0)) == pytest.approx(5.1)
    n = float(s.garside_al_dibouni_exponent(50.0))
    assert (5.1 - n) / (n - 2.7) == pytest.approx(0.1 * 50**0.9, rel=1e-12)


def test_hindered_velocity_table():
    np.testing.assert_allclose(s.hindered_velocity(1.0, [0.05, 0.10, 0.20, 0.30, 0.40]),
                               [0.7878, 0.6127, 0.3543, 0.1904, 0.0930], atol=1e-4)


def test_theta_minus_2_65_drag_implies_exponent_4_65_in_stokes_limit():
    n = s.implied_exponent(2e-6, RHO_P, RHO_F, MU, [0.05, 0.2, 0.4])
    np.testing.assert_allclose(n, 4.65, atol=2e-3)
    # a pure-voidage law theta^-beta in Stokes flow gives beta + 2
    n3 = s.implied_exponent(2e-6, RHO_P, RHO_F, MU, 0.2, drag=lambda Re, th: 24.0 / Re * th**-3.0)
    assert float(n3) == pytest.approx(5.0, abs=1e-9)


def test_mlb_single_species_reduces_to_richardson_zaki():
    a, rho, phi = 50e-6, 2500.0, 0.2
    u0 = float(s.stokes_velocity(2 * a, rho, 1000.0, 1e-3))
    v = s.mlb_batch_velocities([a], [rho], [phi], 1000.0, 1e-3)
    assert float(v[0]) == pytest.approx(u0 * (1 - phi) ** 4.65, rel=1e-12)


def test_davis_batch_interfaces():
    b = s.bidisperse_batch(HEAVY, LIGHT, *DAVIS_FLUID)
    # Davis et al. (1982) parameters, MLB with n = 4.65, evaluated independently
    assert b.v_heavy == pytest.approx(5.4485e-4, rel=2e-4)
    assert b.v_light == pytest.approx(1.8064e-4, rel=2e-4)
    assert b.lower_speed == pytest.approx(5.4485e-4, rel=2e-4)
    assert b.upper_speed == pytest.approx(1.9316e-4, rel=2e-4)
    assert b.phi_light_only == pytest.approx(0.03107, rel=3e-4)
    # light-species flux is continuous across the moving lower interface (jump condition)
    s1 = b.lower_speed
    assert (b.phi_light_only * (b.upper_speed - s1)) == pytest.approx(LIGHT[2] * (b.v_light - s1), rel=1e-10)
    for n, lower, upper in ((4.73, 0.05431e-2, 0.01927e-2), (5.1, 0.05349e-2, 0.01904e-2)):
        bn = s.bidisperse_batch(HEAVY, LIGHT, *DAVIS_FLUID, n=n)
        assert bn.lower_speed == pytest.approx(lower, rel=5e-4)
        assert bn.upper_speed == pytest.approx(upper, rel=5e-4)


def test_davis_interface_heights():
    b = s.bidisperse_batch(HEAVY, LIGHT, *DAVIS_FLUID)
    t = np.array([0.0, 1000.0, 1765.0, 1780.0, 4820.0, 4845.0, 6000.0])
    up, low, bed = s.bidisperse_interface_heights(t, 1.0, b, 0.01, 0.03, 0.6)
    # Kynch (1952) kinematics evaluated independently (packing 0.6 assumed): lower meets bed at ~1772 s, h ~3.4 cm; upper at ~4832 s; bed 6.67 cm
    assert low[1] == pytest.approx(1.0 - b.lower_speed * 1000.0, rel=1e-12)
    assert low[2] > bed[2] and low[3] == bed[3]
    assert bed[3] == pytest.approx(0.034, abs=5e-4)
    assert up[4] > bed[4] and up[5] == bed[5]
    np.testing.assert_allclose([up[-1], low[-1], bed[-1]], 0.04 / 0.6, rtol=1e-9)   # all solids in the bed


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="rho_p"):
        s.terminal_velocity(1e-4, 900.0, 1000.0, 1e-3)
    with pytest.raises(ValueError, match="phi"):
        s.hindered_velocity(1.0, 1.2)
    with pytest.raises(ValueError, match="heavy"):
        s.bidisperse_batch(LIGHT, HEAVY, *DAVIS_FLUID)
