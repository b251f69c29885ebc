"""Taichi functions shared by the particle passes: bilinear stencils (Eq. 36-37), per-cell fast-path flags,
and the run-local deposit into grid copies. The wall and packing rules of a parcel's move are the walls family
of the closures (hfgpu.kernels.closures.walls).

Grids are the engine's channelled arrays (kernels.layout): ``G[channel, k, i]``; a parcel's position enters
as cell coordinates s = (x - x0) / dx (the expression of hfgpu.kernels.stencil_numpy.weights).
The NumPy references are in hfgpu.kernels.stencil_numpy, hfgpu.proppant.interpolation and
hfgpu.proppant.particle_ops_numpy.
"""

from hfgpu.kernels.layout import P_FRICTION_FRACTION, THETA, WIDTH
from hfgpu.kernels.runtime import ti

CHUNK = 64  # parcels per block of the atomic (GPU) deposits
NO_RUN = -2  # stencil base of "no run yet": bilinear bases are >= -1 for points inside the grid (a parcel in
#            the upper-left quarter of the first cell has base (-1, -1))
INTERIOR = 1  # stencil_flags: the cell and its 8 neighbours lie in the grid and are open
QUIET = 2  # ... and none of them has theta_p >= theta_cp
LOOSE = 4  # ... and the cell and the one below it (+z) have theta_p < friction_volume_fraction


@ti.func
def bilinear(sx: ti.f64, sz: ti.f64, grid: ti.template(), mask: ti.template(), interior: ti.template()):
    """Renormalised bilinear weights (Eq. 36-37) onto the active 2 x 2 nodes of channel ``mask`` of ``grid``
    at node coordinates (sx, sz); see proppant/interpolation.py. ``interior``: the parcel's cell is INTERIOR
    (stencil_flags), so all 4 nodes are in the grid and active and the plain weights (summing to 1 up to
    round-off) are used. Returns the stencil base (k0, i0) and the 4 weights."""
    fi = ti.floor(sx)
    fk = ti.floor(sz)
    fx = sx - fi
    fz = sz - fk
    i0 = ti.cast(fi, ti.i32)
    k0 = ti.cast(fk, ti.i32)
    w = ti.Vector([(1 - fz) * (1 - fx), (1 - fz) * fx, fz * (1 - fx), fz * fx], dt=ti.f64)
    if ti.static(not interior):
        nz = grid.shape[1]
        nx = grid.shape[2]
        for a in ti.static(range(2)):
            for b in ti.static(range(2)):
                kk = k0 + a
                ii = i0 + b
                if kk >= 0 and kk < nz and ii >= 0 and ii < nx:
                    w[2 * a + b] = w[2 * a + b] * grid[mask, kk, ii]
                else:
                    w[2 * a + b] = 0.0
        total = w[0] + w[1] + w[2] + w[3]
        if total > 0.0:
            w = w / total
        else:
            w = ti.Vector([0.0, 0.0, 0.0, 0.0], dt=ti.f64)
    return k0, i0, w


@ti.func
def free_grains(theta: ti.f64, PR: ti.template()) -> ti.f64:
    """1 where a cell's grains take the fluid's pressure gradient themselves (theta_p < friction_volume_fraction),
    0 in a contact network, whose skeleton carries it (particle_ops_numpy.free_grains)."""
    return 1.0 if theta < PR[P_FRICTION_FRACTION] else 0.0


@ti.func
def sample(grid: ti.template(), channel: ti.template(), k0: ti.i32, i0: ti.i32, w, interior: ti.template()):
    """Sum of node values x weights (Eq. 40-41) of ``grid[channel]`` over the stencil at base (k0, i0);
    outside INTERIOR cells nodes of weight 0 (possibly outside the grid) are not read."""
    s = 0.0
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if ti.static(interior):
                s += grid[channel, k0 + a, i0 + b] * w[2 * a + b]
            elif w[2 * a + b] > 0.0:
                s += grid[channel, k0 + a, i0 + b] * w[2 * a + b]
    return s


@ti.func
def cell_flags(k: ti.i32, i: ti.i32, cells: ti.template(), theta_cp: ti.f64, dense: ti.f64) -> ti.i32:
    """stencil_flags of cell (k, i): INTERIOR, QUIET and LOOSE (see the constants; the last two only with
    INTERIOR). A parcel owned by an INTERIOR cell has all its stencil nodes active (bilinear's plain weights);
    one owned by a QUIET cell that stays in it is not stopped by any rule of closures.walls.blocked; one owned
    by a LOOSE cell is not on a bed (on_bed)."""
    nz = cells.shape[1]
    nx = cells.shape[2]
    f = 0
    if k >= 1 and k < nz - 1 and i >= 1 and i < nx - 1:
        f = INTERIOR | QUIET
        for a in ti.static(range(3)):
            for b in ti.static(range(3)):
                if cells[WIDTH, k + a - 1, i + b - 1] <= 0.0:
                    f = 0
                elif cells[THETA, k + a - 1, i + b - 1] >= theta_cp:
                    f = f & ~QUIET
        if f != 0 and cells[THETA, k, i] < dense and cells[THETA, k + 1, i] < dense:
            f = f | LOOSE
    return f


@ti.func
def volume_weights(sx: ti.f64, sz: ti.f64, ox: ti.template(), oz: ti.template(), grid: ti.template(),
                   mask: ti.template(), width: ti.template()):
    """Deposit weights (Eq. 38-39) at (sx + ox, sz + oz): the bilinear weights onto the active nodes (channel
    ``mask`` of ``grid``) times each node's width (channel ``width``), renormalised, I_k w_k / sum_j I_j w_j
    (interpolation.deposit_masks). A parcel's share of node k divided by the node's volume dx dz w_k is then
    V I_k / (dx dz sum_j I_j w_j), its bilinear share over the mean width of its stencil, so a narrow cell beside
    a loaded wide one (a fracture's tip, a cell that just opened) is not given w_wide / w_k times its
    neighbours' theta_p. On a uniform width these are the plain bilinear weights."""
    k0, i0, w = bilinear(sx + ox, sz + oz, grid, mask, False)
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if w[2 * a + b] > 0.0:
                w[2 * a + b] = w[2 * a + b] * ti.max(grid[width, k0 + a, i0 + b], 0.0)
    total = w[0] + w[1] + w[2] + w[3]
    if total > 0.0:
        w = w / total
    else:
        w = ti.Vector([0.0, 0.0, 0.0, 0.0], dt=ti.f64)
    return k0, i0, w


@ti.func
def owner(sx: ti.f64, sz: ti.f64):
    """(k, i) of the cell containing the point of cell coordinates (sx, sz) (possibly outside the grid)."""
    return ti.cast(ti.floor(sz + 0.5), ti.i32), ti.cast(ti.floor(sx + 0.5), ti.i32)


@ti.func
def owner_flags(sx: ti.f64, sz: ti.f64, flags: ti.template()) -> ti.i32:
    """stencil_flags of the cell containing the point of cell coordinates (sx, sz); 0 outside the grid."""
    k, i = owner(sx, sz)
    f = 0
    if k >= 0 and k < flags.shape[0] and i >= 0 and i < flags.shape[1]:
        f = flags[k, i]
    return f


@ti.func
def owner_width(sx: ti.f64, sz: ti.f64, cells: ti.template()) -> ti.f64:
    """Width of the cell containing the point of cell coordinates (sx, sz); 0 outside the grid."""
    k, i = owner(sx, sz)
    w = 0.0
    if k >= 0 and k < cells.shape[1] and i >= 0 and i < cells.shape[2]:
        w = cells[WIDTH, k, i]
    return w


@ti.func
def closed(k: ti.i32, i: ti.i32, cells: ti.template()) -> ti.i32:
    """Cell (k, i) is outside the grid or closed."""
    out = 1
    if k >= 0 and k < cells.shape[1] and i >= 0 and i < cells.shape[2]:
        out = ti.cast(cells[WIDTH, k, i] <= 0.0, ti.i32)
    return out


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
