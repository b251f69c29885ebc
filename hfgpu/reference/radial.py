"""Radial (penny-shaped) hydraulic fracture under constant injection: vertex solutions, regime map and
Dontsov's (2016) approximate universal solution.

Sources:

* Savitski & Detournay (2002), Int. J. Solids Struct. 39:6311 -- M (storage-viscosity) vertex.
* Madyarova (2003), MSc thesis, U. Minnesota -- M~ (leak-off-viscosity) vertex.
* K and K~ vertices: uniformly pressurised penny crack (Sneddon) with the propagation criterion K_I = K_Ic
  and global volume balance (storage, resp. Carter leak-off).
* E.V. Dontsov (2016), "An approximate solution for a penny-shaped hydraulic fracture that accounts for
  fracture toughness, fluid viscosity and leak-off", R. Soc. open sci. 3:160737 -- regime numbers
  tau, phi (the hfgpu paper's Eq. 45-46), vertex validity zones and the universal solution.

All quantities SI; material groups as in the paper's Eq. 1 (see :func:`scaled_parameters`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import beta as beta_fn
from scipy.special import betainc

from ..fracture.tip_universal import delta, g_delta
from .checks import non_negative, positive


@dataclass(frozen=True)
class ScaledParameters:
    """Material groups of the paper's Eq. 1: E' [Pa], K' [Pa m^1/2], mu' [Pa s], C' [m/s^1/2]."""

    E_prime: float
    K_prime: float
    mu_prime: float
    C_prime: float


@dataclass(frozen=True)
class VertexSolution:
    """A limiting-regime solution at times t.

    R: radius [m]; w0: opening at the injection point [m]; net_pressure: uniform net pressure [Pa] for the
    toughness vertices (K, Kt), None for the viscosity vertices (M, Mt), whose pressure varies along the
    radius (see :func:`m_vertex_profile`, :func:`mt_pressure_scale`).
    """

    R: np.ndarray
    w0: np.ndarray
    net_pressure: np.ndarray | None


@dataclass(frozen=True)
class RadialSolution:
    """Dontsov's (2016) universal radial solution at times t.

    R [m], w0 [m] (opening at the injection point), efficiency (fluid volume in the fracture / injected),
    delta and lam: opening-profile exponents, w(rho) = w0 (1 - rho)^delta (1 + rho)^lam (see :meth:`opening`).
    """

    t: np.ndarray
    R: np.ndarray
    w0: np.ndarray
    efficiency: np.ndarray
    delta: np.ndarray
    lam: np.ndarray

    def opening(self, rho):
        """w(rho, t) = w0 (1 - rho)^delta (1 + rho)^lambda (Dontsov 2016); rows: times, columns: rho."""
        rho = np.clip(np.atleast_1d(np.asarray(rho, dtype=np.float64)), 0.0, 1.0)
        return (self.w0[:, None] * (1.0 - rho[None, :]) ** self.delta[:, None]
                * (1.0 + rho[None, :]) ** self.lam[:, None])


def scaled_parameters(E: float, nu: float, K_Ic: float, mu: float, C_L: float) -> ScaledParameters:
    """Paper's Eq. 1: E' = E/(1 - nu^2), K' = 4 (2/pi)^{1/2} K_Ic, mu' = 12 mu, C' = 2 C_L.

    Same groups as Savitski & Detournay (2002) and Dontsov (2016).
    """
    positive("E", E)
    if not (np.isfinite(nu) and -1.0 < nu < 0.5):
        raise ValueError(f"nu: got {nu!r}; must be in (-1, 0.5)")
    non_negative("K_Ic", K_Ic)
    non_negative("mu", mu)
    non_negative("C_L", C_L)
    return ScaledParameters(E_prime=E / (1.0 - nu * nu), K_prime=4.0 * np.sqrt(2.0 / np.pi) * K_Ic,
                            mu_prime=12.0 * mu, C_prime=2.0 * C_L)


# ------------------------------------------------------------------------------------------------------------
# Vertex solutions (Savitski & Detournay 2002; Madyarova 2003; Sneddon's penny crack)

M_RADIUS = 0.6955      # gamma_m0, Savitski & Detournay (2002)
_M_A1, _M_B1, _M_C1, _M_C2 = 0.3581, 0.09269, 0.6846, 0.07098   # Savitski & Detournay (2002), M-vertex profile


def m_vertex(E_prime, mu_prime, Q0, t) -> VertexSolution:
    """Storage-viscosity (M) vertex, Savitski & Detournay (2002):

    R = 0.6955 (E' Q0^3 t^4 / mu')^{1/9},  w(0) = gamma_m0 Omega_m0(0) (mu'^2 Q0^3 t / E'^2)^{1/9} = 1.1977 (...)^{1/9}.
    The net pressure is log-singular at the inlet: see :func:`m_vertex_profile`.
    """
    E, mu, Q, t = (positive(n, v) for n, v in
                   (("E_prime", E_prime), ("mu_prime", mu_prime), ("Q0", Q0), ("t", t)))
    R = M_RADIUS * (E * Q**3 * t**4 / mu) ** (1.0 / 9.0)
    eps_L = (mu / (E * t)) ** (1.0 / 3.0) * (E * Q**3 * t**4 / mu) ** (1.0 / 9.0)
    return VertexSolution(R=R, w0=eps_L * _omega_m0(np.zeros(1))[0], net_pressure=None)


def _omega_m0(rho):
    """M-vertex opening Omega_m0(rho) (Savitski & Detournay 2002, as in GEOS HydrofractureSolutions.py)."""
    rho = np.asarray(rho, dtype=np.float64)
    poly = (np.sqrt(70.0) / 3.0 * _M_C1 + 4.0 * np.sqrt(5.0) / 9.0 * _M_C2 * (13.0 * rho - 6.0))
    tip = _M_B1 * 8.0 / np.pi * (np.sqrt(1.0 - rho**2) - rho * np.arccos(rho))
    return M_RADIUS * (poly * (1.0 - rho) ** (2.0 / 3.0) + tip)


def _pi_m0(rho):
    """M-vertex net pressure Pi_m0(rho) = A1 [2.479 - 2/(3 (1-rho)^{1/3})] - B1 [ln(rho/2) + 1] (S&D 2002)."""
    rho = np.asarray(rho, dtype=np.float64)
    return _M_A1 * (2.479 - 2.0 / (3.0 * (1.0 - rho) ** (1.0 / 3.0))) - _M_B1 * (np.log(rho / 2.0) + 1.0)


def m_vertex_profile(E_prime, mu_prime, Q0, t, rho):
    """M-vertex opening and net pressure at scalar time t and rho = r/R in (0, 1) (Savitski & Detournay 2002):

    w = eps L Omega_m0(rho), p = eps E' Pi_m0(rho) = (mu' E'^2 / t)^{1/3} Pi_m0(rho),
    eps = (mu'/(E' t))^{1/3}, L = (E' Q0^3 t^4/mu')^{1/9}. Returns (w, p) arrays shaped like rho.
    """
    E, mu, Q, t = (float(positive(n, v)) for n, v in
                   (("E_prime", E_prime), ("mu_prime", mu_prime), ("Q0", Q0), ("t", t)))
    rho = np.asarray(rho, dtype=np.float64)
    if np.any((rho <= 0.0) | (rho >= 1.0)):
        raise ValueError(f"rho: got {rho!r}; must lie in (0, 1) (the M-vertex pressure is singular at 0 and 1)")
    eps = (mu / (E * t)) ** (1.0 / 3.0)
    L = (E * Q**3 * t**4 / mu) ** (1.0 / 9.0)
    return eps * L * _omega_m0(rho), eps * E * _pi_m0(rho)


K_RADIUS = (3.0 / (np.sqrt(2.0) * np.pi)) ** 0.4   # 0.8546
K_OPENING = (3.0 / (8.0 * np.pi)) ** 0.2           # 0.6537
K_PRESSURE = np.pi / 8.0 * (np.pi / 12.0) ** 0.2   # 0.3004


def k_vertex(E_prime, K_prime, Q0, t) -> VertexSolution:
    """Storage-toughness (K) vertex (Savitski & Detournay 2002; uniformly loaded penny crack):

    R = (3/(sqrt2 pi))^{2/5} (E' Q0 t / K')^{2/5}, w(0) = (3/(8 pi))^{1/5} (K'^4 Q0 t / E'^4)^{1/5},
    p = (pi/8)(pi/12)^{1/5} (K'^6/(E' Q0 t))^{1/5} (uniform); profile w = w(0) (1 - rho^2)^{1/2}.
    """
    E, K, Q, t = (positive(n, v) for n, v in
                  (("E_prime", E_prime), ("K_prime", K_prime), ("Q0", Q0), ("t", t)))
    return VertexSolution(R=K_RADIUS * (E * Q * t / K) ** 0.4, w0=K_OPENING * (K**4 * Q * t / E**4) ** 0.2,
                          net_pressure=K_PRESSURE * (K**6 / (E * Q * t)) ** 0.2)


MP_RADIUS = 0.836406   # the viscous pulse's radius coefficient, PyFrac's HF_reference_solutions.Mp_vertex_solution


def mp_pulse_radius(E_prime, mu_prime, V0, t):
    """Radius of a viscosity-dominated (Mp vertex) pulse, a radial fracture that holds a finite volume V0 of
    fluid without leak-off, long after its injection stopped: R = 0.836406 (E' V0^3 t / mu')^{1/9}, t the time
    since the start of the injection (PyFrac's Mp_vertex_solution)."""
    E, mu, V, t = (positive(n, v) for n, v in (("E_prime", E_prime), ("mu_prime", mu_prime), ("V0", V0), ("t", t)))
    return MP_RADIUS * (E * V**3 * t / mu) ** (1.0 / 9.0)


ARREST_RADIUS = 0.521771773755632468   # the leak-off arrest radius coefficient, PyFrac's LeakOff_arrest


def leakoff_arrest_radius(E_prime, C_prime, V0, mu_prime):
    """Radius at which a viscosity-dominated pulse (toughness 0) of volume V0, injected in a time short against its
    arrest, stops as Carter leak-off (C' = 2 C_L) takes its fluid: R_a = 0.521772 (E' V0^5 / (C'^2 mu'))^{1/13}
    (PyFrac's HF_reference_solutions.LeakOff_arrest; Moeri & Lecampion 2022, "Arrest of a radial hydraulic
    fracture upon shut-in of the injection", Int. J. Solids Struct.)."""
    E, C, V, mu = (positive(n, v) for n, v in (("E_prime", E_prime), ("C_prime", C_prime), ("V0", V0),
                                               ("mu_prime", mu_prime)))
    return ARREST_RADIUS * (E * V**5 / (C**2 * mu)) ** (1.0 / 13.0)


LEAKOFF_RADIUS = np.sqrt(2.0) / np.pi   # 0.4502
MT_OPENING = 1.0493                     # Madyarova (2003) Omega(0): PyFrac's Mt_vertex_solution fit at rho = 0


def _leakoff_radius(C, Q, t):
    """Radius when all injected fluid leaks off (M~ and K~ vertices): R = (sqrt2/pi) (Q0^2 t / C'^2)^{1/4}.

    From Q0 t = int_0^R 2 C' sqrt(t - t0(r)) 2 pi r dr with R ~ t^{1/4} (Carter leak-off, zero storage).
    """
    return LEAKOFF_RADIUS * (Q**2 * t / C**2) ** 0.25


def mt_vertex(E_prime, mu_prime, C_prime, Q0, t) -> VertexSolution:
    """Leak-off-viscosity (M~) vertex (Madyarova 2003):

    R = (sqrt2/pi) (Q0^2 t / C'^2)^{1/4}, w(0) = 1.0493 (mu'^4 Q0^6 t / (E'^4 C'^2))^{1/16}.
    Pressure varies along the radius: p = :func:`mt_pressure_scale` x Pi_mt(rho).
    """
    E, mu, C, Q, t = (positive(n, v) for n, v in (("E_prime", E_prime), ("mu_prime", mu_prime),
                                                    ("C_prime", C_prime), ("Q0", Q0), ("t", t)))
    return VertexSolution(R=_leakoff_radius(C, Q, t),
                          w0=MT_OPENING * (mu**4 * Q**6 * t / (E**4 * C**2)) ** (1.0 / 16.0), net_pressure=None)


def mt_pressure_scale(E_prime, mu_prime, C_prime, Q0, t):
    """M~-vertex pressure scale: p(rho, t) = C'^{3/8} E'^{3/4} mu'^{1/4} Q0^{-1/8} t^{-3/16} Pi_mt(rho)
    (Madyarova 2003; Pi_mt(0.5) = 0.8594 from PyFrac's Mt_vertex_solution fit)."""
    E, mu, C, Q, t = (positive(n, v) for n, v in (("E_prime", E_prime), ("mu_prime", mu_prime),
                                                    ("C_prime", C_prime), ("Q0", Q0), ("t", t)))
    return C**0.375 * E**0.75 * mu**0.25 * Q**-0.125 * t**-0.1875


KT_OPENING = 2.0**-0.25 / np.sqrt(np.pi)                  # 0.4744
KT_PRESSURE = np.pi**1.5 / (8.0 * 2.0**0.75)              # 0.41387


def kt_vertex(E_prime, K_prime, C_prime, Q0, t) -> VertexSolution:
    """Leak-off-toughness (K~) vertex: R = (sqrt2/pi)(Q0^2 t/C'^2)^{1/4} (as M~),

    w(0) = 2^{-1/4} pi^{-1/2} (K'^8 Q0^2 t / (E'^8 C'^2))^{1/8}, p = pi^{3/2}/(8 2^{3/4}) C'^{1/4} K' Q0^{-1/4} t^{-1/8}
    (uniform; Sneddon crack at K_I = K_Ic: p = sqrt(pi) K_Ic / (2 sqrt R), w(0) = 8 p R / (pi E')).
    """
    E, K, C, Q, t = (positive(n, v) for n, v in (("E_prime", E_prime), ("K_prime", K_prime),
                                                   ("C_prime", C_prime), ("Q0", Q0), ("t", t)))
    return VertexSolution(R=_leakoff_radius(C, Q, t), w0=KT_OPENING * (K**8 * Q**2 * t / (E**8 * C**2)) ** 0.125,
                          net_pressure=KT_PRESSURE * C**0.25 * K * Q**-0.25 * t**-0.125)


# ------------------------------------------------------------------------------------------------------------
# Regime numbers (Dontsov 2016; the paper's Eq. 45-46)

def t_mk(E_prime, K_prime, mu_prime, Q0):
    """M-K transition time t_mk = (mu'^5 E'^13 Q0^3 / K'^18)^{1/2} (Dontsov 2016; paper Eq. 45: tau = t/t_mk)."""
    E, K, mu, Q = (positive(n, v) for n, v in
                   (("E_prime", E_prime), ("K_prime", K_prime), ("mu_prime", mu_prime), ("Q0", Q0)))
    return np.exp(0.5 * (5 * np.log(mu) + 13 * np.log(E) + 3 * np.log(Q) - 18 * np.log(K)))


def tau(E_prime, K_prime, mu_prime, Q0, t):
    """Dimensionless time tau = t / t_mk (paper Eq. 45; Dontsov 2016)."""
    return positive("t", t) / t_mk(E_prime, K_prime, mu_prime, Q0)


def phi(E_prime, K_prime, mu_prime, C_prime, Q0):
    """Leak-off number phi = mu'^3 E'^11 C'^4 Q0 / K'^14 (paper Eq. 46; Dontsov 2016); C' = 0 gives 0."""
    E, K, mu, Q = (positive(n, v) for n, v in
                   (("E_prime", E_prime), ("K_prime", K_prime), ("mu_prime", mu_prime), ("Q0", Q0)))
    C = non_negative("C_prime", C_prime)
    return C**4 * np.exp(3 * np.log(mu) + 11 * np.log(E) + np.log(Q) - 14 * np.log(K))


@dataclass(frozen=True)
class TransitionTimes:
    """Characteristic times [s] between vertices (Dontsov 2016; forms as in Detournay 2016, Annu. Rev. Fluid Mech.):
    t_mk = (mu'^5 E'^13 Q0^3/K'^18)^{1/2}; t_mmt = t_mk phi^{-9/14} = (mu'^4 Q0^6/(E'^4 C'^18))^{1/7};
    t_kkt = t_mk phi^{-5/6} = (K'^8 Q0^2/(E'^8 C'^10))^{1/3}; t_mtkt = t_mk phi^{1/2} = mu'^4 E'^12 C'^2 Q0^2/K'^16.
    With C' = 0 the leak-off times are infinite (t_mtkt is 0)."""

    t_mk: float
    t_mmt: float
    t_kkt: float
    t_mtkt: float


def transition_times(E_prime, K_prime, mu_prime, C_prime, Q0) -> TransitionTimes:
    """Characteristic times t_mk, t_mm~, t_kk~, t_m~k~ from t_mk and phi (see :class:`TransitionTimes`)."""
    tmk = float(t_mk(E_prime, K_prime, mu_prime, Q0))
    ph = np.float64(phi(E_prime, K_prime, mu_prime, C_prime, Q0))
    with np.errstate(divide="ignore"):   # C' = 0: phi = 0
        return TransitionTimes(t_mk=tmk, t_mmt=float(tmk * ph ** (-9.0 / 14.0)),
                               t_kkt=float(tmk * ph ** (-5.0 / 6.0)), t_mtkt=float(tmk * ph**0.5))


# Vertex validity zones (solution within ~1 % of the vertex), Dontsov (2016) as encoded in
# the author's egordontsov/Radial-HF-rapid-solution PlotRadialParametricSpace.m.
def regime(E_prime, K_prime, mu_prime, C_prime, Q0, t):
    """Name of the vertex whose ~1 % validity zone holds at time(s) t: "M", "K", "Mt", "Kt" or "transition".

    Zones (Dontsov 2016): M: t/t_mk < 4.54e-2 and t/t_mm~ < 7.41e-6; K: t/t_mk > 2.59e6 and t/t_kk~ < 5.96e-8;
    Mt: t/t_mm~ > 7.20e2 and t/t_m~k~ < 4.18; Kt: t/t_kk~ > 4.81e2 and t/t_m~k~ > 2.01e11
    (:func:`transition_times`). Returns a str for scalar t, else an array of str.
    """
    t = positive("t", t)
    ct = transition_times(E_prime, K_prime, mu_prime, C_prime, Q0)
    with np.errstate(divide="ignore"):
        tt, t_mmt, t_kkt, t_mtkt = t / ct.t_mk, t / ct.t_mmt, t / ct.t_kkt, t / ct.t_mtkt
    names = np.select([(tt < 4.54e-2) & (t_mmt < 7.41e-6), (tt > 2.59e6) & (t_kkt < 5.96e-8),
                       (t_mmt > 7.20e2) & (t_mtkt < 4.18), (t_kkt > 4.81e2) & (t_mtkt > 2.01e11)],
                      ["M", "K", "Mt", "Kt"], default="transition")
    return str(names) if names.ndim == 0 else names


# ------------------------------------------------------------------------------------------------------------
# Dontsov (2016) universal approximate solution

# Tip asymptote g_delta(K, C) and exponent Delta(K, C) (Dontsov & Peirce 2015, Dontsov 2016):
# hfgpu.fracture.tip_universal.g_delta / delta, the one implementation.


def _upper_beta(x, a, b):
    """B(a, b)(1 - I_x(a, b)) = int_x^1 s^{a-1} (1-s)^{b-1} ds."""
    return beta_fn(a, b) * betainc(b, a, 1.0 - x)


def _volume_integral(K, C, alpha, lam):
    """B(K, C, alpha; lambda) = 2^{1+delta}[-Bbar(1/2; lambda+1, 2+delta) + Bbar(1/2; lambda+2, 1+delta)]
    + C alpha^{3/2} B(2 alpha, 3/2) (Dontsov 2016, global volume balance); also returns delta."""
    dlt = 0.5 * (1.0 + delta(K, C))
    storage = 2.0 ** (1.0 + dlt) * (-_upper_beta(0.5, lam + 1.0, 2.0 + dlt) + _upper_beta(0.5, lam + 2.0, 1.0 + dlt))
    leak = C * alpha**1.5 * beta_fn(2.0 * alpha, 1.5)
    return storage + leak, leak, dlt


def _lambda_and_efficiency(K, C, alpha):
    """Profile exponent lambda = 0.487 (1-K^4) eta0 + 0.397 (1-K^4)(1-eta0) + 0.5 K^4 with eta0 the
    efficiency at lambda = 1/2, and efficiency eta = 1 - C alpha^{3/2} B(2 alpha, 3/2) / B (Dontsov 2016)."""
    total, leak, _ = _volume_integral(K, C, alpha, 0.5)
    eta0 = 1.0 - leak / total
    K4 = K**4
    lam = 0.487 * (1.0 - K4) * eta0 + 0.397 * (1.0 - K4) * (1.0 - eta0) + 0.5 * K4
    total, leak, dlt = _volume_integral(K, C, alpha, lam)
    return lam, 1.0 - leak / total, total, dlt


def _solve_K(C, a, K_start):
    """Solve K^6 = a C^3 g(K, C) for K in (0, 1] (Dontsov 2016, propagation condition), a = alpha^{1/2}
    t^-1/2. Safeguarded Newton on u = ln K with dg/dK ~ -g/(1-K) (as in Dontsov's solver), bisection fallback."""
    lo, hi = np.full_like(C, -80.0), np.zeros_like(C)
    u = np.log(np.clip(K_start, 1e-30, 1.0 - 1e-12))
    logaC3 = np.log(a) + 3.0 * np.log(C)
    for _ in range(200):
        K = np.exp(u)
        g = g_delta(K, C)
        F = np.where(g > 0.0, 6.0 * u - logaC3 - np.log(np.where(g > 0.0, g, 1.0)), np.inf)
        lo = np.where(F < 0.0, u, lo)
        hi = np.where(F >= 0.0, u, hi)
        step = F / (6.0 + K / np.maximum(1.0 - K, 1e-300))
        u_new = u - step
        outside = ~((u_new > lo) & (u_new < hi)) | ~np.isfinite(u_new)
        u_new = np.where(outside, 0.5 * (lo + hi), u_new)
        if np.all(np.abs(u_new - u) < 1e-13):
            return np.exp(u_new)
        u = u_new
    return np.exp(u)


def dontsov_radial(E_prime, K_prime, mu_prime, C_prime, Q0, t) -> RadialSolution:
    """Dontsov's (2016) approximate solution for a radial fracture with toughness, viscosity and leak-off.

    Equations (Dontsov 2016, R. Soc. open sci. 3:160737), with
    t_hat = 2^6 phi^{3/2} tau and Q_hat = 8 phi / pi, solved at every time for (K_hat, C_hat):
      K^6 = alpha^{1/2} t_hat^{-1/2} C^3 g_delta(K, C)                     (tip asymptote at the front)
      C = t_hat^{3/10} K^{4/5} alpha^{-1/2} Q_hat^{-1/5} B(K, C, alpha; lambda)^{1/5}   (global volume balance)
    and alpha = d ln l_hat / d ln t_hat (l_hat = C^4 g^2 / K^10) by central differences along t (three passes).
    Outputs R = gamma L*, gamma = l_hat/(16 phi); w(0) = Omega eps* L*, Omega = C^2 g /(K^6 2^lambda 4 phi^{1/2});
    L* = (Q0^3 E' t_mk^4/mu')^{1/9}, eps* = (mu'/(E' t_mk))^{1/3}.

    t: strictly increasing 1-D array of times [s] with at least 10 points (alpha is differentiated along it;
    a log-spaced grid is best), or a scalar, evaluated on geomspace(t/100, t, 40). phi is floored at 1e-30
    as in the author's code, so C' = 0 is allowed.
    """
    t_in = positive("t", t)
    scalar = t_in.ndim == 0
    tt = np.geomspace(float(t_in) / 100.0, float(t_in), 40) if scalar else t_in
    if tt.ndim != 1 or tt.size < 10 or np.any(np.diff(tt) <= 0.0):
        raise ValueError(f"t: got an array of shape {tt.shape}; must be a scalar or a strictly increasing "
                         "1-D array of at least 10 times")
    tmk = np.float64(t_mk(E_prime, K_prime, mu_prime, Q0))
    ph = max(float(phi(E_prime, K_prime, mu_prime, C_prime, Q0)), 1e-30)
    E, mu, Q = np.float64(E_prime), np.float64(mu_prime), np.float64(Q0)
    th = 2.0**6 * ph**1.5 * tt / tmk
    Qh = 8.0 * ph / np.pi

    Kh = np.full_like(tt, 0.5)
    Ch = np.full_like(tt, 0.5)
    alpha = np.full_like(tt, 4.0 / 9.0)
    for _ in range(3):
        for _sweep in range(300):   # alternation contracts by ~1/3 per sweep; float noise ~1e-11
            K_old, C_old = Kh, Ch
            Kh = _solve_K(Ch, np.sqrt(alpha / th), Kh)
            for _fp in range(60):
                _, _, total, _ = _lambda_and_efficiency(Kh, Ch, alpha)
                C_new = th**0.3 * Kh**0.8 * alpha**-0.5 * Qh**-0.2 * total**0.2
                done = np.all(np.abs(C_new - Ch) <= 1e-11 * C_new)
                Ch = C_new
                if done:
                    break
            if np.all(np.abs(Kh - K_old) <= 1e-9 * Kh) and np.all(np.abs(Ch - C_old) <= 1e-9 * Ch):
                break
        s = g_delta(Kh, Ch)
        lh = Ch**4 * s**2 / Kh**10
        alpha = np.gradient(np.log(lh), np.log(th))
        alpha[0], alpha[-1] = alpha[1], alpha[-2]

    lam, eta, _, dlt = _lambda_and_efficiency(Kh, Ch, alpha)
    s = g_delta(Kh, Ch)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):   # absurd inputs: inf or NaN, not an error
        L_star = (Q**3 * E * tmk**4 / mu) ** (1.0 / 9.0)
        eps_star = (mu / (E * tmk)) ** (1.0 / 3.0)
    R = Ch**4 * s**2 / Kh**10 / (16.0 * ph) * L_star
    w0 = Ch**2 * s / (Kh**6 * 2.0**lam) / (4.0 * np.sqrt(ph)) * eps_star * L_star
    sol = RadialSolution(t=tt, R=R, w0=w0, efficiency=eta, delta=dlt, lam=lam)
    if scalar:
        return RadialSolution(*(np.asarray(getattr(sol, f)[-1:]) for f in
                                ("t", "R", "w0", "efficiency", "delta", "lam")))
    return sol
