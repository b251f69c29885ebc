"""Walls of a parcel's move (Eq. 44): what stops a move, NumPy reference and Taichi twin.

A move (x, z) -> (x', z') of a parcel is blocked (cancelled, and that velocity component set to 0: an inelastic
stop; the push applies the rules per component, x first, then z) where it
  - leaves the grid;
  - enters a closed cell (width <= 0);
  - enters another cell narrower than the parcel's bridging width, w < gap = bridging_factor x 2 r: the grain
    bridges at the mouth of an aperture it cannot pass, so proppant never reaches the narrow tip region of a
    growing fracture (inside such a cell a point parcel would put theta_p = V_s / (w dx dz) above close
    packing);
  - raises the parcel's bilinear weight (Eq. 37) on a cell whose theta_p (Eq. 38, this step's scatter) is
    already >= theta_cp: the packing cap. Snider's limiter (particle_stress) bounds the velocity relative to
    the cell's mean parcel velocity, which does not stop a stream of parcels that arrives together against a
    wall; the cap bounds every cell's theta_p by theta_cp plus one step's inflow, whatever the velocities.
    With ``own`` (bed_slope), a cell is judged without the parcel's own deposit, theta_p - I_old n V_p / (dx dz
    w) (I_old its weight on that cell before the move): the grains of a cliff sitting at their column's face
    made their own cells packed and could never slide off (docs/validation.md, "Angle of repose");
  - heads for a wall (domain edge or closed cell) within the half cell next to it while its own cell is dense,
    theta_p >= dense (friction_volume_fraction: a contact network, as for bed friction). There the bilinear
    weights no longer change (the wall's node is inactive), so the move changes no grid field: neither the
    packing cap nor the particle stress (Eq. 16) can see or resist the grains piling up against the wall. In
    a contact network the grains between the parcel and the wall (its mirror image, a cell as dense) carry
    it; in a loose cell it settles through.

NumPy reference (hfgpu.proppant.particle_ops_numpy.push): blocked_numpy, toward_wall_dense_numpy, on float64
arrays of positions [m] with the grid's ``frame`` (any object with x0, z0, dx, dz: hfgpu.records.GridFrame).
Taichi twin (kernels/particles.py ``move``): blocked, toward_wall_dense, packed_near, packed_gain, on a
parcel's cell coordinates s = (x - x0) / dx and the engine's cell channels ``cells`` (kernels.layout:
cells[WIDTH, k, i], cells[CELL, k, i], cells[THETA, k, i]).
"""

from __future__ import annotations

import numpy as np

from hfgpu.kernels.closures.twin import Deferred, ti
from hfgpu.kernels.layout import CELL, THETA, WIDTH
from hfgpu.kernels.stencil_numpy import owning_cell, weights

stencil = Deferred("hfgpu.kernels.stencil")


def blocked_numpy(x, z, x_try, z_try, frame, width, cell_mask, volume_fraction, theta_cp, dense, gap,
                  own=None):
    """True where the move (x, z) -> (x_try, z_try) leaves the grid, enters a closed cell, enters another cell
    narrower than ``gap`` (the parcel's bridging width, bridging_factor x 2 r), raises the bilinear weight
    (Eq. 37) of the parcel on a cell whose theta_p (``volume_fraction``, this step's scatter) is already
    >= theta_cp (less the parcel's own deposit where ``own``, its solid volume n V_p [m^3], is given), or heads
    for a wall from a cell with theta_p >= ``dense`` (toward_wall_dense_numpy); module docstring. ``width``,
    ``cell_mask`` (the active cell nodes) and ``volume_fraction`` are (nz, nx)."""
    k, i, inside = owning_cell(x_try, z_try, frame, width.shape)
    k_old, i_old, _ = owning_cell(x, z, frame, width.shape)
    narrow = ((k != k_old) | (i != i_old)) & (width[k, i] < gap)
    k0, i0, w0 = weights(x, z, frame, "cell", cell_mask)
    k1, i1, w1 = weights(x_try, z_try, frame, "cell", cell_mask)
    same = (k1[:, :, None] == k0[:, None, :]) & (i1[:, :, None] == i0[:, None, :])
    before = np.sum(w0[:, None, :] * same, axis=2)
    theta = volume_fraction[k1, i1]
    if own is not None:
        theta = theta - before * (own / (frame.dx * frame.dz))[:, None] / np.where(width[k1, i1] > 0.0,
                                                                                  width[k1, i1], 1.0)
    packed = theta >= theta_cp
    return ~inside | (width[k, i] <= 0.0) | narrow | np.any(packed & (w1 > before), axis=1) \
        | toward_wall_dense_numpy(x, z, x_try, z_try, frame, width, volume_fraction, dense)


def toward_wall_dense_numpy(x, z, x_try, z_try, frame, width, volume_fraction, dense):
    """True where a parcel in the half cell next to a wall (domain edge or closed cell) moves towards it while
    its own cell is dense, theta_p >= ``dense`` (friction_volume_fraction: a contact network, as for bed
    friction). There the bilinear weights of Eq. 37 no longer change (the wall's node is inactive), so the move
    changes no grid field: neither the packing cap nor the particle stress (Eq. 16) can see or resist the
    grains piling up against the wall, and the stress gradient the parcel reads is that of the face on its other
    side. In a contact network the grains between the parcel and the wall (its mirror image, a cell as dense)
    carry it; in a loose cell it settles through."""
    nz, nx = width.shape
    k, i, inside = owning_cell(x, z, frame, (nz, nx))
    own_dense = inside & (volume_fraction[k, i] >= dense)
    out = np.zeros(x.shape, dtype=bool)
    for pos, new, origin, step, along_x in ((x, x_try, frame.x0, frame.dx, True),
                                            (z, z_try, frame.z0, frame.dz, False)):
        f = (pos - origin) / step - (i if along_x else k)
        moves_out = (np.abs((new - origin) / step - (i if along_x else k)) > np.abs(f)) & (f * (new - pos) > 0)
        side = np.where(f >= 0.0, 1, -1)
        kn, in_ = (k, i + side) if along_x else (k + side, i)
        beyond = (kn < 0) | (kn >= nz) | (in_ < 0) | (in_ >= nx)
        wall = beyond | (width[np.clip(kn, 0, nz - 1), np.clip(in_, 0, nx - 1)] <= 0.0)
        out |= own_dense & moves_out & wall
    return out


@ti.func
def blocked(sx: ti.f64, sz: ti.f64, sxn: ti.f64, szn: ti.f64, cells: ti.template(), theta_cp: ti.f64,
            dense: ti.f64, gap: ti.f64, own: ti.f64) -> ti.i32:
    """The move (sx, sz) -> (sxn, szn) (cell coordinates) leaves the grid, enters a closed cell, enters another
    cell narrower than ``gap`` (the parcel's bridging width, bridging_factor x 2 r), raises the parcel's bilinear
    weight on a cell with theta_p >= theta_cp (less own x its old weight there / the cell's width: ``own`` = n V_p
    / (dx dz) [m] with bed_slope, else 0), or heads for a wall from a cell with theta_p >= dense
    (friction_volume_fraction; blocked_numpy)."""
    out = 1
    width = stencil.owner_width(sxn, szn, cells)
    if width > 0.0:
        out = 0
        if width < gap:
            k0, i0 = stencil.owner(sx, sz)
            k1, i1 = stencil.owner(sxn, szn)
            if k0 != k1 or i0 != i1:
                out = 1
        if out == 0 and packed_near(sxn, szn, cells, theta_cp):
            out = packed_gain(sx, sz, sxn, szn, cells, theta_cp, own)
        if out == 0:
            out = toward_wall_dense(sx, sz, sxn, szn, cells, dense)
    return out


@ti.func
def toward_wall_dense(sx: ti.f64, sz: ti.f64, sxn: ti.f64, szn: ti.f64, cells: ti.template(),
                      dense: ti.f64) -> ti.i32:
    """The parcel's own cell has theta_p >= dense and it moves, within the half cell next to a wall (domain
    edge or closed cell), towards that wall (toward_wall_dense_numpy). The sign of the move is
    that of sxn - sx: cell coordinates are monotone in x, and differ wherever the move counts."""
    out = 0
    k, i = stencil.owner(sx, sz)
    if k >= 0 and k < cells.shape[1] and i >= 0 and i < cells.shape[2]:
        if cells[THETA, k, i] >= dense:
            fx = sx - i
            fz = sz - k
            if ti.abs(sxn - i) > ti.abs(fx) and fx * (sxn - sx) > 0.0:
                out = stencil.closed(k, i + (1 if fx >= 0.0 else -1), cells)
            if ti.abs(szn - k) > ti.abs(fz) and fz * (szn - sz) > 0.0:
                out = out | stencil.closed(k + (1 if fz >= 0.0 else -1), i, cells)
    return out


@ti.func
def packed_near(sx: ti.f64, sz: ti.f64, cells: ti.template(), theta_cp: ti.f64) -> ti.i32:
    """Whether a cell of the 2 x 2 cell stencil of (sx, sz) has theta_p >= theta_cp (fast path of blocked)."""
    i0 = ti.cast(ti.floor(sx), ti.i32)
    k0 = ti.cast(ti.floor(sz), ti.i32)
    found = 0
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if k0 + a >= 0 and k0 + a < cells.shape[1] and i0 + b >= 0 and i0 + b < cells.shape[2]:
                if cells[THETA, k0 + a, i0 + b] >= theta_cp:
                    found = 1
    return found


@ti.func
def packed_gain(sx: ti.f64, sz: ti.f64, sxn: ti.f64, szn: ti.f64, cells: ti.template(), theta_cp: ti.f64,
                own: ti.f64) -> ti.i32:
    """Whether the move raises the parcel's bilinear weight on a cell with theta_p - own x its old weight there
    / the cell's width >= theta_cp (blocked)."""
    out = 0
    k0, i0, w0 = stencil.bilinear(sx, sz, cells, CELL, False)
    k1, i1, w1 = stencil.bilinear(sxn, szn, cells, CELL, False)
    for a in ti.static(range(2)):
        for b in ti.static(range(2)):
            if w1[2 * a + b] > 0.0:
                if cells[THETA, k1 + a, i1 + b] >= theta_cp:
                    before = 0.0
                    for c in ti.static(range(2)):
                        for d in ti.static(range(2)):
                            if k0 + c == k1 + a and i0 + d == i1 + b:
                                before += w0[2 * c + d]
                    theta = cells[THETA, k1 + a, i1 + b]
                    if own > 0.0:
                        theta = theta - before * own / cells[WIDTH, k1 + a, i1 + b]
                    if w1[2 * a + b] > before and theta >= theta_cp:
                        out = 1
    return out
