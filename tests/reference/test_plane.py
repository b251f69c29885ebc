"""KGD and PKN oracles against their closed forms evaluated independently (Adachi & Detournay 2002 and GEOS's
KGDSolutions for KGD; Kovalyshen & Detournay 2010 as in GEOS's PKN example), Sneddon's crack and volume balance."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from hfgpu.reference import plane as pl

E_P = 3.2e10
MU = 1e-3
K_P = np.sqrt(32 / np.pi) * 1e6
Q0 = 1e-3
T = np.array([10.0, 100.0])


def test_kgd_m_vertex_example_numbers():
    # Adachi & Detournay (2002), l = 0.6152 (E' Q0^3 t^4 / mu')^(1/6), w0^2 = 2.1 (mu' Q0 / E')^(1/2) l, evaluated
    # here: t = 10 s -> l = 10.634 m, w0 = 0.6576 mm, p0 = 0.584 MPa; t = 100 s -> 49.36, 1.417, 0.271.
    # (That w0 comes from w0^2 = 2.1 (mu'Q0/E')^{1/2} l, ours from 0.616 Omega_bar(0): 0.2 % apart.)
    s = pl.kgd_m_vertex(E_P, 12 * MU, Q0, T)
    np.testing.assert_allclose(s.length, [10.634, 49.36], rtol=1e-3)
    np.testing.assert_allclose(s.w0, [0.6576e-3, 1.417e-3], rtol=5e-3)
    np.testing.assert_allclose(s.p0, [0.584e6, 0.271e6], rtol=5e-3)
    assert float(pl.kgd_m_opening(E_P, 12 * MU, Q0, 10.0, 0.0)) == pytest.approx(s.w0[0], rel=1e-12)
    assert pl._kgd_m_omega_bar(0.0) == pytest.approx(1.84125, abs=1e-5)


def test_kgd_m_vertex_holds_the_injected_volume():
    """2 int_0^l w dx = Q0 t; the published constants (0.6152, 0.616, Omega_bar) are rounded, so 1.5 %."""
    t = 30.0
    s = pl.kgd_m_vertex(E_P, 12 * MU, Q0, t)
    L = float(s.length)
    vol = 2 * quad(lambda x: float(pl.kgd_m_opening(E_P, 12 * MU, Q0, t, x / L)), 0, L)[0]
    assert vol == pytest.approx(Q0 * t, rel=0.015)


def test_kgd_k_vertex_example_numbers_and_griffith_crack():
    s = pl.kgd_k_vertex(E_P, K_P, Q0, T)
    # K vertex, l = 0.9324 (E' Q0 t / K')^(2/3) (PyFrac KGD_solution_K), evaluated: t=10 s -> l = 20.12 m, w0 = 0.3164 mm, p = 0.1258 MPa; t=100 s -> 93.41, 0.6816, 0.0584
    np.testing.assert_allclose(s.length, [20.12, 93.41], rtol=1e-3)
    np.testing.assert_allclose(s.w0, [0.3164e-3, 0.6816e-3], rtol=1e-3)
    np.testing.assert_allclose(s.p0, [0.1258e6, 0.0584e6], rtol=2e-3)
    # Sneddon: w0 = 4 p l / E', K_I = p (pi l)^{1/2} = K_Ic
    np.testing.assert_allclose(s.w0, 4 * s.p0 * s.length / E_P, rtol=1e-12)
    np.testing.assert_allclose(s.p0 * np.sqrt(np.pi * s.length), 1e6, rtol=1e-12)
    np.testing.assert_allclose(s.w0 / (K_P**2 * Q0 * T / E_P**2) ** (1 / 3), 0.6828, atol=1e-4)


def test_kgd_toughness_number_is_geos_regime_number():
    X = 256 / (3 * np.pi**2) * (1e6) ** 4 / (MU * Q0 * E_P**3)      # GEOS docs
    assert float(pl.kgd_toughness_number(E_P, K_P, 12 * MU, Q0)) ** 4 == pytest.approx(X, rel=1e-12)


def test_pkn_example_numbers_and_elliptic_section():
    s = pl.pkn(E_P, MU, 0.01, 20.0, np.array([100.0, 1000.0]))
    # GEOS PKN example's closed form (Kovalyshen & Detournay 2010), evaluated: t=100 s -> l = 43.85 m, w0 = 1.026 mm, p0 = 0.822 MPa; t=1000 s -> 276.6, 1.627, 1.303
    np.testing.assert_allclose(s.length, [43.85, 276.6], rtol=1e-3)
    np.testing.assert_allclose(s.w0, [1.026e-3, 1.627e-3], rtol=1e-3)
    np.testing.assert_allclose(s.p0, [0.822e6, 1.303e6], rtol=1e-3)
    np.testing.assert_allclose(s.p0, E_P * s.w0 / (2 * 20.0), rtol=2e-3)     # slit of height h (Sneddon)
    # PyFrac PKN_solution length 1.001 (Q0^3 E' t^4/(4 pi^3 mu h^4))^{1/5}
    pyfrac = 1.001 * (0.01**3 * E_P * 100.0**4 / (4 * np.pi**3 * MU * 20.0**4)) ** 0.2
    assert float(s.length[0]) == pytest.approx(pyfrac, rel=1e-3)


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="height"):
        pl.pkn(E_P, MU, 0.01, 0.0, 10.0)
    with pytest.raises(ValueError, match="xi"):
        pl.kgd_m_opening(E_P, 12 * MU, Q0, 10.0, 1.5)
