"""Bilinear particle-grid weights on the staggered grid (the paper, Eq. 36-37; Snider 2001), NumPy reference of
kernels/stencil.py's ``owner`` and ``bilinear``: the node sets, active nodes and renormalisation are described
in hfgpu.proppant.interpolation, which builds the masks (active_nodes, deposit_masks) these weights take.

``frame`` is any object with the grid origin and spacing x0, z0, dx, dz [m] (hfgpu.records.GridFrame); a
point's cell coordinates are s = (x - x0) / dx (minus the node set's offset, OFFSETS).
"""

import numpy as np

#: offset of node [0, 0] from the centre of cell [0, 0], in cells (x, z)
OFFSETS = {"cell": (0.0, 0.0), "xface": (-0.5, 0.0), "zface": (0.0, -0.5)}


def owning_cell(x, z, frame, shape: tuple[int, int]):
    """(k, i, inside) of the cell containing each point; k, i are clipped into the grid."""
    nz, nx = shape
    i = np.floor((x - frame.x0) / frame.dx + 0.5).astype(np.int64)
    k = np.floor((z - frame.z0) / frame.dz + 0.5).astype(np.int64)
    inside = (i >= 0) & (i < nx) & (k >= 0) & (k < nz)
    return np.clip(k, 0, nz - 1), np.clip(i, 0, nx - 1), inside


def weights(x, z, frame, location: str, mask: np.ndarray):
    """Renormalised bilinear weights (Eq. 36-37) of points (x, z) onto the active nodes of ``location``.

    Returns (k, i, w), each (N, 4): node rows/columns (clipped into the grid) and weights summing to 1 per
    point, or to 0 where no node of the 2 x 2 stencil is active. ``mask`` is the node activity array.
    """
    ox, oz = OFFSETS[location]
    nz, nx = mask.shape
    sx = (np.asarray(x) - frame.x0) / frame.dx - ox
    sz = (np.asarray(z) - frame.z0) / frame.dz - oz
    i0 = np.floor(sx)
    k0 = np.floor(sz)
    fx = sx - i0
    fz = sz - k0
    i0 = i0.astype(np.int64)
    k0 = k0.astype(np.int64)
    kk = np.stack([k0, k0, k0 + 1, k0 + 1], axis=1)
    ii = np.stack([i0, i0 + 1, i0, i0 + 1], axis=1)
    w = np.stack([(1 - fz) * (1 - fx), (1 - fz) * fx, fz * (1 - fx), fz * fx], axis=1)
    inside = (kk >= 0) & (kk < nz) & (ii >= 0) & (ii < nx)
    kk = np.clip(kk, 0, nz - 1)
    ii = np.clip(ii, 0, nx - 1)
    w = np.where(inside, w * mask[kk, ii], 0.0)
    total = w.sum(axis=1, keepdims=True)
    w = np.divide(w, total, out=np.zeros_like(w), where=total > 0.0)
    return kk, ii, w
