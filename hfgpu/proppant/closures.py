"""Vectorised MP-PIC closures: drag (Eq. 13-15), particle stress (Eq. 16), collision damping, slurry viscosity
(Eq. 10). Sources of the reference forms are in /work/shared/validation-data/REFERENCE.md section 6."""

from __future__ import annotations

import numpy as np

from .params import MppicParams

STOKES_FACTOR = 4.5  # 24/Re x (3/8) rho_f |du| / r = 4.5 mu / r^2, the Stokes limit of Eq. 13 (per rho_p)
RE_NEWTON = 1000.0  # Eq. 14: constant C_d = 0.44 above this Reynolds number


def fluid_fraction(theta_p, params: MppicParams):
    """theta_f = 1 - theta_p (Eq. 18), with theta_p capped at close packing so that over-packed cells keep a
    finite drag hindrance."""
    return 1.0 - np.minimum(theta_p, params.theta_cp)


def reynolds(slip, radius, fluid_density, viscosity):
    """Particle Reynolds number Re_p = 2 rho_f |u_f - u_p| r / mu (Eq. 15)."""
    return 2.0 * fluid_density * np.abs(slip) * radius / viscosity


def drag_factor(re, theta_f, params: MppicParams):
    """C_d Re / 24, finite at Re = 0.

    "wen-yu": Eq. 14, theta_f^-2.65 (1 + c Re^0.687) below Re = 1000, 0.44 Re/24 theta_f^-2.65 above
    (c = drag_re_coefficient; Wen & Yu 1966 / Schiller-Naumann use 0.15).
    "snider": Snider (2001), theta_f^-2.65 + Re^(2/3) theta_f^-1.78 / 6 (REFERENCE.md 6.2, REEF3D partres_drag).
    """
    re = np.asarray(re, dtype=np.float64)
    theta_f = np.asarray(theta_f, dtype=np.float64)
    if params.drag_law == "snider":
        return theta_f ** -2.65 + re ** (2.0 / 3.0) * theta_f ** -1.78 / 6.0
    return theta_f ** -2.65 * np.where(re < RE_NEWTON, 1.0 + params.drag_re_coefficient * re ** 0.687,
                                       0.44 * re / 24.0)


def drag_coefficient(re, theta_f, params: MppicParams):
    """Drag coefficient C_d of Eq. 14 (or Snider 2001), = 24/Re x drag_factor."""
    return 24.0 / np.asarray(re, dtype=np.float64) * drag_factor(re, theta_f, params)


def drag_rate(slip, radius, particle_density, theta_p, fluid_density, viscosity, params: MppicParams):
    """Drag rate D_p [1/s] = C_d (3/8) (rho_f / rho_p) |u_f - u_p| / r_p (Eq. 13 with Snider's 1/rho_p, which
    the paper's print omits), written as 4.5 mu / (rho_p r^2) x C_d Re / 24 so that it is finite at zero slip.

    ``slip`` is |u_f - u_p| [m/s]; ``viscosity`` is the clean-fluid viscosity mu_o: the theta_f^-2.65 factor
    already carries the crowding, and Eq. 10's slurry viscosity (singular at close packing) would count it
    twice (Snider 2001 and OpenFOAM use the carrier viscosity too).
    """
    re = reynolds(slip, radius, fluid_density, viscosity)
    return STOKES_FACTOR * viscosity / (particle_density * radius ** 2) * \
        drag_factor(re, fluid_fraction(theta_p, params), params)


def _stress_denominator(theta_p, params: MppicParams):
    """max(theta_cp - theta_p, eps (1 - theta_p)) of Eq. 16."""
    return np.maximum(params.theta_cp - theta_p, params.epsilon * (1.0 - theta_p))


def particle_stress(theta_p, params: MppicParams):
    """Harris & Crighton (1994) particle normal stress tau = P_s theta^beta / max(theta_cp - theta,
    eps (1 - theta)) [Pa] (Eq. 16)."""
    theta_p = np.asarray(theta_p, dtype=np.float64)
    return params.P_s * theta_p ** params.beta / _stress_denominator(theta_p, params)


def particle_stress_derivative(theta_p, params: MppicParams):
    """d tau / d theta_p of Eq. 16 (the branch of the max in use), without the beta/theta singularity."""
    theta_p = np.asarray(theta_p, dtype=np.float64)
    den = _stress_denominator(theta_p, params)
    slope = np.where(params.theta_cp - theta_p >= params.epsilon * (1.0 - theta_p), 1.0, params.epsilon)
    tau = params.P_s * theta_p ** params.beta / den
    return params.P_s * params.beta * theta_p ** (params.beta - 1.0) / den + tau * slope / den


def damping_rate(theta_p, velocity_variance, sauter_radius, params: MppicParams):
    """Collision damping rate 1/tau_D [1/s], O'Rourke & Snider (2010) eq. 48 (REFERENCE.md 6.4):
    (16/sqrt(3 pi)) theta_p sigma / r32 g0 eta (1 - eta), eta = (1 + e)/2, g0 = theta_cp / max(theta_cp -
    theta_p, eps (1 - theta_p)) floored at 1 (MFIX). Zero where damping is off, where theta_p <=
    damping_threshold x theta_cp (the paper: damping acts in the packed bed only) or where r32 = 0."""
    theta_p = np.asarray(theta_p, dtype=np.float64)
    if not params.damping:
        return np.zeros_like(theta_p)
    eta = 0.5 * (1.0 + params.restitution)
    g0 = np.maximum(1.0, params.theta_cp / _stress_denominator(theta_p, params))
    sigma = np.sqrt(np.maximum(velocity_variance, 0.0))
    active = (theta_p > params.damping_threshold * params.theta_cp) & (sauter_radius > 0.0)
    safe_r = np.where(active, sauter_radius, 1.0)
    rate = 16.0 / np.sqrt(3.0 * np.pi) * theta_p * sigma / safe_r * g0 * eta * (1.0 - eta)
    return np.where(active, rate, 0.0)


def slurry_viscosity(theta_p, fluid_viscosity, params: MppicParams):
    """Slurry viscosity [Pa s] for the fluid phase: "power" mu_o (1 - theta_p/theta_cp)^n (Eq. 10, Barree &
    Conway, n = -1.82) or "krieger-dougherty" mu_o (1 - theta_p/theta_cp)^(-2.5 theta_cp), capped at
    max_relative_viscosity x mu_o (see MppicParams) so that it stays finite at and beyond close packing."""
    theta_p = np.asarray(theta_p, dtype=np.float64)
    exponent = params.viscosity_exponent if params.viscosity_law == "power" else -2.5 * params.theta_cp
    base = np.maximum(1.0 - theta_p / params.theta_cp, params.max_relative_viscosity ** (1.0 / exponent))
    return fluid_viscosity * base ** exponent


def critical_shields_number(diameter, particle_density, fluid_density, viscosity, gravity):
    """Critical Shields number of the threshold of motion, Soulsby & Whitehouse (1997, Proc. Pacific Coasts
    and Ports 1, eq. 7; Soulsby 1997, Dynamics of Marine Sands, eq. 77): theta_cr = 0.30 / (1 + 1.2 D*) +
    0.055 (1 - exp(-0.020 D*)), with the dimensionless grain size D* = d ((rho_p/rho_f - 1) g / nu^2)^(1/3),
    nu = mu / rho_f (e.g. 0.3 mm sand in water: D* = 7.4, theta_cr = 0.038)."""
    nu = viscosity / fluid_density
    d_star = diameter * ((particle_density / fluid_density - 1.0) * gravity / nu ** 2) ** (1.0 / 3.0)
    return 0.30 / (1.0 + 1.2 * d_star) + 0.055 * (1.0 - np.exp(-0.020 * d_star))


def bed_shear_stress(speed, width, fluid_density, viscosity, law: str):
    """Shear stress [Pa] of the gap-averaged flow of speed |u_f| on a bed surface (the slot floor or a packed
    bed) across a gap of width w: tau_b = f_t sqrt(12) mu |u_f| / w. In the gap-averaged (Hele-Shaw /
    Brinkman) momentum balance mu d^2U/dy^2 = 12 mu U / w^2 + grad p, the velocity rises from 0 at a no-slip
    surface to the outer value over the length w / sqrt(12) (U = U_o (1 - exp(-sqrt(12) y / w)); Zeng, Yortsos
    & Salin 2003, Phys. Fluids 15, 3829), so mu dU/dy = sqrt(12) mu U_o / w at the surface. f_t is the wall
    friction factor of the fluid (hfgpu.proppant.momentum.wall_friction_factor: 1 for "laminar", Dean's
    turbulent c_f Re / 12 past Re = 899 for "dean"): the same ratio of turbulent to laminar wall stress as on
    the fracture faces."""
    from .momentum import wall_friction_factor

    f_t = wall_friction_factor(np.abs(speed), width, viscosity, fluid_density, law)
    return f_t * np.sqrt(12.0) * viscosity * np.abs(speed) / width


def shields_number(tau, diameter, particle_density, fluid_density, gravity):
    """Shields number theta = tau_b / ((rho_p - rho_f) g d) (Shields 1936)."""
    return tau / ((particle_density - fluid_density) * gravity * diameter)
