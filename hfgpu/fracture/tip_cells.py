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
d = 0 with normal grad d; a tip cell holds the tip asymptote w_a(-d) behind it, so its wetted fraction is
the exact area behind the plane (``wetted_fraction``) and its mean width the cell average of w_a(max(-d, 0))
over QUADRATURE x QUADRATURE midpoints (``fill_and_width``).
Here ``advance`` = -d at a cell's centre: how far the front is past the centre (negative: not yet there).

Two-term ribbon fit (``ribbon_fit = "two_term"``, the default). The tip asymptote w_a(s) is the first term of
the width's expansion near the front; a finite fracture adds a relative correction linear in s (the K vertex,
w ~ sqrt(2 R s) (1 - s / (4 R)); the M vertex of Savitski & Detournay 2002 likewise), so the asymptote alone,
inverted at a ribbon 1-2 cells behind the front, puts the front short of it by O((h / R)^2): at 10 cells per
radius of the exact M-vertex profile (one dimension) -0.36 % of R from a ribbon 1 cell behind the front and
-0.84 % from 1.5 cells. The fit takes w(sigma) = w_a(sigma) (1 + b sigma) through the ribbon (width w_1 at
sigma = s) and its channel neighbour one cell further in along the axis nearer the front normal n (w_2 at
sigma = s + Delta, Delta = h |n_axis|, n = -grad w / |grad w| by central differences), b eliminated:

    G(s) = w_2 / w_a(s + Delta) - 1 - (s + Delta) / s (w_1 / w_a(s) - 1) = 0,

with the asymptote's V the ribbon's (at least (s - s_0) / dt, as the one-term distance). Its root, by the
Illinois method on ln s (tip_universal.increasing_root) inside [s_1 / 2, 2 s_1] (s_1: the one-term distance),
places the front from the exact M-vertex widths at the cell centres of a 10-cells-per-radius grid within
+0.11 % of R on average (worst +0.21 %), against -0.44 % (worst -0.79 %) from the asymptote alone
(tests/fracture/test_subgrid_front.py). A ribbon whose bracket holds no root, whose inner neighbour is not a
channel cell or not wider, or whose correction |b (s + Delta)| exceeds FIT_MAX_CORRECTION keeps s_1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .front import OLSON, TipModel, invert_tip, shift, split_by_direction, tip_faces, tip_width
from .tip_universal import increasing_root

QUADRATURE = 8
_OFFSETS = (np.arange(QUADRATURE) + 0.5) / QUADRATURE - 0.5
LAYERS = 3   # cells marched out from the ribbons: the front may cross cells within a step (max_front_advance)
FIT_MAX_CORRECTION = 0.5     # the largest |b (s + Delta)| the fit may apply
RIBBON_FITS = ("two_term", "asymptote")


def ribbon_distances(model: TipModel, channel: np.ndarray, w: np.ndarray, p: np.ndarray, k_prime: np.ndarray,
                     c_prime: np.ndarray, reached: np.ndarray, t: float, dx: float, dz: float,
                     start: tuple[np.ndarray, float] | None = None, fit: str = "two_term"):
    """(s, V): at every ribbon cell the distance s from its centre to the front (front.invert_tip with K'
    itself) and the tip velocity V of the viscous asymptote, the fastest of ``front.tip_velocity`` over the
    sides the cell faces non-channel cells; NaN elsewhere. With ``start`` = (s_0, dt), the ribbons' distances
    at the step's start (NaN: unknown) and the step, V is at least the front's own speed over the step,
    V = max(V, (s - s_0) / dt) (as PyFrac's ILSA; ``_implicit_distance``): on an iterate whose inflow velocity
    is ~0 at some ribbon, V alone let the viscous asymptote put the front tens of cells out in a short step.
    ``fit``: "two_term" refines s by the two-term fit of the module docstring (``_two_term_distance``),
    "asymptote" keeps the asymptote's inverse."""
    if fit not in RIBBON_FITS:
        raise ValueError(f"ribbon_distances: fit = {fit!r}; must be one of {RIBBON_FITS}")
    masks, _, vel = tip_faces(model, channel, w, p, reached, t, dx, dz, box_edge=False)
    v = np.full(w.shape, np.nan)
    for mask, v_dir in zip(masks, split_by_direction(vel, masks)):
        v[mask] = np.fmax(v[mask], v_dir)
    ribbon = np.isfinite(v)
    s = np.full(w.shape, np.nan)
    args = (model, k_prime[ribbon] * OLSON, c_prime[ribbon], w[ribbon])
    v_fluid = v[ribbon]
    s[ribbon] = invert_tip(*args, v_fluid)
    s_0, dt = (np.full(w.shape, np.nan), 1.0) if start is None else start
    if start is not None:
        s[ribbon], v[ribbon] = _implicit_distance(args, s[ribbon], v_fluid, s_0[ribbon], dt)
    if fit == "two_term":
        s[ribbon], v[ribbon] = _two_term_distance(channel, w, ribbon, args, s[ribbon], v[ribbon], v_fluid,
                                                  s_0[ribbon], dt, dx, dz)
    return s, v


def _two_term_distance(channel: np.ndarray, w: np.ndarray, ribbon: np.ndarray, args: tuple, s_1: np.ndarray,
                       v_1: np.ndarray, v_fluid: np.ndarray, s_0: np.ndarray, dt: float, dx: float,
                       dz: float) -> tuple[np.ndarray, np.ndarray]:
    """(s, V) of the ribbons (in the order of ``ribbon``) by the two-term fit of the module docstring; ``args``
    (model, K', C', w) at the ribbons as for front.invert_tip; s_1, v_1 the one-term distance and speed, kept
    where the fit does not apply."""
    k, i = np.nonzero(ribbon)
    padded = np.pad(w, 1)   # the width gradient at the ribbons, by central differences
    gx = (padded[k + 1, i + 2] - padded[k + 1, i]) / (2.0 * dx)
    gz = (padded[k + 2, i + 1] - padded[k, i + 1]) / (2.0 * dz)
    along_x = np.abs(gx) >= np.abs(gz)
    # the inner neighbour: one cell up the width gradient along the axis nearer the normal
    ki = np.clip(np.where(along_x, k, k + np.sign(gz).astype(int)), 0, w.shape[0] - 1)
    ii = np.clip(np.where(along_x, i + np.sign(gx).astype(int), i), 0, w.shape[1] - 1)
    norm = np.hypot(gx, gz)
    delta = np.where(along_x, dx * np.abs(gx), dz * np.abs(gz)) / np.where(norm > 0.0, norm, 1.0)
    model, k_prime, c_prime, w_1 = args
    w_2 = w[ki, ii]
    fits = (norm > 0.0) & channel[ki, ii] & ((ki != k) | (ii != i)) & (w_2 > w_1) & (s_1 > 0.0) & np.isfinite(s_1)
    s, v = s_1.copy(), v_1.copy()
    at = np.flatnonzero(fits)
    fit = _TwoTerm(model, k_prime[at], c_prime[at], w_1[at], w_2[at], delta[at], v_fluid[at], s_0[at], dt)
    lo, hi = 0.5 * s_1[at], 2.0 * s_1[at]
    g_lo, g_hi = fit.gap(lo)[0], fit.gap(hi)[0]
    bracketed = np.sign(g_lo) != np.sign(g_hi)   # (NaN never differs)
    at, fit = at[bracketed], fit.subset(bracketed)
    rising = np.sign(g_hi[bracketed])   # G's orientation over each bracket
    root = increasing_root(lambda x: rising * fit.gap(x)[0], lo[bracketed], hi[bracketed])
    _, b, speed = fit.gap(root)
    good = np.abs(b * (root + fit.delta)) <= FIT_MAX_CORRECTION
    s[at[good]], v[at[good]] = root[good], speed[good]
    return s, v


@dataclass(frozen=True)
class _TwoTerm:
    """The two-term fit's data at the ribbons it applies to (``_two_term_distance``)."""

    model: TipModel
    k_prime: np.ndarray
    c_prime: np.ndarray
    w_1: np.ndarray
    w_2: np.ndarray
    delta: np.ndarray
    v_fluid: np.ndarray
    s_0: np.ndarray
    dt: float

    def subset(self, keep: np.ndarray) -> "_TwoTerm":
        return _TwoTerm(self.model, *(getattr(self, name)[keep] for name in
                                      ("k_prime", "c_prime", "w_1", "w_2", "delta", "v_fluid", "s_0")), self.dt)

    def gap(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(G(s) of the module docstring, b, V) at ribbon distances s."""
        known = np.isfinite(self.s_0)
        speed = np.where(known, np.fmax(self.v_fluid, (s - np.where(known, self.s_0, 0.0)) / self.dt), self.v_fluid)
        b = (self.w_1 / tip_width(self.model, self.k_prime, self.c_prime, s, speed) - 1.0) / s
        far = tip_width(self.model, self.k_prime, self.c_prime, s + self.delta, speed)
        return self.w_2 / far - 1.0 - b * (s + self.delta), b, speed


def _implicit_distance(args: tuple, s: np.ndarray, v: np.ndarray, s_0: np.ndarray,
                       dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(s, V) of ``ribbon_distances`` with V = max(v, (s - s_0) / dt): where s (at speed v) lies beyond
    s_0 + v dt, the root of invert_tip(w, (s - s_0) / dt) = s between s_0 + v dt and s (the inverse falls as V
    rises, so the root is unique), by tip_universal.increasing_root in the advance a = s - s_0 (Illinois on
    ln a, where the inverse is close to a power law); unchanged elsewhere."""
    fast = np.isfinite(s_0) & (s > s_0 + v * dt)
    if not fast.any():
        return s, v
    base, span = s_0[fast], s[fast] - s_0[fast]
    sub = tuple(a[fast] for a in args[1:])

    def excess(a):   # increasing in the advance a
        return base + a - invert_tip(args[0], *sub, a / dt)

    lo = np.maximum(v[fast] * dt, 1e-12 * span)
    advance = np.clip(increasing_root(excess, lo, span), lo, span)
    s, v = s.copy(), v.copy()
    s[fast] = base + advance
    v[fast] = advance / dt
    return s, v


def _eikonal_layer(d: np.ndarray, frozen: np.ndarray, dx: float, dz: float):
    """One layer of the eikonal update (module docstring): for every cell outside ``frozen`` whose d is not
    known yet (inf) and that has a known 4-neighbour, (d, grad d = unit normal, flat index of the neighbour the
    update leans on: the x- or z-neighbour with the smaller d); inf / NaN / -1 elsewhere."""
    flat = np.arange(d.size).reshape(d.shape)
    best = {}
    for axis, (dk, di) in (("x", (0, 1)), ("x", (0, -1)), ("z", (1, 0)), ("z", (-1, 0))):
        near = shift(d, dk, di, np.inf)      # d of the neighbour on the -(dk, di) side
        src = shift(flat, dk, di, -1)
        sign = float(dk + di)                 # the direction from that neighbour to the cell
        a, a_src, a_sign = best.get(axis, (np.full(d.shape, np.inf), np.full(d.shape, -1), np.zeros(d.shape)))
        take = near < a
        best[axis] = (np.where(take, near, a), np.where(take, src, a_src), np.where(take, sign, a_sign))
    (a, src_a, sign_a), (b, src_b, sign_b) = best["x"], best["z"]
    cand = ~frozen & np.isinf(d) & (np.isfinite(a) | np.isfinite(b))
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
    dist = np.where(cand, np.where(good, root, np.where(via_x, a + dx, b + dz)), np.inf)
    gx = np.where(good, (dist - a_f) / dx, np.where(via_x, 1.0, 0.0)) * sign_a
    gz = np.where(good, (dist - b_f) / dz, np.where(via_x, 0.0, 1.0)) * sign_b
    with np.errstate(invalid="ignore", divide="ignore"):
        norm = np.hypot(gx, gz)
        nx, nz = np.where(cand, gx / norm, np.nan), np.where(cand, gz / norm, np.nan)
    lean = np.where(cand, np.where(good & (b < a) | ~good & ~via_x, src_b, src_a), -1)
    return dist, nx, nz, lean


def level_set(s: np.ndarray, channel: np.ndarray, dx: float, dz: float, layers: int = LAYERS):
    """(advance, nx, nz, source): for the non-channel cells up to ``layers`` cells out from the ribbons, -d at
    their centres from the eikonal update (module docstring, marched outward one layer at a time) with
    d = -s at the ribbons, the unit normal of the front (grad d, pointing out of the fracture) and the flat
    index of the ribbon cell the update leans on (through the layers: whose K', C' and V the tip asymptote
    uses); NaN / -1 elsewhere."""
    d = np.where(np.isfinite(s), -s, np.inf)
    source = np.where(np.isfinite(s), np.arange(d.size).reshape(d.shape), -1)
    out, nx, nz = (np.full(d.shape, np.nan) for _ in range(3))
    for _ in range(layers):
        dist, lx, lz, lean = _eikonal_layer(d, channel, dx, dz)
        new = np.isfinite(dist)
        if not new.any():
            break
        d[new], out[new], nx[new], nz[new] = dist[new], -dist[new], lx[new], lz[new]
        source[new] = source.ravel()[lean[new]]
    source[np.isnan(out)] = -1
    return out, nx, nz, source


def _spread(nx: np.ndarray, nz: np.ndarray, dx: float, dz: float):
    """Widths P = |n_x| dx, Q = |n_z| dz of the two uniform variables whose sum is n.(x - x_c) over the cell
    (each at least 1e-7 of the cell: a front along the grid then errs by 1e-7 relative)."""
    floor = 1e-7 * min(dx, dz)
    return np.maximum(np.abs(nx) * dx, floor), np.maximum(np.abs(nz) * dz, floor)


def wetted_fraction(advance: np.ndarray, nx: np.ndarray, nz: np.ndarray, dx: float, dz: float) -> np.ndarray:
    """Exact part of a dx x dz cell behind the plane front d(x) = -advance + n.(x - x_c), the area where
    sigma = n.(x - x_c) < advance: the distribution function of sigma, the sum of two uniform variables of
    widths P and Q (``_spread``), a piecewise quadratic in y = advance + (P + Q)/2,

        f = [y+^2 - (y - P)+^2 - (y - Q)+^2 + (y - P - Q)+^2] / (2 P Q).

    It is exactly 0 before the cell's nearest corner and 1 past the farthest."""
    p, q = _spread(nx, nz, dx, dz)
    y = advance + 0.5 * (p + q)
    g = lambda u: np.maximum(u, 0.0) ** 2
    f = np.clip((g(y) - g(y - p) - g(y - q) + g(y - p - q)) / (2.0 * p * q), 0.0, 1.0)
    return np.where(y >= p + q, 1.0, np.where(y <= 0.0, 0.0, f))


def advance_for_fill(fill: np.ndarray, nx: np.ndarray, nz: np.ndarray, dx: float, dz: float,
                     iterations: int = 64) -> np.ndarray:
    """The inverse of ``wetted_fraction``: the advance at which a cell with front normal n is wetted by
    ``fill`` in (0, 1]. f rises monotonically from 0 at advance -(P + Q)/2 to 1 at +(P + Q)/2; bisection
    on that bracket to round-off."""
    p, q = _spread(nx, nz, dx, dz)
    lo, hi = -0.5 * (p + q), 0.5 * (p + q)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        short = wetted_fraction(mid, nx, nz, dx, dz) < fill
        lo, hi = np.where(short, mid, lo), np.where(short, hi, mid)
    return 0.5 * (lo + hi)


def fill_and_width(model: TipModel, advance: np.ndarray, nx: np.ndarray, nz: np.ndarray, k_prime: np.ndarray,
                   c_prime: np.ndarray, v: np.ndarray, dx: float, dz: float) -> tuple[np.ndarray, np.ndarray]:
    """Wetted fraction (``wetted_fraction``) and mean width of cells crossed by the plane front
    d(x) = -advance + n.(x - x_c): the cell average of the tip asymptote w_a(-d) (front.tip_width with K'
    itself) over QUADRATURE^2 midpoints, 0 outside the front (1-D arrays, one entry per cell). A cell wetted
    short of its nearest midpoint gets its wetted fraction times w_a at a third of the front's distance past
    the nearest corner (the depth of a corner triangle's centroid) instead of 0: a pinned cell of zero width
    between dry neighbours would leave its pressure undetermined."""
    ox, oz = np.meshgrid(_OFFSETS * dx, _OFFSETS * dz)
    d = -advance[:, None] + nx[:, None] * ox.ravel()[None, :] + nz[:, None] * oz.ravel()[None, :]
    inside = d < 0.0
    n = d.shape[1]
    k_olson = k_prime * OLSON
    wa = tip_width(model, np.repeat(k_olson, n), np.repeat(c_prime, n), np.maximum(-d, 0.0).ravel(),
                   np.repeat(v, n)).reshape(d.shape)
    fill = wetted_fraction(advance, nx, nz, dx, dz)
    width = np.where(inside, wa, 0.0).mean(axis=1)
    corner = advance + 0.5 * (np.abs(nx) * dx + np.abs(nz) * dz)
    first = fill * tip_width(model, k_olson, c_prime, np.maximum(corner, 0.0) / 3.0, v)
    return fill, np.where(inside.any(axis=1), width, first)
