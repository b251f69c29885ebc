"""Plane-strain (KGD) and height-contained (PKN) hydraulic fractures under constant injection, no leak-off.

Sources:

* KGD viscosity vertex: Adachi & Detournay (2002), Int. J. Numer. Anal. Meth. Geomech. 26:579; constants as in
  GEOS-DEV/GEOS docs (validationStudies/hydraulicFracture/kgdViscosityDominated/Example.rst, HydrofractureSolutions.py).
* KGD toughness vertex: Griffith crack of half-length l under uniform pressure (Sneddon) with K_I = K_Ic and
  volume balance (PyFrac ``KGD_solution_K``; GEOS ``KGDSolutions``).
* PKN: Perkins & Kern (1961) / Nordgren (1972) as in GEOS pknFracViscosityDominated/Example.rst
  (Kovalyshen & Detournay 2010; Economides & Nolte).

Q0 is the total injection rate: for KGD per unit fracture height [m^2/s] into both wings, for PKN [m^3/s].
E', K', mu' as in the paper's Eq. 1 (see :func:`hfgpu.reference.radial.scaled_parameters`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .checks import positive


@dataclass(frozen=True)
class PlaneSolution:
    """Half-length l [m], opening at the injection point w0 [m] and net pressure p0 [Pa] there, at times t."""

    length: np.ndarray
    w0: np.ndarray
    p0: np.ndarray


KGD_M_LENGTH = 0.6152      # Adachi & Detournay (2002), GEOS Example.rst
KGD_M_GAMMA = 0.616        # gamma_m0 in GEOS KGDSolutions (w = gamma Omega_bar eps L)


def _kgd_m_omega_bar(xi):
    """KGD M-vertex opening shape (Adachi & Detournay 2002, GEOS ``KGDSolutions``):
    sqrt3 (1-xi^2)^{2/3} - 0.156 (1-xi^2)^{5/3} + 0.0663 [4 s + 2 xi^2 ln((1-s)/(1+s))], s = (1-xi^2)^{1/2}."""
    xi = np.abs(np.asarray(xi, dtype=np.float64))
    a = 1.0 - xi**2
    s = np.sqrt(a)
    with np.errstate(divide="ignore", invalid="ignore"):
        log_term = np.where(xi > 0.0, xi**2 * np.log((1.0 - s) / (1.0 + s)), 0.0)
    return np.sqrt(3.0) * a ** (2.0 / 3.0) - 0.156 * a ** (5.0 / 3.0) + 0.0663 * (4.0 * s + 2.0 * log_term)


def kgd_m_vertex(E_prime, mu_prime, Q0, t) -> PlaneSolution:
    """KGD storage-viscosity vertex (Adachi & Detournay 2002):

    l = 0.6152 (E' Q0^3 t^4 / mu')^{1/6};  w0 = 0.616 Omega_bar(0) (mu' Q0^3 t^2 / E')^{1/6} = 1.134 (...)^{1/6};
    inlet net pressure from w0 p0 = 0.62 (mu' Q0 E')^{1/2} (GEOS Example.rst).
    """
    E, mu, Q, t = (positive(n, v) for n, v in (("E_prime", E_prime), ("mu_prime", mu_prime), ("Q0", Q0), ("t", t)))
    w0 = KGD_M_GAMMA * _kgd_m_omega_bar(0.0) * (mu * Q**3 * t**2 / E) ** (1.0 / 6.0)
    return PlaneSolution(length=KGD_M_LENGTH * (E * Q**3 * t**4 / mu) ** (1.0 / 6.0), w0=w0,
                         p0=0.62 * np.sqrt(mu * Q * E) / w0)


def kgd_m_opening(E_prime, mu_prime, Q0, t, xi):
    """KGD M-vertex opening w(xi) = 0.616 Omega_bar(xi) (mu' Q0^3 t^2/E')^{1/6} at scalar t, xi = x/l in [-1, 1]."""
    E, mu, Q, t = (float(positive(n, v)) for n, v in
                   (("E_prime", E_prime), ("mu_prime", mu_prime), ("Q0", Q0), ("t", t)))
    xi = np.asarray(xi, dtype=np.float64)
    if np.any(np.abs(xi) > 1.0):
        raise ValueError("xi: got values with |xi| > 1; must be x/l in [-1, 1]")
    return KGD_M_GAMMA * _kgd_m_omega_bar(xi) * (mu * Q**3 * t**2 / E) ** (1.0 / 6.0)


KGD_K_LENGTH = 2.0 / np.pi ** (2.0 / 3.0)                 # 0.9324
KGD_K_PRESSURE = np.pi ** (1.0 / 3.0) / 8.0               # 0.1831


def kgd_k_vertex(E_prime, K_prime, Q0, t) -> PlaneSolution:
    """KGD storage-toughness vertex: Griffith crack of half-length l under uniform net pressure p (Sneddon):
    w(x) = (4 p/E') (l^2 - x^2)^{1/2}, K_I = p (pi l)^{1/2} = K_Ic = K' (pi/32)^{1/2}, volume pi l w0 / 2 = Q0 t. Hence

    l = (2/pi^{2/3}) (E' Q0 t / K')^{2/3},  p = (pi^{1/3}/8) (K'^4 / (E' Q0 t))^{1/3},
    w0 = 2 Q0 t / (pi l) = 0.6828 (K'^2 Q0 t / E'^2)^{1/3} (PyFrac KGD_solution_K; GEOS KGDSolutions).
    """
    E, K, Q, t = (positive(n, v) for n, v in (("E_prime", E_prime), ("K_prime", K_prime), ("Q0", Q0), ("t", t)))
    length = KGD_K_LENGTH * (E * Q * t / K) ** (2.0 / 3.0)
    return PlaneSolution(length=length, w0=2.0 * Q * t / (np.pi * length),
                         p0=KGD_K_PRESSURE * (K**4 / (E * Q * t)) ** (1.0 / 3.0))


def kgd_toughness_number(E_prime, K_prime, mu_prime, Q0):
    """Dimensionless KGD toughness K_m = K' (E'^3 mu' Q0)^{-1/4} (Detournay 2004); the GEOS docs' regime number
    X = 256 K_Ic^4 / (3 pi^2 mu Q0 E'^3) equals K_m^4. M vertex for K_m << 1, K vertex for K_m >~ 4."""
    E, K, mu, Q = (positive(n, v) for n, v in
                   (("E_prime", E_prime), ("K_prime", K_prime), ("mu_prime", mu_prime), ("Q0", Q0)))
    return K * (E**3 * mu * Q) ** -0.25


PKN_LENGTH = 0.3817       # GEOS pknFracViscosityDominated/Example.rst (PyFrac PKN_solution: 0.3816)


def pkn(E_prime, mu, Q0, height, t) -> PlaneSolution:
    """PKN fracture (height h, viscosity dominated, no leak-off), GEOS Example.rst (Kovalyshen & Detournay 2010):

    l = 0.3817 (E' Q0^3 t^4 / (mu h^4))^{1/5},  w0 = 3 (mu Q0 l / E')^{1/4} (maximum opening at the inlet),
    p0 = (16 mu Q0 E'^3 l / (pi h^4))^{1/4} = E' w0 / (2 h) (elliptic vertical section, Sneddon). Note: mu, not mu'.
    """
    E, m, Q, h, t = (positive(n, v) for n, v in (("E_prime", E_prime), ("mu", mu), ("Q0", Q0), ("height", height),
                                                   ("t", t)))
    length = PKN_LENGTH * (E * Q**3 * t**4 / (m * h**4)) ** 0.2
    return PlaneSolution(length=length, w0=3.0 * (m * Q * length / E) ** 0.25,
                         p0=(16.0 * m * Q * E**3 * length / (np.pi * h**4)) ** 0.25)
