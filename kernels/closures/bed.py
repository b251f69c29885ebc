"""The bed: Coulomb friction of grains resting in or on a dense bed, the overburden stress that friction acts on,
and the threshold of motion of grains on a bed surface; NumPy references and Taichi twins. Where a grain rests
(on a dense cell, on the floor) is the push's business (particle_ops_numpy.on_bed, kernels.particles.on_bed);
this family says what the bed does.

Bed friction, in the implicit velocity update of Eq. 43: a friction force per unit mass a_f opposes the motion
along the bed (x, normal to gravity) and, being static friction, at most cancels it:

    u <- sign(u) max(|u| - dt a_f / den, 0),    den = 1 + dt (D_p + 1 / (2 tau_D)) (Eq. 43's).

What presses the grain onto the bed (``bed_stress``, BED_STRESSES):

- "grain": its own submerged weight, a_f = mu_b |g'|, g' = (1 - rho_f / rho_p) g.
- "overburden": Coulomb friction on the vertical normal stress of the grains above, as the frictional stress
  of dense granular flow is (Johnson & Jackson 1987, J. Fluid Mech. 176, 67: tau = p_f sin phi, p_f the
  frictional normal stress; Schaeffer 1987, J. Differ. Equations 66, 19), with the normal stress taken as the
  submerged weight of the contact network above (a Janssen column without wall friction). The stress at the
  base of cell k of a column is the submerged weight per unit area of the run of dense cells (theta_p >=
  friction_volume_fraction) that ends at k, counted from the top of that run (a loose or closed cell carries
  no contact network and starts the run again):

      sigma_v(k) = sum_{j = top of the run .. k} theta_p,j (rho_p,j - rho_f) g dz
                 = sum_j (m_j - rho_f V_j) g / (dx w_j)      (m_j, V_j: solid mass and volume of cell j),

  and the base's shear strength mu_b sigma_v(k) is shared by the grains of cell k, per unit mass

      a_f(k) = mu_b sigma_v(k) dx w_k / m_k,

  so a grain of the top cell of a run has the own-weight friction (a_f = mu_b g' at one density) and one n
  equal cells deep n times it. A parcel on a bed whose own cell is dense takes max(mu_b |g'|, a_f(k)); one
  on a loose cell (a surface grain, a grain on the floor) its own weight's. What it leaves out: the load that
  the cells above pass down through a cell's top (each cell mobilises the whole strength of its base for its
  own grains): right where the drag of a flow over the bed acts on its top cell, an overestimate under a load
  through the whole depth (seepage), whose Coulomb criterion does not grow with depth; and Janssen's
  saturation (1895, Z. Ver. Dtsch. Ing. 39, 1045): the fracture faces carry part of the weight, sigma_v ->
  gamma' w / (2 mu_w K) over a depth w / (2 mu_w K) (~2.5 w at mu_w = 0.5, K = 0.4), but the same face
  friction resists sliding along x, which is not counted either (docs/proppant-closures.md).

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

from __future__ import annotations

import numpy as np

from hfgpu.kernels.closures.twin import ti
from hfgpu.kernels.closures.wall_friction import wall_friction_factor, wall_friction_factor_numpy
from hfgpu.kernels.layout import BED_STRENGTH, M_MASS, M_VOLUME, THETA, WIDTH

#: what presses a resting grain onto the bed (module docstring); the kernels' code is the index
BED_STRESSES = ("grain", "overburden")


def bed_friction_numpy(u, resting, friction, dt, den):
    """u after bed friction (module docstring) where ``resting``, unchanged elsewhere; friction = a_f [m/s^2]."""
    slide = np.maximum(np.abs(u) - dt * friction / den, 0.0)
    return np.where(resting, np.copysign(slide, u), u)


@ti.func
def bed_friction(u, friction, dt, den):
    """u of a resting grain after bed friction a_f (module docstring), scalar."""
    slide = ti.max(ti.abs(u) - dt * friction / den, 0.0)
    return -slide if u < 0.0 else slide


def bed_strength_numpy(mass, volume, width, volume_fraction, dense, dx, fluid_density, gravity, mu_b):
    """a_f(k) = mu_b sigma_v(k) dx w_k / m_k [m/s^2] per cell (nz, nx) of the "overburden" stress (module
    docstring), 0 outside the contact network (theta_p < ``dense``); the columns scanned down (+z)."""
    strength = np.zeros_like(mass)
    above = np.zeros(mass.shape[1])
    for k in range(mass.shape[0]):
        network = (volume_fraction[k] >= dense) & (width[k] > 0.0) & (mass[k] > 0.0)
        span = np.where(network, dx * width[k], 1.0)
        above = np.where(network, above + (mass[k] - fluid_density * volume[k]) * gravity / span, 0.0)
        strength[k] = np.where(network, mu_b * above * span / np.where(network, mass[k], 1.0), 0.0)
    return strength


@ti.func
def column_strength(cells: ti.template(), i: ti.i32, dense: ti.f64, dx: ti.f64, fluid_density: ti.f64,
                    gravity: ti.f64, mu_b: ti.f64):
    """a_f of every cell of column i into cells[BED_STRENGTH] (bed_strength_numpy), scanning down; the moment
    channels M_MASS, M_VOLUME, THETA and WIDTH of ``cells`` (hfgpu.kernels.layout) are read."""
    above = 0.0
    for k in range(cells.shape[1]):
        mass = cells[M_MASS, k, i]
        width = cells[WIDTH, k, i]
        strength = 0.0
        if cells[THETA, k, i] >= dense and width > 0.0 and mass > 0.0:
            span = dx * width
            above = above + (mass - fluid_density * cells[M_VOLUME, k, i]) * gravity / span
            strength = mu_b * above * span / mass
        else:
            above = 0.0
        cells[BED_STRENGTH, k, i] = strength


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
