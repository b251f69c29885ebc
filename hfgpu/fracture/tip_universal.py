"""Universal tip asymptote of a steadily moving hydraulic-fracture tip with toughness, viscosity and leak-off.

Dontsov, E.V. & Peirce, A.P. (2015), "A non-singular integral equation formulation to analyse multiscale
behaviour in semi-infinite hydraulic fractures", J. Fluid Mech. 781, R1: the width w at distance s behind a
tip moving at speed V in a rock with K' = sqrt(32/pi) K_Ic, E', fluid mu' = 12 mu and Carter's C' = 2 C_L is
given in closed form by the separable approximation of their non-singular integral equation. With

    K^ = K' s^(1/2) / (E' w),   C^ = 2 C' s^(1/2) / (V^(1/2) w),   s^ = mu' V s^2 / (E' w^3),

the relation is s^ = g_delta(K^, C^) = f(K^, b(delta) C^, C1(delta)), with

    f(K, C, C1) = [1 - K^3 - 3/2 C (1 - K^2) + 3 C^2 (1 - K) - 3 C^3 ln((C + 1) / (C + K))] / (3 C1),
    C1(d) = 4 (1 - 2d) / (d (1 - d)) tan(pi d),   C2(d) = 16 (1 - 3d) / (3d (2 - 3d)) tan(3 pi d / 2),
    b(d) = C2(d) / C1(d),

and the local exponent delta (w ~ s^((1 + delta)/2)) from the zero-order solution g0 = f(K^, b0 C^,
beta_m^3/3), delta = (beta_m^3 / 3) (1 + b0 C^) g0, b0 = 3 beta_mt^4 / (4 beta_m^3) (Dontsov & Peirce 2017,
CMAME 313, "A multiscale implicit level set algorithm (ILSA)", eq. for g_delta). The relation is exact at
the three vertices: K (s^ = 0: w = K'/E' s^1/2), M (K^ = C^ = 0, delta = 1/3: w = beta_m (mu' V/E')^(1/3)
s^(2/3), beta_m = 2^(1/3) 3^(5/6)) and M~ (K^ = 0, C^ -> inf, delta = 1/4: w = beta_mt (2 C' mu' / E')^(1/4)
V^(1/8) s^(5/8), beta_mt = 4 / (15 (sqrt 2 - 1))^(1/4)), and Dontsov & Peirce report it within about 1 % of
their numerical solution in between.

``width`` (w for given s) and ``distance`` (s for given w) solve the relation for one unknown per cell with
a vectorised bracketed root find (Illinois regula falsi on the logarithm of the unknown): at fixed s the
residual s^ - g is decreasing in w, at fixed w increasing in s, and the vertex widths bound the root. Where
K' = C' = 0 (a pure-viscosity scene) the relation is the M vertex itself, delta = 1/3 and 3 C1(1/3) =
beta_m^3, and both are its closed form (no root to find).
"""

from __future__ import annotations

import numpy as np

BETA_M = 2.0 ** (1.0 / 3.0) * 3.0 ** (5.0 / 6.0)
BETA_MT = 4.0 / (15.0 * (np.sqrt(2.0) - 1.0)) ** 0.25
C1_M = BETA_M**3 / 3.0                      # C1(1/3) = 6 sqrt(3)
B0 = 3.0 * BETA_MT**4 / (4.0 * BETA_M**3)   # makes the zero-order g0 exact at the M~ vertex
SERIES_FROM = 8.0                           # C above which f's bracket is summed as its 1/C series
SERIES_TERMS = 20
ITERATIONS = 100
RTOL = 1e-10


def m_scale(e_prime, mu_prime, v):
    """beta_m (mu' V / E')^(1/3): the M-vertex width is m_scale s^(2/3) (Desroches et al. 1994)."""
    return BETA_M * np.cbrt(mu_prime * v / e_prime)


def _bracket(k: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The bracket of f, 1 - K^3 - 3/2 C (1 - K^2) + 3 C^2 (1 - K) - 3 C^3 ln((C + 1)/(C + K)), for
    0 <= K <= 1, C >= 0. For C > SERIES_FROM it is summed as its convergent expansion in y = 1/C,
    3 [T(y) - K^3 T(K y)] with T(y) = sum_{m>=1} (-1)^(m+1) y^m / (m + 3), which avoids the cancellation of
    the closed form's O(C^3) terms (the leading term 3 (1 - K^4) / (4 C) gives the M~K edge)."""
    big = c > SERIES_FROM
    cs = np.where(big, SERIES_FROM, c)
    with np.errstate(divide="ignore", invalid="ignore"):
        log = np.where(cs > 0.0, cs**3 * np.log((cs + 1.0) / (cs + k)), 0.0)
    closed = 1.0 - k**3 - 1.5 * cs * (1.0 - k**2) + 3.0 * cs**2 * (1.0 - k) - 3.0 * log
    if big.any():
        kb, y = k[big], 1.0 / c[big]
        t_y, t_ky = np.zeros_like(y), np.zeros_like(y)
        for m in range(SERIES_TERMS, 0, -1):    # Horner: T = y (1/4 - y (1/5 - y (...)))
            t_y = y * (1.0 / (m + 3) - t_y)
            t_ky = kb * y * (1.0 / (m + 3) - t_ky)
        closed[big] = 3.0 * (t_y - kb**3 * t_ky)
    return closed


def _c1(d: np.ndarray) -> np.ndarray:
    """C1(delta) = 4 (1 - 2 delta) / (delta (1 - delta)) tan(pi delta); 4 pi at delta = 0."""
    safe = np.maximum(d, 1e-12)
    return 4.0 * (1.0 - 2.0 * safe) / (1.0 - safe) * np.tan(np.pi * safe) / safe


def _c2(d: np.ndarray) -> np.ndarray:
    """C2(delta) = 16 (1 - 3 delta) / (3 delta (2 - 3 delta)) tan(3 pi delta / 2); 8 pi at delta = 0 and
    its limit 32 / pi at delta = 1/3."""
    safe = np.clip(d, 1e-12, 1.0 / 3.0 - 1e-9)
    return 16.0 * (1.0 - 3.0 * safe) / (3.0 * safe * (2.0 - 3.0 * safe)) * np.tan(1.5 * np.pi * safe)


def delta(k_hat: np.ndarray, c_hat: np.ndarray) -> np.ndarray:
    """The local tip exponent delta(K^, C^) = (beta_m^3/3) (1 + b0 C^) g0, g0 = f(K^, b0 C^, beta_m^3/3), in
    [0, 1/3] (w ~ s^((1 + delta)/2); Dontsov 2016, Dontsov & Peirce 2017)."""
    k_hat = np.clip(k_hat, 0.0, 1.0)
    g0 = _bracket(k_hat, B0 * c_hat) / (3.0 * C1_M)
    return np.clip(C1_M * (1.0 + B0 * c_hat) * g0, 0.0, 1.0 / 3.0)


def g_delta(k_hat: np.ndarray, c_hat: np.ndarray) -> np.ndarray:
    """s^ = g_delta(K^, C^) of Dontsov & Peirce (2015), with delta from the zero-order solution."""
    k_hat = np.clip(k_hat, 0.0, 1.0)
    d = delta(k_hat, c_hat)
    c1 = _c1(d)
    return _bracket(k_hat, _c2(d) / c1 * c_hat) / (3.0 * c1)


def _residual(w, s, e_prime, k_prime, c_prime, mu_prime, v):
    """s^ - g_delta(K^, C^): negative where w is wider than the asymptote's width at s, positive where
    narrower (K^ > 1 counts as K^ = 1, i.e. s^ against g = 0)."""
    k_hat = k_prime * np.sqrt(s) / (e_prime * w)
    c_hat = 2.0 * c_prime * np.sqrt(s) / (np.sqrt(v) * w)
    s_hat = mu_prime * v * s**2 / (e_prime * w**3)
    return s_hat - g_delta(k_hat, c_hat) + np.maximum(k_hat - 1.0, 0.0)


def _vertex_widths(s, e_prime, k_prime, c_prime, mu_prime, v):
    """K, M and M~ vertex widths at s (their maximum is a lower bound of the universal width)."""
    w_k = k_prime / e_prime * np.sqrt(s)
    w_m = m_scale(e_prime, mu_prime, v) * s ** (2.0 / 3.0)
    w_mt = BETA_MT * (2.0 * c_prime * mu_prime / e_prime) ** 0.25 * v**0.125 * s**0.625
    return np.maximum(np.maximum(w_k, w_m), w_mt)


def increasing_root(fun, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Root of fun(x), increasing in x > 0, per element: lo and hi are widened by factors of 4 until they bracket
    it, then Illinois regula falsi on ln x to a relative change of RTOL (also tip_cells' ribbon distances)."""
    f_lo, f_hi = fun(lo), fun(hi)
    for _ in range(ITERATIONS):
        low, high = f_lo > 0.0, f_hi < 0.0
        if not (low.any() or high.any()):
            break
        lo, hi = np.where(low, lo / 4.0, lo), np.where(high, hi * 4.0, hi)
        f_lo, f_hi = np.where(low, fun(lo), f_lo), np.where(high, fun(hi), f_hi)
    a, b = np.log(lo), np.log(hi)
    side = np.zeros(a.shape, dtype=int)
    x = b
    for _ in range(ITERATIONS):
        with np.errstate(invalid="ignore", divide="ignore"):
            x = np.where(f_hi != f_lo, (a * f_hi - b * f_lo) / (f_hi - f_lo), 0.5 * (a + b))
        x = np.clip(x, np.minimum(a, b), np.maximum(a, b))
        f_x = fun(np.exp(x))
        right = f_x > 0.0                       # the root lies left of x: x replaces b
        f_lo = np.where(right & (side == 1), 0.5 * f_lo, f_lo)
        f_hi = np.where(~right & (side == -1), 0.5 * f_hi, f_hi)
        step = np.where(right, np.abs(b - x), np.abs(x - a))
        b, f_hi = np.where(right, x, b), np.where(right, f_x, f_hi)
        a, f_lo = np.where(right, a, x), np.where(right, f_lo, f_x)
        side = np.where(right, 1, -1)
        if np.all((step < RTOL) | (b - a < RTOL) | (f_x == 0.0)):
            break
    return np.exp(x)


def width(s, e_prime, k_prime, c_prime, mu_prime, v) -> np.ndarray:
    """Width w at distance s behind the tip (Dontsov & Peirce 2015); the K vertex where V = 0."""
    s, k_prime, c_prime, v = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (s, k_prime, c_prime, v)))
    w = k_prime / e_prime * np.sqrt(s)
    moving = (v > 0.0) & (s > 0.0)
    m_edge = moving & (k_prime == 0.0) & (c_prime == 0.0)
    w[m_edge] = m_scale(e_prime, mu_prime, v[m_edge]) * s[m_edge] ** (2.0 / 3.0)
    moving &= ~m_edge
    if moving.any():
        args = (e_prime, k_prime[moving], c_prime[moving], mu_prime, v[moving])
        sm = s[moving]
        lo = _vertex_widths(sm, *args)
        w[moving] = increasing_root(lambda x: -_residual(x, sm, *args), lo, 3.0 * lo)
    return w


def distance(w, e_prime, k_prime, c_prime, mu_prime, v) -> np.ndarray:
    """Distance s behind the tip at which the asymptote's width is w (the inverse of ``width``); 0 where
    w = 0, the K vertex (E' w / K')^2 where V = 0 (infinite where K' = 0 too)."""
    w, k_prime, c_prime, v = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (w, k_prime, c_prime, v)))
    with np.errstate(divide="ignore"):
        s = np.where(k_prime > 0.0, (e_prime * w / np.where(k_prime > 0.0, k_prime, 1.0)) ** 2, np.inf)
    s[w == 0.0] = 0.0
    moving = (v > 0.0) & (w > 0.0)
    m_edge = moving & (k_prime == 0.0) & (c_prime == 0.0)
    s[m_edge] = (w[m_edge] / m_scale(e_prime, mu_prime, v[m_edge])) ** 1.5
    moving &= ~m_edge
    if moving.any():
        args = (e_prime, k_prime[moving], c_prime[moving], mu_prime, v[moving])
        wm = w[moving]
        vm, cm = v[moving], c_prime[moving]
        hi = np.minimum(s[moving], (wm / m_scale(e_prime, mu_prime, vm)) ** 1.5)
        with np.errstate(divide="ignore"):
            hi = np.minimum(hi, (wm / (BETA_MT * (2.0 * cm * mu_prime / e_prime) ** 0.25 * vm**0.125)) ** 1.6)
        s[moving] = increasing_root(lambda x: _residual(wm, x, *args), hi / 9.0, hi)
    return s
