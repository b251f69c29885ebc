"""Bilinear particle-grid weights on the staggered grid (the paper, Eq. 36-37; Snider 2001).

Three node sets (shared data layout): cell centres (nz, nx) at (x0 + i dx, z0 + k dz); x-faces (nz, nx+1) at
(x0 + (i - 1/2) dx, z0 + k dz); z-faces (nz+1, nx) at (x0 + i dx, z0 + (k - 1/2) dz).

A parcel touches the 2 x 2 nodes around it with weights I = I_x I_z, I_x = 1 - |x_p - x_f| / dx (Eq. 37).
Nodes that are outside the grid or not *active* get weight 0 and the rest are renormalised to sum 1, so that
what a parcel deposits is conserved exactly and a field is never read where it is undefined. Active nodes:
open cells (width > 0); faces strictly inside the grid with an open cell on both sides (boundary faces and
faces of closed cells carry boundary conditions only: no fluid momentum is solved there, so no force is
deposited there and no gradient is defined there). A parcel whose 4 nodes are all inactive gets all-zero
weights (it deposits and reads nothing); a parcel in an open cell always has an active cell node (its own).
"""

from __future__ import annotations

import numpy as np

from ..records import GridFrame

#: offset of node [0, 0] from the centre of cell [0, 0], in cells (x, z)
OFFSETS = {"cell": (0.0, 0.0), "xface": (-0.5, 0.0), "zface": (0.0, -0.5)}


def active_nodes(width: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(cell (nz, nx), xface (nz, nx+1), zface (nz+1, nx)) activity masks as float64 1.0 / 0.0."""
    cell = width > 0.0
    nz, nx = width.shape
    xface = np.zeros((nz, nx + 1), dtype=bool)
    xface[:, 1:nx] = cell[:, :-1] & cell[:, 1:]
    zface = np.zeros((nz + 1, nx), dtype=bool)
    zface[1:nz, :] = cell[:-1, :] & cell[1:, :]
    return cell.astype(np.float64), xface.astype(np.float64), zface.astype(np.float64)


def face_widths(width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Widths at active x-faces (nz, nx+1) and z-faces (nz+1, nx): the mean of the two cells, else 0."""
    _, xmask, zmask = active_nodes(width)
    wx = np.zeros_like(xmask)
    wx[:, 1:-1] = 0.5 * (width[:, :-1] + width[:, 1:])
    wz = np.zeros_like(zmask)
    wz[1:-1, :] = 0.5 * (width[:-1, :] + width[1:, :])
    return wx * xmask, wz * zmask


def deposit_masks(width: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Node weights of the deposits (Eq. 38-39) on (cell, xface, zface): each active node's width, 0 elsewhere.
    Passed to :func:`weights` as its ``mask``, they give I_k w_k / sum_j I_j w_j, so that a parcel's share of
    node k divided by the node's volume dx dz w_k is V I_k / (dx dz sum_j I_j w_j), its bilinear share over the
    mean width of its stencil: a narrow cell beside a loaded wide one (a fracture's tip, a cell that just
    opened) gets a share like its neighbours', not w_wide / w_k times theirs. On a uniform width these are the
    plain bilinear weights of :func:`active_nodes`'s masks."""
    xface, zface = face_widths(width)
    return np.where(width > 0.0, width, 0.0), xface, zface


def owning_cell(x, z, frame: GridFrame, shape: tuple[int, int]):
    """(k, i, inside) of the cell containing each point; k, i are clipped into the grid."""
    nz, nx = shape
    i = np.floor((x - frame.x0) / frame.dx + 0.5).astype(np.int64)
    k = np.floor((z - frame.z0) / frame.dz + 0.5).astype(np.int64)
    inside = (i >= 0) & (i < nx) & (k >= 0) & (k < nz)
    return np.clip(k, 0, nz - 1), np.clip(i, 0, nx - 1), inside


def weights(x, z, frame: GridFrame, location: str, mask: np.ndarray):
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


def interpolate(field: np.ndarray, k, i, w) -> np.ndarray:
    """Value at each point: sum of node values x weights (Eq. 40-41)."""
    return np.sum(field[k, i] * w, axis=1)


def deposit(values: np.ndarray, k, i, w, shape: tuple[int, int]) -> np.ndarray:
    """Sum of point values x weights onto the nodes (the sums of Eq. 38-39, before dividing by V)."""
    flat = (k * shape[1] + i).ravel()
    return np.bincount(flat, weights=(w * np.asarray(values)[:, None]).ravel(),
                       minlength=shape[0] * shape[1]).reshape(shape).astype(np.float64, copy=False)
