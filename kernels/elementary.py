"""Inline float64 exp and log for the Taichi kernels: plain arithmetic and bit operations, no libm call.

On the CPU backend ``ti.exp`` / ``ti.log`` in float64 are calls into libm: one parcel at a time, and every
call spills the vector registers around it. These versions are straight-line code that LLVM inlines and
vectorises across the LANES parcels of the push. Accuracy: relative error below 2 x 2^-52
(tests/kernels/test_elementary.py compares them with NumPy over the whole range the kernels use). They need
Taichi's fast_math off (runtime.init): reassociating the split ln 2 reduction loses its accuracy.

Methods (Cody & Waite 1980, "Software Manual for the Elementary Functions", the reductions of fdlibm
e_exp.c / e_log.c, whose split constants ln 2 = LN2_HI + LN2_LO are used here):
exp(x) = 2^k exp(r), k = round(x / ln 2), r = x - k ln 2 in [-ln2/2, ln2/2], exp(r) by its Taylor series to
r^13 (truncation error < 0.35^14 / 14! = 5e-18 relative); polynomials by Estrin's scheme.
log(x) = e ln 2 + log(m), x = 2^e m with m in [sqrt(1/2), sqrt(2)), log(m) = 2 atanh(s), s = (m - 1) / (m + 1),
|s| <= 0.172, by the series 2 s sum s^2j / (2j + 1) to j = 10 (truncation error < 0.172^22 / 23 < 1e-18).
"""

import math

from hfgpu.kernels.runtime import ti

LN2_HI = 6.93147180369123816490e-01  # fdlibm e_exp.c: ln 2 with 32 trailing zero bits (k LN2_HI exact)
LN2_LO = 1.90821492927058770002e-10  # ln 2 - LN2_HI
INV_LN2 = 1.44269504088896338700e+00
SQRT2 = 1.4142135623730951
EXP_MIN, EXP_MAX = -708.0, 709.0  # exp argument range kept normal (below: exp(-708) ~ 3e-308 instead of 0)
ROUNDER = 6755399441055744.0  # 1.5 x 2^52: y + ROUNDER - ROUNDER rounds |y| < 2^51 to an integer
ROUNDER_BITS = 0x4338000000000000  # bits of ROUNDER: bits(y + ROUNDER) - ROUNDER_BITS = round(y)
TWO54 = 18014398509481984.0  # 2^54: scales subnormal log arguments into the normal range
MANTISSA = 0x000FFFFFFFFFFFFF
ONE_BITS = 0x3FF0000000000000  # bits of 1.0


EXP_TAYLOR = tuple(1.0 / math.factorial(j) for j in range(14))  # exp(r) = sum r^j / j!, j <= 13
ATANH_SERIES = tuple(1.0 / (2 * j + 3) for j in range(10))  # (atanh(s) / s - 1) / s^2 = sum z^j / (2j + 3)


@ti.func
def estrin(x, c: ti.template()):
    """sum_j c[j] x^j (10 to 16 coefficients) by Estrin's scheme (Knuth, TAOCP vol. 2, 4.6.4): pairs
    c[j] + c[j+1] x combined with x^2, x^4, x^8; a short dependency chain, so that the independent parcels of a
    push task overlap."""
    x2 = x * x
    x4 = x2 * x2
    x8 = x4 * x4
    low = (c[0] + c[1] * x + (c[2] + c[3] * x) * x2) + (c[4] + c[5] * x + (c[6] + c[7] * x) * x2) * x4
    high = c[8] + c[9] * x
    if ti.static(len(c) > 10):
        high = high + (c[10] + c[11] * x) * x2
    if ti.static(len(c) > 12):
        high = high + (c[12] + c[13] * x) * x4
    if ti.static(len(c) > 14):
        high = high + (c[14] + c[15] * x) * x2 * x4
    return low + high * x8


@ti.func
def exp(x):
    """e^x (relative error < 2 x 2^-52) for x in [-708, 709] (arguments clamped there), elementwise for a
    vector x (the push's LANES parcels: one body, vectorised by LLVM); see the module docstring."""
    xc = ti.min(ti.max(x, EXP_MIN), EXP_MAX)
    t = xc * INV_LN2 + ROUNDER  # k = round(x / ln 2) in the low bits of t (no float-to-int conversion)
    k = t - ROUNDER
    r = (xc - k * LN2_HI) - k * LN2_LO
    p = estrin(r, EXP_TAYLOR)
    scale = ti.bit_cast((ti.bit_cast(t, ti.i64) - ti.i64(ROUNDER_BITS) + 1023) << 52, ti.f64)
    return p * scale


@ti.func
def log(x):
    """Natural logarithm (relative error < 2 x 2^-52) of finite x > 0, subnormals included, elementwise for a
    vector x; see the module docstring."""
    small = x < 2.2250738585072014e-308
    xs = ti.select(small, x * TWO54, x)
    bits = ti.bit_cast(xs, ti.i64)
    e = ti.cast((bits >> 52) - 1023, ti.f64) - ti.select(small, 54.0, 0.0)
    m = ti.bit_cast((bits & ti.i64(MANTISSA)) | ti.i64(ONE_BITS), ti.f64)
    high = m > SQRT2
    m = ti.select(high, 0.5 * m, m)
    e = e + ti.select(high, 1.0, 0.0)
    f = m - 1.0
    s = f / (2.0 + f)
    z = s * s
    q = estrin(z, ATANH_SERIES)
    return e * LN2_HI + (2.0 * s + 2.0 * s * z * q + e * LN2_LO)
