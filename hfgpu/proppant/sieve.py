"""Proppant sieve classes and particle-size distributions (seeded, reproducible).

A mesh class "A/B" is the sand that passes sieve No. A and is retained on No. B, so its diameters lie between
the openings of B and A. Openings are the US Standard series of ASTM E11 (frac-sand practice per API RP 19C /
ISO 13503-2).
"100 mesh" frac sand is nominally 70/140 (0.106-0.212 mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr, ndtri

#: ASTM E11 sieve number -> nominal opening [m].
ASTM_E11_OPENINGS = {
    8: 2.36e-3, 10: 2.00e-3, 12: 1.70e-3, 14: 1.40e-3, 16: 1.18e-3, 18: 1.00e-3, 20: 0.850e-3,
    25: 0.710e-3, 30: 0.600e-3, 35: 0.500e-3, 40: 0.425e-3, 45: 0.355e-3, 50: 0.300e-3, 60: 0.250e-3,
    70: 0.212e-3, 80: 0.180e-3, 100: 0.150e-3, 120: 0.125e-3, 140: 0.106e-3, 170: 0.090e-3,
    200: 0.075e-3,
}

#: Single-number frac-sand names and the sieve pair they stand for.
NAMED_CLASSES = {"100 mesh": (70, 140), "100": (70, 140)}

DISTRIBUTIONS = ("fixed", "uniform", "normal")


def sieve_range(label: str) -> tuple[float, float]:
    """(d_min, d_max) [m] of a sieve class "A/B" (A < B) or "100 mesh"; ValueError names what is allowed."""
    text = " ".join(label.strip().lower().split())
    if text in NAMED_CLASSES:
        coarse, fine = NAMED_CLASSES[text]
    else:
        parts = text.removesuffix(" mesh").split("/")
        try:
            coarse, fine = (int(p) for p in parts)
        except ValueError:
            raise ValueError('expected a sieve class "A/B" (e.g. "30/50", "40/70") or "100 mesh"') from None
    for number in (coarse, fine):
        if number not in ASTM_E11_OPENINGS:
            raise ValueError(f"sieve No. {number} is not in the ASTM E11 table; known: "
                             f"{sorted(ASTM_E11_OPENINGS)}")
    if coarse >= fine:
        raise ValueError(f'"A/B" needs the coarser sieve first (A < B), e.g. "30/50"; got {label!r}')
    return ASTM_E11_OPENINGS[fine], ASTM_E11_OPENINGS[coarse]


@dataclass(frozen=True)
class SizeDistribution:
    """Number distribution of particle diameters [m].

    kind "fixed": every particle has ``mean``; "uniform": uniform on [d_min, d_max]; "normal": a normal
    (mean, std) truncated to [d_min, d_max], as the paper's Fig. 15 (defaults: mean = mid-range,
    std = range / 6).
    """

    kind: str
    mean: float
    d_min: float
    d_max: float
    std: float = 0.0

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """n diameters drawn with ``rng`` (inverse-CDF sampling: one uniform number per particle)."""
        if self.kind == "fixed":
            return np.full(n, self.mean)
        u = rng.random(n)
        if self.kind == "uniform":
            return self.d_min + u * (self.d_max - self.d_min)
        a, b = self._standard_bounds()
        lo, hi = ndtr(a), ndtr(b)
        return self.mean + self.std * ndtri(lo + u * (hi - lo))

    def mean_particle_volume(self) -> float:
        """E[pi d^3 / 6] over the distribution (closed form for fixed/uniform, quadrature for normal)."""
        if self.kind == "fixed":
            return math.pi * self.mean**3 / 6.0
        if self.kind == "uniform":
            return math.pi / 24.0 * (self.d_max**4 - self.d_min**4) / (self.d_max - self.d_min)
        d = np.linspace(self.d_min, self.d_max, 2001)
        pdf = np.exp(-0.5 * ((d - self.mean) / self.std) ** 2)
        return float(np.trapezoid(math.pi * d**3 / 6.0 * pdf, d) / np.trapezoid(pdf, d))

    def _standard_bounds(self) -> tuple[float, float]:
        return (self.d_min - self.mean) / self.std, (self.d_max - self.mean) / self.std


def make_distribution(kind: str, d_min: float, d_max: float, mean: float | None = None,
                      std: float | None = None) -> SizeDistribution:
    """A :class:`SizeDistribution` over [d_min, d_max] with the defaults documented there."""
    if kind not in DISTRIBUTIONS:
        raise ValueError(f"distribution {kind!r}: allowed {DISTRIBUTIONS}")
    mid = 0.5 * (d_min + d_max)
    mean = mid if mean is None else mean
    if kind == "normal":
        std = (d_max - d_min) / 6.0 if std is None else std
        if d_max <= d_min or std <= 0.0:
            raise ValueError("a normal distribution needs d_max > d_min and std > 0")
    return SizeDistribution(kind=kind, mean=mean, d_min=d_min, d_max=d_max, std=std or 0.0)
