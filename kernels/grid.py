"""The grid passes of an MP-PIC sub-step as Taichi functions, each one top-level loop over cells or faces
(hfgpu.kernels.engine launches them). NumPy references: hfgpu.proppant.particle_ops_numpy (finish_moments,
grid_fields, per_face_volume), hfgpu.kernels.closures (particle_stress, damping: reference and twin),
hfgpu.proppant.interpolation (active_nodes, face_widths) and hfgpu.proppant.simulator (pressure_reaction).
Layout: hfgpu.kernels.layout.
"""

from hfgpu.kernels.closures import bed, damping, particle_stress
from hfgpu.kernels.layout import (
    BED_STRENGTH, CELL, DAMPING, DEPOSIT_BETA, DEPOSIT_FORCE, F_BETA, F_DP, F_DTAU, F_FORCE, F_MASK, F_VELOCITY,
    F_WALLS, F_WIDTH, M_MASS, M_MASS_SPEED2, M_MASS_U, M_MASS_V, M_NR2, M_NR3, M_VOLUME, MEAN_U, MEAN_V, MOMENT_COUNT,
    OUTLET, P_BED_FRICTION, P_BED_SLOPE, P_BED_STRESS, P_DAMPING, P_DAMPING_THRESHOLD, P_DX, P_DZ, P_EPSILON,
    P_FRICTION_FRACTION, P_GRAVITY, P_RESTITUTION, P_RHO_F, P_STRESS_BETA, P_STRESS_P, P_THETA_CP, PRESSURE,
    SAUTER, TAU, THETA, VARIANCE, WIDTH)
from hfgpu.kernels.runtime import ti
from hfgpu.kernels.stencil import cell_flags, free_grains


@ti.func
def ratio(a: ti.f64, b: ti.f64) -> ti.f64:
    """a / b where b > 0, else 0."""
    out = 0.0
    if b > 0.0:
        out = a / b
    return out


@ti.func
def face_sides(F: ti.template(), k: ti.i32, i: ti.i32, axis: ti.template()):
    """The cells (k_a, i_a), (k_b, i_b) either side of face (k, i) of the face set normal to ``axis`` (1: x-faces
    (nz, nx+1), 0: z-faces (nz+1, nx)), and whether the face lies strictly inside the grid."""
    inside = False
    ka, ia = k, i
    if ti.static(axis == 1):
        ia = i - 1
        inside = i >= 1 and i <= F.shape[2] - 2
    else:
        ka = k - 1
        inside = k >= 1 and k <= F.shape[1] - 2
    return ka, ia, inside


@ti.func
def set_faces(width: ti.template(), F: ti.template(), axis: ti.template()):
    """Active-face mask (open cells on both sides, strictly inside the grid), face width (the mean of the two
    cells there, else 0) and the mask of the fluid velocity's nodes (an open cell on at least one side) of one
    face set from the width field (interpolation.active_nodes, face_widths, velocity_nodes)."""
    for k, i in ti.ndrange((0, F.shape[1]), (0, F.shape[2])):
        ka, ia, inside = face_sides(F, k, i, axis)
        mask = 0.0
        w = 0.0
        if inside:
            if width[ka, ia] > 0.0 and width[k, i] > 0.0:
                mask = 1.0
                w = 0.5 * (width[ka, ia] + width[k, i])
        walls = 0.0
        if ka >= 0 and ia >= 0:
            if width[ka, ia] > 0.0:
                walls = 1.0
        if k < width.shape[0] and i < width.shape[1]:
            if width[k, i] > 0.0:
                walls = 1.0
        F[F_MASK, k, i] = mask
        F[F_WIDTH, k, i] = w
        F[F_WALLS, k, i] = walls


@ti.func
def set_cells(width: ti.template(), outlets: ti.template(), C: ti.template()):
    """Width, open-cell mask and outlet mask of the cells from the host's width and outlet arrays."""
    for k, i in ti.ndrange((0, C.shape[1]), (0, C.shape[2])):
        C[WIDTH, k, i] = width[k, i]
        C[CELL, k, i] = 1.0 if width[k, i] > 0.0 else 0.0
        C[OUTLET, k, i] = ti.cast(outlets[k, i], ti.f64)


@ti.func
def flags_pass(C: ti.template(), FLAGS: ti.template(), PR: ti.template()):
    """stencil_flags of every cell from the width and the theta_p in C."""
    for k, i in FLAGS:
        FLAGS[k, i] = cell_flags(k, i, C, PR[P_THETA_CP], PR[P_FRICTION_FRACTION])


@ti.func
def load_faces(values: ti.template(), pressure: ti.template(), F: ti.template(), spacing: ti.f64,
               axis: ti.template()):
    """Fluid velocity of one face set from the host's array, and the pressure gradient (p_b - p_a) / spacing
    at active faces, 0 elsewhere (particle_ops_numpy.grid_fields)."""
    for k, i in ti.ndrange((0, F.shape[1]), (0, F.shape[2])):
        F[F_VELOCITY, k, i] = values[k, i]
        ka, ia, inside = face_sides(F, k, i, axis)
        g = 0.0
        if inside:
            g = (pressure[k, i] - pressure[ka, ia]) / spacing
        F[F_DP, k, i] = g * F[F_MASK, k, i]


@ti.func
def load_pressure(pressure: ti.template(), C: ti.template()):
    """The dynamic pressure of the cells from the host's array (snapshots read it back)."""
    for k, i in ti.ndrange((0, C.shape[1]), (0, C.shape[2])):
        C[PRESSURE, k, i] = pressure[k, i]


@ti.func
def zero_copies(D: ti.template(), copies: ti.i32, channels: ti.template()):
    """Zero the first ``copies`` grid copies of a deposit array (copies, n1, n2, channels)."""
    for c, k, i in ti.ndrange((0, copies), (0, D.shape[1]), (0, D.shape[2])):
        for j in ti.static(range(channels)):
            D[c, k, i, j] = 0.0


@ti.func
def finish_cells(C: ti.template(), CD: ti.template(), copies: ti.i32, PR: ti.template()):
    """Per cell: the moment sums over the deposit copies, theta_p = volume / (dx dz w) (Eq. 38), mass-averaged
    velocity, velocity variance, Sauter radius (particle_ops_numpy.finish_moments), the particle stress tau of
    Eq. 16 (closures.particle_stress) and the collision damping rate (closures.damping, O'Rourke & Snider 2010
    eq. 48), 0 in closed cells."""
    for k, i in ti.ndrange((0, C.shape[1]), (0, C.shape[2])):
        sums = ti.Vector.zero(ti.f64, MOMENT_COUNT)
        for c in range(copies):
            for j in ti.static(range(MOMENT_COUNT)):
                sums[j] += CD[c, k, i, j]
        for j in ti.static(range(MOMENT_COUNT)):
            C[j, k, i] = sums[j]
        theta = ratio(sums[M_VOLUME], PR[P_DX] * PR[P_DZ] * C[WIDTH, k, i])
        mean_u = ratio(sums[M_MASS_U], sums[M_MASS])
        mean_v = ratio(sums[M_MASS_V], sums[M_MASS])
        variance = ti.max(ratio(sums[M_MASS_SPEED2], sums[M_MASS]) - mean_u ** 2 - mean_v ** 2, 0.0)
        sauter = ratio(sums[M_NR3], sums[M_NR2])
        C[THETA, k, i] = theta
        C[MEAN_U, k, i] = mean_u
        C[MEAN_V, k, i] = mean_v
        C[VARIANCE, k, i] = variance
        C[SAUTER, k, i] = sauter
        C[TAU, k, i] = particle_stress.particle_stress(theta, PR[P_STRESS_P], PR[P_STRESS_BETA], PR[P_THETA_CP],
                                                       PR[P_EPSILON])
        rate = damping.damping_rate(theta, variance, sauter, PR[P_DAMPING], PR[P_RESTITUTION],
                                    PR[P_DAMPING_THRESHOLD], PR[P_THETA_CP], PR[P_EPSILON])
        C[DAMPING, k, i] = rate * C[CELL, k, i]


@ti.func
def bed_pass(C: ti.template(), PR: ti.template()):
    """One thread per column scanning down: the overburden's bed friction per unit mass a_f of every cell into
    C[BED_STRENGTH] (closures.bed.column_strength; particle_ops_numpy.bed_strength; 0 with bed_stress "grain"),
    and with bed_slope the loads of the slope into C[LOAD_TOP], C[LOAD_OWN] (closures.bed.column_load; not
    written, and not read, without it)."""
    for i in range(C.shape[2]):
        if PR[P_BED_STRESS] > 0.0:
            bed.column_strength(C, i, PR[P_FRICTION_FRACTION], PR[P_DX], PR[P_RHO_F], PR[P_GRAVITY],
                                PR[P_BED_FRICTION])
        else:
            for k in range(C.shape[1]):
                C[BED_STRENGTH, k, i] = 0.0
        if PR[P_BED_SLOPE] > 0.0:
            bed.column_load(C, i, PR[P_FRICTION_FRACTION], PR[P_DX], PR[P_RHO_F], PR[P_GRAVITY])


@ti.func
def stress_gradient(C: ti.template(), F: ti.template(), spacing: ti.f64, axis: ti.template()):
    """d tau / dx (or dz) at the active faces of one face set, 0 elsewhere (particle_ops_numpy.grid_fields)."""
    for k, i in ti.ndrange((0, F.shape[1]), (0, F.shape[2])):
        ka, ia, inside = face_sides(F, k, i, axis)
        g = 0.0
        if inside:
            g = (C[TAU, k, i] - C[TAU, ka, ia]) / spacing
        F[F_DTAU, k, i] = g * F[F_MASK, k, i]


@ti.func
def finish_faces(C: ti.template(), F: ti.template(), D: ti.template(), copies: ti.i32, substeps: ti.f64,
                 first: ti.i32, PR: ti.template(), axis: ti.template()):
    """Per face of one set: the deposits summed over copies per unit face volume dx dz w_f (Eq. 39,
    particle_ops_numpy.per_face_volume), the drag plus the pressure reaction -theta_p,f grad p
    (simulator.pressure_reaction: theta_p,f = (theta_p w)_f / w_f), and the implicit drag coefficient beta,
    each added / ``substeps`` to the sub-loop's means F_FORCE, F_BETA (zeroed on the ``first`` sub-step)."""
    for k, i in ti.ndrange((0, F.shape[1]), (0, F.shape[2])):
        force = 0.0
        beta = 0.0
        for c in range(copies):
            force += D[c, k, i, DEPOSIT_FORCE]
            beta += D[c, k, i, DEPOSIT_BETA]
        volume = PR[P_DX] * PR[P_DZ] * F[F_WIDTH, k, i]
        reaction = 0.0
        if F[F_WIDTH, k, i] > 0.0:
            force = force / volume
            beta = beta / volume
            ka, ia, _ = face_sides(F, k, i, axis)
            load = 0.5 * (free_grains(C[THETA, ka, ia], PR) * C[THETA, ka, ia] * C[WIDTH, ka, ia]
                          + free_grains(C[THETA, k, i], PR) * C[THETA, k, i] * C[WIDTH, k, i])
            reaction = -(load / F[F_WIDTH, k, i]) * F[F_DP, k, i]
        else:
            force = 0.0
            beta = 0.0
        if first:
            F[F_FORCE, k, i] = 0.0
            F[F_BETA, k, i] = 0.0
        F[F_FORCE, k, i] += (force + reaction) / substeps
        F[F_BETA, k, i] += beta / substeps


__all__ = ["set_faces", "set_cells", "flags_pass", "load_faces", "load_pressure", "zero_copies", "finish_cells",
           "bed_pass", "stress_gradient", "finish_faces"]
