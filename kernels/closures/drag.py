"""Drag, Eq. 13-15: the drag rate D_p [1/s] of a parcel, NumPy reference and Taichi twin.

D_p = C_d (3/8) (rho_f / rho_p) |u_f - u_p| / r_p (Eq. 13 with Snider's 1/rho_p, which the paper's print omits),
written as 4.5 mu / (rho_p r^2) x C_d Re / 24 so that it is finite at zero slip, with Re_p = 2 rho_f |u_f - u_p|
r / mu (Eq. 15) and theta_f = 1 - min(theta_p, theta_cp) (Eq. 18, capped so that over-packed cells keep a finite
hindrance). Laws (DRAG_LAWS, selected by name; kernels take the index):
"wen-yu": Eq. 14, C_d Re / 24 = theta_f^-2.65 (1 + c Re^0.687) below Re = 1000, 0.44 Re / 24 theta_f^-2.65
above (c = drag_re_coefficient; Wen & Yu 1966 / Schiller-Naumann use 0.15);
"snider": Snider (2001), C_d Re / 24 = theta_f^-2.65 + Re^(2/3) theta_f^-1.78 / 6 (REEF3D partres_drag).
mu is the clean-fluid viscosity mu_o: the theta_f^-2.65 factor already carries the crowding, and Eq. 10's
slurry viscosity (singular at close packing) would count it twice (Snider 2001 and OpenFOAM use the carrier
viscosity too).

The Taichi twin is split where the push's implicit solve (kernels/particles.py) iterates: hindered_stokes
once per parcel, drag_rate once per iteration; the powers are exp(a log b) with the inline exp and log of
hfgpu.kernels.elementary (LANES-wide vectors, no libm call).
"""

import numpy as np

from hfgpu.kernels.closures.twin import Deferred, ti

elementary = Deferred("hfgpu.kernels.elementary")

DRAG_LAWS = ("wen-yu", "snider")
SNIDER = DRAG_LAWS.index("snider")
STOKES_FACTOR = 4.5  # 24/Re x (3/8) rho_f |du| / r = 4.5 mu / r^2, the Stokes limit of Eq. 13 (per rho_p)
RE_NEWTON = 1000.0  # Eq. 14: constant C_d = 0.44 above this Reynolds number


def fluid_fraction_numpy(theta_p, theta_cp):
    """theta_f = 1 - min(theta_p, theta_cp) (Eq. 18, capped at close packing)."""
    return 1.0 - np.minimum(theta_p, theta_cp)


def reynolds_numpy(slip, radius, fluid_density, viscosity):
    """Particle Reynolds number Re_p = 2 rho_f |u_f - u_p| r / mu (Eq. 15)."""
    return 2.0 * fluid_density * np.abs(slip) * radius / viscosity


def drag_factor_numpy(re, theta_f, law, re_coefficient):
    """C_d Re / 24 of law index ``law`` (module docstring), finite at Re = 0."""
    re = np.asarray(re, dtype=np.float64)
    theta_f = np.asarray(theta_f, dtype=np.float64)
    if law == SNIDER:
        return theta_f ** -2.65 + re ** (2.0 / 3.0) * theta_f ** -1.78 / 6.0
    return theta_f ** -2.65 * np.where(re < RE_NEWTON, 1.0 + re_coefficient * re ** 0.687, 0.44 * re / 24.0)


def drag_coefficient_numpy(re, theta_f, law, re_coefficient):
    """Drag coefficient C_d of Eq. 14 (or Snider 2001) = 24/Re x drag_factor_numpy."""
    return 24.0 / np.asarray(re, dtype=np.float64) * drag_factor_numpy(re, theta_f, law, re_coefficient)


def drag_rate_numpy(slip, radius, particle_density, theta_p, fluid_density, viscosity, theta_cp, law,
                    re_coefficient):
    """D_p [1/s] = 4.5 mu / (rho_p r^2) x C_d Re / 24 (Eq. 13-15) of slip |u_f - u_p| [m/s]."""
    re = reynolds_numpy(slip, radius, fluid_density, viscosity)
    return STOKES_FACTOR * viscosity / (particle_density * radius ** 2) * \
        drag_factor_numpy(re, fluid_fraction_numpy(theta_p, theta_cp), law, re_coefficient)


@ti.func
def power(base, exponent):
    """base^exponent for base >= 0 (elementwise) as exp(exponent log base), 0 at base 0."""
    positive = base > 0.0
    return ti.select(positive, elementary.exp(exponent * elementary.log(ti.select(positive, base, 1.0))), 0.0)


@ti.func
def hindered_stokes(stokes, theta_p, theta_cp, law):
    """The parts of D_p that do not depend on the slip, from the Stokes rate stokes = 4.5 mu / (rho_p r^2):
    (stokes theta_f^-2.65, stokes theta_f^-1.78 / 6 for "snider", else 0), theta_f = 1 - min(theta_p,
    theta_cp) (Eq. 18); elementwise."""
    log_tf = elementary.log(1.0 - ti.min(theta_p, theta_cp))
    stokes_hinder = stokes * elementary.exp(-2.65 * log_tf)
    snider = stokes * 0.0
    if law == SNIDER:
        snider = stokes * elementary.exp(-1.78 * log_tf) * (1.0 / 6.0)
    return stokes_hinder, snider


@ti.func
def drag_rate(re, stokes_hinder, snider, law, re_coefficient):
    """D_p = stokes x C_d Re / 24 (Eq. 13-15) at Reynolds number re from hindered_stokes' parts: "wen-yu"
    stokes_hinder (1 + c Re^0.687) below Re = 1000, stokes_hinder 0.44 Re / 24 above; "snider" stokes_hinder +
    snider Re^(2/3); elementwise."""
    exponent = 2.0 / 3.0 if law == SNIDER else 0.687
    re_power = power(re, exponent)
    drag = stokes_hinder + snider * re_power
    if law != SNIDER:
        drag = stokes_hinder * ti.select(re < RE_NEWTON, 1.0 + re_coefficient * re_power, (0.44 / 24.0) * re)
    return drag
