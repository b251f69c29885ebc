"""Finite-volume lubrication (Eq. 22-24, discretised as Eq. 29) on the active cells of a uniform grid.

Poiseuille flow between the crack faces, q = -w^3/mu' grad p (mu' = 12 mu), conserved cell by cell: the
flux through the face between active cells P and E is

    T_PE (p_E - p_P),   T_PE = (w_P + w_E)^3 / (8 mu') * (face length / centre distance),

i.e. the face opening is the arithmetic mean of the two cells (Eq. 29); with a slurry (fracture/slurry.py) mu'
is the face's, mu' r_PE with r_PE = (r_P + r_E) / 2 the mean of the two cells' viscosity ratios. Faces
towards inactive cells carry no flux, and so do faces of closed cells (w <= 0: the positive part of w enters the conductance, smoothed
over a width delta much smaller than the opening, 1e-3 of the largest, so Newton sees no kink). ``Faces`` holds the face list of the active set; ``divergence_matrix`` assembles the sparse
operator L(w) with (L p)_P = sum_faces T_PE (p_E - p_P), so that volume is conserved exactly: the columns
of L sum to zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse


@dataclass(frozen=True)
class Faces:
    """Interior faces of the active set: cell indices ``a``, ``b`` (into the active list) and the
    geometric factor ``g`` = face length / (8 mu' centre distance) of each face."""

    a: np.ndarray
    b: np.ndarray
    g: np.ndarray


def build_faces(ix: np.ndarray, iz: np.ndarray, dx: float, dz: float, mu_prime: float,
                ratio: np.ndarray | None = None) -> Faces:
    """Faces between 4-neighbouring active cells (ix, iz): x-faces get dz/dx, z-faces dx/dz (Eq. 29); with
    ``ratio`` (each active cell's mu_eff / mu), mu' of a face is mu' (r_a + r_b) / 2."""
    index = {(int(i), int(k)): n for n, (i, k) in enumerate(zip(ix, iz))}
    a, b, g = [], [], []
    for n, (i, k) in enumerate(zip(ix.tolist(), iz.tolist())):
        east = index.get((i + 1, k))
        if east is not None:
            a.append(n), b.append(east), g.append(dz / dx)
        south = index.get((i, k + 1))
        if south is not None:
            a.append(n), b.append(south), g.append(dx / dz)
    a, b = np.array(a, dtype=np.int64), np.array(b, dtype=np.int64)
    mu_face = mu_prime if ratio is None else mu_prime * 0.5 * (ratio[a] + ratio[b])
    return Faces(a, b, np.array(g, dtype=float) / (8.0 * mu_face))


def positive_part(w: np.ndarray, delta: float) -> tuple[np.ndarray, np.ndarray]:
    """Smoothed max(w, 0) = (w + sqrt(w^2 + delta^2)) / 2 and its derivative (delta = 0: the plain max)."""
    if delta == 0.0:
        return np.maximum(w, 0.0), (w > 0.0).astype(float)
    root = np.sqrt(w * w + delta * delta)
    return 0.5 * (w + root), 0.5 * (1.0 + w / root)


def conductance(faces: Faces, w: np.ndarray, delta: float = 0.0):
    """T = g (w+_a + w+_b)^3 of each face (w+ the smoothed positive part: a closed cell conducts nothing)
    and the derivatives dT/dw_a, dT/dw_b."""
    wp, dwp = positive_part(w, delta)
    s = wp[faces.a] + wp[faces.b]
    ds = 3.0 * faces.g * s**2
    return faces.g * s**3, ds * dwp[faces.a], ds * dwp[faces.b]


def divergence_matrix(faces: Faces, t: np.ndarray, n: int) -> scipy.sparse.csr_matrix:
    """Sparse L with (L p)_P = sum over faces of T (p_neighbour - p_P): net inflow rate into each cell."""
    rows = np.concatenate([faces.a, faces.b, faces.a, faces.b])
    cols = np.concatenate([faces.b, faces.a, faces.a, faces.b])
    vals = np.concatenate([t, t, -t, -t])
    return scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(n, n))


def net_inflow(faces: Faces, t: np.ndarray, p: np.ndarray) -> np.ndarray:
    """L p of ``divergence_matrix`` without assembling L: each face's T (p_b - p_a) added to cell a and taken
    from cell b."""
    flux = t * (p[faces.b] - p[faces.a])
    return np.bincount(faces.a, flux, p.size) - np.bincount(faces.b, flux, p.size)


def face_fluxes(faces: Faces, w: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Volume rate through each face from b to a, T (p_b - p_a) [m^3/s] (Eq. 23)."""
    t = conductance(faces, w)[0]
    return t * (p[faces.b] - p[faces.a])
