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

The fluid velocity is read on more nodes (:func:`velocity_nodes`): the active faces and the walls, the faces
with an open cell on one side only (domain edges, closed cells), where the normal velocity is the boundary
condition 0. A parcel between the last active face and a wall so sees the normal velocity fall linearly to
zero at the wall, as the fluid's own flux does. Read on the active faces only, it would see the last face's
value up to the wall: the parcels near a wall would cross a face the fluid does not cross, and the volume
fraction they deposit would change where the fluid's is held, at a rate theta_p u / dx. In a settling column
with side walls that change drives a flow along the walls whose density difference drives it further; the
measurement is in docs/proppant-closures.md ("Walls in the gather"). Along a wall (the tangential velocity)
the stencil's nodes beyond the wall lie outside the grid and the renormalisation gives the free-slip value,
as the fluid's viscous stress at walls is free-slip.

The weights and the owning cell of a point are hfgpu.kernels.stencil_numpy's (weights, owning_cell); here are
the node masks they take and the sums over them.
"""

from __future__ import annotations

import numpy as np


def active_nodes(width: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(cell (nz, nx), xface (nz, nx+1), zface (nz+1, nx)) activity masks as float64 1.0 / 0.0."""
    cell = width > 0.0
    nz, nx = width.shape
    xface = np.zeros((nz, nx + 1), dtype=bool)
    xface[:, 1:nx] = cell[:, :-1] & cell[:, 1:]
    zface = np.zeros((nz + 1, nx), dtype=bool)
    zface[1:nz, :] = cell[:-1, :] & cell[1:, :]
    return cell.astype(np.float64), xface.astype(np.float64), zface.astype(np.float64)


def velocity_nodes(width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(xface (nz, nx+1), zface (nz+1, nx)) masks, float64 1.0 / 0.0, of the nodes the fluid velocity is read
    on: faces with an open cell on at least one side, the edges of the grid included (module docstring)."""
    cell = width > 0.0
    nz, nx = width.shape
    xface = np.zeros((nz, nx + 1), dtype=bool)
    xface[:, :-1] |= cell
    xface[:, 1:] |= cell
    zface = np.zeros((nz + 1, nx), dtype=bool)
    zface[:-1, :] |= cell
    zface[1:, :] |= cell
    return xface.astype(np.float64), zface.astype(np.float64)


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
    Passed to hfgpu.kernels.stencil_numpy.weights as its ``mask``, they give I_k w_k / sum_j I_j w_j, so that a
    parcel's share of node k divided by the node's volume dx dz w_k is V I_k / (dx dz sum_j I_j w_j), its
    bilinear share over the mean width of its stencil: a narrow cell beside a loaded wide one (a fracture's tip,
    a cell that just opened) gets a share like its neighbours', not w_wide / w_k times theirs. On a uniform
    width these are the plain bilinear weights of :func:`active_nodes`'s masks."""
    xface, zface = face_widths(width)
    return np.where(width > 0.0, width, 0.0), xface, zface


def interpolate(field: np.ndarray, k, i, w) -> np.ndarray:
    """Value at each point: sum of node values x weights (Eq. 40-41)."""
    return np.sum(field[k, i] * w, axis=1)


def deposit(values: np.ndarray, k, i, w, shape: tuple[int, int]) -> np.ndarray:
    """Sum of point values x weights onto the nodes (the sums of Eq. 38-39, before dividing by V)."""
    flat = (k * shape[1] + i).ravel()
    return np.bincount(flat, weights=(w * np.asarray(values)[:, None]).ravel(),
                       minlength=shape[0] * shape[1]).reshape(shape).astype(np.float64, copy=False)
