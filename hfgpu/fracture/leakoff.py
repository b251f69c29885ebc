"""Carter leak-off (Eq. 29's C'/sqrt(t - tau) term), integrated exactly over a time step.

The leak-off velocity through both faces of an element that opened at time tau is q_L = C'/sqrt(t - tau)
with C' = 2 C_L (Carter 1957; the convention of PyFrac and Dontsov 2016, REFERENCE.md section 1). Over a
step [t0, t1] the volume per unit area is the exact integral

    int_{max(t0, tau)}^{t1} C'/sqrt(t - tau) dt = 2 C' (sqrt(t1 - tau) - sqrt(max(t0, tau) - tau)).

A cell cannot leak fluid it does not hold: the Carter demand is multiplied by a smooth ramp
``available_fraction(w) = 1 - exp(-w / w_eps)`` of the end-of-step width, with w_eps a fraction
(``leakoff_width_fraction``, default 0.01) of the step's demand per unit area (at least 1e-2 of the
largest width, which keeps the ramp smooth where the demand is tiny): the ramp is 1 to within
exp(-5) once the cell keeps 5 % of its step's demand, and 0 for an empty cell, so a cell's width never goes
negative; scaling w_eps with the demand keeps the ramp's slope (1/fraction) and so Newton's conditioning
bounded. The volume actually leaked is what the balance records, so the volume balance stays exact.
"""

from __future__ import annotations

import numpy as np


def carter_volume(c_prime: np.ndarray, tau: np.ndarray, t0: float, t1: float,
                  filled: np.ndarray | None = None) -> np.ndarray:
    """Leaked volume per unit area over [t0, t1]: 2 C' (sqrt(t1 - tau) - sqrt(max(t0, tau) - tau)) (Eq. 29).

    With ``filled`` (partially filled tip cells), the front crosses the cell between tau and ``filled``:
    the opening time is spread uniformly over the cell's area, tau(x) in [tau, filled], and the cell-mean
    is the exact average of Eq. 29's integral over it,
    2 C' (2/3) [F(t1) - F(t0)] / (filled - tau), F(t) = (t - tau)_+^(3/2) - (t - filled)_+^(3/2).
    """
    tau = np.asarray(tau, dtype=float)
    if filled is not None:
        span = np.asarray(filled, dtype=float) - tau
        spread = span > 0.0
        if spread.any():
            safe = np.where(spread, span, 1.0)

            def f(t):
                return np.maximum(t - tau, 0.0) ** 1.5 - np.maximum(t - tau - safe, 0.0) ** 1.5

            mean = 2.0 * np.asarray(c_prime, dtype=float) * (2.0 / 3.0) * (f(t1) - f(t0)) / safe
            return np.where(spread, mean, carter_volume(c_prime, tau, t0, t1))
    start = np.maximum(t0, tau)
    open_ = t1 > tau
    out = 2.0 * np.asarray(c_prime, dtype=float) * (np.sqrt(np.maximum(t1 - tau, 0.0))
                                                   - np.sqrt(np.maximum(start - tau, 0.0)))
    return np.where(open_, out, 0.0)


def available_fraction(w: np.ndarray, w_eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Ramp g(w) = 1 - exp(-w / w_eps) limiting leak-off to fluid present, and its derivative g'(w).

    Continued linearly, g = w / w_eps, for w < 0 (where Newton iterates may stray), so it never overflows.
    """
    x = np.asarray(w, dtype=float) / w_eps
    e = np.exp(-np.maximum(x, 0.0))
    return np.where(x >= 0.0, 1.0 - e, x), np.where(x >= 0.0, e, 1.0) / w_eps
