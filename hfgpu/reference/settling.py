"""Particle settling oracles: terminal velocities, hindered settling and the bidisperse batch test of
Davis, Herbolzheimer & Acrivos (1982).

Sources:

* Stokes (1851) terminal velocity; Schiller & Naumann (1933) drag; Snider (2001), J. Comput. Phys. 170:523, drag.
* The hfgpu paper's Eq. 13-15 (drag of the MP-PIC model with the theta_f^-2.65 voidage function of Wen & Yu 1966).
* Richardson & Zaki (1954), Trans. Inst. Chem. Eng. 32:35 (exponent n(Re, d/D)); Rowe (1987), Chem. Eng. Sci.
  42:2795 (smooth fit); Garside & Al-Dibouni (1977), Ind. Eng. Chem. Proc. Des. Dev. 16:206.
* Masliyah (1979), Chem. Eng. Sci. 34:1166, and Lockett & Bassoon (1979), Powder Technol. 24:1 ("MLB") slip
  velocities for polydisperse suspensions; Kynch (1952) jump conditions; Davis et al. (1982),
  Int. J. Multiphase Flow 8:571 (batch test parameters in the hfgpu paper, section 5.2.1).

Velocities are positive downward (settling). SI units; phi = particle volume fraction.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from .checks import fraction, non_negative, positive

G = 9.81
STOKES_RZ_EXPONENT = 4.65   # Richardson & Zaki (1954), Re -> 0, no wall effect


def stokes_velocity(d, rho_p, rho_f, mu, g=G):
    """Stokes terminal velocity u0 = (rho_p - rho_f) g d^2 / (18 mu) (valid for Re_p <~ 0.1-1)."""
    d, rho_p, rho_f, mu = (positive(n, v) for n, v in (("d", d), ("rho_p", rho_p), ("rho_f", rho_f), ("mu", mu)))
    return (rho_p - rho_f) * g * d**2 / (18.0 * mu)


def paper_drag_coefficient(Re, theta_f=1.0, coefficient=0.15):
    """Drag coefficient of the paper's Eq. 14 (Schiller-Naumann with the Wen-Yu voidage factor):

    C_d = 24/Re theta_f^-2.65 (1 + c Re^0.687) for Re < 1000, 0.44 theta_f^-2.65 for Re >= 1000.
    The paper prints c = 0.5; Schiller & Naumann (1933) and every code that implements this law (OpenFOAM
    SchillerNaumann/WenYu, MFIX) use c = 0.15, which is the default here. Note that with c = 0.15 the two
    branches do not meet exactly at Re = 1000 (0.4365 vs 0.44), as in the original law.
    Re = 2 rho_f |u_f - u_p| r / mu_f (Eq. 15).
    """
    Re = positive("Re", Re)
    theta = positive("theta_f", theta_f)
    low = 24.0 / Re * (1.0 + coefficient * Re**0.687)
    return np.where(Re < 1000.0, low, 0.44) * theta**-2.65


def snider_drag_coefficient(Re, theta_f=1.0):
    """Snider (2001) drag: C_d = (24/Re) (theta_f^-2.65 + Re^{2/3} theta_f^-1.78 / 6) (Snider 2001;
    as in REEF3D partres_drag.cpp)."""
    Re = positive("Re", Re)
    theta = positive("theta_f", theta_f)
    return 24.0 / Re * (theta**-2.65 + Re ** (2.0 / 3.0) * theta**-1.78 / 6.0)


DragLaw = Callable[[np.ndarray, np.ndarray], np.ndarray]


def _slip_velocity(d, rho_p, rho_f, mu, phi, drag: DragLaw, g):
    """Particle-fluid slip u_s in a uniform suspension from the force balance per particle volume
    (3/4) C_d(Re, 1 - phi) rho_f u_s^2 / d = (rho_p - rho_s) g = (1 - phi)(rho_p - rho_f) g, Re = rho_f u_s d / mu,
    i.e. C_d Re^2 = (4/3) Ar (1 - phi) with Ar = rho_f (rho_p - rho_f) g d^3 / mu^2 (buoyancy from the mixture
    pressure gradient). phi = 0 gives the single-particle terminal velocity."""
    target = 4.0 / 3.0 * rho_f * (rho_p - rho_f) * g * d**3 / mu**2 * (1.0 - phi)
    theta = 1.0 - phi

    def residual(log_re):
        Re = np.exp(log_re)
        return np.log(float(drag(np.asarray(Re), np.asarray(theta))) * Re**2) - np.log(target)

    Re = np.exp(brentq(residual, np.log(1e-14), np.log(1e9), xtol=1e-14, rtol=1e-14))
    return Re * mu / (rho_f * d)


def terminal_velocity(d, rho_p, rho_f, mu, drag: DragLaw = paper_drag_coefficient, g=G):
    """Single-particle terminal velocity for a drag law C_d(Re, theta_f) (evaluated at theta_f = 1), from
    (pi/6) d^3 (rho_p - rho_f) g = C_d (rho_f u^2 / 2)(pi d^2 / 4) (weight = drag). Vectorised over d."""
    d = positive("d", d)
    rho_p, rho_f, mu = (float(positive(n, v)) for n, v in (("rho_p", rho_p), ("rho_f", rho_f), ("mu", mu)))
    if rho_p <= rho_f:
        raise ValueError(f"rho_p: got {rho_p!r}; must exceed rho_f = {rho_f!r} for settling")
    return np.vectorize(lambda di: _slip_velocity(di, rho_p, rho_f, mu, 0.0, drag, g))(d)


def column_settling_velocity(d, rho_p, rho_f, mu, phi, drag: DragLaw = paper_drag_coefficient, g=G):
    """Settling velocity (vessel frame) of a uniform monodisperse suspension in an MP-PIC-type model:
    slip u_s from :func:`_slip_velocity` with the drag's voidage factor at theta_f = 1 - phi, then the
    zero-net-volume-flux frame change v = (1 - phi) u_s (Richardson & Zaki 1954; Masliyah 1979). Vectorised over phi."""
    d, rho_p, rho_f, mu = (float(positive(n, v)) for n, v in
                           (("d", d), ("rho_p", rho_p), ("rho_f", rho_f), ("mu", mu)))
    phi = fraction("phi", phi)
    return np.vectorize(lambda p: (1.0 - p) * _slip_velocity(d, rho_p, rho_f, mu, p, drag, g))(phi)


def implied_exponent(d, rho_p, rho_f, mu, phi, drag: DragLaw = paper_drag_coefficient, g=G):
    """Richardson-Zaki exponent implied by a drag law: n = ln(v(phi)/u_t) / ln(1 - phi), v from
    :func:`column_settling_velocity`, u_t the terminal velocity. In the Stokes limit a drag ~ theta_f^-beta
    gives n = beta + 2 (theta_f^beta from drag, theta_f from buoyancy in the mixture, theta_f from the
    zero-flux frame), i.e. 4.65 for beta = 2.65 (Richardson & Zaki 1954's low-Re exponent)."""
    phi = fraction("phi", phi)
    if np.any(phi <= 0.0):
        raise ValueError(f"phi: got {phi!r}; must be in (0, 1)")
    v = column_settling_velocity(d, rho_p, rho_f, mu, phi, drag, g)
    return np.log(v / terminal_velocity(d, rho_p, rho_f, mu, drag, g)) / np.log1p(-phi)


def richardson_zaki_exponent(Re, d_over_D=0.0):
    """Richardson & Zaki (1954) exponent n (Re = u0 d / nu of one particle, D = vessel diameter):
    4.65 + 19.5 d/D (Re < 0.2); (4.35 + 17.5 d/D) Re^-0.03 (0.2-1); (4.45 + 18 d/D) Re^-0.1 (1-200);
    4.45 Re^-0.1 (200-500); 2.39 (Re > 500)."""
    Re = positive("Re", Re)
    r = non_negative("d_over_D", d_over_D)
    return np.select([Re < 0.2, Re < 1.0, Re < 200.0, Re <= 500.0],
                     [4.65 + 19.5 * r, (4.35 + 17.5 * r) * Re**-0.03, (4.45 + 18.0 * r) * Re**-0.1,
                      4.45 * Re**-0.1], default=2.39)


def rowe_exponent(Re):
    """Rowe (1987) smooth fit of the Richardson-Zaki exponent: n = (4.7 + 0.41 Re^0.75)/(1 + 0.175 Re^0.75)."""
    Re = non_negative("Re", Re)
    x = Re**0.75
    return (4.7 + 0.41 * x) / (1.0 + 0.175 * x)


def garside_al_dibouni_exponent(Re):
    """Garside & Al-Dibouni (1977): (5.1 - n)/(n - 2.7) = 0.1 Re^0.9, i.e. n = (5.1 + 0.27 Re^0.9)/(1 + 0.1 Re^0.9).
    (Transcription not checked against the paper.)"""
    x = 0.1 * non_negative("Re", Re) ** 0.9
    return (5.1 + 2.7 * x) / (1.0 + x)


def hindered_velocity(u0, phi, n=STOKES_RZ_EXPONENT):
    """Richardson & Zaki (1954) hindered settling v = u0 (1 - phi)^n."""
    return non_negative("u0", u0) * (1.0 - fraction("phi", phi)) ** positive("n", n)


# ------------------------------------------------------------------------------------------------------------
# Polydisperse (MLB) settling and the Davis et al. (1982) batch test

def mlb_batch_velocities(radius, rho, phi, rho_f, mu, n=STOKES_RZ_EXPONENT, g=G):
    """Masliyah (1979) / Lockett & Bassoon (1979) species velocities in a batch vessel (zero net volume flux):

    slip u_si = (2 a_i^2 g / (9 mu)) (rho_i - rho_s) (1 - phi)^{n-2}, rho_s = (1 - phi) rho_f + sum_j phi_j rho_j,
    phi = sum_j phi_j; vessel frame v_i = u_si - sum_j phi_j u_sj. One species gives v = u0 (1 - phi)^n.
    radius, rho, phi: one entry per species. Returns v_i [m/s], positive downward.
    """
    a, rho_i = positive("radius", radius), positive("rho", rho)
    ph = fraction("phi", phi)
    rho_f, mu = float(positive("rho_f", rho_f)), float(positive("mu", mu))
    if not (a.shape == rho_i.shape == ph.shape and a.ndim == 1):
        raise ValueError(f"radius, rho, phi: got shapes {a.shape}, {rho_i.shape}, {ph.shape}; "
                         "must be equal 1-D (one entry per species)")
    total = float(ph.sum())
    if total >= 1.0:
        raise ValueError(f"phi: got total {total!r}; the species' fractions must sum below 1")
    rho_s = (1.0 - total) * rho_f + float(np.dot(ph, rho_i))
    slip = 2.0 * a**2 * g / (9.0 * mu) * (rho_i - rho_s) * (1.0 - total) ** (n - 2.0)
    return slip - float(np.dot(ph, slip))


@dataclass(frozen=True)
class BidisperseBatch:
    """Kynch-theory answer for a bidisperse batch test (Davis et al. 1982): zones from the top are clear fluid |
    light-only suspension at phi_light_only | original mixture | sediment.

    lower_speed: speed of the light-only/mixture interface (= heavy velocity in the mixture) [m/s];
    upper_speed: speed of the clear/light-only interface [m/s]; phi_light_only: light fraction above the
    lower interface; v_heavy, v_light: species velocities in the mixture [m/s].
    """

    lower_speed: float
    upper_speed: float
    phi_light_only: float
    v_heavy: float
    v_light: float


def bidisperse_batch(heavy, light, rho_f, mu, n=STOKES_RZ_EXPONENT, g=G) -> BidisperseBatch:
    """Interface speeds of a bidisperse batch test, heavy = (radius, density, phi), light likewise.

    MLB velocities in the mixture (:func:`mlb_batch_velocities`); lower interface s1 = v_H(mixture);
    light-species jump condition across it: (phi_L - phi_L') s1 = phi_L v_L(mixture) - phi_L' v_L'(phi_L'),
    with v_L'(phi_L') the light-only velocity (MLB with one species, = u_L0 (1 - phi_L')^n);
    upper interface s2 = v_L'(phi_L') (Kynch 1952; Davis et al. 1982).
    """
    (aH, rH, pH), (aL, rL, pL) = heavy, light
    vH, vL = mlb_batch_velocities([aH, aL], [rH, rL], [pH, pL], rho_f, mu, n, g)
    if vH <= vL:
        raise ValueError(f"heavy: got mixture velocity {vH!r} <= light {vL!r}; 'heavy' must settle faster")

    def light_only(p):
        return float(mlb_batch_velocities([aL], [rL], [p], rho_f, mu, n, g)[0])

    # F(x) = (phi_L - x) s1 - phi_L v_L + x v_L'(x) decreases in x from phi_L (s1 - v_L) > 0 to < 0 near x = 1.
    phi_p = brentq(lambda x: (pL - x) * vH - pL * vL + x * light_only(x), 0.0, 1.0 - 1e-9, xtol=1e-15, rtol=1e-14)
    return BidisperseBatch(lower_speed=float(vH), upper_speed=light_only(phi_p), phi_light_only=float(phi_p),
                           v_heavy=float(vH), v_light=float(vL))


def bidisperse_interface_heights(t, H0, batch: BidisperseBatch, phi_heavy, phi_light, phi_packed):
    """Heights of the upper (clear/light-only) and lower (light-only/mixture) interfaces over a sediment bed of
    uniform packing phi_packed (an assumption: the bed fraction is not given by Davis et al.), for a column
    initially uniform to height H0. The bed rises at (phi_H v_H + phi_L v_L)/(phi_packed - phi_H - phi_L) while
    the mixture exists, then at phi_L' s2 / (phi_packed - phi_L'); each interface ends on the bed
    (kinematic wave theory, Kynch 1952). Returns (h_upper, h_lower, h_bed) arrays like t.
    """
    t = non_negative("t", t)
    H0 = float(positive("H0", H0))
    pH, pL = float(fraction("phi_heavy", phi_heavy)), float(fraction("phi_light", phi_light))
    pk = float(fraction("phi_packed", phi_packed))
    if pk <= max(pH + pL, batch.phi_light_only):
        raise ValueError(f"phi_packed: got {pk!r}; must exceed the suspension fractions")
    s1, s2, pLp = batch.lower_speed, batch.upper_speed, batch.phi_light_only
    r1 = (pH * batch.v_heavy + pL * batch.v_light) / (pk - pH - pL)
    r2 = pLp * s2 / (pk - pLp)
    t1 = H0 / (s1 + r1)
    h1 = r1 * t1
    t2 = (H0 - h1 + r2 * t1) / (s2 + r2)
    bed = np.where(t <= t1, r1 * t, np.minimum(h1 + r2 * (t - t1), h1 + r2 * (t2 - t1)))
    return np.maximum(H0 - s2 * t, bed), np.maximum(H0 - s1 * t, bed), bed
