"""The bed: Coulomb friction of grains resting in or on a dense bed, the overburden stress that friction acts on,
and the threshold of motion of grains on a bed surface; NumPy references and Taichi twins. Where a grain rests
(on a dense cell, on the floor) is the push's business (particle_ops_numpy.on_bed, kernels.particles.on_bed);
this family says what the bed does.

Bed friction, in the implicit velocity update of Eq. 43: a friction force per unit mass a_f opposes the motion
along the bed (x, normal to gravity) and, being static friction, at most cancels it:

    u <- sign(u) max(|u| - dt a_f / den, 0),

den the push's drag denominator: 1 + dt D_p (damping_scheme "relaxation", and with bed_slope), or
1 + dt (D_p + 1 / (2 tau_D)) (damping_scheme "implicit", Eq. 43's).

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

Slope (``bed_slope``): the frictional normal stress of the contact network also pushes sideways. Taken
isotropic (the frictional pressure p_f of Johnson & Jackson and Schaeffer, whose Coulomb bound is the shear
strength above), its gradient along x is a force per unit volume -d p_f / dx on the skeleton, which a grain of
density rho_p in a skeleton at close packing feels per unit mass as

    a_s = -(d p_f / dx) / (theta_cp rho_p),      p_f(x, z) = W(x, z), the submerged weight per unit area above
                                                  z in the loaded cells of the column at x.

A loaded cell is a dense cell (theta_p >= friction_volume_fraction) or the loose cell on top of a dense cell or
of a floor (a closed cell or the grid's edge below), the cell of the grains that rest on a bed (on_bed); a
loose cell starts the column's load again. Within cell k of a column, W = W_top(k) + W_own(k) - (1 - zeta) G(k),
G = W_own / min(theta_p / theta_cp, 1): the cell's grains packed at its bottom over a share f = min(theta_p /
theta_cp, 1) of its height (zeta in [0, 1] the depth within the cell), W continued linearly above the
surface of a partly filled cell (negative there: p_f = gamma (h - z) of the surface at height h), and into the
empty open cell over a loaded one. d p_f / dx is differenced across the x-faces of the parcel's row at the
parcel's depth, between open cells (0 across a closed cell or the grid's edge: a wall carries the stress), and
interpolated linearly in x. On a bed surface sloping at angle alpha, p_f = theta_cp (rho_p - rho_f) g (h(x) -
z), so a_s = g' tan alpha down the slope at every depth, the surface grains' too (the two columns' surfaces
being at most a row apart), against bed friction mu_b g' (the surface grains, own weight) to
n mu_b g' (n cells deep, "overburden"): a slope steeper than atan(mu_b) sheds its surface grains and a
shallower one holds, the Coulomb (infinite-slope) angle of repose of a cohesionless material, tan alpha_r =
tan phi (Terzaghi 1943, Theoretical Soil Mechanics, sec. 103; Nedderman 1992, Statics and Kinematics of
Granular Materials, ch. 4). The push acts on the grains of dense cells and on the grains of a bed surface
(own cell loose) that are below the threshold of motion (held): a grain the flow entrains is carried by it,
not resting on the slope (without this, a moving suspension over a one-cell bed, counted as its load, lifted
grains: docs/validation.md, "Angle of repose"). A grain so pushed harder than its friction is not held by the
threshold of motion (an avalanche is not the flow's doing).

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

from hfgpu.kernels.closures.twin import Deferred, ti
from hfgpu.kernels.closures.wall_friction import wall_friction_factor, wall_friction_factor_numpy
from hfgpu.kernels.layout import BED_STRENGTH, LOAD_OWN, LOAD_TOP, M_MASS, M_VOLUME, THETA, WIDTH

stencil = Deferred("hfgpu.kernels.stencil")

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


def bed_load_numpy(mass, volume, width, volume_fraction, dense, dx, fluid_density, gravity):
    """(W_top, W_own) [Pa] per cell (nz, nx): the submerged weight per unit area of the loaded cells above the
    cell's top in its column, and of the cell itself (module docstring, slope); both 0 in a cell not loaded."""
    nz = mass.shape[0]
    top = np.zeros_like(mass)
    own = np.zeros_like(mass)
    above = np.zeros(mass.shape[1])
    for k in range(nz):
        filled = (width[k] > 0.0) & (mass[k] > 0.0)
        dense_k = filled & (volume_fraction[k] >= dense)
        if k + 1 < nz:
            support = (width[k + 1] <= 0.0) | ((volume_fraction[k + 1] >= dense) & (mass[k + 1] > 0.0))
        else:
            support = np.ones(mass.shape[1], dtype=bool)
        loaded = dense_k | (filled & support)
        weight = (mass[k] - fluid_density * volume[k]) * gravity / np.where(filled, dx * width[k], 1.0)
        above = np.where(dense_k, above, 0.0)
        top[k] = np.where(loaded, above, 0.0)
        own[k] = np.where(loaded, weight, 0.0)
        above = np.where(loaded, above + weight, 0.0)
    return top, own


def slope_acceleration_numpy(sx, sz, density, top, own, volume_fraction, width, theta_cp, dx):
    """a_s [m/s^2] of parcels of density ``density`` at cell coordinates (sx, sz) inside the grid (cell (k, i)
    spans [i - 1/2, i + 1/2) x [k - 1/2, k + 1/2)), from the loads of bed_load_numpy (module docstring, slope)."""
    nz, nx = top.shape
    k = np.floor(sz + 0.5).astype(np.int64)
    i = np.floor(sx + 0.5).astype(np.int64)
    xi = sx - i + 0.5
    zeta = sz - k + 0.5

    def packed(row, c):  # W_top + W_own and G = W_own / min(theta_p / theta_cp, 1) of cell (row, c)
        fill = np.minimum(volume_fraction[row, c] / theta_cp, 1.0)
        return top[row, c] + own[row, c], own[row, c] / np.where(fill > 0.0, fill, 1.0)

    def load(col):  # W at the parcel's depth in column col, and whether the face to it is open
        c = np.clip(col, 0, nx - 1)
        inside = (col >= 0) & (col < nx)
        base, unit = packed(k, c)
        below = np.minimum(k + 1, nz - 1)
        base_b, unit_b = packed(below, c)
        surface_below = inside & (own[k, c] == 0.0) & (k + 1 < nz) & (own[below, c] != 0.0)
        w = np.where(own[k, c] != 0.0, base - (1.0 - zeta) * unit,
                     np.where(surface_below, base_b - unit_b - (1.0 - zeta) * unit_b, 0.0))
        return np.where(inside, w, 0.0), inside & (width[k, c] > 0.0)

    here, _ = load(i)
    left, left_open = load(i - 1)
    right, right_open = load(i + 1)
    gradient = ((1.0 - xi) * np.where(left_open, here - left, 0.0)
                + xi * np.where(right_open, right - here, 0.0)) / dx
    return -gradient / (theta_cp * density)


@ti.func
def column_load(cells: ti.template(), i: ti.i32, dense: ti.f64, dx: ti.f64, fluid_density: ti.f64,
                gravity: ti.f64):
    """W_top and W_own of every cell of column i into cells[LOAD_TOP], cells[LOAD_OWN] (bed_load_numpy),
    scanning down; the channels M_MASS, M_VOLUME, THETA and WIDTH are read."""
    nz = cells.shape[1]
    above = 0.0
    for k in range(nz):
        width = cells[WIDTH, k, i]
        mass = cells[M_MASS, k, i]
        filled = width > 0.0 and mass > 0.0
        dense_k = filled and cells[THETA, k, i] >= dense
        support = True
        if k + 1 < nz:
            support = cells[WIDTH, k + 1, i] <= 0.0 or (cells[THETA, k + 1, i] >= dense
                                                       and cells[M_MASS, k + 1, i] > 0.0)
        top = 0.0
        own = 0.0
        if not dense_k:
            above = 0.0
        if dense_k or (filled and support):
            top = above
            own = (mass - fluid_density * cells[M_VOLUME, k, i]) * gravity / (dx * width)
            above = above + own
        cells[LOAD_TOP, k, i] = top
        cells[LOAD_OWN, k, i] = own


@ti.func
def packed(cells: ti.template(), k: ti.i32, col: ti.i32, theta_cp: ti.f64):
    """W_top + W_own and G = W_own / min(theta_p / theta_cp, 1) of cell (k, col) (slope_acceleration_numpy)."""
    fill = ti.min(cells[THETA, k, col] / theta_cp, 1.0)
    own = cells[LOAD_OWN, k, col]
    return cells[LOAD_TOP, k, col] + own, own / (fill if fill > 0.0 else 1.0)


@ti.func
def load_at(cells: ti.template(), k: ti.i32, col: ti.i32, zeta: ti.f64, theta_cp: ti.f64) -> ti.f64:
    """W at depth zeta within cell (k, col) (slope_acceleration_numpy's load); 0 outside the grid."""
    w = 0.0
    if col >= 0 and col < cells.shape[2]:
        if cells[LOAD_OWN, k, col] != 0.0:
            base, unit = packed(cells, k, col, theta_cp)
            w = base - (1.0 - zeta) * unit
        elif k + 1 < cells.shape[1]:
            if cells[LOAD_OWN, k + 1, col] != 0.0:
                base, unit = packed(cells, k + 1, col, theta_cp)
                w = base - unit - (1.0 - zeta) * unit
    return w


@ti.func
def slope_acceleration(sx: ti.f64, sz: ti.f64, density: ti.f64, cells: ti.template(), theta_cp: ti.f64,
                       dx: ti.f64) -> ti.f64:
    """a_s of a parcel at cell coordinates (sx, sz) inside the grid (slope_acceleration_numpy), from the
    channels LOAD_TOP, LOAD_OWN, THETA and WIDTH of ``cells``."""
    k = ti.cast(ti.floor(sz + 0.5), ti.i32)
    i = ti.cast(ti.floor(sx + 0.5), ti.i32)
    xi = sx - i + 0.5
    zeta = sz - k + 0.5
    here = load_at(cells, k, i, zeta, theta_cp)
    gradient = 0.0
    if not stencil.closed(k, i - 1, cells):
        gradient += (1.0 - xi) * (here - load_at(cells, k, i - 1, zeta, theta_cp))
    if not stencil.closed(k, i + 1, cells):
        gradient += xi * (load_at(cells, k, i + 1, zeta, theta_cp) - here)
    return -gradient / dx / (theta_cp * density)


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
