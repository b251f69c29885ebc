"""Perforation friction and the wellbore node of a stage of several clusters.

Perforation friction (limited entry). The pressure a cluster of n perforations of diameter d and discharge
coefficient C_d costs a slurry of density rho entering at the rate q is (Bell, Sukup & Tariq, *Perforating*, SPE
Monograph 16, 1993; the form of Crump & Conway, JPT 40(8), 1988)

    dp_perf = 0.2369 rho q^2 / (n^2 d^4 C_d^2)      [psi; rho in lb/gal, q in bbl/min, d in in]
            = K rho q^2 / (n^2 d^4 C_d^2)           [Pa;  rho in kg/m^3, q in m^3/s, d in m],

K = 0.2369 psi (bbl/min)^-2 in^4 (lb/gal)^-1 in SI (:data:`K_SI` = 0.80806, the field constant times the unit
factors, :func:`field_constant` goes back). Bernoulli through n orifices of area pi d^2 / 4 whose jets contract to
C_d^2 of it, dp = rho v^2 / (2 C_d^2) with v = q / (n pi d^2 / 4), gives K = 8 / pi^2 = 0.81057 (0.23764 in
field units): the published 0.2369 is 0.31 % lower (its unit factors rounded); hfgpu uses the published constant,
a difference well inside the spread of C_d (0.5 for sharp new holes to 0.9 once eroded).

The wellbore node. The clusters of a stage share one wellbore pressure p_w (the wellbore between the clusters is
taken as frictionless):

    p_w = p_i(q_i) + a_i q_i^2   for every cluster i taking fluid (q_i > 0),   sum_i q_i = Q,

with p_i(q) the fluid pressure at cluster i's fracture entry at the rate q and a_i = K rho / (n_i^2 d_i^4 C_d,i^2).
:func:`split_rate` solves it for entry pressures given by their linearisation p_i(q) = p0_i + s_i (q - q0_i)
(:class:`Entry`): for a trial p_w each cluster's rate is the root of a_i q^2 + s_i q = p_w - p0_i + s_i q0_i (0
where p_w is below what that cluster needs to take fluid: no back-flow), and the sum of those rates, continuous
and increasing in p_w, meets Q at one p_w (Brent's method, to 1e-13 of the bracket).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from .units import convert

#: The field-unit constant of the perforation friction (module docstring): psi (bbl/min)^-2 in^4 (lb/gal)^-1.
K_FIELD = 0.2369


def field_constant(k_si: float) -> float:
    """A perforation-friction constant of SI units (Pa from kg/m^3, m^3/s, m) in the field units of K_FIELD."""
    rho, q, d = convert(1.0, "lb/gal", "kg/m**3"), convert(1.0, "bbl/min", "m**3/s"), convert(1.0, "in", "m")
    return convert(k_si * rho * q * q / d**4, "Pa", "psi")


#: K_FIELD in SI: dp [Pa] = K_SI rho [kg/m^3] q^2 [m^6/s^2] / (n^2 d^4 [m^4] C_d^2).
K_SI = K_FIELD / field_constant(1.0)
#: The Bernoulli orifice constant 8 / pi^2 (module docstring), for comparison only.
K_BERNOULLI = 8.0 / math.pi**2


def entry_coefficient(density: float, perforations: int, diameter: float, discharge_coefficient: float) -> float:
    """a [Pa s^2/m^6] of dp_perf = a q^2 for a slurry of ``density`` [kg/m^3] through ``perforations`` holes of
    ``diameter`` [m] with the given C_d (module docstring)."""
    return K_SI * density / (perforations**2 * diameter**4 * discharge_coefficient**2)


def perforation_friction(rate, density: float, perforations: int, diameter: float,
                         discharge_coefficient: float) -> np.ndarray:
    """dp_perf [Pa] at the cluster rate(s) ``rate`` [m^3/s] (module docstring; q |q|, so a sign is kept)."""
    q = np.asarray(rate, dtype=float)
    return entry_coefficient(density, perforations, diameter, discharge_coefficient) * q * np.abs(q)


@dataclass(frozen=True)
class Entry:
    """A cluster's fracture-entry pressure linearised about the rate ``rate`` q0 [m^3/s]: p(q) = ``pressure`` +
    ``slope`` (q - q0) [Pa], ``slope`` >= 0 [Pa s/m^3]."""

    pressure: float
    slope: float
    rate: float = 0.0


def _cluster_rate(p_w: float, entry: Entry, a: float) -> float:
    """The rate at which cluster (``entry``, a) meets the wellbore pressure p_w: the positive root of
    a q^2 + s q = c, c = p_w - p0 + s q0, written 2 c / (s + sqrt(s^2 + 4 a c)) (no cancellation, a = 0 allowed);
    0 for c <= 0."""
    c = p_w - entry.pressure + entry.slope * entry.rate
    if c <= 0.0:
        return 0.0
    return 2.0 * c / (entry.slope + math.sqrt(entry.slope**2 + 4.0 * a * c))


def split_rate(total: float, entries: list[Entry], coefficients) -> tuple[np.ndarray, float]:
    """(q_i [m^3/s], p_w [Pa]) of the wellbore node (module docstring) for the pump rate ``total`` Q > 0, the
    clusters' linearised entry pressures and their perforation coefficients a_i (:func:`entry_coefficient`; 0
    without perforation friction). One cluster takes Q. Raises ValueError for a cluster with a_i = s_i = 0 among
    several (its rate would be undetermined)."""
    a = np.asarray(coefficients, dtype=float)
    if len(entries) == 1:
        e = entries[0]
        return np.array([total]), e.pressure + e.slope * (total - e.rate) + a[0] * total * total
    for i, e in enumerate(entries):
        if e.slope <= 0.0 and a[i] <= 0.0:
            raise ValueError(f"split_rate: cluster {i} has neither an entry slope nor perforation friction")
    low = min(e.pressure - e.slope * e.rate for e in entries)
    high = max(e.pressure + e.slope * (total - e.rate) + a[i] * total * total for i, e in enumerate(entries))

    def excess(p_w: float) -> float:
        return sum(_cluster_rate(p_w, e, a[i]) for i, e in enumerate(entries)) - total

    p_w = brentq(excess, low, high, xtol=1e-13 * max(abs(high - low), 1.0), rtol=4.0 * np.finfo(float).eps)
    rates = np.array([_cluster_rate(p_w, e, a[i]) for i, e in enumerate(entries)])
    return rates * (total / rates.sum()), p_w
