"""A penny-shaped crack of radius a under a uniform internal pressure p in an infinite solid (Sneddon 1946,
"The distribution of stress in the neighbourhood of a crack in an elastic solid", Proc. R. Soc. A 187:229;
Sneddon & Lowengrub 1969, "Crack problems in the classical theory of elasticity", ch. 3):

* opening w(r) = (8 p a / (pi E')) sqrt(1 - r^2 / a^2), E' = E / (1 - nu^2), so the crack holds
  V = 16 p a^3 / (3 E') and its stress intensity is K_I = 2 p sqrt(a / pi): holding V, it stands at K_I = K_Ic
  at R = (3 E' V / (8 sqrt(pi) K_Ic))^(2/5), where a fracture that stops being fed arrests (toughness arrest);
* normal stress on its axis at a distance z from its plane (tension positive)

      sigma_zz(0, z) / p = -(1/pi) [2 arctan(a/z) - 2 a z / (a^2 + z^2) + 4 a^3 z / (a^2 + z^2)^2],

  -1 at the crack (z -> 0: the pressure itself), -0.8576, -0.5, -0.1424, -0.0520 at z/a = 0.5, 1, 2, 3, and
  -(16 / (3 pi)) (a/z)^3 far away (the dipole of the opening volume). The stress shadow an opening fracture
  casts on a parallel one (issue 36). tests/fracture/test_shadow.py sums the displacement-discontinuity
  kernel of hfgpu.fracture.shadow over the crack's opening and finds the same numbers within 0.2 %.
"""

from __future__ import annotations

import numpy as np

from .checks import positive


def penny_opening(r, a: float, p: float, e_prime: float) -> np.ndarray:
    """w(r) [m] (0 outside the crack)."""
    a, p, e = (float(positive(n, v)) for n, v in (("a", a), ("p", p), ("e_prime", e_prime)))
    r = np.asarray(r, dtype=float)
    return 8.0 * p * a / (np.pi * e) * np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None))


def penny_arrest_radius(e_prime: float, k_ic: float, volume: float) -> float:
    """R [m] of the penny crack holding ``volume`` [m^3] at K_I = K_Ic: (3 E' V / (8 sqrt(pi) K_Ic))^(2/5)."""
    e, k, v = (float(positive(n, x)) for n, x in (("e_prime", e_prime), ("k_ic", k_ic), ("volume", volume)))
    return (3.0 * e * v / (8.0 * np.sqrt(np.pi) * k)) ** 0.4


def penny_axis_stress(z, a: float) -> np.ndarray:
    """sigma_zz(0, z) / p on the axis (tension positive), z > 0 [m]."""
    a = float(positive("a", a))
    z = positive("z", z)
    s = a * a + z * z
    return -(2.0 * np.arctan(a / z) - 2.0 * a * z / s + 4.0 * a**3 * z / s**2) / np.pi
