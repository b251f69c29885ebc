"""Vectorised MP-PIC closures with MppicParams: drag (Eq. 13-15), particle stress (Eq. 16), collision damping
(their NumPy references and Taichi twins are in hfgpu.kernels.closures, one module per family), slurry
viscosity (Eq. 10), the threshold of motion. Sources: the paper's equations; Snider (2001); Harris & Crighton
(1994); O'Rourke & Snider (2010)."""

from __future__ import annotations

import numpy as np

from ..kernels.closures import damping, drag
from ..kernels.closures import particle_stress as stress
from .params import MppicParams


def fluid_fraction(theta_p, params: MppicParams):
    """theta_f = 1 - theta_p (Eq. 18), capped at close packing (hfgpu.kernels.closures.drag)."""
    return drag.fluid_fraction_numpy(theta_p, params.theta_cp)


def reynolds(slip, radius, fluid_density, viscosity):
    """Particle Reynolds number Re_p = 2 rho_f |u_f - u_p| r / mu (Eq. 15)."""
    return drag.reynolds_numpy(slip, radius, fluid_density, viscosity)


def drag_factor(re, theta_f, params: MppicParams):
    """C_d Re / 24 of params.drag_law (Eq. 14 or Snider 2001, hfgpu.kernels.closures.drag)."""
    return drag.drag_factor_numpy(re, theta_f, params.drag_law_code, params.drag_re_coefficient)


def drag_coefficient(re, theta_f, params: MppicParams):
    """Drag coefficient C_d of Eq. 14 (or Snider 2001), = 24/Re x drag_factor."""
    return drag.drag_coefficient_numpy(re, theta_f, params.drag_law_code, params.drag_re_coefficient)


def drag_rate(slip, radius, particle_density, theta_p, fluid_density, viscosity, params: MppicParams):
    """Drag rate D_p [1/s] of Eq. 13-15 (hfgpu.kernels.closures.drag); ``slip`` is |u_f - u_p| [m/s],
    ``viscosity`` the clean-fluid viscosity mu_o."""
    return drag.drag_rate_numpy(slip, radius, particle_density, theta_p, fluid_density, viscosity, params.theta_cp,
                                params.drag_law_code, params.drag_re_coefficient)


def particle_stress(theta_p, params: MppicParams):
    """Harris & Crighton (1994) particle normal stress tau [Pa] (Eq. 16, hfgpu.kernels.closures.particle_stress)."""
    return stress.particle_stress_numpy(theta_p, params.P_s, params.beta, params.theta_cp, params.epsilon)


def particle_stress_derivative(theta_p, params: MppicParams):
    """d tau / d theta_p of Eq. 16 (the branch of the max in use), without the beta/theta singularity."""
    return stress.particle_stress_derivative_numpy(theta_p, params.P_s, params.beta, params.theta_cp,
                                                   params.epsilon)


def damping_rate(theta_p, velocity_variance, sauter_radius, params: MppicParams):
    """Collision damping rate 1/tau_D [1/s], O'Rourke & Snider (2010) eq. 48 (hfgpu.kernels.closures.damping)."""
    return damping.damping_rate_numpy(theta_p, velocity_variance, sauter_radius, params.damping,
                                      params.restitution, params.damping_threshold, params.theta_cp, params.epsilon)


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
