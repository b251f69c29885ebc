"""Taichi kernels of the MP-PIC particle operations; the NumPy references are in
``hfgpu.proppant.particle_ops_numpy`` (same formulas, same order of operations up to round-off; tests compare
them).

Gather: one task per LANES (16) consecutive parcels, their cell coordinates as vectors, then parcel by parcel.
Push: one task per LANES consecutive parcels; their drag solves (Eq. 43) run as LANES-wide vectors so that the
independent dependency chains of the parcels interleave (one parcel's fixed-point iteration is a serial chain
of sqrt, log, exp and a division); then bed friction, bridging and the move (Eq. 44, walls) parcel by parcel.
The powers theta_f^-2.65, theta_f^-1.78 and Re^0.687, Re^(2/3) are exp(a log b) with the inline exp and log of
``elementary`` (no libm call, so LLVM vectorises them across the lanes; libm calls were a third of the push),
log theta_f shared. Parcel positions enter the stencils as cell coordinates s = (x - x0) / dx (the same
expression as ``interpolation.weights``).

Fast paths (per-cell bits of stencil_flags, which the backend computes for each push, and for the other
kernels once per width field): a parcel whose cell and its 8 neighbours are open and inside the grid
(INTERIOR) uses plain bilinear weights without mask reads (gather, scatter, exchange); one whose 3 x 3 cells
are also below close packing (QUIET) and that stays in its cell skips the wall checks of its move; one in a
LOOSE cell is not on a bed. Each gives what the general path gives (up to round-off: the renormalisation by a
sum of weights that is 1 up to an ulp). The gather reads its node fields as flat arrays, one index per
stencil.

Scatter and exchange: the parcels are split into ``blocks`` ranges, one task each, which sum runs of parcels
sharing a stencil in registers and add them to the grid copy ``out[copy]``. On the CPU (``private`` true)
each block has its own copy, written without atomics, and the caller sums the copies: no atomics at all,
results are deterministic, and random parcel order costs little more than sorted order. On a GPU
(``private`` false) blocks are CHUNK parcels that add into one copy with float64 atomics (round-off then
varies from run to run), and parcels sorted by cell (Parcels.sort_by_cell) need few atomics.
All arrays are numpy arrays passed as ``ti.types.ndarray`` (zero copy on the CPU; copied to and from the
device on a GPU, once per call).
"""

from hfgpu.kernels import elementary
from hfgpu.kernels.momentum import wall_friction_factor
from hfgpu.kernels.runtime import ti

F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
F2 = ti.types.ndarray(dtype=ti.f64, ndim=2)
F4 = ti.types.ndarray(dtype=ti.f64, ndim=4)
I1 = ti.types.ndarray(dtype=ti.i32, ndim=1)
I2 = ti.types.ndarray(dtype=ti.i32, ndim=2)

PI = 3.141592653589793
CHUNK = 64  # parcels per block of the atomic (GPU) deposits
SEEN = 11  # what a parcel sees, in the order of ParcelFluid: u_f, v_f, dp/dx, dp/dz, dtau/dx, dtau/dz,
#            theta_p, <u>, <v>, 1/tau_D, width


@ti.func
def bilinear(sx: ti.f64, sz: ti.f64, mask: ti.template(), interior: ti.template()):
    """Renormalised bilinear weights (Eq. 36-37) onto the active 2 x 2 nodes of ``mask`` at node coordinates
    (sx, sz) = ((x - x0) / dx - ox, (z - z0) / dz - oz); see proppant/interpolation.py. ``interior``: the
    parcel's cell is INTERIOR (stencil_flags), so all 4 nodes are in the grid and active and the plain weights
    (summing to 1 up to round-off) are used."""
    fi = ti.floor(sx)
    fk = ti.floor(sz)
    fx = sx - fi
    fz = sz - fk
    i0 = ti.cast(fi, ti.i32)
    k0 = ti.cast(fk, ti.i32)
    w = ti.Vector([(1 - fz) * (1 - fx), (1 - fz) * fx, fz * (1 - fx), fz * fx], dt=ti.f64)
    if ti.static(not interior):
        nz = mask.shape[0]
        nx = mask.shape[1]
        for a in ti.static(range(2)):
            for b in ti.static(range(2)):
                kk = k0 + a
                ii = i0 + b
                if kk >= 0 and kk < nz and ii >= 0 and ii < nx:
                    w[2 * a + b] = w[2 * a + b] * mask[kk, ii]
                else:
                    w[2 * a + b] = 0.0
        total = w[0] + w[1] + w[2] + w[3]
        if total > 0.0:
            w = w / total
        else:
            w = ti.Vector([0.0, 0.0, 0.0, 0.0], dt=ti.f64)
    return k0, i0, w


@ti.func
def sample(field: ti.template(), base: ti.i32, stride: ti.i32, w, interior: ti.template()):
    """Sum of node values x weights (Eq. 40-41) of a field given flat (row-major, ``stride`` nodes per row),
    stencil node [0, 0] at flat index base; outside INTERIOR cells nodes of weight 0 are not read."""
    s = 0.0
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if ti.static(interior):
                s += field[base + a * stride + b] * w[2 * a + b]
            elif w[2 * a + b] > 0.0:
                s += field[base + a * stride + b] * w[2 * a + b]
    return s


INTERIOR = 1  # stencil_flags: the cell and its 8 neighbours lie in the grid and are open
QUIET = 2  # ... and none of them has theta_p >= theta_cp
LOOSE = 4  # ... and the cell and the one below it (+z) have theta_p < friction_volume_fraction


@ti.kernel
def stencil_flags(width: F2, theta: F2, theta_cp: ti.f64, dense: ti.f64, flags: I2):
    """Per cell the bits INTERIOR, QUIET and LOOSE (see the constants; the last two only with INTERIOR): a
    parcel owned by an INTERIOR cell has all its stencil nodes active (bilinear's plain weights); one owned by
    a QUIET cell that stays in it is not stopped by any rule of blocked(); one owned by a LOOSE cell is not on
    a bed (on_bed)."""
    nz = width.shape[0]
    nx = width.shape[1]
    for k in range(nz):
        for i in range(nx):
            flags[k, i] = cell_flags(k, i, nz, nx, width, theta, theta_cp, dense)


@ti.func
def cell_flags(k: ti.i32, i: ti.i32, nz: ti.i32, nx: ti.i32, width: ti.template(), theta: ti.template(),
               theta_cp: ti.f64, dense: ti.f64) -> ti.i32:
    """stencil_flags of cell (k, i)."""
    f = 0
    if k >= 1 and k < nz - 1 and i >= 1 and i < nx - 1:
        f = INTERIOR | QUIET
        for a in ti.static(range(3)):
            for b in ti.static(range(3)):
                if width[k + a - 1, i + b - 1] <= 0.0:
                    f = 0
                elif theta[k + a - 1, i + b - 1] >= theta_cp:
                    f = f & ~QUIET
        if f != 0 and theta[k, i] < dense and theta[k + 1, i] < dense:
            f = f | LOOSE
    return f


@ti.func
def deposit_weights(sx: ti.f64, sz: ti.f64, ox: ti.template(), oz: ti.template(), mask: ti.template(),
                    flag: ti.i32):
    """bilinear at (sx + ox, sz + oz) onto ``mask`` for a parcel at cell coordinates (sx, sz) whose cell has
    the stencil_flags ``flag`` (owner_flags): plain weights where it is INTERIOR."""
    k0 = ti.cast(0, ti.i32)
    i0 = ti.cast(0, ti.i32)
    w = ti.Vector.zero(ti.f64, 4)
    if flag & INTERIOR:
        k0, i0, w = bilinear(sx + ox, sz + oz, mask, True)
    else:
        k0, i0, w = bilinear(sx + ox, sz + oz, mask, False)
    return k0, i0, w


@ti.func
def owner_flags(sx: ti.f64, sz: ti.f64, flags: ti.template()) -> ti.i32:
    """stencil_flags of the cell containing the point of cell coordinates (sx, sz); 0 outside the grid."""
    i = ti.cast(ti.floor(sx + 0.5), ti.i32)
    k = ti.cast(ti.floor(sz + 0.5), ti.i32)
    f = 0
    if k >= 0 and k < flags.shape[0] and i >= 0 and i < flags.shape[1]:
        f = flags[k, i]
    return f


@ti.func
def owner_width(sx: ti.f64, sz: ti.f64, width: ti.template()) -> ti.f64:
    """Width of the cell containing the point of cell coordinates (sx, sz); 0 outside the grid."""
    i = ti.cast(ti.floor(sx + 0.5), ti.i32)
    k = ti.cast(ti.floor(sz + 0.5), ti.i32)
    w = 0.0
    if k >= 0 and k < width.shape[0] and i >= 0 and i < width.shape[1]:
        w = width[k, i]
    return w


@ti.func
def blocked(sx: ti.f64, sz: ti.f64, sxn: ti.f64, szn: ti.f64, width: ti.template(), cell_mask: ti.template(),
            theta: ti.template(), theta_cp: ti.f64, dense: ti.f64) -> ti.i32:
    """The move (sx, sz) -> (sxn, szn) (cell coordinates) leaves the grid, enters a closed cell, raises the
    parcel's bilinear weight on a cell with theta_p >= theta_cp, or heads for a wall from a cell with theta_p >=
    dense (friction_volume_fraction; particle_ops_numpy._blocked)."""
    out = 1
    if owner_width(sxn, szn, width) > 0.0:
        out = 0
        if packed_near(sxn, szn, theta, theta_cp):
            out = packed_gain(sx, sz, sxn, szn, cell_mask, theta, theta_cp)
        if out == 0:
            out = toward_wall_dense(sx, sz, sxn, szn, width, theta, dense)
    return out


@ti.func
def closed(k: ti.i32, i: ti.i32, width: ti.template()) -> ti.i32:
    """Cell (k, i) is outside the grid or closed."""
    out = 1
    if k >= 0 and k < width.shape[0] and i >= 0 and i < width.shape[1]:
        out = ti.cast(width[k, i] <= 0.0, ti.i32)
    return out


@ti.func
def toward_wall_dense(sx: ti.f64, sz: ti.f64, sxn: ti.f64, szn: ti.f64, width: ti.template(),
                      theta: ti.template(), dense: ti.f64) -> ti.i32:
    """The parcel's own cell has theta_p >= dense and it moves, within the half cell next to a wall (domain
    edge or closed cell), towards that wall (particle_ops_numpy._toward_wall_dense). The sign of the move is
    that of sxn - sx: cell coordinates are monotone in x, and differ wherever the move counts."""
    out = 0
    i = ti.cast(ti.floor(sx + 0.5), ti.i32)
    k = ti.cast(ti.floor(sz + 0.5), ti.i32)
    if k >= 0 and k < width.shape[0] and i >= 0 and i < width.shape[1]:
        if theta[k, i] >= dense:
            fx = sx - i
            fz = sz - k
            if ti.abs(sxn - i) > ti.abs(fx) and fx * (sxn - sx) > 0.0:
                out = closed(k, i + (1 if fx >= 0.0 else -1), width)
            if ti.abs(szn - k) > ti.abs(fz) and fz * (szn - sz) > 0.0:
                out = out | closed(k + (1 if fz >= 0.0 else -1), i, width)
    return out


@ti.func
def packed_near(sx: ti.f64, sz: ti.f64, theta: ti.template(), theta_cp: ti.f64) -> ti.i32:
    """Whether a cell of the 2 x 2 cell stencil of (sx, sz) has theta_p >= theta_cp (fast path of blocked)."""
    i0 = ti.cast(ti.floor(sx), ti.i32)
    k0 = ti.cast(ti.floor(sz), ti.i32)
    found = 0
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if k0 + a >= 0 and k0 + a < theta.shape[0] and i0 + b >= 0 and i0 + b < theta.shape[1]:
                if theta[k0 + a, i0 + b] >= theta_cp:
                    found = 1
    return found


@ti.func
def packed_gain(sx: ti.f64, sz: ti.f64, sxn: ti.f64, szn: ti.f64, cell_mask: ti.template(), theta: ti.template(),
                theta_cp: ti.f64) -> ti.i32:
    """Whether the move raises the parcel's bilinear weight on a cell with theta_p >= theta_cp."""
    out = 0
    k0, i0, w0 = bilinear(sx, sz, cell_mask, False)
    k1, i1, w1 = bilinear(sxn, szn, cell_mask, False)
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if w1[2 * a + b] > 0.0:
                if theta[k1 + a, i1 + b] >= theta_cp:
                    before = 0.0
                    for c in ti.static(range(2)):
                        for d in ti.static(range(2)):
                            if k0 + c == k1 + a and i0 + d == i1 + b:
                                before += w0[2 * c + d]
                    if w1[2 * a + b] > before:
                        out = 1
    return out


NO_RUN = -2  # stencil base of "no run yet": bilinear bases are >= -1 for points inside the grid (a parcel in
#            the upper-left quarter of the first cell has base (-1, -1))


@ti.func
def flush(out: ti.template(), copy: ti.i32, k0: ti.i32, i0: ti.i32, acc: ti.template(), nch: ti.template(),
          private: ti.template()):
    """Add the locally summed 2 x 2 x nch block acc onto out[copy] (copies, nz, nx, channels) at base (k0, i0):
    plainly where the copy is private to this task, else with atomics; nothing at base NO_RUN (no run yet);
    blocks that sum to exactly 0 (every node outside the grid or inactive carries 0) are skipped."""
    if k0 != NO_RUN:
        for a in ti.static(range(2)):
            for b in ti.static(range(2)):
                for c in ti.static(range(nch)):
                    if acc[2 * a + b, c] != 0.0:
                        if ti.static(private):
                            out[copy, k0 + a, i0 + b, c] = out[copy, k0 + a, i0 + b, c] + acc[2 * a + b, c]
                        else:
                            ti.atomic_add(out[copy, k0 + a, i0 + b, c], acc[2 * a + b, c])


@ti.func
def run_sum(out: ti.template(), copy: ti.i32, k0: ti.i32, i0: ti.i32, kb: ti.i32, ib: ti.i32, acc,
            nch: ti.template(), private: ti.template()):
    """Run-local summation of the deposits: when the next parcel's stencil base (k0, i0) differs from the
    run's (kb, ib), flush the run's sums and start a new run at (k0, i0). Returns the run's (acc, kb, ib)."""
    if k0 != kb or i0 != ib:
        flush(out, copy, kb, ib, acc, nch, private)
        acc = ti.Matrix.zero(ti.f64, 4, nch)
        kb = k0
        ib = i0
    return acc, kb, ib


@ti.func
def block_range(block: ti.i32, blocks: ti.i32, n: ti.i32, private: ti.template()):
    """Parcels [start, end) of a deposit block: ``blocks`` near-equal ranges (private copies) or CHUNK."""
    start = ti.cast(0, ti.i32)
    end = ti.cast(0, ti.i32)
    if ti.static(private):
        start = ti.cast(ti.cast(n, ti.i64) * block // blocks, ti.i32)
        end = ti.cast(ti.cast(n, ti.i64) * (block + 1) // blocks, ti.i32)
    else:
        start = ti.cast(block * CHUNK, ti.i32)
        end = ti.cast(ti.min(n, start + CHUNK), ti.i32)
    return start, end


@ti.kernel
def moment_sums(x: F1, z: F1, u: F1, v: F1, radius: F1, density: F1, particles: F1,
                x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, cell_mask: F2, flags: I2, blocks: ti.i32,
                private: ti.template(), out: F4):
    """Bilinear sums of volume, mass, mass u, mass v, mass |u|^2, n r^3, n r^2 (Eq. 38) into out (copies, nz,
    nx, 7) (channel last: a node's sums share a cache line), which the caller zeroes and sums over copies.

    Each block walks its parcels and sums in registers while the stencil base stays the same, so parcels
    sorted by cell (Parcels.sort_by_cell) flush rarely; any order gives the same sums up to round-off."""
    n = ti.cast(x.shape[0], ti.i32)
    for block in range(blocks):
        copy = block if ti.static(private) else 0
        start, end = block_range(block, blocks, n, private)
        acc = ti.Matrix.zero(ti.f64, 4, 7)
        kb = NO_RUN
        ib = NO_RUN
        for p in range(start, end):
            sx = (x[p] - x0) / dx
            sz = (z[p] - z0) / dz
            k0, i0, w = deposit_weights(sx, sz, 0.0, 0.0, cell_mask, owner_flags(sx, sz, flags))
            acc, kb, ib = run_sum(out, copy, k0, i0, kb, ib, acc, 7, private)
            r = radius[p]
            vol = particles[p] * (4.0 / 3.0 * PI * r ** 3)
            mass = vol * density[p]
            vals = ti.Vector([vol, mass, mass * u[p], mass * v[p], mass * (u[p] ** 2 + v[p] ** 2),
                              particles[p] * r ** 3, particles[p] * r ** 2], dt=ti.f64)
            for j in ti.static(range(4)):
                for c in ti.static(range(7)):
                    acc[j, c] += vals[c] * w[j]
        flush(out, copy, kb, ib, acc, 7, private)


@ti.func
def seen_at(sx: ti.f64, sz: ti.f64, interior: ti.template(), cell_mask: ti.template(), xface_mask: ti.template(),
            zface_mask: ti.template(), fluid_u: ti.template(), fluid_v: ti.template(), dpdx: ti.template(),
            dpdz: ti.template(), dtaudx: ti.template(), dtaudz: ti.template(), theta: ti.template(),
            mean_u: ti.template(), mean_v: ti.template(), damping: ti.template(), width: ti.template()):
    """The SEEN grid values at cell coordinates (sx, sz) (Eq. 40-41 with x-/z-face weights; cell fields with
    cell weights; the width of the own cell); ``interior``: the own cell is INTERIOR (bilinear). The masks are
    2-D, the fields flat (row-major) views of the (nz, nx+1), (nz+1, nx) and (nz, nx) node sets."""
    nx = cell_mask.shape[1]
    kx, ix, wx = bilinear(sx + 0.5, sz, xface_mask, interior)
    kz, iz, wz = bilinear(sx, sz + 0.5, zface_mask, interior)
    kc, ic, wc = bilinear(sx, sz, cell_mask, interior)
    bx = kx * (nx + 1) + ix
    bz = kz * nx + iz
    bc = kc * nx + ic
    i = ti.cast(ti.floor(sx + 0.5), ti.i32)
    k = ti.cast(ti.floor(sz + 0.5), ti.i32)
    own = 0.0
    if k >= 0 and k < cell_mask.shape[0] and i >= 0 and i < nx:
        own = width[k * nx + i]
    return ti.Vector([sample(fluid_u, bx, nx + 1, wx, interior), sample(fluid_v, bz, nx, wz, interior),
                      sample(dpdx, bx, nx + 1, wx, interior), sample(dpdz, bz, nx, wz, interior),
                      sample(dtaudx, bx, nx + 1, wx, interior), sample(dtaudz, bz, nx, wz, interior),
                      sample(theta, bc, nx, wc, interior), sample(mean_u, bc, nx, wc, interior),
                      sample(mean_v, bc, nx, wc, interior), sample(damping, bc, nx, wc, interior), own],
                     dt=ti.f64)


LANES = 16  # parcels per gather and push task: the push's drag solves interleave (8: 1.2x slower; compiles in
#            10-15 s)


@ti.kernel
def gather(x: F1, z: F1, x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, flags: I2,
           cell_mask: F2, xface_mask: F2, zface_mask: F2,
           fluid_u: F1, fluid_v: F1, dpdx: F1, dpdz: F1, dtaudx: F1, dtaudz: F1,
           theta: F1, mean_u: F1, mean_v: F1, damping: F1, width: F1,
           s_u: F1, s_v: F1, s_dpdx: F1, s_dpdz: F1, s_dtaudx: F1, s_dtaudz: F1,
           s_theta: F1, s_mean_u: F1, s_mean_v: F1, s_damping: F1, s_width: F1):
    """Grid fields at the parcels (Eq. 40-41) into the rows s_* (those of ParcelFluid); flags of
    stencil_flags; the fields flat (seen_at). One task per LANES parcels: their cell coordinates first, as
    LANES-wide vectors (lanes), then parcel by parcel. That takes the division of x and z off each parcel's
    chain of dependent steps (cell coordinates, flags, stencil, loads), which had the CPU wait on one parcel
    at a time (1.2x the speed). The rows are 1-D arrays (as in push): into a 2-D seen[j, p] every store
    recomputed its index from the array's shape, reloaded after each store (0.9x the speed)."""
    n = ti.cast(x.shape[0], ti.i32)
    for q in range(ti.cast((n + LANES - 1) // LANES, ti.i32)):
        p0 = ti.cast(q * LANES, ti.i32)
        sxs = (lanes(x, p0, n) - x0) / dx
        szs = (lanes(z, p0, n) - z0) / dz
        for l in range(ti.cast(ti.min(LANES, n - p0), ti.i32)):
            sx = sxs[l]
            sz = szs[l]
            s = ti.Vector.zero(ti.f64, SEEN)
            if owner_flags(sx, sz, flags) & INTERIOR:
                s = seen_at(sx, sz, True, cell_mask, xface_mask, zface_mask, fluid_u, fluid_v, dpdx, dpdz, dtaudx,
                            dtaudz, theta, mean_u, mean_v, damping, width)
            else:
                s = seen_at(sx, sz, False, cell_mask, xface_mask, zface_mask, fluid_u, fluid_v, dpdx, dpdz,
                            dtaudx, dtaudz, theta, mean_u, mean_v, damping, width)
            for j, row_arr in ti.static(enumerate((s_u, s_v, s_dpdx, s_dpdz, s_dtaudx, s_dtaudz, s_theta,
                                                    s_mean_u, s_mean_v, s_damping, s_width))):
                row_arr[p0 + l] = s[j]


@ti.func
def lanewise_exp(x):
    """elementary.exp of each of the LANES entries of x (inlined: no libm call)."""
    return ti.Vector([elementary.exp(x[l]) for l in ti.static(range(LANES))], dt=ti.f64)


@ti.func
def lanewise_log(x):
    """elementary.log of each of the LANES entries of x (> 0)."""
    return ti.Vector([elementary.log(x[l]) for l in ti.static(range(LANES))], dt=ti.f64)


@ti.func
def power(base, exponent):
    """base^exponent for base >= 0 (elementwise) as exp(exponent log base), 0 at base 0."""
    positive = base > 0.0
    return ti.select(positive, lanewise_exp(exponent * lanewise_log(ti.select(positive, base, 1.0))), 0.0)


@ti.func
def limited(delta, slip, grad, restitution: ti.f64):
    """Snider (2001) eqs. 39-41 packing limiter of the stress velocity (particle_ops_numpy), elementwise."""
    bound = (1.0 + restitution) * slip
    return ti.select(grad <= 0.0, ti.max(ti.min(delta, bound), 0.0), ti.min(ti.max(delta, bound), 0.0))


@ti.func
def lanes(arr: ti.template(), p0: ti.i32, n: ti.i32):
    """arr at the LANES parcels p0, p0 + 1, ... (the last parcel repeated past n)."""
    return ti.Vector([arr[ti.min(p0 + l, n - 1)] for l in ti.static(range(LANES))], dt=ti.f64)


@ti.func
def on_bed(sx: ti.f64, sz: ti.f64, radius: ti.f64, dz: ti.f64, theta: ti.template(), width: ti.template(),
           dense: ti.f64) -> ti.f64:
    """1.0 where the cell containing (sx, sz) or the cell below it (+z) has theta_p >= dense, or the cell below
    is closed or outside the grid and the parcel is within 2 radius of that wall, else 0.0
    (particle_ops_numpy._on_bed; 0 outside the grid)."""
    out = 0.0
    i = ti.cast(ti.floor(sx + 0.5), ti.i32)
    k = ti.cast(ti.floor(sz + 0.5), ti.i32)
    if k >= 0 and k < theta.shape[0] and i >= 0 and i < theta.shape[1]:
        if theta[k, i] >= dense:
            out = 1.0
        if closed(k + 1, i, width):
            if (k + 0.5 - sz) * dz <= 2.0 * radius:
                out = 1.0
        elif theta[k + 1, i] >= dense:
            out = 1.0
    return out


@ti.func
def deposited(sx: ti.f64, sz: ti.f64, fluid_u: ti.f64, width: ti.f64, radius: ti.f64, rho_p: ti.f64,
              theta: ti.template(), dense: ti.f64, rho_f: ti.f64, mu: ti.f64, gravity: ti.f64,
              wall_law: ti.i32) -> ti.i32:
    """For a parcel on a bed (on_bed): its own cell is loose (theta_p < dense) and the Shields number of the bed
    shear stress f_t sqrt(12) mu |u_f| / w is below Soulsby & Whitehouse's (1997) critical one
    (particle_ops_numpy._deposited; closures.bed_shear_stress, critical_shields_number)."""
    out = 0
    i = ti.cast(ti.floor(sx + 0.5), ti.i32)
    k = ti.cast(ti.floor(sz + 0.5), ti.i32)
    if theta[k, i] < dense:
        speed = ti.abs(fluid_u)
        tau = wall_friction_factor(speed, width, mu, rho_f, wall_law) * ti.sqrt(12.0) * mu * speed / width
        d = 2.0 * radius
        shields = tau / ((rho_p - rho_f) * gravity * d)
        d_star = d * ti.pow((rho_p / rho_f - 1.0) * gravity / (mu / rho_f) ** 2, 1.0 / 3.0)
        critical = 0.30 / (1.0 + 1.2 * d_star) + 0.055 * (1.0 - ti.exp(-0.020 * d_star))
        out = ti.cast(shields < critical, ti.i32)
    return out


@ti.func
def row(s: ti.template(), j: ti.template()):
    """Row j of a (SEEN, LANES) matrix as a LANES vector."""
    return ti.Vector([s[j, l] for l in ti.static(range(LANES))], dt=ti.f64)


@ti.func
def buoyant_gravity(inv_rho, rho_f: ti.f64, gravity: ti.f64):
    """g' = (1 - rho_f / rho_p) g (elementwise), from 1 / rho_p."""
    return (1.0 - rho_f * inv_rho) * gravity


@ti.func
def friction_speed(p: ti.i32, density: ti.template(), damping: ti.template(), drag: ti.template(), dt: ti.f64,
                   rho_f: ti.f64, gravity: ti.f64, bed_friction: ti.f64) -> ti.f64:
    """The most speed that bed friction can take from parcel p in a step, dt mu_b |g'| / den with den = 1 +
    dt (D_p + tau_D^-1 / 2) of its last drag solve (velocity_lanes; particle_ops_numpy._bed_friction)."""
    inv_den = 1.0 / (1.0 + dt * (drag[p] + 0.5 * damping[p]))
    return dt * bed_friction * ti.abs(buoyant_gravity(1.0 / density[p], rho_f, gravity)) * inv_den


@ti.func
def velocity_lanes(p0: ti.i32, n: ti.i32, u: ti.template(), v: ti.template(), radius: ti.template(),
                   density: ti.template(), s: ti.template(), dt: ti.f64, rho_f: ti.f64, mu: ti.f64,
                   gravity: ti.f64, theta_cp: ti.f64, epsilon: ti.f64, restitution: ti.f64, law: ti.i32,
                   re_coefficient: ti.f64, iterations: ti.i32):
    """New velocities (Eq. 43 with the packing limiter of particle_ops_numpy.push) and D_p of the last drag
    solve of the LANES parcels p0, p0 + 1, ... (vectors; lanes past n repeat the last parcel), which see s
    (SEEN, LANES), rows in the order of ParcelFluid. One power Re^a per drag iteration, a = 0.687 or 2/3 by the law;
    what does not change between iterations (stokes x theta_f^-2.65, Snider's stokes x theta_f^-1.78 / 6 and
    1 + dt / (2 tau_D)) is computed once, dt D_p once per iteration (1.07x the speed of the push).

    D_p = 4.5 mu / (rho_p r^2) x C_d Re / 24 (Eq. 13-15, closures.drag_rate): law 0 Eq. 14 (theta_f^-2.65
    (1 + c Re^0.687) below Re = 1000, else 0.44 Re / 24 theta_f^-2.65), law 1 Snider (2001)."""
    rho_p = lanes(density, p0, n)
    r = lanes(radius, p0, n)
    u0 = lanes(u, p0, n)
    v0 = lanes(v, p0, n)
    uf = row(s, 0)
    vf = row(s, 1)
    dpdx = row(s, 2)
    dpdz = row(s, 3)
    theta = row(s, 6)
    mean_u = row(s, 7)
    mean_v = row(s, 8)
    half_rate = 0.5 * row(s, 9)
    inv_rho = 1.0 / rho_p
    buoyant_g = buoyant_gravity(inv_rho, rho_f, gravity)
    log_tf = lanewise_log(1.0 - ti.min(theta, theta_cp))  # theta_f of closures.fluid_fraction
    stokes = 4.5 * mu * inv_rho / (r * r)
    stokes_hinder = stokes * lanewise_exp(-2.65 * log_tf)
    snider = stokes * 0.0
    if law == 1:
        snider = stokes * lanewise_exp(-1.78 * log_tf) * (1.0 / 6.0)
    exponent = 2.0 / 3.0 if law == 1 else 0.687
    re_per_slip = (2.0 * rho_f / mu) * r
    force_u = u0 + dt * (half_rate * mean_u - dpdx * inv_rho)
    force_v = v0 + dt * (half_rate * mean_v + buoyant_g - dpdz * inv_rho)
    den_rest = 1.0 + dt * half_rate
    un = u0
    vn = v0
    drag = u0 * 0.0
    inv_den = drag + 1.0
    for _ in range(iterations):
        re = re_per_slip * ti.sqrt((uf - un) ** 2 + (vf - vn) ** 2)
        re_power = power(re, exponent)
        if law == 1:
            drag = stokes_hinder + snider * re_power
        else:
            drag = stokes_hinder * ti.select(re < 1000.0, 1.0 + re_coefficient * re_power, (0.44 / 24.0) * re)
        dt_drag = dt * drag
        inv_den = 1.0 / (den_rest + dt_drag)
        un = (force_u + dt_drag * uf) * inv_den
        vn = (force_v + dt_drag * vf) * inv_den
    scale = -dt * inv_den * inv_rho / ti.max(theta, epsilon)
    gx = row(s, 4)
    gz = row(s, 5)
    un = un + limited(scale * gx, mean_u - un, gx, restitution)
    vn = vn + limited(scale * gz, mean_v - vn, gz, restitution)
    return un, vn, drag


@ti.func
def move(p: ti.i32, sx: ti.f64, sz: ti.f64, flag: ti.i32, x: ti.template(), z: ti.template(), u: ti.template(),
         v: ti.template(), x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, dt: ti.f64, width: ti.template(),
         cell_mask: ti.template(), theta_grid: ti.template(), theta_cp: ti.f64, dense: ti.f64):
    """Eq. 44 for parcel p at cell coordinates (sx, sz) with its new velocity (u[p], v[p]), x first, then z;
    a move that blocked() stops is cancelled and that velocity component set to 0 (particle_ops_numpy.push).
    A parcel of a QUIET cell (``flag``, stencil_flags) that stays in it is not stopped and skips the checks."""
    xn = x[p] + dt * u[p]
    sxn = (xn - x0) / dx
    zn = z[p] + dt * v[p]
    szn = (zn - z0) / dz
    stays = ti.floor(sxn + 0.5) == ti.floor(sx + 0.5) and ti.floor(szn + 0.5) == ti.floor(sz + 0.5)
    if not (stays and flag & QUIET):
        if blocked(sx, sz, sxn, sz, width, cell_mask, theta_grid, theta_cp, dense):
            xn = x[p]
            sxn = sx
            u[p] = 0.0
        if blocked(sxn, sz, sxn, szn, width, cell_mask, theta_grid, theta_cp, dense):
            zn = z[p]
            v[p] = 0.0
    x[p] = xn
    z[p] = zn


@ti.func
def push_lanes(p0: ti.i32, n: ti.i32, s: ti.template(), x: ti.template(), z: ti.template(), u: ti.template(),
               v: ti.template(), radius: ti.template(), density: ti.template(), state: ti.template(),
               x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, flags: ti.template(), width: ti.template(),
               cell_mask: ti.template(), theta_grid: ti.template(), dt: ti.f64, rho_f: ti.f64, mu: ti.f64,
               gravity: ti.f64, theta_cp: ti.f64, epsilon: ti.f64, restitution: ti.f64, law: ti.i32,
               re_coefficient: ti.f64, bridging_factor: ti.f64, iterations: ti.i32, bed_friction: ti.f64,
               friction_fraction: ti.f64, shields: ti.i32, wall_law: ti.i32, drag_out: ti.template(),
               s_u: ti.template(), s_damping: ti.template(), s_width: ti.template()):
    """Eq. 43-44 in place for the LANES parcels p0, p0 + 1, ... (< n) that see s: velocity_lanes; then per
    parcel bed friction (on_bed), the threshold of motion on a bed surface (deposited, where ``shields``) and
    bridging (particle_ops_numpy.push), and move. The per-parcel loop reads what it needs of a parcel from
    the arrays (s_u, s_width; friction_speed from drag_out), never a lane of a vector at its runtime index l:
    such an index makes Taichi keep the vectors in stack arrays, which made the whole push 1.3x slower."""
    un, vn, drag = velocity_lanes(p0, n, u, v, radius, density, s, dt, rho_f, mu, gravity, theta_cp, epsilon,
                                  restitution, law, re_coefficient, iterations)
    for l in ti.static(range(LANES)):
        if p0 + l < n:
            u[p0 + l] = un[l]
            v[p0 + l] = vn[l]
            drag_out[p0 + l] = drag[l]
    for l in range(ti.cast(ti.min(LANES, n - p0), ti.i32)):
        p = p0 + l
        sx = (x[p] - x0) / dx
        sz = (z[p] - z0) / dz
        flag = owner_flags(sx, sz, flags)
        if not flag & LOOSE:
            if on_bed(sx, sz, radius[p], dz, theta_grid, width, friction_fraction) > 0.0:
                friction = friction_speed(p, density, s_damping, drag_out, dt, rho_f, gravity, bed_friction)
                speed = ti.max(ti.abs(u[p]) - friction, 0.0)
                u[p] = -speed if u[p] < 0.0 else speed
                if shields:
                    if deposited(sx, sz, s_u[p], s_width[p], radius[p], density[p], theta_grid,
                                 friction_fraction, rho_f, mu, gravity, wall_law):
                        u[p] = 0.0
        state[p] = ti.cast(0, ti.i32)
        if s_width[p] < bridging_factor * 2.0 * radius[p]:
            u[p] = 0.0
            v[p] = 0.0
            state[p] = ti.cast(1, ti.i32)
        move(p, sx, sz, flag, x, z, u, v, x0, z0, dx, dz, dt, width, cell_mask, theta_grid, theta_cp,
             friction_fraction)


@ti.kernel
def push(x: F1, z: F1, u: F1, v: F1, radius: F1, density: F1, state: I1,
         s_u: F1, s_v: F1, s_dpdx: F1, s_dpdz: F1, s_dtaudx: F1, s_dtaudz: F1,
         s_theta: F1, s_mean_u: F1, s_mean_v: F1, s_damping: F1, s_width: F1,
         x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, flags: I2, width: F2, cell_mask: F2, theta_grid: F2,
         dt: ti.f64, rho_f: ti.f64, mu: ti.f64, gravity: ti.f64,
         theta_cp: ti.f64, epsilon: ti.f64, restitution: ti.f64, law: ti.i32, re_coefficient: ti.f64,
         bridging_factor: ti.f64, iterations: ti.i32, bed_friction: ti.f64, friction_fraction: ti.f64,
         shields: ti.i32, wall_law: ti.i32, drag_out: F1):
    """Eq. 43-44 in place with what the parcels see (s_*, the rows of ParcelFluid); D_p into drag_out; flags of
    stencil_flags; shields: MppicParams.shields_deposition (0/1), wall_law: its wall_friction_code. One task
    per LANES parcels (push_lanes)."""
    n = ti.cast(x.shape[0], ti.i32)
    for q in range(ti.cast((n + LANES - 1) // LANES, ti.i32)):
        p0 = ti.cast(q * LANES, ti.i32)
        s = ti.Matrix([[arr[ti.min(p0 + l, n - 1)] for l in ti.static(range(LANES))]
                       for arr in ti.static((s_u, s_v, s_dpdx, s_dpdz, s_dtaudx, s_dtaudz, s_theta, s_mean_u,
                                             s_mean_v, s_damping, s_width))], dt=ti.f64)
        push_lanes(p0, n, s, x, z, u, v, radius, density, state, x0, z0, dx, dz, flags, width, cell_mask,
                   theta_grid, dt, rho_f, mu, gravity, theta_cp, epsilon, restitution, law, re_coefficient,
                   bridging_factor, iterations, bed_friction, friction_fraction, shields, wall_law, drag_out,
                   s_u, s_damping, s_width)


@ti.func
def face_forces(p: ti.i32, u: ti.template(), v: ti.template(), radius: ti.template(), density: ti.template(),
                particles: ti.template(), s_u: ti.template(), s_v: ti.template(), s_dpdx: ti.template(),
                s_dpdz: ti.template(), drag: ti.template()):
    """n rho_p V_p [D (u_f - u_p) - grad p / rho_p] of parcel p along x and along z (numerators of Eq. 39)."""
    vol = particles[p] * (4.0 / 3.0 * PI * radius[p] ** 3)
    mass = vol * density[p]
    return (mass * drag[p] * (s_u[p] - u[p]) - vol * s_dpdx[p],
            mass * drag[p] * (s_v[p] - v[p]) - vol * s_dpdz[p])


@ti.kernel
def exchange_sums(x: F1, z: F1, u: F1, v: F1, radius: F1, density: F1, particles: F1,
                  s_u: F1, s_v: F1, s_dpdx: F1, s_dpdz: F1, drag: F1,
                  x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, xface_mask: F2, zface_mask: F2, flags: I2,
                  blocks: ti.i32, private: ti.template(), out_x: F4, out_z: F4):
    """Face sums of n rho_p V_p [D (u_f - u_p) - grad p / rho_p] I (numerators of Eq. 39) for the x-faces
    (xface_mask (nz, nx+1)) into out_x (copies, nz, nx+1, 1) and the z-faces (zface_mask (nz+1, nx)) into out_z
    (copies, nz+1, nx, 1), zeroed by the caller and summed over copies; one walk over the parcels, each face
    set with its own run-local sum (blocks as in moment_sums). One launch instead of one per face set: at 1e4
    parcels a launch with its 15 array arguments costs about as much as the walk."""
    n = ti.cast(x.shape[0], ti.i32)
    for block in range(blocks):
        copy = block if ti.static(private) else 0
        start, end = block_range(block, blocks, n, private)
        acc_x = ti.Matrix.zero(ti.f64, 4, 1)
        acc_z = ti.Matrix.zero(ti.f64, 4, 1)
        kx = NO_RUN
        ix = NO_RUN
        kz = NO_RUN
        iz = NO_RUN
        for p in range(start, end):
            sx = (x[p] - x0) / dx
            sz = (z[p] - z0) / dz
            flag = owner_flags(sx, sz, flags)
            k0, i0, w = deposit_weights(sx, sz, 0.5, 0.0, xface_mask, flag)
            k1, i1, w1 = deposit_weights(sx, sz, 0.0, 0.5, zface_mask, flag)
            fx, fz = face_forces(p, u, v, radius, density, particles, s_u, s_v, s_dpdx, s_dpdz, drag)
            acc_x, kx, ix = run_sum(out_x, copy, k0, i0, kx, ix, acc_x, 1, private)
            acc_z, kz, iz = run_sum(out_z, copy, k1, i1, kz, iz, acc_z, 1, private)
            for j in ti.static(range(4)):
                acc_x[j, 0] += fx * w[j]
                acc_z[j, 0] += fz * w1[j]
        flush(out_x, copy, kx, ix, acc_x, 1, private)
        flush(out_z, copy, kz, iz, acc_z, 1, private)
