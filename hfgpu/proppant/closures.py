"""The MP-PIC closures as the NumPy engine calls them, with their constants from MppicParams: drag (Eq. 13-15),
particle stress (Eq. 16), collision damping and slurry viscosity (Eq. 10). Each is its family's NumPy
reference in hfgpu.kernels.closures (one module per family, beside its Taichi twin), which holds the equations
and their sources."""

from __future__ import annotations

from ..kernels.closures import damping, drag
from ..kernels.closures import slurry_viscosity as viscosity
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
    """Slurry viscosity [Pa s] of params.viscosity_law for the fluid phase, capped at max_relative_viscosity x
    mu_o (Eq. 10 or Krieger & Dougherty, hfgpu.kernels.closures.slurry_viscosity)."""
    return viscosity.slurry_viscosity_numpy(theta_p, fluid_viscosity, params.viscosity_law,
                                            params.viscosity_exponent, params.theta_cp,
                                            params.max_relative_viscosity)
