"""Fixed-grid front tracking (Eq. 33-35): tip asymptotes, element activation, tip speeds, time step.

Front advance. An inactive cell next to the fracture opens when the width of its active 4-neighbour (the
tip element) says the front has reached their shared edge, at distance s = h/2 from the tip element's
centre (h = dx or dz). The paper uses Olson's criterion (Eq. 33), 0.806 w = K'/E' s^(1/2), i.e. the
linear-elastic (toughness) tip asymptote with Olson's (1991) correction of the constant-DD tip width.
On its own that asymptote says "propagate" for almost any width when K' is small (viscosity-dominated
growth), so the default ``tip_asymptote = "km"`` uses the larger of the toughness asymptote and the
viscosity (M-vertex) asymptote of Desroches et al. (1994), w = beta_m (mu' V / E')^(1/3) s^(2/3),
beta_m = 2^(1/3) 3^(5/6) (Dontsov 2016): a cheap envelope of the universal K-M asymptote of Dontsov &
Peirce (2015), exact at both ends. Olson's 0.806 multiplies the toughness term only: it was derived for
the s^(1/2) profile of constant-DD tip elements, not for the s^(2/3) viscous one. ``tip_asymptote =
"universal"`` uses that universal asymptote itself (tip_universal.py), with Carter's leak-off C' = 2 C_L of
the tip element as a third process (K, M and M~ vertices and the transitions between them) and the same
Olson correction of the toughness (K'/0.806 in place of K'), so it equals "km" at the K and M vertices and
is wider in between (docs/presets.md has the measurements). V is the fluid velocity through
the tip element's inner face towards the candidate cell (at the tip, fluid and front move together), or
with ``tip_velocity = "front"`` at least the mean front speed h / (t - t_reached) through the tip element.
Leak-off needs no extra rule: a new cell's Carter demand keeps it nearly empty until the inflow exceeds it
(with ``partial_tip_cells`` the demand follows the wetted part of the cell, and with ``leakoff_clock`` the
time a cell stays dry does not count as Carter exposure, see simulator.py). Opened cells
never close, so the front cannot retreat.

Sub-grid front. The same asymptote, inverted at the cells on the fracture's edge, locates the front
inside the grid: the front summary (views.front_extents) takes, for each edge cell, its centre's distance from the
injection point plus the inverted distance s (capped at one cell), which measures the radius of a radial
fracture more finely than whole cells, and the extents up/down/left/right the same way.

Tip speeds and time step. A cell opened at time t from a parent tip element opened at t_P records
V_T = d / (t - t_P) (Eq. 34), d the centre distance; the next step is dt = lambda min(dx, dz) / max V_T
(Eq. 35) over the cells opened most recently.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import tip_universal
from .tip_universal import m_scale

OLSON = 0.806

# (row shift, column shift) of the four neighbours: +x, -x, +z, -z.
DIRECTIONS = ((0, 1), (0, -1), (1, 0), (-1, 0))


@dataclass(frozen=True)
class TipModel:
    """Material constants of the tip asymptote: E', mu' = 12 mu, the asymptote's name and the tip-velocity
    estimate (``tip_velocity``)."""

    e_prime: float
    mu_prime: float
    mode: str  # "olson", "km" or "universal"
    velocity: str = "fluid"  # "fluid" or "front" (see tip_velocity)


def tip_width(model: TipModel, k_prime: np.ndarray, c_prime: np.ndarray, s: np.ndarray,
              v: np.ndarray) -> np.ndarray:
    """Cell width that puts the front at distance s: Eq. 33, 0.806 w = K'/E' s^(1/2), or with "km" the
    larger of that and w = beta_m (mu' V / E')^(1/3) s^(2/3) (M-vertex asymptote), or with "universal" the
    universal asymptote of K'/0.806, mu' V and C' (tip_universal.width)."""
    if model.mode == "universal":
        return tip_universal.width(s, model.e_prime, k_prime / OLSON, c_prime, model.mu_prime,
                                   np.maximum(v, 0.0))
    w = k_prime / model.e_prime * np.sqrt(s) / OLSON
    if model.mode == "km":
        w = np.maximum(w, m_scale(model.e_prime, model.mu_prime, np.maximum(v, 0.0)) * s ** (2 / 3))
    return w


def invert_tip(model: TipModel, k_prime: np.ndarray, c_prime: np.ndarray, w: np.ndarray,
               v: np.ndarray) -> np.ndarray:
    """Distance s from a cell centre to the front implied by its width w: the inverse of ``tip_width``."""
    w = np.maximum(w, 0.0)
    if model.mode == "universal":
        return tip_universal.distance(w, model.e_prime, k_prime / OLSON, c_prime, model.mu_prime,
                                      np.maximum(v, 0.0))
    with np.errstate(divide="ignore"):
        s = np.where(k_prime > 0.0, (OLSON * w * model.e_prime / np.where(k_prime > 0, k_prime, 1.0)) ** 2,
                     np.inf)
        if model.mode == "km":
            scale = m_scale(model.e_prime, model.mu_prime, np.maximum(v, 0.0))
            s = np.minimum(s, np.where(scale > 0.0, (w / np.where(scale > 0, scale, 1.0)) ** 1.5, np.inf))
    return s


def tip_velocity(model: TipModel, v_fluid: np.ndarray, h: float, t: float, reached: np.ndarray) -> np.ndarray:
    """Velocity V of the viscous tip asymptote: the fluid velocity through the tip element's inner face, or
    with ``velocity = "front"`` at least the mean front speed since the front reached the tip element,
    h / (t - t_reached) (Eq. 34's V_T: the front must cross the element to open the next cell)."""
    if model.velocity == "fluid":
        return v_fluid
    with np.errstate(invalid="ignore"):
        v_front = h / np.maximum(t - reached, 1e-300)
    return np.fmax(v_fluid, np.where(np.isfinite(reached), v_front, 0.0))


def shift(a: np.ndarray, dk: int, di: int, fill) -> np.ndarray:
    """b[k, i] = a[k - dk, i - di]: every cell's neighbour on the -(dk, di) side, ``fill`` outside the box
    (the neighbour access of the front rules, the level set and the footprint, on whole box arrays)."""
    out = np.full_like(a, fill)
    nz, nx = a.shape
    out[max(dk, 0):nz + min(dk, 0), max(di, 0):nx + min(di, 0)] = \
        a[max(-dk, 0):nz + min(-dk, 0), max(-di, 0):nx + min(-di, 0)]
    return out


def inflow_velocity(active: np.ndarray, w: np.ndarray, p: np.ndarray, h: float, dk: int, di: int,
                    mu_prime: float) -> np.ndarray:
    """Mean fluid velocity through each cell's face on the -(dk, di) side, positive along (dk, di):
    v = (w_a + w_b)^2 / (4 mu') (p_a - p_b) / h (Poiseuille, Eq. 23); 0 where either cell is inactive."""
    w_in = shift(w, dk, di, 0.0)
    p_in = shift(p, dk, di, 0.0)
    both = active & shift(active, dk, di, False)
    v = (np.maximum(w_in, 0) + np.maximum(w, 0)) ** 2 / (4.0 * mu_prime) * (p_in - p) / h
    return np.where(both, np.maximum(v, 0.0), 0.0)


def tip_faces(model: TipModel, active: np.ndarray, w: np.ndarray, p: np.ndarray, reached: np.ndarray, t: float,
              dx: float, dz: float, box_edge: bool) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """For each of DIRECTIONS, the active cells whose neighbour on that side is inactive (or, with
    ``box_edge``, outside the box); and, over all of them in that order, the distance h/2 from their centre
    to that face and the tip velocity V of ``tip_velocity`` through their opposite face (one asymptote
    evaluation for the four directions)."""
    masks, half, vel = [], [], []
    for dk, di in DIRECTIONS:
        h = dz if dk else dx
        mask = active & ~shift(active, -dk, -di, not box_edge)
        v = tip_velocity(model, inflow_velocity(active, w, p, h, dk, di, model.mu_prime), h, t, reached)
        masks.append(mask)
        half.append(np.full(int(mask.sum()), 0.5 * h))
        vel.append(v[mask])
    return masks, np.concatenate(half), np.concatenate(vel)


def split_by_direction(values: np.ndarray, masks: list[np.ndarray]) -> list[np.ndarray]:
    """Split values gathered over ``masks`` (in order, as ``tip_faces`` gathers them) back into one array per
    mask, so that one asymptote evaluation serves the four directions."""
    return np.split(values, np.cumsum([int(m.sum()) for m in masks])[:-1])


def cells_to_open(model: TipModel, active: np.ndarray, w: np.ndarray, p: np.ndarray, k_prime: np.ndarray,
                  c_prime: np.ndarray, reached: np.ndarray, t: float, dx: float, dz: float,
                  blocked: np.ndarray | None = None):
    """Inactive cells whose tip element satisfies the front criterion (Eq. 33) at s = h/2; with ``blocked``
    (bridged slurry, fracture/slurry.py) neither a blocked tip element opens a cell nor a blocked cell opens.

    Returns a boolean mask of cells to open and their tip speeds V_T = d / (t - t_parent) (Eq. 34), the
    fastest over the triggering parents (NaN where nothing opens). ``reached`` holds the times the front
    reached each cell; ``k_prime`` and ``c_prime`` are K' and C' at every cell.
    """
    masks, half, vel = tip_faces(model, active, w, p, reached, t, dx, dz, box_edge=False)
    w_tip = tip_width(model, np.concatenate([k_prime[m] for m in masks]),
                      np.concatenate([c_prime[m] for m in masks]), half, vel)
    to_open = np.zeros_like(active)
    speed = np.full(active.shape, np.nan)
    for (dk, di), tips, w_dir in zip(DIRECTIONS, masks, split_by_direction(w_tip, masks)):
        h = dz if dk else dx
        ok = np.zeros_like(active)
        ok[tips] = w[tips] >= w_dir
        if blocked is not None:
            ok &= ~blocked
        # candidate = the cell on the (dk, di) side of a triggering tip element
        cand = shift(ok, dk, di, False) & ~active
        parent_time = shift(reached, dk, di, np.nan)
        vt = h / np.maximum(t - parent_time, 1e-300)
        speed = np.where(cand, np.fmax(speed, vt), speed)
        to_open |= cand
    if blocked is not None:
        to_open &= ~blocked
        speed = np.where(to_open, speed, np.nan)
    return to_open, speed


def edge_cells(active: np.ndarray) -> np.ndarray:
    """Active cells with at least one inactive 4-neighbour."""
    edge = np.zeros_like(active)
    for dk, di in DIRECTIONS:
        edge |= active & ~shift(active, dk, di, False)
    return edge


def front_distances(model: TipModel, active: np.ndarray, w: np.ndarray, p: np.ndarray, k_prime: np.ndarray,
                    c_prime: np.ndarray, reached: np.ndarray, t: float, dx: float,
                    dz: float) -> list[np.ndarray]:
    """Sub-grid front position: for each of DIRECTIONS, the distance s from every active cell's centre to the
    front on that side (the inverse of ``tip_width`` at the cell's width, Eq. 33) where the neighbour on that
    side is inactive, NaN elsewhere. V is the tip velocity of ``tip_velocity`` through the opposite face."""
    masks, _, vel = tip_faces(model, active, w, p, reached, t, dx, dz, box_edge=True)
    s_all = invert_tip(model, np.concatenate([k_prime[m] for m in masks]),
                       np.concatenate([c_prime[m] for m in masks]), np.concatenate([w[m] for m in masks]), vel)
    out = []
    for facing, s_dir in zip(masks, split_by_direction(s_all, masks)):
        s = np.full(w.shape, np.nan)
        s[facing] = s_dir
        out.append(s)
    return out
