"""Carter leak-off (Eq. 29's C'/sqrt(t - tau) term), integrated exactly over a time step.

The leak-off velocity through both faces of an element that opened at time tau is q_L = C'/sqrt(t - tau)
with C' = 2 C_L (Carter 1957; the convention of PyFrac and Dontsov 2016). Over a
step [t0, t1] the volume per unit area is the exact integral

    int_{max(t0, tau)}^{t1} C'/sqrt(t - tau) dt = 2 C' (sqrt(t1 - tau) - sqrt(max(t0, tau) - tau)).

A cell cannot leak fluid it does not hold: the Carter demand is multiplied by a smooth ramp
``available_fraction(w) = 1 - exp(-w / w_eps)`` of the end-of-step width, with w_eps a fraction
(``leakoff_width_fraction``, default 0.01) of the step's demand per unit area (at least 1e-2 of the
largest width, which keeps the ramp smooth where the demand is tiny): the ramp is 1 to within
exp(-5) once the cell keeps 5 % of its step's demand, and 0 for an empty cell, so a cell's width never goes
negative; scaling w_eps with the demand keeps the ramp's slope (1/fraction) and so Newton's conditioning
bounded. The volume actually leaked is what the balance records, so the volume balance stays exact.

Leak-off clock (``carter_demand``). Carter's law is the filtrate-controlled rate q_L = 2 C'^2 / V_L of a
face that has let through V_L = 2 C' sqrt(t - tau) per unit area (the filter cake and invaded zone grow with
the filtrate volume; Carter 1957, Howard & Fast 1957). A cell whose ramp held its leak-off below the demand
(it was opened ahead of the fluid and stayed dry) has let through less, so it continues from the exposure
time u0 at which Carter's cumulative volume equals what it actually leaked, V_L(u0) = leaked, instead of
from t0 - tau: the dry part of its history does not count as exposure. A cell that always leaked its full
demand has u0 = t0 - tau and the step's volume is the exact integral above.
"""

from __future__ import annotations

import numpy as np

BISECTIONS = 64


def carter_cumulative(c_prime: np.ndarray, u: np.ndarray, span: np.ndarray) -> np.ndarray:
    """Volume per unit area leaked by exposure time u (Eq. 29 integrated from the opening): 2 C' sqrt(u)
    where span = 0; with the opening time spread uniformly over [0, span] across the cell (partially filled
    tip cells), the exact cell mean 2 C' (2/3) [u_+^(3/2) - (u - span)_+^(3/2)] / span."""
    c_prime, u, span = (np.asarray(a, dtype=float) for a in (c_prime, u, span))
    spread = span > 0.0
    safe = np.where(spread, span, 1.0)
    mean = (4.0 / 3.0) * c_prime * (np.maximum(u, 0.0) ** 1.5 - np.maximum(u - safe, 0.0) ** 1.5) / safe
    return np.where(spread, mean, 2.0 * c_prime * np.sqrt(np.maximum(u, 0.0)))


def exposure_time(c_prime: np.ndarray, leaked: np.ndarray, span: np.ndarray) -> np.ndarray:
    """The inverse of :func:`carter_cumulative`: the exposure time u at which Carter's cumulative volume per
    unit area is ``leaked``. Closed form where span = 0, (leaked / 2 C')^2, and where the whole cell is not
    yet reached (u <= span), (3 span leaked / 4 C')^(2/3); bisection on [span, span + (leaked / 2 C')^2]
    (the cumulative is at least 2 C' sqrt(u - span)) otherwise."""
    c_prime, leaked, span = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (c_prime, leaked, span)))
    leaked = np.maximum(leaked, 0.0)
    ratio = leaked / (2.0 * c_prime)
    u = np.where(span > 0.0, (1.5 * span * ratio) ** (2.0 / 3.0), ratio**2)
    late = (span > 0.0) & (u > span)
    if late.any():
        c, v, s = c_prime[late], leaked[late], span[late]
        lo, hi = s, s + ratio[late] ** 2
        for _ in range(BISECTIONS):
            mid = 0.5 * (lo + hi)
            below = carter_cumulative(c, mid, s) < v
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        u[late] = 0.5 * (lo + hi)
    return u


def _span(tau: np.ndarray, filled: np.ndarray | None) -> np.ndarray:
    """Time the front takes to cross each cell (partially filled tip cells: filled - tau, >= 0); 0 without."""
    return np.zeros_like(tau) if filled is None else np.maximum(np.asarray(filled, dtype=float) - tau, 0.0)


def carter_volume(c_prime: np.ndarray, tau: np.ndarray, t0: float, t1: float,
                  filled: np.ndarray | None = None) -> np.ndarray:
    """Leaked volume per unit area over [t0, t1]: 2 C' (sqrt(t1 - tau) - sqrt(max(t0, tau) - tau)) (Eq. 29).

    With ``filled`` (partially filled tip cells), the front crosses the cell between tau and ``filled``:
    the opening time is spread uniformly over the cell's area, tau(x) in [tau, filled], and the cell-mean
    is the exact average of Eq. 29's integral over it (:func:`carter_cumulative`).
    """
    tau = np.asarray(tau, dtype=float)
    span = _span(tau, filled)
    return np.where(t1 > tau, carter_cumulative(c_prime, t1 - tau, span)
                    - carter_cumulative(c_prime, np.maximum(t0, tau) - tau, span), 0.0)


def carter_demand(c_prime: np.ndarray, tau: np.ndarray, leaked: np.ndarray, t0: float, t1: float,
                  filled: np.ndarray | None = None) -> np.ndarray:
    """Carter volume per unit area over [t0, t1] of cells that have leaked ``leaked`` per unit area since
    they opened (the leak-off clock, module docstring): V_L(u0 + t1 - max(t0, tau)) - V_L(u0) with
    u0 = min(t0 - tau, exposure_time(leaked)) and V_L = :func:`carter_cumulative`; equal to
    :func:`carter_volume` for a cell that leaked its full demand so far."""
    c_prime, tau, leaked = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (c_prime, tau, leaked)))
    span = _span(tau, filled)
    elapsed = np.maximum(t0 - tau, 0.0)
    u0 = elapsed.copy()
    short = leaked < carter_cumulative(c_prime, elapsed, span)   # the ramp held some demand back (C' > 0)
    u0[short] = np.minimum(exposure_time(c_prime[short], leaked[short], span[short]), elapsed[short])
    u1 = u0 + np.maximum(t1 - np.maximum(t0, tau), 0.0)
    return carter_cumulative(c_prime, u1, span) - carter_cumulative(c_prime, u0, span)


def available_fraction(w: np.ndarray, w_eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Ramp g(w) = 1 - exp(-w / w_eps) limiting leak-off to fluid present, and its derivative g'(w).

    Continued linearly, g = w / w_eps, for w < 0 (where Newton iterates may stray), so it never overflows.
    """
    x = np.asarray(w, dtype=float) / w_eps
    e = np.exp(-np.maximum(x, 0.0))
    return np.where(x >= 0.0, 1.0 - e, x), np.where(x >= 0.0, e, 1.0) / w_eps
