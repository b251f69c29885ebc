"""Averaging: the volume fraction theta_p a parcel sees (the hindrance of its drag, Eq. 14, and the scale of the
packing limiter), by name as in OpenFOAM's MPPIC AveragingMethods (OpenFOAM Foundation 2013, src/lagrangian/
intermediate/submodels/MPPIC/AveragingMethods: Basic, Dual, Moment); NumPy reference and Taichi twin.

- "dual": the bilinear deposit onto the cell centres (Eq. 38) read back bilinearly (Eq. 40): the nodes of the
  deposit are the cell centres, the dual mesh of the cells. Smooth, but a parcel sees its neighbours' cells.
- "basic": the own cell's volume fraction from the parcels it holds (nearest grid point),
  theta = S / (dx dz w), S = sum over the cell's parcels of n V_p.
- "moment": the linear function over the own cell with the same zeroth and first moments as the volume of the
  parcels in it,

      theta(o) = max(0, S + 12 (S_x o_x + S_z o_z)) / (dx dz w),   S_x = sum n V_p o_x,p,  S_z likewise,

  o = ((x - x_c) / dx, (z - z_c) / dz) in [-1/2, 1/2]^2 the offset from the cell centre (a uniform density over
  the cell has second moment 1/12 along each axis: a density theta (1 + c o) has mean offset c / 12).

Why a choice: at the top of a settling suspension the interface lies inside a cell. With "dual" the parcels
just under it see a theta_p mixed with the clear fluid above, settle faster than the suspension below them and
pile up under the interface; the excess grows with time. The same happens in the continuum: a settling speed
that depends on the concentration averaged over a neighbourhood (the nonlocal sedimentation model of Betancourt,
Bürger, Karlsen & Tory 2011, Nonlinearity 24, 855) gives solutions with oscillations next to the discontinuities
(Chalons, Goatin & Villada 2018, SIAM J. Sci. Comput. 40, A288). With "moment" the parcels, which sit in the
lower part of the interface cell, see the fraction of the part they fill (docs/proppant-closures.md,
"Averaging", measures both).
"""

from __future__ import annotations

import numpy as np

from hfgpu.kernels.closures.twin import ti

#: The averaging methods by name (``[mppic] averaging``); the kernels take the index.
AVERAGINGS = ("dual", "basic", "moment")


def own_cell_fraction_numpy(volume, volume_x, volume_z, offset_x, offset_z, cell_volume, moment):
    """theta_p at offsets (offset_x, offset_z) of the own cell from its sums S, S_x, S_z [m^3] and volume dx dz w
    [m^3] (module docstring): "basic" (moment false) or "moment"; 0 in a closed cell (cell_volume 0)."""
    volume = np.asarray(volume, dtype=np.float64)
    value = volume + 12.0 * (np.asarray(volume_x) * offset_x + np.asarray(volume_z) * offset_z) if moment \
        else volume
    cell_volume = np.asarray(cell_volume, dtype=np.float64)
    return np.divide(np.maximum(value, 0.0), cell_volume, out=np.zeros(np.broadcast(value, cell_volume).shape),
                     where=cell_volume > 0.0)


@ti.func
def own_cell_fraction(volume: ti.f64, volume_x: ti.f64, volume_z: ti.f64, offset_x: ti.f64, offset_z: ti.f64,
                      cell_volume: ti.f64, moment: ti.i32) -> ti.f64:
    """Taichi twin of own_cell_fraction_numpy for one parcel."""
    value = volume
    if moment:
        value = volume + 12.0 * (volume_x * offset_x + volume_z * offset_z)
    out = 0.0
    if cell_volume > 0.0:
        out = ti.max(value, 0.0) / cell_volume
    return out
