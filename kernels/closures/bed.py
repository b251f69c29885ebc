"""The bed: Coulomb friction of grains resting in or on a dense bed, and the threshold of motion of grains on
a bed surface; NumPy references and Taichi twins. Where a grain rests (on a dense cell, on the floor) is the
push's business (particle_ops_numpy.on_bed, kernels.particles.on_bed); this family says what the bed does.

Bed friction, in the implicit velocity update of Eq. 43: the friction force per unit mass mu_b |g'| (g' =
(1 - rho_f / rho_p) g, the submerged weight) opposes the motion along the bed (x, normal to gravity) and, being
static friction, at most cancels it:

    u <- sign(u) max(|u| - dt mu_b |g'| / den, 0),    den = 1 + dt (D_p + 1 / (2 tau_D)) (Eq. 43's).

Threshold of motion: a grain of diameter d on a bed surface is held where the Shields number (Shields 1936)
of the bed shear stress is below the critical one of Soulsby & Whitehouse (1997, Proc. Pacific Coasts and
Ports 1, eq. 7; Soulsby 1997, Dynamics of Marine Sands, eq. 77):

    theta = tau_b / ((rho_p - rho_f) g d) < theta_cr = 0.30 / (1 + 1.2 D*) + 0.055 (1 - exp(-0.020 D*)),
    D* = d ((rho_p / rho_f - 1) g / nu^2)^(1/3),  nu = mu / rho_f

(0.3 mm sand in water: D* = 7.4, theta_cr = 0.038). The bed shear stress of the gap-averaged flow of speed
|u_f| across a gap w: in the gap-averaged (Hele-Shaw / Brinkman) balance mu d^2U/dy^2 = 12 mu U / w^2 + grad p
the velocity rises from 0 at a no-slip surface to the outer value over w / sqrt(12) (U = U_o (1 - exp(-sqrt(12)
y / w)); Zeng, Yortsos & Salin 2003, Phys. Fluids 15, 3829), so

    tau_b = f_t sqrt(12) mu |u_f| / w,

f_t the fluid's wall-friction factor (closures.wall_friction: the same ratio of turbulent to laminar stress as
on the fracture faces). A neutrally buoyant grain (rho_p = rho_f) has no threshold and is never held.
"""

import numpy as np

from hfgpu.kernels.closures.twin import ti
from hfgpu.kernels.closures.wall_friction import wall_friction_factor, wall_friction_factor_numpy


def bed_friction_numpy(u, resting, buoyant_g, dt, den, mu_b):
    """u after bed friction (module docstring) where ``resting``, unchanged elsewhere; buoyant_g = g' [m/s^2]."""
    slide = np.maximum(np.abs(u) - dt * mu_b * np.abs(buoyant_g) / den, 0.0)
    return np.where(resting, np.copysign(slide, u), u)


@ti.func
def bed_friction(u, buoyant_g, dt, den, mu_b):
    """u of a resting grain after bed friction (module docstring), scalar."""
    slide = ti.max(ti.abs(u) - dt * mu_b * ti.abs(buoyant_g) / den, 0.0)
    return -slide if u < 0.0 else slide


def bed_shear_stress_numpy(speed, width, fluid_density, viscosity, code: int):
    """tau_b = f_t sqrt(12) mu |u_f| / w [Pa] (module docstring); ``code``: the wall-friction law's."""
    f_t = wall_friction_factor_numpy(np.abs(speed), width, viscosity, fluid_density, code)
    return f_t * np.sqrt(12.0) * viscosity * np.abs(speed) / width


def shields_number_numpy(tau, diameter, particle_density, fluid_density, gravity):
    """theta = tau_b / ((rho_p - rho_f) g d) (Shields 1936)."""
    return tau / ((particle_density - fluid_density) * gravity * diameter)


def critical_shields_number_numpy(diameter, particle_density, fluid_density, viscosity, gravity):
    """theta_cr of Soulsby & Whitehouse (1997) at the dimensionless grain size D* (module docstring)."""
    nu = viscosity / fluid_density
    d_star = diameter * ((particle_density / fluid_density - 1.0) * gravity / nu ** 2) ** (1.0 / 3.0)
    return 0.30 / (1.0 + 1.2 * d_star) + 0.055 * (1.0 - np.exp(-0.020 * d_star))


def held_numpy(speed, width, diameter, particle_density, fluid_density, viscosity, gravity, code: int):
    """True where a grain on a bed surface is below the threshold of motion, theta < theta_cr (module
    docstring), under fluid of speed |u_f| along the bed across the gap ``width``."""
    tau = bed_shear_stress_numpy(speed, width, fluid_density, viscosity, code)
    with np.errstate(divide="ignore", invalid="ignore"):  # a neutrally buoyant grain: no threshold, never held
        shields = shields_number_numpy(tau, diameter, particle_density, fluid_density, gravity)
    return shields < critical_shields_number_numpy(diameter, particle_density, fluid_density, viscosity, gravity)


@ti.func
def held(speed, width, diameter, particle_density, fluid_density, viscosity, gravity, code):
    """1 where a grain on a bed surface is below the threshold of motion (held_numpy), else 0; scalar."""
    s = ti.abs(speed)
    tau = wall_friction_factor(s, width, viscosity, fluid_density, code) * ti.sqrt(12.0) * viscosity * s / width
    shields = tau / ((particle_density - fluid_density) * gravity * diameter)
    d_star = diameter * ti.pow((particle_density / fluid_density - 1.0) * gravity
                               / (viscosity / fluid_density) ** 2, 1.0 / 3.0)
    critical = 0.30 / (1.0 + 1.2 * d_star) + 0.055 * (1.0 - ti.exp(-0.020 * d_star))
    return ti.cast(shields < critical, ti.i32)
