"""The fall-off after shut-in read with Nolte's G-function: G, the superposition derivative G dP/dG, the closure
pick by the tangent line, the fluid efficiency and the apparent leak-off coefficient. Pure NumPy/SciPy; SI units.

Nolte's g-function (Nolte 1979, SPE 8341; general form: Valko & Economides 1995, *Hydraulic Fracture Mechanics*,
ch. 9). A fracture whose area grew as A(t) = A_e (t / t_p)^alpha while pumping (0 <= t <= t_p) and keeps A_e after
shut-in leaks by Carter's law 2 C_L / sqrt(t - tau) (two faces) from each element opened at tau. Its leaked volume
is V_L(t) = 2 A_e C_L sqrt(t_p) g(dt_D, alpha), dt_D = (t - t_p) / t_p, with

    g(dt_D, alpha) = 2 int_0^1 sqrt(1 + dt_D - s^(1/alpha)) ds                                         (1)
                   = [4 alpha sqrt(dt_D) + 2 sqrt(1 + dt_D) 2F1(1/2, alpha; 1 + alpha; 1/(1 + dt_D))]
                     / (1 + 2 alpha)                                                                  (2)

((2) is Valko & Economides' closed form with the Gauss hypergeometric function; tests/fracture/test_falloff.py
checks it against the quadrature (1) and against the closed forms below). Particular cases:

    alpha = 1/2 (low efficiency):   g = (1 + dt_D) arcsin((1 + dt_D)^(-1/2)) + dt_D^(1/2),  g_0 = pi/2
    alpha = 1   (high efficiency):  g = (4/3) ((1 + dt_D)^(3/2) - dt_D^(3/2)),            g_0 = 4/3

(Carter-dominated growth, A ~ t^(1/2), is the low-efficiency bound; A ~ t the high-efficiency one), and
G(dt_D) = (4/pi) (g(dt_D) - g_0), g_0 = g(0), so that G(0) = 0 and the volume leaked after shut-in is
(pi/2) A_e C_L sqrt(t_p) G.

Mass balance after shut-in (Nolte 1979; Valko & Economides 1995, ch. 9): with the fracture's compliance
c_f = w_mean / p_net [m/Pa] (its stiffness S_f = 1 / c_f) and a leaking share r_p = h_p / h_f of its area, the
stored volume A_e c_f p_net falls by the leaked volume, so

    p_w(G) = p_ISIP - m G,   m = pi r_p sqrt(t_p) C_L S_f / 2,   C_L = 2 m / (pi r_p sqrt(t_p) S_f)     (3)

(:func:`leakoff_coefficient`; without spurt loss; the tests integrate Carter's law numerically for a
constant-area fracture and recover C_L from the slope). Compliances (Valko & Economides 1995, from Sneddon's
crack openings under a uniform net pressure; E' = E / (1 - nu^2)): PKN c_f = pi h_f / (2 E'), KGD
c_f = pi x_f / E', radial c_f = 16 R / (3 pi E') (:func:`fracture_stiffness`). The form
C_L = pi h_p m' / (4 sqrt(t_p) E') is (3) for a PKN fracture with h_f = h_p and r_p = 1 only when m' is the slope
against g, m' = 4 m / pi; with the slope against G it would be pi/4 too small.

Closure at G_c with no spurt: the fracture volume at shut-in is what leaks by closure, (pi/2) A_e C_L sqrt(t_p)
G_c, and what leaked while pumping is 2 A_e C_L sqrt(t_p) g_0, so the efficiency at the end of pumping is (Nolte
1979)

    eta = G_c / (4 g_0 / pi + G_c)          (alpha = 1/2: G_c / (2 + G_c); alpha = 1: G_c / (16/(3 pi) + G_c))  (4)

(with the same alpha as G; derived here from (1) and the mass balance above; G_c / (2 + G_c), the form usually
quoted, is its alpha = 1/2 value).

Superposition derivative and closure (Barree et al. 2009): G dP/dG, with dP/dG the slope of a least-squares line
through the records within +-``window`` x G of each point G (a window of constant width in log G, as for a Bourdet
derivative; at least 3 records, the nearest ones in G when the window holds fewer), sign changed so that a falling
pressure gives a positive derivative. While the fracture is open and its area constant, p is linear in G and G
dP/dG = m G, a straight line through the origin; closure is where the curve leaves that line
(:func:`closure_pick`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.special import hyp2f1

#: Default area-growth exponent of G: alpha = 1, g = (4/3)((1 + dt_D)^(3/2) - dt_D^(3/2)), the G most fall-off
#: analyses plot.
DEFAULT_ALPHA = 1.0
#: Default half-width of the derivative's fitting window, as a share of the point's G.
DEFAULT_WINDOW = 0.01
#: Default tolerance: closure where G dP/dG leaves the line by more than this share of the line.
DEFAULT_TOLERANCE = 0.05


def g_function(dtd, alpha: float = DEFAULT_ALPHA) -> np.ndarray:
    """Nolte's g(dt_D, alpha), eq. (2) of the module docstring (Valko & Economides 1995); ``dtd`` >= 0."""
    d = np.asarray(dtd, dtype=np.float64)
    if np.any(d < 0.0):
        raise ValueError("dimensionless shut-in time dt_D must be >= 0")
    if not 0.0 < alpha <= 1.0:
        raise ValueError(f"alpha must lie in (0, 1], got {alpha}")
    return (4.0 * alpha * np.sqrt(d) + 2.0 * np.sqrt(1.0 + d) * hyp2f1(0.5, alpha, 1.0 + alpha, 1.0 / (1.0 + d))) \
        / (1.0 + 2.0 * alpha)


def g0(alpha: float = DEFAULT_ALPHA) -> float:
    """g_0 = g(0, alpha) by eq. (2): pi/2 at alpha = 1/2, 4/3 at alpha = 1."""
    return float(g_function(0.0, alpha))


def G_function(dtd, alpha: float = DEFAULT_ALPHA) -> np.ndarray:  # noqa: N802 (Nolte's capital G)
    """Nolte's G(dt_D, alpha) = (4/pi) (g(dt_D, alpha) - g_0(alpha)); G(0) = 0."""
    return 4.0 / math.pi * (g_function(dtd, alpha) - g0(alpha))


def efficiency_at_closure(G_c: float, alpha: float = DEFAULT_ALPHA) -> float:  # noqa: N803
    """Fluid efficiency at the end of pumping from the closure's G, eq. (4): G_c / (4 g_0 / pi + G_c)."""
    return float(G_c / (4.0 * g0(alpha) / math.pi + G_c))


def fracture_stiffness(geometry: str, youngs_plane_strain: float, size: float) -> float:
    """S_f = 1 / c_f [Pa/m] (Valko & Economides 1995): "pkn" 2 E' / (pi h_f) (``size`` = height h_f), "kgd"
    E' / (pi x_f) (half-length x_f), "radial" 3 pi E' / (16 R) (radius R); E' = E / (1 - nu^2) [Pa]."""
    factors = {"pkn": 2.0 / math.pi, "kgd": 1.0 / math.pi, "radial": 3.0 * math.pi / 16.0}
    if geometry not in factors:
        raise ValueError(f"geometry must be one of {sorted(factors)}, got {geometry!r}")
    return factors[geometry] * youngs_plane_strain / size


def nolte_geometry(area: float, length: float, height: float) -> tuple[str, float]:
    """(geometry, size) of :func:`fracture_stiffness` for a fracture of ``area`` [m^2] (one face), ``length`` (tip
    to tip) and ``height`` [m] at shut-in: "pkn" (size: the height) when it is more than twice as long as high,
    "kgd" (size: the half-length) when more than twice as high as long, else "radial" (size: sqrt(area / pi))."""
    if length > 2.0 * height:
        return "pkn", height
    if height > 2.0 * length:
        return "kgd", 0.5 * length
    return "radial", math.sqrt(area / math.pi)


def leakoff_coefficient(slope: float, t_p: float, stiffness: float, permeable_fraction: float = 1.0) -> float:
    """Apparent Carter coefficient C_L [m/s^0.5] from the G-slope m = -dp/dG [Pa], eq. (3):
    2 m / (pi r_p sqrt(t_p) S_f)."""
    return float(2.0 * slope / (math.pi * permeable_fraction * math.sqrt(t_p) * stiffness))


def superposition_derivative(G, p, window: float = DEFAULT_WINDOW) -> np.ndarray:  # noqa: N803
    """G dP/dG with the sign changed (positive for a falling pressure): at each record, G times minus the slope of the
    least-squares line through the records with |G_j - G_i| <= ``window`` x G_i (at least the 3 nearest in G). A
    kink of p at G_c moves the derivative no earlier than (1 - ``window``) G_c. An exactly linear p = a - m G gives
    m G to round-off."""
    G, p = np.asarray(G, dtype=np.float64), np.asarray(p, dtype=np.float64)  # noqa: N806
    if G.shape != p.shape or G.ndim != 1 or G.size < 2:
        raise ValueError("G and p must be 1-D arrays of the same length, at least 2")
    n_min = min(3, G.size)
    out = np.empty_like(G)
    for i, gi in enumerate(G):
        near = np.abs(G - gi) <= window * abs(gi)
        if np.count_nonzero(near) < n_min:
            near = np.zeros(G.size, dtype=bool)
            near[np.argsort(np.abs(G - gi), kind="stable")[:n_min]] = True
        x, y = G[near], p[near]
        dx = x - x.mean()
        denominator = float(np.dot(dx, dx))
        slope = float(np.dot(dx, y - y.mean())) / denominator if denominator > 0.0 else math.nan
        out[i] = -gi * slope
    return out


@dataclass(frozen=True)
class ClosurePick:
    """Where G dP/dG leaves the line through the origin: closure's G, pressure [Pa], time [s] (None without
    times), the index of the record, the line's slope m [Pa] (G dP/dG = m G while open; for a "peak" pick the
    line's through the origin and the pick, dP/dG at closure)
    and the side it left to ("below": the derivative falls under the line, normal closure; "above"; "peak": the
    curve had no straight early part and closure is where it turns down)."""
    G: float
    pressure: float
    time: float | None
    index: int
    slope: float
    side: str


#: The straight part must hold while G grows by at least this factor (a curve that bends everywhere is straight
#: within the tolerance over a few close records).
LINE_SPAN = 2.0
#: Why no closure was picked (:attr:`FalloffAnalysis.note`).
NO_DEPARTURE = "G dP/dG stays on its straight line through the origin"
NO_LINE = "G dP/dG has no straight early part through the origin and does not turn down"
TOO_SHORT = "too few records after shut-in to pick closure"


def _pick(G, p, time, window, tolerance, skip, min_points, persist) -> tuple[ClosurePick | None, str]:  # noqa: N803
    G, p = np.asarray(G, dtype=np.float64), np.asarray(p, dtype=np.float64)  # noqa: N806
    derivative = superposition_derivative(G, p, window)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(G > 0.0, derivative / G, np.nan)
    n = G.size
    start = min(skip, max(n - min_points - persist, 0))
    if n - start < min_points + persist:
        return None, TOO_SHORT
    for j in range(start, n - min_points - persist + 1):   # the straight part may follow an early transient
        for i in range(j + min_points, n - persist + 1):
            m = float(np.median(ratio[j:i]))
            if not (math.isfinite(m) and m > 0.0) or np.any(np.abs(ratio[j:i] - m) > tolerance * m):
                break
            off = (ratio[i:i + persist] - m) / m
            if G[i - 1] >= LINE_SPAN * G[j] and (np.all(off > tolerance) or np.all(off < -tolerance)):
                k = i - 1
                return ClosurePick(G=float(G[k]), pressure=float(p[k]),
                                   time=None if time is None else float(np.asarray(time)[k]), index=k, slope=m,
                                   side="above" if off[0] > 0 else "below"), ""
        else:   # straight to the end of the record: a line, not closed; or too short a stretch for one
            if G[-1] >= LINE_SPAN * G[j]:
                return None, NO_DEPARTURE
            break
    return _peak(G, p, time, derivative, start, tolerance, persist)


def _peak(G, p, time, derivative, start, tolerance, persist) -> tuple[ClosurePick | None, str]:  # noqa: N803
    """The pick where G dP/dG has no straight early part (``closure_pick``): its largest value so far, once
    ``persist`` consecutive records after it lie more than ``tolerance`` below it (before any higher one);
    (None, NO_LINE) when it never turns down so."""
    best, below = start, 0
    for i in range(start + 1, G.size):
        if derivative[i] > derivative[best]:
            best, below = i, 0
            continue
        below = below + 1 if derivative[i] < (1.0 - tolerance) * derivative[best] else 0
        if below == persist:
            return ClosurePick(G=float(G[best]), pressure=float(p[best]),
                               time=None if time is None else float(np.asarray(time)[best]), index=best,
                               slope=float(derivative[best] / G[best]), side="peak"), ""
    return None, NO_LINE


def closure_pick(G, p, time=None, window: float = DEFAULT_WINDOW, tolerance: float = DEFAULT_TOLERANCE,  # noqa: N803
                 skip: int = 2, min_points: int = 5, persist: int = 3) -> ClosurePick | None:
    """Closure by the tangent line (Barree et al. 2009): the line through the origin G dP/dG = m G with m the
    median of (G dP/dG) / G over a run of at least ``min_points`` consecutive records that all lie within
    ``tolerance`` x m of it while G grows by at least :data:`LINE_SPAN` (the straight part; it may start after
    an early transient; the first ``skip`` records are never used, their derivative window being least sure);
    closure is the last record of the run before one whose derivative leaves the line by more than ``tolerance``
    x the line (above or below) with its next ``persist`` - 1 records off it on the same side. The earliest
    such run is taken. Where no part is straight (the fracture still extends after shut-in, so the curve bends
    from the start), closure is where G dP/dG turns down: its largest value so far, once ``persist``
    consecutive records after it lie more than ``tolerance`` below it (side "peak", its slope the line's
    through the origin and the pick: the stiffness-controlled decline ends there; our rule, for the simulated
    fall-offs of fractures that grow after shut-in). None when the curve stays on its line (not closed in the
    record), bends and never turns down (:data:`NO_LINE`), or the record is shorter than ``min_points`` +
    ``persist``."""
    return _pick(G, p, time, window, tolerance, skip, min_points, persist)[0]


@dataclass(frozen=True)
class FalloffAnalysis:
    """A fall-off read with G (:func:`falloff_analysis`); pressures in Pa, times in s. ``isip``: the BHTP of the first
    record after the pumps stop; ``t_p``: pumping time; ``alpha``, ``g0``: the G used; arrays over the records
    after the stop: ``time``, ``dtd``, ``G``, ``pressure``, ``derivative`` (G dP/dG); ``slope``: m = -dp/dG of the
    open fracture's straight line (the closure pick's line; without closure, the whole record's when it stays on
    one, else NaN); ``closure``: the :class:`ClosurePick` or None; ``closure_time`` (after the stop),
    ``closure_pressure``, ``closure_net_pressure`` (less ``sigma_min``), ``G_c``, ``efficiency`` (eq. 4) are None
    without closure; ``leakoff_coefficient`` [m/s^0.5] (eq. 3) only when a stiffness was given, ``geometry`` the
    compliance it was read with (e.g. "radial, R = 7.1 m"; empty without); ``note``: why no closure was picked
    (:data:`NO_DEPARTURE`, :data:`NO_LINE`, :data:`TOO_SHORT`), empty with one."""
    isip: float
    t_p: float
    sigma_min: float
    alpha: float
    g0: float
    time: np.ndarray = field(repr=False)
    dtd: np.ndarray = field(repr=False)
    G: np.ndarray = field(repr=False)
    pressure: np.ndarray = field(repr=False)
    derivative: np.ndarray = field(repr=False)
    slope: float
    closure: ClosurePick | None
    closure_time: float | None
    closure_pressure: float | None
    closure_net_pressure: float | None
    G_c: float | None
    efficiency: float | None
    leakoff_coefficient: float | None
    note: str = ""
    geometry: str = ""


def falloff_analysis(time, bhp, t_pump_end: float, sigma_min: float, alpha: float = DEFAULT_ALPHA,
                     window: float = DEFAULT_WINDOW, tolerance: float = DEFAULT_TOLERANCE,
                     stiffness: float | None = None, permeable_fraction: float = 1.0,
                     geometry: str = "") -> FalloffAnalysis:
    """Read the fall-off of the bottom-hole pressure ``bhp`` [Pa] at ``time`` [s] (pumping from t = 0 to
    ``t_pump_end``) with G(alpha); ``sigma_min`` [Pa] the minimum stress at the injection depth; ``stiffness``
    S_f [Pa/m] (:func:`fracture_stiffness`) for the leak-off coefficient, ``geometry`` what it is (kept as the
    analysis's label). Raises ValueError when fewer than two records follow the end of pumping."""
    time, bhp = np.asarray(time, dtype=np.float64), np.asarray(bhp, dtype=np.float64)
    if not (t_pump_end is not None and math.isfinite(t_pump_end) and t_pump_end > 0.0):
        raise ValueError("no fall-off to analyse: the run has no end of pumping")
    after = time > t_pump_end
    if np.count_nonzero(after) < 2:
        raise ValueError("no fall-off to analyse: fewer than 2 records after the pumps stop")
    t, p = time[after], bhp[after]
    dtd = (t - t_pump_end) / t_pump_end
    G = G_function(dtd, alpha)  # noqa: N806
    derivative = superposition_derivative(G, p, window)
    pick, note = _pick(G, p, t, window, tolerance, 2, 5, 3)
    if pick is not None:
        slope = pick.slope
    elif note == NO_DEPARTURE:
        slope = float(np.median(derivative[G > 0.0] / G[G > 0.0]))
    else:  # no straight line to read a slope from
        slope = math.nan
    closed = pick is not None
    leakoff = (leakoff_coefficient(slope, t_pump_end, stiffness, permeable_fraction)
               if stiffness is not None and math.isfinite(slope) else None)
    return FalloffAnalysis(isip=float(p[0]), t_p=float(t_pump_end), sigma_min=float(sigma_min), alpha=float(alpha),
                           g0=g0(alpha), time=t, dtd=dtd, G=G, pressure=p, derivative=derivative, slope=slope,
                           closure=pick, closure_time=pick.time - t_pump_end if closed else None,
                           closure_pressure=pick.pressure if closed else None,
                           closure_net_pressure=pick.pressure - sigma_min if closed else None,
                           G_c=pick.G if closed else None,
                           efficiency=efficiency_at_closure(pick.G, alpha) if closed else None,
                           leakoff_coefficient=leakoff, note=note, geometry=geometry if leakoff is not None else "")
