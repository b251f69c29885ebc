"""Taichi kernels of the MP-PIC particle operations; the NumPy references are in
``hfgpu.proppant.particle_ops_numpy`` (same formulas, same order of operations; tests compare them).

Gather and push: one thread per parcel. Scatter and exchange: one task per CHUNK consecutive parcels, which
sums runs of parcels sharing a stencil in registers and adds them to the grid with float64 atomics, so
round-off differs from run to run and parcels sorted by cell (Parcels.sort_by_cell) need few atomics.
All arrays are numpy arrays passed as ``ti.types.ndarray`` (zero copy on the CPU; copied to and from the
device on a GPU, once per call).
"""


from hfgpu.kernels.runtime import ti

F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
F2 = ti.types.ndarray(dtype=ti.f64, ndim=2)
F3 = ti.types.ndarray(dtype=ti.f64, ndim=3)
I1 = ti.types.ndarray(dtype=ti.i32, ndim=1)

PI = 3.141592653589793


@ti.func
def bilinear(x: ti.f64, z: ti.f64, ox: ti.f64, oz: ti.f64, x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64,
             mask: ti.template()):
    """Renormalised bilinear weights (Eq. 36-37) onto the active 2 x 2 nodes; see proppant/interpolation.py."""
    sx = (x - x0) / dx - ox
    sz = (z - z0) / dz - oz
    fi = ti.floor(sx)
    fk = ti.floor(sz)
    fx = sx - fi
    fz = sz - fk
    i0 = ti.cast(fi, ti.i32)
    k0 = ti.cast(fk, ti.i32)
    nz = mask.shape[0]
    nx = mask.shape[1]
    w = ti.Vector([(1 - fz) * (1 - fx), (1 - fz) * fx, fz * (1 - fx), fz * fx], dt=ti.f64)
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
def sample(field: ti.template(), k0: ti.i32, i0: ti.i32, w):
    """Sum of node values x weights (Eq. 40-41); nodes of weight 0 are not read."""
    s = 0.0
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if w[2 * a + b] > 0.0:
                s += field[k0 + a, i0 + b] * w[2 * a + b]
    return s


@ti.func
def owner_width(x: ti.f64, z: ti.f64, x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64,
                width: ti.template()) -> ti.f64:
    """Width of the cell containing (x, z); 0 outside the grid."""
    i = ti.cast(ti.floor((x - x0) / dx + 0.5), ti.i32)
    k = ti.cast(ti.floor((z - z0) / dz + 0.5), ti.i32)
    w = 0.0
    if k >= 0 and k < width.shape[0] and i >= 0 and i < width.shape[1]:
        w = width[k, i]
    return w


@ti.func
def blocked(x: ti.f64, z: ti.f64, xn: ti.f64, zn: ti.f64, x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64,
            width: ti.template(), cell_mask: ti.template(), theta: ti.template(), theta_cp: ti.f64) -> ti.i32:
    """The move (x, z) -> (xn, zn) leaves the grid, enters a closed cell, or raises the parcel's bilinear
    weight on a cell with theta_p >= theta_cp (particle_ops_numpy._blocked)."""
    out = 1
    if owner_width(xn, zn, x0, z0, dx, dz, width) > 0.0:
        out = 0
        if packed_near(xn, zn, x0, z0, dx, dz, theta, theta_cp):
            out = packed_gain(x, z, xn, zn, x0, z0, dx, dz, cell_mask, theta, theta_cp)
    return out


@ti.func
def packed_near(x: ti.f64, z: ti.f64, x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, theta: ti.template(),
                theta_cp: ti.f64) -> ti.i32:
    """Whether a cell of the 2 x 2 cell stencil of (x, z) has theta_p >= theta_cp (fast path of blocked)."""
    i0 = ti.cast(ti.floor((x - x0) / dx), ti.i32)
    k0 = ti.cast(ti.floor((z - z0) / dz), ti.i32)
    found = 0
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if k0 + a >= 0 and k0 + a < theta.shape[0] and i0 + b >= 0 and i0 + b < theta.shape[1]:
                if theta[k0 + a, i0 + b] >= theta_cp:
                    found = 1
    return found


@ti.func
def packed_gain(x: ti.f64, z: ti.f64, xn: ti.f64, zn: ti.f64, x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64,
                cell_mask: ti.template(), theta: ti.template(), theta_cp: ti.f64) -> ti.i32:
    """Whether the move raises the parcel's bilinear weight on a cell with theta_p >= theta_cp."""
    out = 0
    k0, i0, w0 = bilinear(x, z, 0.0, 0.0, x0, z0, dx, dz, cell_mask)
    k1, i1, w1 = bilinear(xn, zn, 0.0, 0.0, x0, z0, dx, dz, cell_mask)
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


CHUNK = 64  # parcels per thread task in the deposits; runs of parcels sharing a stencil are summed locally


@ti.func
def flush(out: ti.template(), k0: ti.i32, i0: ti.i32, acc: ti.template(), nch: ti.template()):
    """Atomic add of the locally summed 2 x 2 x nch block acc onto out (nz, nx, channels) at base (k0, i0);
    blocks that sum to exactly 0 (every node outside the grid or inactive carries 0) are skipped."""
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            for c in ti.static(range(nch)):
                if acc[2 * a + b, c] != 0.0:
                    ti.atomic_add(out[k0 + a, i0 + b, c], acc[2 * a + b, c])


@ti.kernel
def moment_sums(x: F1, z: F1, u: F1, v: F1, radius: F1, density: F1, particles: F1,
                x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, cell_mask: F2, out: F3):
    """Bilinear sums of volume, mass, mass u, mass v, mass |u|^2, n r^3, n r^2 (Eq. 38) into out (nz, nx, 7)
    (channel last: a node's sums share a cache line), which the caller zeroes.

    Each task walks CHUNK consecutive parcels and sums in registers while the stencil base stays the same,
    so parcels sorted by cell (Parcels.sort_by_cell) need few atomics; any order gives the same sums."""
    n = ti.cast(x.shape[0], ti.i32)
    for chunk in range(ti.cast((n + CHUNK - 1) // CHUNK, ti.i32)):
        acc = ti.Matrix.zero(ti.f64, 4, 7)
        kb = -1
        ib = -1
        for p in range(ti.cast(chunk * CHUNK, ti.i32), ti.cast(ti.min(n, (chunk + 1) * CHUNK), ti.i32)):
            k0, i0, w = bilinear(x[p], z[p], 0.0, 0.0, x0, z0, dx, dz, cell_mask)
            if k0 != kb or i0 != ib:
                if kb != -1 or ib != -1:
                    flush(out, kb, ib, acc, 7)
                acc = ti.Matrix.zero(ti.f64, 4, 7)
                kb = k0
                ib = i0
            r = radius[p]
            vol = particles[p] * (4.0 / 3.0 * PI * r ** 3)
            mass = vol * density[p]
            vals = ti.Vector([vol, mass, mass * u[p], mass * v[p], mass * (u[p] ** 2 + v[p] ** 2),
                              particles[p] * r ** 3, particles[p] * r ** 2], dt=ti.f64)
            for j in ti.static(range(4)):
                for c in ti.static(range(7)):
                    acc[j, c] += vals[c] * w[j]
        if kb != -1 or ib != -1:
            flush(out, kb, ib, acc, 7)


@ti.kernel
def gather(x: F1, z: F1, x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64,
           cell_mask: F2, xface_mask: F2, zface_mask: F2,
           fluid_u: F2, fluid_v: F2, dpdx: F2, dpdz: F2, dtaudx: F2, dtaudz: F2,
           theta: F2, mean_u: F2, mean_v: F2, damping: F2, width: F2,
           o_u: F1, o_v: F1, o_dpdx: F1, o_dpdz: F1, o_dtaudx: F1, o_dtaudz: F1,
           o_theta: F1, o_mean_u: F1, o_mean_v: F1, o_damping: F1, o_width: F1):
    """Grid fields at the parcels (Eq. 40-41 with x-/z-face weights; cell fields with cell weights)."""
    for p in x:
        kx, ix, wx = bilinear(x[p], z[p], -0.5, 0.0, x0, z0, dx, dz, xface_mask)
        kz, iz, wz = bilinear(x[p], z[p], 0.0, -0.5, x0, z0, dx, dz, zface_mask)
        kc, ic, wc = bilinear(x[p], z[p], 0.0, 0.0, x0, z0, dx, dz, cell_mask)
        o_u[p] = sample(fluid_u, kx, ix, wx)
        o_dpdx[p] = sample(dpdx, kx, ix, wx)
        o_dtaudx[p] = sample(dtaudx, kx, ix, wx)
        o_v[p] = sample(fluid_v, kz, iz, wz)
        o_dpdz[p] = sample(dpdz, kz, iz, wz)
        o_dtaudz[p] = sample(dtaudz, kz, iz, wz)
        o_theta[p] = sample(theta, kc, ic, wc)
        o_mean_u[p] = sample(mean_u, kc, ic, wc)
        o_mean_v[p] = sample(mean_v, kc, ic, wc)
        o_damping[p] = sample(damping, kc, ic, wc)
        o_width[p] = owner_width(x[p], z[p], x0, z0, dx, dz, width)


@ti.func
def drag_rate(slip: ti.f64, r: ti.f64, rho_p: ti.f64, rho_f: ti.f64, mu: ti.f64, hinder: ti.f64,
              hinder_snider: ti.f64, law: ti.i32, re_coefficient: ti.f64) -> ti.f64:
    """D_p = 4.5 mu / (rho_p r^2) x C_d Re / 24 (Eq. 13-15; closures.drag_rate), with the crowding powers
    hinder = theta_f^-2.65 and hinder_snider = theta_f^-1.78 computed once per parcel by the caller."""
    re = 2.0 * rho_f * ti.abs(slip) * r / mu
    factor = 0.0
    if law == 1:
        factor = hinder + re ** (2.0 / 3.0) * hinder_snider / 6.0
    elif re < 1000.0:
        factor = hinder * (1.0 + re_coefficient * re ** 0.687)
    else:
        factor = hinder * (0.44 * re / 24.0)
    return 4.5 * mu / (rho_p * r ** 2) * factor


@ti.func
def limited(delta: ti.f64, slip: ti.f64, grad: ti.f64, restitution: ti.f64) -> ti.f64:
    """Snider (2001) eqs. 39-41 packing limiter of the stress velocity (particle_ops_numpy)."""
    bound = (1.0 + restitution) * slip
    out = 0.0
    if grad <= 0.0:
        out = ti.max(ti.min(delta, bound), 0.0)
    else:
        out = ti.min(ti.max(delta, bound), 0.0)
    return out


@ti.kernel
def push(x: F1, z: F1, u: F1, v: F1, radius: F1, density: F1, state: I1,
         s_u: F1, s_v: F1, s_dpdx: F1, s_dpdz: F1, s_dtaudx: F1, s_dtaudz: F1,
         s_theta: F1, s_mean_u: F1, s_mean_v: F1, s_damping: F1, s_width: F1,
         x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, width: F2, cell_mask: F2, theta_grid: F2,
         dt: ti.f64, rho_f: ti.f64, mu: ti.f64, gravity: ti.f64,
         theta_cp: ti.f64, epsilon: ti.f64, restitution: ti.f64, law: ti.i32, re_coefficient: ti.f64,
         bridging_factor: ti.f64, iterations: ti.i32, drag_out: F1):
    """Eq. 43-44 with the packing limiter and cap, walls and bridging of particle_ops_numpy.push, in place."""
    for p in x:
        rho_p = density[p]
        theta = s_theta[p]
        half_rate = 0.5 * s_damping[p]
        buoyant_g = (1.0 - rho_f / rho_p) * gravity
        un = u[p]
        vn = v[p]
        theta_f = 1.0 - ti.min(theta, theta_cp)
        hinder = theta_f ** -2.65
        hinder_snider = 0.0
        if law == 1:
            hinder_snider = theta_f ** -1.78
        drag = 0.0
        den = 1.0
        for _ in range(iterations):
            slip = ti.sqrt((s_u[p] - un) ** 2 + (s_v[p] - vn) ** 2)
            drag = drag_rate(slip, radius[p], rho_p, rho_f, mu, hinder, hinder_snider, law, re_coefficient)
            den = 1.0 + dt * (drag + half_rate)
            un = (u[p] + dt * (drag * s_u[p] - s_dpdx[p] / rho_p + half_rate * s_mean_u[p])) / den
            vn = (v[p] + dt * (drag * s_v[p] - s_dpdz[p] / rho_p + buoyant_g + half_rate * s_mean_v[p])) / den
        scale = -dt / (ti.max(theta, epsilon) * rho_p * den)
        un = un + limited(scale * s_dtaudx[p], s_mean_u[p] - un, s_dtaudx[p], restitution)
        vn = vn + limited(scale * s_dtaudz[p], s_mean_v[p] - vn, s_dtaudz[p], restitution)
        bridged = s_width[p] < bridging_factor * 2.0 * radius[p]
        if bridged:
            un = 0.0
            vn = 0.0
        xn = x[p] + dt * un
        if blocked(x[p], z[p], xn, z[p], x0, z0, dx, dz, width, cell_mask, theta_grid, theta_cp):
            xn = x[p]
            un = 0.0
        zn = z[p] + dt * vn
        if blocked(xn, z[p], xn, zn, x0, z0, dx, dz, width, cell_mask, theta_grid, theta_cp):
            zn = z[p]
            vn = 0.0
        x[p] = xn
        z[p] = zn
        u[p] = un
        v[p] = vn
        state[p] = ti.cast(1 if bridged else 0, ti.i32)
        drag_out[p] = drag


@ti.kernel
def exchange_sums(x: F1, z: F1, u: F1, v: F1, radius: F1, density: F1, particles: F1,
                  s_u: F1, s_v: F1, s_dpdx: F1, s_dpdz: F1, drag: F1,
                  x0: ti.f64, z0: ti.f64, dx: ti.f64, dz: ti.f64, mask: F2, ox: ti.f64, oz: ti.f64,
                  along_x: ti.i32, out: F3):
    """Face sums of n rho_p V_p [D (u_f - u_p) - grad p / rho_p] I (numerators of Eq. 39) for x-faces
    (along_x = 1, ox = -1/2) or z-faces (along_x = 0, oz = -1/2) into out (faces, 1), zeroed by the caller;
    run-local summation as in moment_sums."""
    n = ti.cast(x.shape[0], ti.i32)
    for chunk in range(ti.cast((n + CHUNK - 1) // CHUNK, ti.i32)):
        acc = ti.Matrix.zero(ti.f64, 4, 1)
        kb = -1
        ib = -1
        for p in range(ti.cast(chunk * CHUNK, ti.i32), ti.cast(ti.min(n, (chunk + 1) * CHUNK), ti.i32)):
            k0, i0, w = bilinear(x[p], z[p], ox, oz, x0, z0, dx, dz, mask)
            if k0 != kb or i0 != ib:
                if kb != -1 or ib != -1:
                    flush(out, kb, ib, acc, 1)
                acc = ti.Matrix.zero(ti.f64, 4, 1)
                kb = k0
                ib = i0
            vol = particles[p] * (4.0 / 3.0 * PI * radius[p] ** 3)
            mass = vol * density[p]
            f = 0.0
            if along_x == 1:
                f = mass * drag[p] * (s_u[p] - u[p]) - vol * s_dpdx[p]
            else:
                f = mass * drag[p] * (s_v[p] - v[p]) - vol * s_dpdz[p]
            for j in ti.static(range(4)):
                acc[j, 0] += f * w[j]
        if kb != -1 or ib != -1:
            flush(out, kb, ib, acc, 1)
