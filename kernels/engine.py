"""The launches of the MP-PIC engine (hfgpu.proppant.engine_taichi): each kernel is one launch made of the
passes of kernels.particles, kernels.grid and kernels.store, run one after another (every top-level loop of a
Taichi kernel is a parallel pass; the next starts when it ends). Layout of the arguments: kernels.layout.

A fluid step of the engine is: ``begin_step`` (sort and compact the parcels into the work buffer, load the
fluid), [``moments`` for the inlets' room, ``append``], ``substep`` x n, ``read_faces``, ``moments``,
``read_cells``. Only
the arguments typed NUMPY cross between host and device; everything else stays where the kernels run.
"""

from hfgpu.kernels import grid, particles, store
from hfgpu.kernels.layout import (F_BETA, F_FORCE, M_MASS, M_OWN, M_OWN_X, M_OWN_Z, M_VOLUME, MEAN_U, MEAN_V,
                                  MOMENT_COUNT, NO_BAD, SAUTER,
                                  THETA, VARIANCE, P_DX, P_DZ, ST_BAD_PARCEL, ST_BAD_STEP, ST_LEFT, ST_OUTFLOW,
                                  ST_SPEED, ST_VOLUME)
from hfgpu.kernels.runtime import ti

#: what crosses to the host, by the name the host gives it: after a sub-loop, these channels of both face sets
#: (hfgpu.proppant.engine_seam.SubLoop's force_x, beta_z, ...); after a scatter, these cell channels
#: (the fields of hfgpu.proppant.particle_ops_numpy.CellMoments)
FACE_OUT = dict(force=F_FORCE, beta=F_BETA)
CELL_OUT = dict(volume_fraction=THETA, solid_volume=M_VOLUME, mass=M_MASS, mean_u=MEAN_U, mean_v=MEAN_V,
                velocity_variance=VARIANCE, sauter_radius=SAUTER, own_volume=M_OWN, own_volume_x=M_OWN_X,
                own_volume_z=M_OWN_Z)
_FACE_CHANNELS, _CELL_CHANNELS = tuple(FACE_OUT.values()), tuple(CELL_OUT.values())  # read_channels' static tuples

F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
F2 = ti.types.ndarray(dtype=ti.f64, ndim=2)
F3 = ti.types.ndarray(dtype=ti.f64, ndim=3)
F4 = ti.types.ndarray(dtype=ti.f64, ndim=4)
L1 = ti.types.ndarray(dtype=ti.i64, ndim=1)
I2 = ti.types.ndarray(dtype=ti.i32, ndim=2)


@ti.func
def block_sum(BS: ti.template(), row: ti.template(), blocks: ti.i32, ST: ti.template(), slot: ti.template()):
    """ST[slot] += BS[row, 0] + BS[row, 1] + ... in block order (serial: the same sum on every run; for the few
    private blocks of the CPU; a GPU's many blocks reduce with atomics in their pass)."""
    ti.loop_config(serialize=True)
    for b in range(blocks):
        ST[slot] += BS[row, b]


@ti.func
def block_max(BS: ti.template(), row: ti.template(), blocks: ti.i32, ST: ti.template(), slot: ti.template()):
    """ST[slot] = max(0, BS[row, 0], BS[row, 1], ...)."""
    ST[slot] = 0.0
    ti.loop_config(serialize=True)
    for b in range(blocks):
        ST[slot] = ti.max(ST[slot], BS[row, b])


@ti.kernel
def set_grid(width: F2, outlets: I2, C: F3, XF: F3, ZF: F3, FLAGS: I2, PR: F1):
    """A new width field (and the outlet cells) from the host: masks, face widths, stencil flags."""
    grid.set_cells(width, outlets, C)
    grid.set_faces(width, XF, 1)
    grid.set_faces(width, ZF, 0)
    grid.flags_pass(C, FLAGS, PR)


@ti.kernel
def begin_step(P: F2, S: I2, P2: F2, S2: I2, keys: L1, counts: L1, n: ti.i32, stable: ti.template(),
               u: F2, v: F2, pressure: F2, C: F3, XF: F3, ZF: F3, PR: F1, ST: F1):
    """The accepted parcels P, S sorted by cell into the work buffer P2, S2 without those that left (their
    count in ST[ST_LIVE]); the fluid of the step's start (u, v, pressure: NUMPY, from the host's solver)."""
    store.counting_sort(P, S, P2, S2, keys, counts, n, C.shape[1], C.shape[2], stable, PR, ST)
    grid.load_faces(u, pressure, XF, PR[P_DX], 1)
    grid.load_faces(v, pressure, ZF, PR[P_DZ], 0)
    grid.load_pressure(pressure, C)


@ti.kernel
def substep(P: F2, S: I2, W: F2, C: F3, XF: F3, ZF: F3, FLAGS: I2, CD: F4, XD: F4, ZD: F4, BS: F2, PR: F1,
            ST: F1, n: ti.i32, blocks: ti.i32, copies: ti.i32, private: ti.template(), h: ti.f64, step: ti.i32,
            substeps: ti.f64):
    """One particle sub-step of length h (the ``step``-th of ``substeps``): scatter (Eq. 38) -> cell fields
    (theta_p, tau, damping, flags) -> the bed's overburden friction and slope loads (one thread per column) ->
    stress gradients -> gather (Eq. 40-41) -> push (Eq. 43-44) -> exchange (Eq. 39) with the outlets and the
    finiteness check -> face means of F and beta over the sub-loop."""
    if step == 0:
        ST[ST_OUTFLOW] = 0.0
        ST[ST_LEFT] = 0.0
        ST[ST_BAD_STEP] = NO_BAD
        ST[ST_BAD_PARCEL] = NO_BAD
    grid.zero_copies(CD, copies, MOMENT_COUNT)
    grid.zero_copies(XD, copies, 2)
    grid.zero_copies(ZD, copies, 2)
    particles.scatter_pass(P, S, n, C, FLAGS, CD, BS, blocks, private, PR, ST)
    grid.finish_cells(C, CD, copies, PR)
    grid.flags_pass(C, FLAGS, PR)
    grid.bed_pass(C, PR)
    grid.stress_gradient(C, XF, PR[P_DX], 1)
    grid.stress_gradient(C, ZF, PR[P_DZ], 0)
    particles.gather_pass(P, S, W, n, C, XF, ZF, FLAGS, PR, step == 0)
    particles.push_pass(P, S, W, n, C, FLAGS, h, PR)
    ST[ST_SPEED] = 0.0
    particles.exchange_pass(P, S, W, n, C, XF, ZF, XD, ZD, BS, blocks, private, PR, ST, step)
    grid.finish_faces(C, XF, XD, copies, substeps, step == 0, PR, 1)
    grid.finish_faces(C, ZF, ZD, copies, substeps, step == 0, PR, 0)
    if ti.static(private):
        block_sum(BS, 1, blocks, ST, ST_OUTFLOW)
        block_max(BS, 2, blocks, ST, ST_SPEED)


@ti.kernel
def moments(P: F2, S: I2, C: F3, FLAGS: I2, CD: F4, BS: F2, PR: F1, ST: F1, n: ti.i32, blocks: ti.i32,
            copies: ti.i32, private: ti.template()):
    """The cell moments and fields of the parcels as they are (scatter, Eq. 38), the solid volume in the domain
    (ST[ST_VOLUME]) and the largest parcel speed (ST[ST_SPEED])."""
    ST[ST_VOLUME] = 0.0
    ST[ST_SPEED] = 0.0
    grid.zero_copies(CD, copies, MOMENT_COUNT)
    particles.scatter_pass(P, S, n, C, FLAGS, CD, BS, blocks, private, PR, ST)
    grid.finish_cells(C, CD, copies, PR)
    grid.flags_pass(C, FLAGS, PR)
    if ti.static(private):
        block_sum(BS, 0, blocks, ST, ST_VOLUME)
        block_max(BS, 2, blocks, ST, ST_SPEED)


@ti.kernel
def append(P: F2, S: I2, n: ti.i32, values: F2, ints: I2):
    """New parcels (values, ints: NUMPY) at columns n, n + 1, ..."""
    store.append(P, S, n, values, ints)


@ti.kernel
def copy_parcels(P: F2, S: I2, P2: F2, S2: I2, n: ti.i32):
    """The first n parcels into another buffer (a larger one when the capacity grows)."""
    store.copy_parcels(P, S, P2, S2, n)


@ti.kernel
def read_parcels(P: F2, S: I2, values: F2, ints: I2):
    """The first values.shape[1] parcels into the host's arrays (values, ints: NUMPY)."""
    for j, p in values:
        values[j, p] = P[j, p]
    for j, p in ints:
        ints[j, p] = S[j, p]


@ti.kernel
def read_stats(ST: F1, stats: F1):
    """The reports into the host's copy (stats: NUMPY)."""
    for j in ST:
        stats[j] = ST[j]


@ti.func
def read_channels(G: ti.template(), channels: ti.template(), out: ti.template()):
    """out[j] = G[channels[j]] for each listed channel (a static tuple), over the grid of G."""
    for k, i in ti.ndrange((0, G.shape[1]), (0, G.shape[2])):
        for j in ti.static(range(len(channels))):
            out[j, k, i] = G[channels[j], k, i]


@ti.kernel
def read_faces(XF: F3, ZF: F3, ST: F1, xfaces: F3, zfaces: F3, stats: F1):
    """The sub-loop's face means F and beta (FACE_OUT) and the reports into the host's copies (xfaces, zfaces,
    stats: NUMPY)."""
    read_channels(XF, _FACE_CHANNELS, xfaces)
    read_channels(ZF, _FACE_CHANNELS, zfaces)
    for j in ST:
        stats[j] = ST[j]


@ti.kernel
def read_cells(C: F3, ST: F1, cells: F3, stats: F1):
    """The cell moments the host uses (CELL_OUT) and the reports into the host's copies (cells, stats: NUMPY)."""
    read_channels(C, _CELL_CHANNELS, cells)
    for j in ST:
        stats[j] = ST[j]
