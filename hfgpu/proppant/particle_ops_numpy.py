"""MP-PIC particle operations, NumPy reference (the test oracle of the Taichi kernels in ``hfgpu.kernels``):
scatter (``moment_sums``, ``finish_moments``, Eq. 38), grid fields (``grid_fields``), gather (Eq. 40-41), push
(Eq. 43-44), exchange (Eq. 39, with ``pressure_reaction``) and the implicit-drag lag (``parcel_response``).
:class:`hfgpu.proppant.engine_numpy.NumpyEngine` runs them as a sub-loop; kernels/particles.py and
kernels/grid.py are the Taichi versions, pass for pass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kernels.closures import averaging, bed
from ..kernels.closures.particle_stress import packing_limiter_numpy
from ..kernels.closures.walls import blocked_numpy
from ..kernels.layout import (BRIDGED, M_MASS, M_MASS_SPEED2, M_MASS_U, M_MASS_V, M_NR2, M_NR3, M_OWN, M_OWN_X,
                              M_OWN_Z, M_VOLUME, MOMENT_COUNT, MOMENT_FIELDS, SEEN_FIELDS, SUSPENDED)
from ..kernels.stencil_numpy import owning_cell, weights
from ..records import GridFrame
from . import closures
from .grid import face_mean
from .interpolation import active_nodes, deposit, deposit_masks, interpolate, velocity_nodes
from .params import MppicParams
from .parcels import Parcels


@dataclass(frozen=True)
class CellMoments:
    """Per-cell parcel statistics (nz, nx) from the scatter (bilinear cell weights, Eq. 38).

    volume_fraction theta_p = sum n V_p I / (dx dz w) (Eq. 38; 0 in closed cells); solid_volume = sum n V_p I
    [m^3]; mass [kg]; mean_u, mean_v: mass-averaged velocity; velocity_variance: mass-weighted mean of
    |u - mean|^2 [m^2/s^2]; sauter_radius r32 = sum n r^3 / sum n r^2 [m] (0 where no parcel); own_volume,
    own_volume_x, own_volume_z: S, S_x, S_z of the parcels each cell holds (hfgpu.kernels.closures.averaging).
    """

    volume_fraction: np.ndarray
    solid_volume: np.ndarray
    mass: np.ndarray
    mean_u: np.ndarray
    mean_v: np.ndarray
    velocity_variance: np.ndarray
    sauter_radius: np.ndarray
    own_volume: np.ndarray
    own_volume_x: np.ndarray
    own_volume_z: np.ndarray


@dataclass(frozen=True)
class GridFields:
    """Node fields the gather and push read: activity masks (and those of the fluid velocity, with the walls:
    interpolation.velocity_nodes), fluid velocities and gradients at faces, the cell
    fields theta_p, mean parcel velocity, damping rate and width (the push reads theta_p and width for its
    walls and packing cap), bed_strength, the bed friction per unit mass of the overburden a_f [m/s^2], and
    the loads W_top, W_own [Pa] of the bed's slope (hfgpu.kernels.closures.bed; zeros without bed_slope), and
    what the averaging (its name, ``averaging``) reads: the moments' S, S_x, S_z and the cell volume dx dz w
    (hfgpu.kernels.closures.averaging). Built once per particle step by ``grid_fields``."""

    cell_mask: np.ndarray
    xface_mask: np.ndarray
    zface_mask: np.ndarray
    xface_velocity_mask: np.ndarray
    zface_velocity_mask: np.ndarray
    fluid_u: np.ndarray
    fluid_v: np.ndarray
    dpdx: np.ndarray
    dpdz: np.ndarray
    dtaudx: np.ndarray
    dtaudz: np.ndarray
    volume_fraction: np.ndarray
    mean_u: np.ndarray
    mean_v: np.ndarray
    damping_rate: np.ndarray
    width: np.ndarray
    free_grains: np.ndarray
    bed_strength: np.ndarray
    load_top: np.ndarray
    load_own: np.ndarray
    own_volume: np.ndarray
    own_volume_x: np.ndarray
    own_volume_z: np.ndarray
    cell_volume: np.ndarray
    averaging: str


@dataclass(frozen=True)
class ParcelFluid:
    """What a parcel sees (1-D arrays over parcels): fluid velocity u_f, v_f (Eq. 40), dynamic pressure
    gradient (Eq. 41) and particle-stress gradient [Pa/m] (face gradients, same weights), theta_p, mean parcel
    velocity and collision damping rate 1/tau_D (cell weights), and the width of the parcel's own cell [m]."""

    # the fields fluid_u, fluid_v, dpdx, dpdz, dtaudx, dtaudz, volume_fraction, mean_u, mean_v, damping_rate,
    # width: kernels/layout.py SEEN_FIELDS, the SEEN rows of the Taichi engine's work array (S_UF, ...)
    __annotations__ = {name: "np.ndarray" for name in SEEN_FIELDS}


def check_width(width: np.ndarray) -> tuple[int, int]:
    """(nz, nx) of a valid width field; ValueError naming the problem otherwise."""
    if width.ndim != 2 or min(width.shape) < 1:
        raise ValueError(f"width: shape {width.shape}; allowed: a 2-D (nz, nx) array with nz, nx >= 1")
    if not np.all(np.isfinite(width)) or np.any(width < 0.0):
        raise ValueError("width: has negative or non-finite values; allowed: finite values >= 0")
    return width.shape


def check_fluid(width: np.ndarray, u: np.ndarray, v: np.ndarray, pressure: np.ndarray) -> None:
    """Shapes of the fluid fields against the width field (shared layout); ValueError naming the field."""
    nz, nx = check_width(width)
    for name, arr, shape in (("u", u, (nz, nx + 1)), ("v", v, (nz + 1, nx)), ("pressure", pressure, (nz, nx))):
        if arr.shape != shape:
            raise ValueError(f"{name}: shape {arr.shape}; allowed: {shape} for width of shape {(nz, nx)}")


def moment_sums(parcels: Parcels, frame: GridFrame, width: np.ndarray) -> np.ndarray:
    """Sums (MOMENT_COUNT, nz, nx) over parcels of the MOMENT_FIELDS (kernels/layout.py), each in its channel
    M_VOLUME, M_MASS, ... by name: with the bilinear weights the numerators of Eq. 38 and of the mass averages
    of O'Rourke & Snider 2010; over the parcels each cell holds (nearest grid point) the averaging's S, S_x, S_z
    (solid volume and solid volume times the offset from the cell centre in cells)."""
    shape = check_width(width)
    cell_weight, _, _ = deposit_masks(width)
    k, i, w = weights(parcels.x, parcels.z, frame, "cell", cell_weight)
    vol = parcels.solid_volume()
    mass = vol * parcels.density
    values = {"volume": vol, "mass": mass, "mass_u": mass * parcels.u, "mass_v": mass * parcels.v,
              "mass_speed2": mass * (parcels.u ** 2 + parcels.v ** 2),
              "n_r3": parcels.particles * parcels.radius ** 3, "n_r2": parcels.particles * parcels.radius ** 2}
    ko, io, inside = owning_cell(parcels.x, parcels.z, frame, shape)
    own = np.where(inside, vol, 0.0)
    owned = {"own_volume": own, "own_volume_x": own * ((parcels.x - frame.x0) / frame.dx - io),
             "own_volume_z": own * ((parcels.z - frame.z0) / frame.dz - ko)}
    if set(values) | set(owned) != set(MOMENT_FIELDS):
        raise RuntimeError(f"moment_sums: sums {sorted(values) + sorted(owned)} != MOMENT_FIELDS "
                           f"{sorted(MOMENT_FIELDS)}")
    sums = np.empty((MOMENT_COUNT, *shape))
    for name, val in values.items():
        sums[MOMENT_FIELDS.index(name)] = deposit(val, k, i, w, shape)
    for name, val in owned.items():
        sums[MOMENT_FIELDS.index(name)] = deposit(val, ko[:, None], io[:, None], np.ones((ko.size, 1)), shape)
    return sums


def finish_moments(sums: np.ndarray, frame: GridFrame, width: np.ndarray) -> CellMoments:
    """CellMoments from the channel sums: theta_p by Eq. 38 (V = dx dz w), mass averages and Sauter radius."""
    vol, mass, mu, mv, ms2, nr3, nr2 = (sums[c] for c in (M_VOLUME, M_MASS, M_MASS_U, M_MASS_V, M_MASS_SPEED2,
                                                          M_NR3, M_NR2))
    own, own_x, own_z = (np.ascontiguousarray(sums[c]) for c in (M_OWN, M_OWN_X, M_OWN_Z))
    cell_volume = frame.dx * frame.dz * width

    def ratio(a, b):
        return np.divide(a, b, out=np.zeros_like(a), where=b > 0.0)

    mean_u = ratio(mu, mass)
    mean_v = ratio(mv, mass)
    return CellMoments(volume_fraction=ratio(vol, cell_volume), solid_volume=np.ascontiguousarray(vol),
                       mass=np.ascontiguousarray(mass),
                       mean_u=mean_u, mean_v=mean_v,
                       velocity_variance=np.maximum(ratio(ms2, mass) - mean_u ** 2 - mean_v ** 2, 0.0),
                       sauter_radius=ratio(nr3, nr2), own_volume=own, own_volume_x=own_x, own_volume_z=own_z)


def grid_fields(frame: GridFrame, width: np.ndarray, u: np.ndarray, v: np.ndarray, pressure: np.ndarray,
                moments: CellMoments, params: MppicParams, fluid_density: float, gravity: float) -> GridFields:
    """Node fields for the gather: pressure and stress (Eq. 16) gradients differenced to active faces
    (0 elsewhere), the damping rate 1/tau_D per cell (O'Rourke & Snider 2010 eq. 48), ``free_grains`` and the
    overburden's bed friction per unit mass (closures.bed.bed_strength_numpy; 0 with bed_stress "grain") and
    the slope's loads (closures.bed.bed_load_numpy; 0 without bed_slope)."""
    check_fluid(width, u, v, pressure)
    cell, xmask, zmask = active_nodes(width)
    tau = closures.particle_stress(moments.volume_fraction, params)

    def grad_x(f):
        g = np.zeros_like(xmask)
        g[:, 1:-1] = (f[:, 1:] - f[:, :-1]) / frame.dx
        return g * xmask

    def grad_z(f):
        g = np.zeros_like(zmask)
        g[1:-1, :] = (f[1:, :] - f[:-1, :]) / frame.dz
        return g * zmask

    damping = closures.damping_rate(moments.volume_fraction, moments.velocity_variance,
                                    moments.sauter_radius, params)
    xvel, zvel = velocity_nodes(width)
    return GridFields(cell_mask=cell, xface_mask=xmask, zface_mask=zmask, xface_velocity_mask=xvel,
                      zface_velocity_mask=zvel,
                      fluid_u=np.ascontiguousarray(u, dtype=np.float64),
                      fluid_v=np.ascontiguousarray(v, dtype=np.float64),
                      dpdx=grad_x(pressure), dpdz=grad_z(pressure), dtaudx=grad_x(tau), dtaudz=grad_z(tau),
                      volume_fraction=moments.volume_fraction, mean_u=moments.mean_u, mean_v=moments.mean_v,
                      damping_rate=damping * cell, width=np.ascontiguousarray(width, dtype=np.float64),
                      free_grains=free_grains(moments.volume_fraction, params),
                      bed_strength=bed_strength(frame, width, moments, params, fluid_density, gravity),
                      **bed_load(frame, width, moments, params, fluid_density, gravity),
                      own_volume=moments.own_volume, own_volume_x=moments.own_volume_x,
                      own_volume_z=moments.own_volume_z,
                      cell_volume=frame.dx * frame.dz * np.where(width > 0.0, width, 0.0),
                      averaging=params.averaging)


def bed_strength(frame: GridFrame, width: np.ndarray, moments: CellMoments, params: MppicParams,
                 fluid_density: float, gravity: float) -> np.ndarray:
    """a_f per cell with bed_stress "overburden" (closures.bed.bed_strength_numpy), zeros with "grain"."""
    if params.bed_stress == "grain":
        return np.zeros_like(moments.mass)
    return bed.bed_strength_numpy(moments.mass, moments.solid_volume, width, moments.volume_fraction,
                                  params.friction_volume_fraction, frame.dx, fluid_density, gravity,
                                  params.bed_friction)


def bed_load(frame: GridFrame, width: np.ndarray, moments: CellMoments, params: MppicParams,
             fluid_density: float, gravity: float) -> dict[str, np.ndarray]:
    """load_top and load_own per cell with bed_slope (closures.bed.bed_load_numpy), zeros without it."""
    if not params.bed_slope:
        return {"load_top": np.zeros_like(moments.mass), "load_own": np.zeros_like(moments.mass)}
    top, own = bed.bed_load_numpy(moments.mass, moments.solid_volume, width, moments.volume_fraction,
                                  params.friction_volume_fraction, frame.dx, fluid_density, gravity)
    return {"load_top": top, "load_own": own}


def slope(parcels: Parcels, pushed: np.ndarray, frame: GridFrame, fields: GridFields,
          params: MppicParams) -> np.ndarray:
    """The slope's push a_s per unit mass [m/s^2] (closures.bed, slope_acceleration_numpy) of the parcels
    ``pushed`` (push: those on a bed in a dense cell, or on a bed surface and below the threshold of motion), 0
    for the others and without bed_slope."""
    out = np.zeros(parcels.n)
    if params.bed_slope and pushed.any():
        out[pushed] = bed.slope_acceleration_numpy(
            (parcels.x[pushed] - frame.x0) / frame.dx, (parcels.z[pushed] - frame.z0) / frame.dz,
            parcels.density[pushed], fields.load_top, fields.load_own, fields.volume_fraction, fields.width,
            params.theta_cp, frame.dx)
    return out


def free_grains(volume_fraction: np.ndarray, params: MppicParams) -> np.ndarray:
    """1 where a cell's grains take the fluid's pressure gradient -V_p grad p themselves (theta_p <
    friction_volume_fraction), 0 in a contact network: there the skeleton carries that load to the walls and
    floor (as it carries the bed's friction), and the fluid keeps the whole -grad p (``pressure_reaction``).
    Why: with each grain of a settled bed taking -grad p, a parcel move that changes the fluid's storage sets a
    pressure whose gradient moves the parcels back a step later, a loop whose gain does not depend on dt; the
    dynamic pressure of the bed's bottom rows alternated in sign and grew ~3x a fluid step (docs/proppant-closures.md)."""
    return (volume_fraction < params.friction_volume_fraction).astype(np.float64)


def gather(parcels: Parcels, frame: GridFrame, fields: GridFields) -> ParcelFluid:
    """Grid fields at the parcels: face fields with x-/z-face weights (Eq. 40-41; the fluid velocity with the
    walls' zero normal velocity among the nodes, interpolation.velocity_nodes), cell fields with cell weights,
    width of the own cell (0 outside the grid); the pressure gradient times the own cell's ``free_grains`` (1
    outside the grid)."""
    kc, ic, wc = weights(parcels.x, parcels.z, frame, "cell", fields.cell_mask)
    kx, ix, wx = weights(parcels.x, parcels.z, frame, "xface", fields.xface_mask)
    kz, iz, wz = weights(parcels.x, parcels.z, frame, "zface", fields.zface_mask)
    kxu, ixu, wxu = weights(parcels.x, parcels.z, frame, "xface", fields.xface_velocity_mask)
    kzv, izv, wzv = weights(parcels.x, parcels.z, frame, "zface", fields.zface_velocity_mask)
    ko, io, inside = owning_cell(parcels.x, parcels.z, frame, fields.width.shape)
    free = np.where(inside, fields.free_grains[ko, io], 1.0)
    return ParcelFluid(
        fluid_u=interpolate(fields.fluid_u, kxu, ixu, wxu), fluid_v=interpolate(fields.fluid_v, kzv, izv, wzv),
        dpdx=free * interpolate(fields.dpdx, kx, ix, wx), dpdz=free * interpolate(fields.dpdz, kz, iz, wz),
        dtaudx=interpolate(fields.dtaudx, kx, ix, wx), dtaudz=interpolate(fields.dtaudz, kz, iz, wz),
        volume_fraction=seen_fraction(parcels, frame, fields, interpolate(fields.volume_fraction, kc, ic, wc),
                                      (ko, io, inside)),
        mean_u=interpolate(fields.mean_u, kc, ic, wc), mean_v=interpolate(fields.mean_v, kc, ic, wc),
        damping_rate=interpolate(fields.damping_rate, kc, ic, wc),
        width=np.where(inside, fields.width[ko, io], 0.0))


def seen_fraction(parcels: Parcels, frame: GridFrame, fields: GridFields, dual: np.ndarray,
                  owner: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
    """The volume fraction the parcels see by ``fields.averaging`` (hfgpu.kernels.closures.averaging): ``dual``
    (the bilinear read of the cells' theta_p) for "dual", else from the own cell's S, S_x, S_z (0 outside the
    grid); ``owner``: the parcels' owning_cell."""
    if fields.averaging == "dual":
        return dual
    ko, io, inside = owner
    value = averaging.own_cell_fraction_numpy(
        fields.own_volume[ko, io], fields.own_volume_x[ko, io], fields.own_volume_z[ko, io],
        (parcels.x - frame.x0) / frame.dx - io, (parcels.z - frame.z0) / frame.dz - ko,
        fields.cell_volume[ko, io], fields.averaging == "moment")
    return np.where(inside, value, 0.0)


def on_bed(x, z, radius, frame: GridFrame, width: np.ndarray, volume_fraction: np.ndarray,
           params: MppicParams) -> np.ndarray:
    """True where the parcel rests in or on a dense bed: its own cell or the cell below it (+z, the direction
    of gravity) has theta_p (Eq. 38, this step's scatter) >= friction_volume_fraction; or it lies on the floor:
    the cell below is closed or outside the grid and the parcel is within one diameter 2 r of that wall (the
    sub-cell layer of grains on a floor that a cell-averaged theta_p does not resolve)."""
    nz, _ = width.shape
    k, i, inside = owning_cell(x, z, frame, width.shape)
    below = np.minimum(k + 1, nz - 1)
    has_below = k + 1 < nz
    dense = (volume_fraction[k, i] >= params.friction_volume_fraction) \
        | (has_below & (volume_fraction[below, i] >= params.friction_volume_fraction))
    floor = ~has_below | (width[below, i] <= 0.0)
    on_floor = floor & ((k + 0.5 - (z - frame.z0) / frame.dz) * frame.dz <= 2.0 * radius)
    return inside & (dense | on_floor)


def _on_surface(parcels: Parcels, on_bed: np.ndarray, seen: ParcelFluid, frame: GridFrame, fields: GridFields,
                params: MppicParams, fluid_density, fluid_viscosity, gravity) -> tuple[np.ndarray, np.ndarray]:
    """(surface, held): the parcels on a bed (on_bed) whose own cell is loose (theta_p <
    friction_volume_fraction: a grain on the floor or on top of a dense cell, not inside the bed), and those of
    them below the threshold of motion of the fluid velocity along the bed they see, a Shields number
    tau_b / ((rho_p - rho_f) g 2r) < theta_cr (hfgpu.kernels.closures.bed.held_numpy; evaluated only where
    shields_deposition or bed_slope reads it, else none held)."""
    k, i, _ = owning_cell(parcels.x, parcels.z, frame, fields.width.shape)
    surface = on_bed & (fields.volume_fraction[k, i] < params.friction_volume_fraction)
    if not (params.shields_deposition or params.bed_slope):
        return surface, np.zeros(parcels.n, dtype=bool)
    width = np.where(surface, seen.width, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):  # a neutrally buoyant grain: never held
        held = bed.held_numpy(seen.fluid_u, width, 2.0 * parcels.radius, parcels.density, fluid_density,
                              fluid_viscosity, gravity, params.wall_friction_code)
    return surface, surface & held


def bed_friction(parcels: Parcels, frame: GridFrame, fields: GridFields, buoyant_g: np.ndarray,
                 params: MppicParams) -> np.ndarray:
    """Bed friction per unit mass a_f of each parcel (closures.bed): mu_b |g'| of its own submerged weight, or
    the larger of that and its own cell's ``bed_strength`` (0 outside a contact network and with "grain")."""
    own = params.bed_friction * np.abs(buoyant_g)
    k, i, inside = owning_cell(parcels.x, parcels.z, frame, fields.width.shape)
    return np.maximum(own, np.where(inside, fields.bed_strength[k, i], 0.0))


def push(parcels: Parcels, seen: ParcelFluid, frame: GridFrame, fields: GridFields, dt: float,
         params: MppicParams, fluid_density: float, fluid_viscosity: float, gravity: float) -> np.ndarray:
    """Advance parcel velocities (Eq. 43) and positions (Eq. 44) in place; returns D_p per parcel [1/s].

    Velocity (:func:`velocity_step`): with damping_scheme "relaxation" (default) the old velocity is relaxed
    towards the cell's mean, u' = u^o + dt h (<u> - u^o) / (1 + dt h), h = 1/(2 tau_D), then
    u~ = (u' + dt (D u_f - grad p / rho_p + (1 - rho_f/rho_p) g)) / (1 + dt D); with "implicit"
    u~ = (u^o + dt (D u_f - grad p / rho_p + (1 - rho_f/rho_p) g + h <u>)) / (1 + dt (D + h)); drag D(|u_f - u|)
    iterated ``drag_iterations`` times starting from u^o (the returned D is the one of the last solve). Then the
    stress term -dt grad tau / (theta_p rho_p (1 + ...)), limited per component by Snider (2001) eqs. 39-41
    (packing limiter, hfgpu.kernels.closures.particle_stress).
    Walls, per component (x first): a move that would leave the grid, enter a closed cell, enter another cell
    narrower than the parcel's bridging width (bridging_factor x 2 r), or raise the
    parcel's bilinear weight on a cell whose theta_p (this step's scatter, less the parcel's own deposit with
    bed_slope) is already >= theta_cp, or approach a
    wall within the half cell next to it when the parcel's own cell is dense (hfgpu.kernels.closures.walls),
    is cancelled and that velocity component set to 0 (inelastic stop). The last rule is our packing cap: Snider's limiter
    bounds the velocity relative to the cell's mean parcel velocity, which does not stop a stream of parcels
    that arrives together against a wall; the cap bounds every cell's theta_p by theta_cp plus one step's
    inflow, whatever the parcels' velocities.
    Bed friction: where the parcel rests in or on a dense bed or on the floor (on_bed) its x velocity gains
    the slope's push (with bed_slope, ``slope``) and is reduced by Coulomb friction
    (hfgpu.kernels.closures.bed, mu_b = bed_friction, on the normal stress bed_stress names: ``bed_friction``)
    before the walls, each as dt a / den; with bed_slope over the drag's 1 + dt D only: these contact forces
    act on the skeleton, whose mean velocity the collision damping (which relaxes a grain towards its
    cell's mean) must not hold back (at theta_p >= theta_cp its rate reaches 1e5-1e6 1/s, which froze a
    packed cliff). The slope pushes a grain in a dense cell, and one on a bed surface only below the threshold
    of motion (_on_surface: a grain the flow entrains is carried by it); with shields_deposition, one on a bed
    surface below the threshold of motion stops along x unless |a_s| exceeds its friction (an avalanche).
    Bridging: where the width of the parcel's cell is below bridging_factor x 2 r the parcel is set to state 1
    with zero velocity and does not move; others get state 0. Gravity [m/s^2] acts along +z (depth).
    """
    rho_p = parcels.density
    theta = seen.volume_fraction
    buoyant_g = (1.0 - fluid_density / rho_p) * gravity
    u_new, v_new, drag, den, mean_u, mean_v = velocity_step(parcels, seen, dt, params, fluid_density,
                                                            fluid_viscosity, buoyant_g)
    scale = -dt / (np.maximum(theta, params.epsilon) * rho_p * den)
    u_new = u_new + packing_limiter_numpy(scale * seen.dtaudx, mean_u - u_new, seen.dtaudx,
                                          params.packing_restitution)
    v_new = v_new + packing_limiter_numpy(scale * seen.dtaudz, mean_v - v_new, seen.dtaudz,
                                          params.packing_restitution)
    resting = on_bed(parcels.x, parcels.z, parcels.radius, frame, fields.width, fields.volume_fraction, params)
    friction = bed_friction(parcels, frame, fields, buoyant_g, params)
    surface, held = _on_surface(parcels, resting, seen, frame, fields, params, fluid_density, fluid_viscosity,
                                gravity)
    push_down = slope(parcels, resting & (~surface | held), frame, fields, params)
    contact = 1.0 + dt * drag if params.bed_slope else den
    u_new = np.where(resting, u_new + dt * push_down / contact, u_new)
    u_new = bed.bed_friction_numpy(u_new, resting, friction, dt, contact)
    deposited = held & (np.abs(push_down) <= friction) if params.shields_deposition else np.zeros(parcels.n, bool)
    u_new = np.where(deposited, 0.0, u_new)
    bridged = seen.width < params.bridging_factor * 2.0 * parcels.radius
    u_new = np.where(bridged, 0.0, u_new)
    v_new = np.where(bridged, 0.0, v_new)
    x_try = parcels.x + dt * u_new
    gap = params.bridging_factor * 2.0 * parcels.radius
    own = parcels.solid_volume() if params.bed_slope else None
    blocked = blocked_numpy(parcels.x, parcels.z, x_try, parcels.z, frame, fields.width, fields.cell_mask,
                            fields.volume_fraction, params.theta_cp, params.friction_volume_fraction, gap, own)
    x_new = np.where(blocked, parcels.x, x_try)
    u_new = np.where(blocked, 0.0, u_new)
    z_try = parcels.z + dt * v_new
    blocked = blocked_numpy(x_new, parcels.z, x_new, z_try, frame, fields.width, fields.cell_mask,
                            fields.volume_fraction, params.theta_cp, params.friction_volume_fraction, gap, own)
    z_new = np.where(blocked, parcels.z, z_try)
    v_new = np.where(blocked, 0.0, v_new)
    parcels.x[:] = x_new
    parcels.z[:] = z_new
    parcels.u[:] = u_new
    parcels.v[:] = v_new
    parcels.state[:] = np.where(bridged, BRIDGED, SUSPENDED)
    return drag


def velocity_step(parcels: Parcels, seen: ParcelFluid, dt: float, params: MppicParams, fluid_density: float,
                  fluid_viscosity: float, buoyant_g: np.ndarray) -> tuple[np.ndarray, ...]:
    """The drag solve of :func:`push` with the collision damping, h = 1/(2 tau_D), as ``params.damping_scheme``
    names it (hfgpu.kernels.closures.damping.DAMPING_SCHEMES):

    - "implicit": u = (u^o + dt (D u_f + a + h <u>)) / (1 + dt (D + h));
    - "relaxation": the old velocity relaxed towards the cell's mean first, u' = u^o + dt h / (1 + dt h)
      (<u> - u^o), then u = (u' + dt (D u_f + a)) / (1 + dt D).

    a = -grad p / rho_p (+ the buoyant weight along z), D iterated ``drag_iterations`` times from u^o. Returns (u,
    v, D, the denominator, and the mean velocity that bounds the packing limiter: <u> with "implicit", the mean
    moved by the same step, (<u> + dt (D u_f + a)) / (1 + dt D), with "relaxation")."""
    rho_p = parcels.density
    half_rate = 0.5 * seen.damping_rate
    relaxation = params.damping_scheme == "relaxation"
    start_u, start_v, rate = parcels.u, parcels.v, half_rate   # rate: h inside the drag's denominator
    if relaxation:
        keep = dt * half_rate / (1.0 + dt * half_rate)
        start_u = parcels.u + keep * (seen.mean_u - parcels.u)
        start_v = parcels.v + keep * (seen.mean_v - parcels.v)
        rate = 0.0
    u_new, v_new = parcels.u, parcels.v
    for _ in range(params.drag_iterations):
        slip = np.hypot(seen.fluid_u - u_new, seen.fluid_v - v_new)
        drag = closures.drag_rate(slip, parcels.radius, rho_p, seen.volume_fraction, fluid_density,
                                  fluid_viscosity, params)
        den = 1.0 + dt * (drag + rate)
        u_new = (start_u + dt * (drag * seen.fluid_u - seen.dpdx / rho_p + rate * seen.mean_u)) / den
        v_new = (start_v + dt * (drag * seen.fluid_v - seen.dpdz / rho_p + buoyant_g + rate * seen.mean_v)) / den
    if not relaxation:
        return u_new, v_new, drag, den, seen.mean_u, seen.mean_v
    return (u_new, v_new, drag, den, (seen.mean_u + dt * (drag * seen.fluid_u - seen.dpdx / rho_p)) / den,
            (seen.mean_v + dt * (drag * seen.fluid_v - seen.dpdz / rho_p + buoyant_g)) / den)


def exchange(parcels: Parcels, seen: ParcelFluid, drag: np.ndarray, frame: GridFrame,
             width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The drag part of the interphase momentum transfer per unit volume at active faces, F_x (nz, nx+1), F_z
    (nz+1, nx) [N/m^3] (Eq. 39): sum n rho_p V_p D (u_f - u_p) I / V_face, V_face = dx dz w_face; it is the force
    of the fluid on the particles (the fluid gets -F, Eq. 26). The pressure part of Eq. 39 is pressure_reaction's.
    Uses the parcels' current positions and velocities (after ``push``: u^{n+1}, the implicit drag velocity),
    the u_f they saw before it and the D returned by ``push``."""
    rate = parcels.solid_volume() * parcels.density * drag
    return face_sums(parcels, rate * (seen.fluid_u - parcels.u), rate * (seen.fluid_v - parcels.v), frame, width)


def face_sums(parcels: Parcels, values_x: np.ndarray, values_z: np.ndarray, frame: GridFrame,
              width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-parcel values deposited with x-face and z-face weights (Eq. 37), per unit face volume dx dz w_face:
    sum value I / V_face on the x-faces (nz, nx+1) and the z-faces (nz+1, nx), 0 at inactive faces."""
    check_width(width)
    _, wxf, wzf = deposit_masks(width)
    k, i, w = weights(parcels.x, parcels.z, frame, "xface", wxf)
    sx = deposit(values_x, k, i, w, wxf.shape)
    k, i, w = weights(parcels.x, parcels.z, frame, "zface", wzf)
    sz = deposit(values_z, k, i, w, wzf.shape)
    return per_face_volume(sx, frame, wxf), per_face_volume(sz, frame, wzf)


def per_face_volume(sums: np.ndarray, frame: GridFrame, face_width: np.ndarray) -> np.ndarray:
    """Face sums divided by V_face = dx dz w_face (Eq. 39; 0 at inactive faces)."""
    volume = frame.dx * frame.dz * face_width
    return np.divide(sums, volume, out=np.zeros_like(sums), where=face_width > 0.0)


def pressure_reaction(fields: GridFields) -> tuple[np.ndarray, np.ndarray]:
    """The pressure part of Eq. 39 on the faces, -sum n V_p grad p I / V_face, with each face's own gradient
    (the one the fluid feels there) instead of the gradient interpolated at the parcels (Eq. 41): -theta_p,f
    grad p_f, theta_p,f = (theta_p w)_f / w_f the face mean of Eq. 38's fraction (as the fluid's (theta_f w)_f),
    so that the fluid feels -grad p + theta_p,f grad p = -theta_f,f grad p (Eq. 8 with Eq. 19) face by face.
    Why: Eq. 41 spreads a face's gradient over the parcels a cell either side, and Eq. 39 deposits it back on
    the faces a cell further on; beside a packed inlet, whose gradient is 100-1000 times that of the open
    fracture next to it, that moved more than the whole local pressure force onto the open faces around it,
    pushed the fluid towards the high pressure and drove eddies at 3-6 m/s (tests/proppant/test_inlet_speeds.py).
    The gradient is the old pressure's, the one the parcels feel: taken implicitly (the fluid feeling
    theta_f grad p^(n+1)), the loop parcels -> continuity -> pressure -> parcels gained theta_p / theta_f per
    step and oscillated in settling beds above theta_p = 0.5. Cells in a contact network (``free_grains`` 0)
    add no load: their grains do not take the gradient, so the fluid there keeps -grad p."""
    is_open = fields.width > 0.0
    load = fields.free_grains * fields.volume_fraction * fields.width
    out = []
    for axis, gradient in ((1, fields.dpdx), (0, fields.dpdz)):
        w_f = face_mean(fields.width, is_open, axis)
        theta = np.divide(face_mean(load, is_open, axis), w_f, out=np.zeros_like(w_f), where=w_f > 0.0)
        out.append(-theta * gradient)
    return out[0], out[1]


def parcel_response(lag: np.ndarray, velocity: np.ndarray, drag: np.ndarray, h: float,
                    held: np.ndarray) -> np.ndarray:
    """1 - r after one more sub-step h of Eq. 43: a parcel following the fluid keeps 1/(1 + D h) of the lag
    it had (r = (r^o + D h)/(1 + D h); the collision damping relaxes a parcel towards its cell's mean velocity,
    which follows u_f as the parcel does). Lag 1 (no response) where the push stopped the parcel (velocity
    exactly 0) or where it is ``held`` in a dense bed, whose packing stress (Eq. 16, the limiter, the packing
    cap) and collision damping, not drag alone, set its velocity (``held``: theta_p >= damping_threshold x
    theta_cp)."""
    return np.where((velocity == 0.0) | held, 1.0, lag / (1.0 + drag * h))
