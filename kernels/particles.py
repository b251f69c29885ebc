"""The per-parcel passes of an MP-PIC sub-step as Taichi functions, each one top-level loop over the parcels
(hfgpu.kernels.engine launches them): scatter (Eq. 38), gather (Eq. 40-41), push (Eq. 43-44) and exchange
(Eq. 39). The NumPy references are in hfgpu.proppant.particle_ops_numpy (same formulas, same order of
operations up to round-off; tests compare them). State layout: hfgpu.kernels.layout. Parcels marked GONE
(left through an outlet) are skipped until the next compaction drops them.

Gather: one task per LANES (16) consecutive parcels, their cell coordinates as vectors, then parcel by parcel.
Push: one task per LANES consecutive parcels; their drag solves (Eq. 43) run as LANES-wide vectors so that the
independent dependency chains of the parcels interleave (one parcel's fixed-point iteration is a serial chain
of sqrt, log, exp and a division); then bed friction, bridging and the move (Eq. 44, walls) parcel by parcel.
The drag and the packing limiter are the closures' Taichi twins (hfgpu.kernels.closures.drag, particle_stress),
evaluated on LANES-wide vectors; bed friction and the threshold of motion are hfgpu.kernels.closures.bed's.

Fast paths (per-cell bits of stencil.cell_flags): a parcel whose cell and its 8 neighbours are open and inside
the grid (INTERIOR) uses plain bilinear weights without mask reads in the gather (scatter and exchange weight
each node by its width, stencil.volume_weights); one whose 3 x 3
cells are also below close packing (QUIET) and that stays in its cell skips the wall checks of its move; one in
a LOOSE cell is not on a bed. Each gives what the general path gives (up to round-off: the renormalisation by
a sum of weights that is 1 up to an ulp).

Scatter and exchange: the parcels are split into ``blocks`` ranges, one task each, which sum runs of parcels
sharing a stencil in registers and add them to the grid copy ``out[copy]``. On the CPU (``private`` true)
each block has its own copy, written without atomics, and the engine sums the copies: no atomics at all,
results are deterministic, and random parcel order costs little more than sorted order. On a GPU
(``private`` false) blocks are CHUNK parcels that add into one copy with float64 atomics (round-off then
varies from run to run); the engine keeps the parcels sorted by cell, so runs are long and atomics few.
"""

from hfgpu.kernels.closures import averaging, bed, drag, particle_stress
from hfgpu.kernels.closures.walls import blocked
from hfgpu.kernels.layout import (
    PARAM_COUNT, BED_STRENGTH,
    M_MASS, M_MASS_SPEED2, M_MASS_U, M_MASS_V, M_NR2, M_NR3, M_OWN, M_OWN_X, M_OWN_Z, M_VOLUME, MOMENT_COUNT,
    BRIDGED, CELL, DAMPING, DENSITY, DRAG, F_DP, F_DTAU, F_MASK, F_VELOCITY, F_WALLS, GONE, LAG_X, LAG_Z, MEAN_U,
    F_WIDTH, MEAN_V, OUTLET, P_BED_FRICTION, P_BRIDGING, P_DAMPING_THRESHOLD, P_DRAG_ITERATIONS, P_DRAG_LAW, P_DX, P_DZ,
    P_AVERAGING, P_EPSILON, P_FRICTION_FRACTION, P_GRAVITY, P_MU, P_PACKING_RESTITUTION, P_RE_COEFFICIENT, P_RHO_F,
    P_BED_SLOPE, P_DAMPING_SCHEME, P_SHIELDS,
    P_THETA_CP, P_WALL_LAW, P_X0, P_Z0, PARTICLES, RADIUS, S_DAMPING, S_DPDX, S_DPDZ, S_DTDX, S_DTDZ, S_MEAN_U,
    S_MEAN_V, S_THETA, S_UF, S_VF, S_WIDTH, SEEN, ST_BAD_PARCEL, ST_BAD_STEP, ST_LEFT, ST_OUTFLOW, ST_SPEED,
    ST_VOLUME, STATE, SUSPENDED, THETA, U, V, WIDTH, X, Z)
from hfgpu.kernels.runtime import ti
from hfgpu.kernels.stencil import (
    INTERIOR, LOOSE, NO_RUN, QUIET, bilinear, block_range, closed, flush, free_grains, owner,
    owner_flags, run_sum, sample, volume_weights)

PI = 3.141592653589793
#: A deposit pass with private copies runs ``blocks`` tasks; its loop counts blocks x SPREAD iterations, one in
#: SPREAD doing a block's work, because Taichi 1.7.4's CPU runtime runs a range-for of fewer than ~1 000
#: iterations on one thread (measured: 4 heavy iterations serial whatever block_dim, 4 x 256 parallel).
SPREAD = 256
LANES = 8  # parcels per gather and push task: their drag solves interleave (measured at 1e6 parcels on 2 cores:
#          the push 134 ms with 8, 150 ms with 16; 8 also halves the code to build and compile)


@ti.func
def constants(PR: ti.template()):
    """The run constants PR as a vector of registers (a task reads them once: loads from PR inside a loop are
    repeated after every store, which may alias them)."""
    return ti.Vector([PR[j] for j in ti.static(range(PARAM_COUNT))], dt=ti.f64)


@ti.func
def solid_volume(P: ti.template(), p: ti.i32) -> ti.f64:
    """n 4/3 pi r^3 of parcel p [m^3]."""
    r = P[RADIUS, p]
    return P[PARTICLES, p] * (4.0 / 3.0 * PI * r ** 3)


@ti.func
def cell_coordinates(P: ti.template(), p: ti.i32, PR: ti.template()):
    """(sx, sz) = ((x - x0) / dx, (z - z0) / dz) of parcel p."""
    return (P[X, p] - PR[P_X0]) / PR[P_DX], (P[Z, p] - PR[P_Z0]) / PR[P_DZ]


@ti.func
def report_block(BS: ti.template(), ST: ti.template(), block: ti.i32, row: ti.template(), slot: ti.template(),
                 total: ti.f64, fastest: ti.f64, private: ti.template()):
    """A deposit block's sum ``total`` (of BS row ``row``, ST slot ``slot``) and largest parcel speed: into
    BS[row, block] and BS[2, block] for the caller to reduce in block order (private copies: the CPU's few
    blocks), or straight into ST[slot] and ST[ST_SPEED] with atomics (shared copies: a GPU's many blocks)."""
    if ti.static(private):
        BS[row, block] = total
        BS[2, block] = fastest
    else:
        ti.atomic_add(ST[slot], total)
        ti.atomic_max(ST[ST_SPEED], fastest)


@ti.func
def scatter_pass(P: ti.template(), S: ti.template(), n: ti.i32, C: ti.template(), FLAGS: ti.template(),
                 CD: ti.template(), BS: ti.template(), blocks: ti.i32, private: ti.template(), PR: ti.template(),
                 ST: ti.template()):
    """Bilinear sums of volume, mass, mass u, mass v, mass |u|^2, n r^3, n r^2 (Eq. 38; channels M_VOLUME, ...,
    layout.MOMENT_FIELDS) into CD (copies, nz, nx, MOMENT_COUNT) (channel last: a node's sums share a cache
    line), which the caller zeroes and sums over copies; the solid volume of each block's parcels into
    BS[0, block] (the domain's solid volume, summed by the caller in block order: the same on every run) and
    their largest |u| + |v| into BS[2, block]; with shared copies (a GPU: many blocks) both go straight into
    ST[ST_VOLUME], ST[ST_SPEED] with atomics instead. Each block sums in registers while the stencil base stays
    the same."""
    spread = ti.static(SPREAD if private else 1)
    for t in range(blocks * spread):
        if t % spread == 0:
            block = t // spread
            copy = block if ti.static(private) else 0
            start, end = block_range(block, blocks, n, private)
            acc = ti.Matrix.zero(ti.f64, 4, MOMENT_COUNT)
            kb = NO_RUN
            ib = NO_RUN
            total = 0.0
            fastest = 0.0
            for p in range(start, end):
                if S[STATE, p] != GONE:
                    sx, sz = cell_coordinates(P, p, PR)
                    k0, i0, w = volume_weights(sx, sz, 0.0, 0.0, C, CELL, WIDTH)
                    acc, kb, ib = run_sum(CD, copy, k0, i0, kb, ib, acc, MOMENT_COUNT, private)
                    r = P[RADIUS, p]
                    n_p = P[PARTICLES, p]
                    vol = n_p * (4.0 / 3.0 * PI * r ** 3)
                    mass = vol * P[DENSITY, p]
                    u = P[U, p]
                    v = P[V, p]
                    vals = ti.Vector.zero(ti.f64, MOMENT_COUNT)  # by channel name (layout.MOMENT_FIELDS)
                    vals[M_VOLUME] = vol
                    vals[M_MASS] = mass
                    vals[M_MASS_U] = mass * u
                    vals[M_MASS_V] = mass * v
                    vals[M_MASS_SPEED2] = mass * (u ** 2 + v ** 2)
                    vals[M_NR3] = n_p * r ** 3
                    vals[M_NR2] = n_p * r ** 2
                    total += vol
                    fastest = ti.max(fastest, ti.abs(u) + ti.abs(v))
                    for j in ti.static(range(4)):
                        for c in ti.static(range(M_OWN)):
                            acc[j, c] += vals[c] * w[j]
                    ko, io = owner(sx, sz)   # the averaging's sums over the parcels a cell holds
                    if ko >= 0 and ko < C.shape[1]:
                        if io >= 0 and io < C.shape[2]:
                            own = 2 * (ko - k0) + (io - i0)
                            for j in ti.static(range(4)):
                                if j == own:
                                    acc[j, M_OWN] += vol
                                    acc[j, M_OWN_X] += vol * (sx - io)
                                    acc[j, M_OWN_Z] += vol * (sz - ko)
            flush(CD, copy, kb, ib, acc, MOMENT_COUNT, private)
            report_block(BS, ST, block, 0, ST_VOLUME, total, fastest, private)


@ti.func
def seen_at(sx: ti.f64, sz: ti.f64, interior: ti.template(), C: ti.template(), XF: ti.template(),
            ZF: ti.template(), PR: ti.template()):
    """The SEEN grid values at cell coordinates (sx, sz) (Eq. 40-41 with x-/z-face weights, the fluid velocity's
    over the active faces and the walls, F_WALLS; cell fields with cell weights; the width of the own cell);
    ``interior``: the own cell is INTERIOR (bilinear: no wall in reach, both face weights the same). The
    pressure gradient is 0 where the own cell is in a contact network (particle_ops_numpy.gather)."""
    kx, ix, wx = bilinear(sx + 0.5, sz, XF, F_MASK, interior)
    kz, iz, wz = bilinear(sx, sz + 0.5, ZF, F_MASK, interior)
    kxu, ixu, wxu = kx, ix, wx
    kzv, izv, wzv = kz, iz, wz
    if ti.static(not interior):
        kxu, ixu, wxu = bilinear(sx + 0.5, sz, XF, F_WALLS, False)
        kzv, izv, wzv = bilinear(sx, sz + 0.5, ZF, F_WALLS, False)
    kc, ic, wc = bilinear(sx, sz, C, CELL, interior)
    k, i = owner(sx, sz)
    own = 0.0
    free = 1.0
    if k >= 0 and k < C.shape[1] and i >= 0 and i < C.shape[2]:
        own = C[WIDTH, k, i]
        free = free_grains(C[THETA, k, i], PR)
    s = ti.Vector.zero(ti.f64, SEEN)  # by row name (layout.SEEN_FIELDS)
    s[S_UF] = sample(XF, F_VELOCITY, kxu, ixu, wxu, interior)
    s[S_VF] = sample(ZF, F_VELOCITY, kzv, izv, wzv, interior)
    s[S_DPDX] = free * sample(XF, F_DP, kx, ix, wx, interior)
    s[S_DPDZ] = free * sample(ZF, F_DP, kz, iz, wz, interior)
    s[S_DTDX] = sample(XF, F_DTAU, kx, ix, wx, interior)
    s[S_DTDZ] = sample(ZF, F_DTAU, kz, iz, wz, interior)
    s[S_THETA] = seen_fraction(sx, sz, sample(C, THETA, kc, ic, wc, interior), C, PR)
    s[S_MEAN_U] = sample(C, MEAN_U, kc, ic, wc, interior)
    s[S_MEAN_V] = sample(C, MEAN_V, kc, ic, wc, interior)
    s[S_DAMPING] = sample(C, DAMPING, kc, ic, wc, interior)
    s[S_WIDTH] = own
    return s


@ti.func
def seen_fraction(sx: ti.f64, sz: ti.f64, dual: ti.f64, C: ti.template(), PR: ti.template()) -> ti.f64:
    """The volume fraction a parcel at cell coordinates (sx, sz) sees by the averaging PR[P_AVERAGING]
    (closures.averaging): ``dual`` (the bilinear read of theta_p) for "dual", else from its own cell's S, S_x,
    S_z (0 outside the grid; particle_ops_numpy.seen_fraction)."""
    out = dual
    code = ti.cast(PR[P_AVERAGING], ti.i32)
    if code > 0:
        out = 0.0
        k, i = owner(sx, sz)
        if k >= 0 and k < C.shape[1]:
            if i >= 0 and i < C.shape[2]:
                out = averaging.own_cell_fraction(C[M_OWN, k, i], C[M_OWN_X, k, i], C[M_OWN_Z, k, i], sx - i,
                                                  sz - k, PR[P_DX] * PR[P_DZ] * ti.max(C[WIDTH, k, i], 0.0),
                                                  code == 2)
    return out


@ti.func
def lanes(P: ti.template(), row: ti.template(), p0: ti.i32, n: ti.i32):
    """Row ``row`` of P at the LANES parcels p0, p0 + 1, ... (the last parcel repeated past n)."""
    return ti.Vector([P[row, ti.min(p0 + l, n - 1)] for l in ti.static(range(LANES))], dt=ti.f64)


@ti.func
def gather_pass(P: ti.template(), S: ti.template(), W: ti.template(), n: ti.i32, C: ti.template(),
                XF: ti.template(), ZF: ti.template(), FLAGS: ti.template(), PR: ti.template(), first: ti.i32):
    """Grid fields at the parcels (Eq. 40-41) into the SEEN rows of W; on the sub-loop's ``first`` sub-step also
    the lags 1 - r_p = 1 (LAG_X, LAG_Z). One task per LANES parcels: their cell coordinates first, as
    LANES-wide vectors, then parcel by parcel (takes the division of x and z off each parcel's chain of
    dependent steps: 1.2x the speed)."""
    for q in range(ti.cast((n + LANES - 1) // LANES, ti.i32)):
        p0 = ti.cast(q * LANES, ti.i32)
        sxs = (lanes(P, X, p0, n) - PR[P_X0]) / PR[P_DX]
        szs = (lanes(P, Z, p0, n) - PR[P_Z0]) / PR[P_DZ]
        for l in range(ti.cast(ti.min(LANES, n - p0), ti.i32)):
            p = p0 + l
            if S[STATE, p] != GONE:
                sx = sxs[l]
                sz = szs[l]
                s = ti.Vector.zero(ti.f64, SEEN)
                if owner_flags(sx, sz, FLAGS) & INTERIOR:
                    s = seen_at(sx, sz, True, C, XF, ZF, PR)
                else:
                    s = seen_at(sx, sz, False, C, XF, ZF, PR)
                for j in ti.static(range(SEEN)):
                    W[j, p] = s[j]
                if first:
                    W[LAG_X, p] = 1.0
                    W[LAG_Z, p] = 1.0


@ti.func
def on_bed(sx: ti.f64, sz: ti.f64, radius: ti.f64, dz: ti.f64, C: ti.template(), dense: ti.f64) -> ti.f64:
    """1.0 where the cell containing (sx, sz) or the cell below it (+z) has theta_p >= dense, or the cell below
    is closed or outside the grid and the parcel is within 2 radius of that wall, else 0.0
    (particle_ops_numpy.on_bed; 0 outside the grid)."""
    out = 0.0
    k, i = owner(sx, sz)
    if k >= 0 and k < C.shape[1] and i >= 0 and i < C.shape[2]:
        if C[THETA, k, i] >= dense:
            out = 1.0
        if closed(k + 1, i, C):
            if (k + 0.5 - sz) * dz <= 2.0 * radius:
                out = 1.0
        elif C[THETA, k + 1, i] >= dense:
            out = 1.0
    return out


@ti.func
def row(s: ti.template(), j: ti.template()):
    """Row j of a (SEEN, LANES) matrix as a LANES vector."""
    return ti.Vector([s[j, l] for l in ti.static(range(LANES))], dt=ti.f64)


@ti.func
def velocity_lanes(p0: ti.i32, n: ti.i32, P: ti.template(), s: ti.template(), dt: ti.f64, PR: ti.template()):
    """New velocities (Eq. 43 with the packing limiter of particle_ops_numpy.push) and D_p of the last drag
    solve of the LANES parcels p0, p0 + 1, ... (vectors; lanes past n repeat the last parcel), which see s
    (SEEN, LANES), rows in the order of ParcelFluid. One power Re^a per drag iteration, a = 0.687 or 2/3 by the
    law; what does not change between iterations (stokes x theta_f^-2.65, Snider's stokes x theta_f^-1.78 / 6
    and 1 + dt / (2 tau_D)) is computed once, dt D_p once per iteration.

    D_p: closures.drag (Eq. 13-15, hindered_stokes once, drag_rate per iteration); the stress velocity:
    closures.particle_stress.packing_limiter (Snider 2001 eqs. 39-41)."""
    rho_f = PR[P_RHO_F]
    mu = PR[P_MU]
    law = ti.cast(PR[P_DRAG_LAW], ti.i32)
    re_coefficient = PR[P_RE_COEFFICIENT]
    rho_p = lanes(P, DENSITY, p0, n)
    r = lanes(P, RADIUS, p0, n)
    u0 = lanes(P, U, p0, n)
    v0 = lanes(P, V, p0, n)
    uf = row(s, S_UF)
    vf = row(s, S_VF)
    dpdx = row(s, S_DPDX)
    dpdz = row(s, S_DPDZ)
    theta = row(s, S_THETA)
    mean_u = row(s, S_MEAN_U)
    mean_v = row(s, S_MEAN_V)
    half_rate = 0.5 * row(s, S_DAMPING)
    inv_rho = 1.0 / rho_p
    buoyant_g = (1.0 - rho_f * inv_rho) * PR[P_GRAVITY]
    stokes_hinder, snider = drag.hindered_stokes(drag.STOKES_FACTOR * mu * inv_rho / (r * r), theta,
                                                 PR[P_THETA_CP], law)
    re_per_slip = (2.0 * rho_f / mu) * r
    force_u = u0 + dt * (half_rate * mean_u - dpdx * inv_rho)
    force_v = v0 + dt * (half_rate * mean_v + buoyant_g - dpdz * inv_rho)
    den_rest = 1.0 + dt * half_rate
    push_u = -dt * dpdx * inv_rho
    push_v = dt * (buoyant_g - dpdz * inv_rho)
    relaxation = PR[P_DAMPING_SCHEME] > 0.0
    if relaxation:  # closures.damping.DAMPING_SCHEMES, particle_ops_numpy.velocity_step
        keep = dt * half_rate / (1.0 + dt * half_rate)
        force_u = u0 + keep * (mean_u - u0) + push_u
        force_v = v0 + keep * (mean_v - v0) + push_v
        den_rest = half_rate * 0.0 + 1.0
    un = u0
    vn = v0
    rate = u0 * 0.0
    inv_den = rate + 1.0
    dt_drag = rate
    for _ in range(ti.cast(PR[P_DRAG_ITERATIONS], ti.i32)):
        re = re_per_slip * ti.sqrt((uf - un) ** 2 + (vf - vn) ** 2)
        rate = drag.drag_rate(re, stokes_hinder, snider, law, re_coefficient)
        dt_drag = dt * rate
        inv_den = 1.0 / (den_rest + dt_drag)
        un = (force_u + dt_drag * uf) * inv_den
        vn = (force_v + dt_drag * vf) * inv_den
    bound_u = mean_u
    bound_v = mean_v
    if relaxation:  # the mean moved by the same step
        bound_u = (mean_u + push_u + dt_drag * uf) * inv_den
        bound_v = (mean_v + push_v + dt_drag * vf) * inv_den
    scale = -dt * inv_den * inv_rho / ti.max(theta, PR[P_EPSILON])
    gx = row(s, S_DTDX)
    gz = row(s, S_DTDZ)
    restitution = PR[P_PACKING_RESTITUTION]
    un = un + particle_stress.packing_limiter(scale * gx, bound_u - un, gx, restitution)
    vn = vn + particle_stress.packing_limiter(scale * gz, bound_v - vn, gz, restitution)
    return un, vn, rate


@ti.func
def move(p: ti.i32, sx: ti.f64, sz: ti.f64, flag: ti.i32, P: ti.template(), dt: ti.f64, C: ti.template(),
         PR: ti.template()):
    """Eq. 44 for parcel p at cell coordinates (sx, sz) with its new velocity, x first, then z; a move that
    blocked() (closures.walls) stops is cancelled and that velocity component set to 0 (particle_ops_numpy.push,
    walls.blocked_numpy). A parcel of a QUIET cell (``flag``, stencil_flags) that stays in it is not stopped and
    skips the checks."""
    theta_cp = PR[P_THETA_CP]
    dense = PR[P_FRICTION_FRACTION]
    gap = PR[P_BRIDGING] * 2.0 * P[RADIUS, p]
    xn = P[X, p] + dt * P[U, p]
    sxn = (xn - PR[P_X0]) / PR[P_DX]
    zn = P[Z, p] + dt * P[V, p]
    szn = (zn - PR[P_Z0]) / PR[P_DZ]
    stays = ti.floor(sxn + 0.5) == ti.floor(sx + 0.5) and ti.floor(szn + 0.5) == ti.floor(sz + 0.5)
    if not (stays and flag & QUIET):
        own = 0.0
        if PR[P_BED_SLOPE] > 0.0:
            own = solid_volume(P, p) / (PR[P_DX] * PR[P_DZ])
        if blocked(sx, sz, sxn, sz, C, theta_cp, dense, gap, own):
            xn = P[X, p]
            sxn = sx
            P[U, p] = 0.0
        if blocked(sxn, sz, sxn, szn, C, theta_cp, dense, gap, own):
            zn = P[Z, p]
            P[V, p] = 0.0
    P[X, p] = xn
    P[Z, p] = zn


@ti.func
def push_parcel(p: ti.i32, P: ti.template(), S: ti.template(), W: ti.template(), C: ti.template(),
                FLAGS: ti.template(), dt: ti.f64, PR: ti.template()):
    """After the drag solve of parcel p: on a bed (on_bed), the slope's push (with bed_slope, in a dense cell or
    on a bed surface below the threshold of motion, closures.bed.slope_acceleration; both it and the friction
    then over the drag's denominator only, particle_ops_numpy.push), bed friction (a_f the larger of the own
    weight's and the own cell's BED_STRENGTH, particle_ops_numpy.bed_friction) and the threshold of motion on a
    bed surface (closures.bed.held once per parcel, particle_ops_numpy._on_surface: with shields_deposition a
    held grain stops, unless the slope's push exceeds a_f); bridging, the move, and the lags 1 - r of the
    implicit drag (simulator.parcel_response)."""
    sx, sz = cell_coordinates(P, p, PR)
    flag = owner_flags(sx, sz, FLAGS)
    rho_f = PR[P_RHO_F]
    gravity = PR[P_GRAVITY]
    dense = PR[P_FRICTION_FRACTION]
    if not flag & LOOSE:
        if on_bed(sx, sz, P[RADIUS, p], PR[P_DZ], C, dense) > 0.0:
            den = 1.0 + dt * (W[DRAG, p] + 0.5 * W[S_DAMPING, p])
            if PR[P_DAMPING_SCHEME] > 0.0 or PR[P_BED_SLOPE] > 0.0:
                den = 1.0 + dt * W[DRAG, p]
            k, i = owner(sx, sz)
            friction = ti.max(PR[P_BED_FRICTION] * ti.abs((1.0 - rho_f / P[DENSITY, p]) * gravity),
                              C[BED_STRENGTH, k, i])
            surface = C[THETA, k, i] < dense
            held = 0
            if surface:
                if PR[P_SHIELDS] > 0.0 or PR[P_BED_SLOPE] > 0.0:
                    held = bed.held(W[S_UF, p], W[S_WIDTH, p], 2.0 * P[RADIUS, p], P[DENSITY, p], rho_f, PR[P_MU],
                                    gravity, ti.cast(PR[P_WALL_LAW], ti.i32))
            slope = 0.0
            if PR[P_BED_SLOPE] > 0.0:
                if not surface or held:
                    slope = bed.slope_acceleration(sx, sz, P[DENSITY, p], C, PR[P_THETA_CP], PR[P_DX])
                P[U, p] += dt * slope / den
            P[U, p] = bed.bed_friction(P[U, p], friction, dt, den)
            if PR[P_SHIELDS] > 0.0 and held:
                if ti.abs(slope) <= friction:
                    P[U, p] = 0.0
    S[STATE, p] = SUSPENDED
    if W[S_WIDTH, p] < PR[P_BRIDGING] * 2.0 * P[RADIUS, p]:
        P[U, p] = 0.0
        P[V, p] = 0.0
        S[STATE, p] = BRIDGED
    move(p, sx, sz, flag, P, dt, C, PR)
    held = W[S_THETA, p] >= PR[P_DAMPING_THRESHOLD] * PR[P_THETA_CP]
    relax = 1.0 + W[DRAG, p] * dt
    W[LAG_X, p] = 1.0 if P[U, p] == 0.0 or held else W[LAG_X, p] / relax
    W[LAG_Z, p] = 1.0 if P[V, p] == 0.0 or held else W[LAG_Z, p] / relax


@ti.func
def push_pass(P: ti.template(), S: ti.template(), W: ti.template(), n: ti.i32, C: ti.template(),
              FLAGS: ti.template(), dt: ti.f64, PR: ti.template()):
    """Eq. 43-44 in place for every parcel with what it sees (W's SEEN rows); D_p into W[DRAG]. One task per
    LANES parcels: velocity_lanes, then push_parcel parcel by parcel. The per-parcel part reads what it needs
    from the arrays, never a lane of a vector at its runtime index: such an index makes Taichi keep the vectors
    in stack arrays (1.3x slower)."""
    for q in range(ti.cast((n + LANES - 1) // LANES, ti.i32)):
        p0 = ti.cast(q * LANES, ti.i32)
        pr = constants(PR)
        s = ti.Matrix([[W[j, ti.min(p0 + l, n - 1)] for l in ti.static(range(LANES))]
                       for j in ti.static(range(SEEN))], dt=ti.f64)
        un, vn, rates = velocity_lanes(p0, n, P, s, dt, pr)
        for l in ti.static(range(LANES)):  # GONE parcels too: nothing reads them before the next sort drops them
            if p0 + l < n:
                P[U, p0 + l] = un[l]
                P[V, p0 + l] = vn[l]
                W[DRAG, p0 + l] = rates[l]
        for l in range(ti.cast(ti.min(LANES, n - p0), ti.i32)):
            if S[STATE, p0 + l] != GONE:
                push_parcel(p0 + l, P, S, W, C, FLAGS, dt, pr)


@ti.func
def finite(a: ti.f64) -> ti.i32:
    """a is neither NaN nor infinite."""
    return ti.abs(a) <= 1.7976931348623157e308


@ti.func
def exchange_pass(P: ti.template(), S: ti.template(), W: ti.template(), n: ti.i32, C: ti.template(),
                  XF: ti.template(), ZF: ti.template(), XD: ti.template(), ZD: ti.template(),
                  BS: ti.template(), blocks: ti.i32, private: ti.template(), PR: ti.template(), ST: ti.template(),
                  step: ti.i32):
    """Face sums (numerators of Eq. 39) of the drag n rho_p V_p D (u_f - u_p) and of the implicit drag
    coefficient n rho_p V_p D (1 - r_p) into XD (copies, nz, nx+1, 2) and ZD (copies, nz+1, nx, 2), channels
    DEPOSIT_FORCE, DEPOSIT_BETA (zeroed by the caller and summed over copies; blocks as in scatter_pass), with the
    parcels' new positions and velocities and the u_f, D_p of their push. Then per parcel: a non-finite state
    records the sub-step ``step`` and the parcel in ST; one in an outlet cell becomes GONE and its solid volume
    goes into its block's outflow BS[1, block] (summed by the caller in block order); the others' largest
    |u| + |v| into BS[2, block] (with shared copies: into ST[ST_OUTFLOW], ST[ST_SPEED] with atomics)."""
    nz = C.shape[1]
    nx = C.shape[2]
    spread = ti.static(SPREAD if private else 1)
    for t in range(blocks * spread):
        if t % spread == 0:
            block = t // spread
            copy = block if ti.static(private) else 0
            start, end = block_range(block, blocks, n, private)
            acc_x = ti.Matrix.zero(ti.f64, 4, 2)
            acc_z = ti.Matrix.zero(ti.f64, 4, 2)
            kx = NO_RUN
            ix = NO_RUN
            kz = NO_RUN
            iz = NO_RUN
            outflow = 0.0
            fastest = 0.0
            for p in range(start, end):
                if S[STATE, p] != GONE:
                    sx, sz = cell_coordinates(P, p, PR)
                    k0, i0, w = volume_weights(sx, sz, 0.5, 0.0, XF, F_MASK, F_WIDTH)
                    k1, i1, w1 = volume_weights(sx, sz, 0.0, 0.5, ZF, F_MASK, F_WIDTH)
                    vol = solid_volume(P, p)
                    rate = vol * P[DENSITY, p] * W[DRAG, p]
                    fx = ti.Vector([rate * (W[S_UF, p] - P[U, p]), rate * W[LAG_X, p]], dt=ti.f64)
                    fz = ti.Vector([rate * (W[S_VF, p] - P[V, p]), rate * W[LAG_Z, p]], dt=ti.f64)
                    acc_x, kx, ix = run_sum(XD, copy, k0, i0, kx, ix, acc_x, 2, private)
                    acc_z, kz, iz = run_sum(ZD, copy, k1, i1, kz, iz, acc_z, 2, private)
                    for j in ti.static(range(4)):
                        for c in ti.static(range(2)):
                            acc_x[j, c] += fx[c] * w[j]
                            acc_z[j, c] += fz[c] * w1[j]
                    if not (finite(P[X, p]) and finite(P[Z, p]) and finite(P[U, p]) and finite(P[V, p])):
                        ti.atomic_min(ST[ST_BAD_STEP], ti.cast(step, ti.f64))
                        ti.atomic_min(ST[ST_BAD_PARCEL], ti.cast(p, ti.f64))
                    else:
                        k = ti.min(ti.max(ti.cast(ti.floor(sz + 0.5), ti.i32), 0), nz - 1)
                        i = ti.min(ti.max(ti.cast(ti.floor(sx + 0.5), ti.i32), 0), nx - 1)
                        if C[OUTLET, k, i] > 0.0:
                            S[STATE, p] = GONE
                            outflow += vol
                            ti.atomic_add(ST[ST_LEFT], 1.0)
                        else:
                            fastest = ti.max(fastest, ti.abs(P[U, p]) + ti.abs(P[V, p]))
            flush(XD, copy, kx, ix, acc_x, 2, private)
            flush(ZD, copy, kz, iz, acc_z, 2, private)
            report_block(BS, ST, block, 1, ST_OUTFLOW, outflow, fastest, private)


__all__ = ["LANES", "scatter_pass", "gather_pass", "push_pass", "exchange_pass"]
