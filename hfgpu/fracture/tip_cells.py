"""Sub-grid front on the fixed grid (``front_tracking = "subgrid"``): ribbon distances, level set, tip cells.

The implicit level-set algorithm of Peirce & Detournay (2008) (also Dontsov & Peirce 2017, PyFrac) in its
simplest form. Cells are channel cells (fully behind the front, width unknown) or tip cells (the front
crosses them). A ribbon cell is a channel cell next to a non-channel cell; the tip asymptote inverted at
its width (front.invert_tip, without Olson's constant-DD correction: a ribbon cell is not a tip element)
gives its distance s to the front, i.e. the level set (signed distance, negative inside) d_R = -s. The
level set at the cells next to the ribbons follows from the eikonal equation |grad d| = 1 with the
first-order upwind update of fast marching (Sethian 1996):

    (d - a)^2 / dx^2 + (d - b)^2 / dz^2 = 1,   a, b the smallest d of the x- and z-neighbours,

(d = a + dx or b + dz where only one is known or the root falls below max(a, b)). The front is the plane
d = 0 with normal grad d; a tip cell holds the tip asymptote w_a(-d) behind it, so its wetted fraction and
mean width are the cell averages of [d < 0] and w_a(max(-d, 0)) over QUADRATURE x QUADRATURE points.
Here ``advance`` = -d at a cell's centre: how far the front is past the centre (negative: not yet there).
"""

from __future__ import annotations

import numpy as np

from .front import OLSON, TipModel, _per_direction, _shift, _tip_cells, invert_tip, tip_width

QUADRATURE = 8
_OFFSETS = (np.arange(QUADRATURE) + 0.5) / QUADRATURE - 0.5


def ribbon_distances(model: TipModel, channel: np.ndarray, w: np.ndarray, p: np.ndarray, k_prime: np.ndarray,
                     c_prime: np.ndarray, reached: np.ndarray, t: float, dx: float, dz: float):
    """(s, V): at every ribbon cell the distance s from its centre to the front (front.invert_tip with K'
    itself) and the tip velocity V used (the fastest of ``front.tip_velocity`` over the sides it faces
    non-channel cells); NaN elsewhere."""
    masks, _, vel = _tip_cells(model, channel, w, p, reached, t, dx, dz, box_edge=False)
    v = np.full(w.shape, np.nan)
    for mask, v_dir in zip(masks, _per_direction(vel, masks)):
        v[mask] = np.fmax(v[mask], v_dir)
    ribbon = np.isfinite(v)
    s = np.full(w.shape, np.nan)
    s[ribbon] = invert_tip(model, k_prime[ribbon] * OLSON, c_prime[ribbon], w[ribbon], v[ribbon])
    return s, v


def level_set(s: np.ndarray, channel: np.ndarray, dx: float, dz: float):
    """(advance, nx, nz, source): for every non-channel cell next to a ribbon, -d at its centre from the
    eikonal update (module docstring) with d = -s at the ribbons, the unit normal of the front (grad d,
    pointing out of the fracture) and the flat index of the ribbon neighbour with the smallest d (whose
    K', C' and V the tip asymptote uses); NaN / -1 elsewhere."""
    d = np.where(np.isfinite(s), -s, np.inf)
    flat = np.arange(d.size).reshape(d.shape)
    best = {}
    for axis, (dk, di) in (("x", (0, 1)), ("x", (0, -1)), ("z", (1, 0)), ("z", (-1, 0))):
        near = _shift(d, dk, di, np.inf)      # d of the neighbour on the -(dk, di) side
        src = _shift(flat, dk, di, -1)
        sign = float(dk + di)                 # the direction from that neighbour to the cell
        a, a_src, a_sign = best.get(axis, (np.full(d.shape, np.inf), np.full(d.shape, -1), np.zeros(d.shape)))
        take = near < a
        best[axis] = (np.where(take, near, a), np.where(take, src, a_src), np.where(take, sign, a_sign))
    (a, src_a, sign_a), (b, src_b, sign_b) = best["x"], best["z"]
    cand = ~channel & (np.isfinite(a) | np.isfinite(b))
    out = np.full(d.shape, np.nan)
    a_f, b_f = np.where(np.isfinite(a), a, 0.0), np.where(np.isfinite(b), b, 0.0)
    both = np.isfinite(a) & np.isfinite(b)
    # (d - a)^2 / dx^2 + (d - b)^2 / dz^2 = 1, larger root
    qa = 1.0 / dx**2 + 1.0 / dz**2
    qb = -2.0 * (a_f / dx**2 + b_f / dz**2)
    qc = a_f**2 / dx**2 + b_f**2 / dz**2 - 1.0
    disc = qb**2 - 4.0 * qa * qc
    with np.errstate(invalid="ignore"):
        root = (-qb + np.sqrt(np.where(disc >= 0.0, disc, np.nan))) / (2.0 * qa)
    via_x = np.where(np.isfinite(a), a + dx, np.inf) <= np.where(np.isfinite(b), b + dz, np.inf)
    good = both & np.isfinite(root) & (root >= np.maximum(a_f, b_f))
    dist = np.where(good, root, np.where(via_x, a + dx, b + dz))
    out[cand] = -dist[cand]
    gx = np.where(good, (dist - a_f) / dx, np.where(via_x, 1.0, 0.0)) * sign_a
    gz = np.where(good, (dist - b_f) / dz, np.where(via_x, 0.0, 1.0)) * sign_b
    with np.errstate(invalid="ignore", divide="ignore"):
        norm = np.hypot(gx, gz)
        nx, nz = gx / norm, gz / norm
    source = np.where(good & (b < a) | ~good & ~via_x, src_b, src_a)
    nx[~cand], nz[~cand] = np.nan, np.nan
    source[~cand] = -1
    return out, nx, nz, source


def fill_and_width(model: TipModel, advance: np.ndarray, nx: np.ndarray, nz: np.ndarray, k_prime: np.ndarray,
                   c_prime: np.ndarray, v: np.ndarray, dx: float, dz: float) -> tuple[np.ndarray, np.ndarray]:
    """Wetted fraction and mean width of cells crossed by the plane front d(x) = -advance + n.(x - x_c):
    the averages of [d < 0] and of the tip asymptote w_a(-d) (front.tip_width with K' itself) over
    QUADRATURE^2 points of the cell (1-D arrays, one entry per cell)."""
    ox, oz = np.meshgrid(_OFFSETS * dx, _OFFSETS * dz)
    d = -advance[:, None] + nx[:, None] * ox.ravel()[None, :] + nz[:, None] * oz.ravel()[None, :]
    inside = d < 0.0
    n = d.shape[1]
    wa = tip_width(model, np.repeat(k_prime * OLSON, n), np.repeat(c_prime, n), np.maximum(-d, 0.0).ravel(),
                   np.repeat(v, n)).reshape(d.shape)
    return inside.mean(axis=1), np.where(inside, wa, 0.0).mean(axis=1)
