"""Sampling designs: the varied inputs of every member, in SI, from the sweep's design and seed.

Sampled designs draw points u in [0, 1)^d (d = number of varied keys, one row per member):

* ``latin-hypercube``: SciPy's ``qmc.LatinHypercube(d)`` seeded with ``numpy.random.default_rng(seed)``: each
  column has exactly one point in each of the ``members`` strata [k/n, (k+1)/n);
* ``random``: ``numpy.random.default_rng(seed).random((n, d))``.

Each column is mapped through the inverse CDF of its distribution:

* uniform:      x = low + u (high - low)
* log-uniform:  x = exp(ln low + u (ln high - ln low))
* normal:       x = mean + std Phi^-1(u)   (Phi: the standard normal CDF)
* triangular:   with c = (mode - low) / (high - low),
  x = low + sqrt(u (high - low)(mode - low)) for u < c, else high - sqrt((1 - u)(high - low)(high - mode))
* values:       x = values[floor(u n_values)]   (each value equally likely)

``grid``: every combination of the ``values`` lists, the first ``[[vary]]`` varying slowest.
The points depend on the sweep file and seed only, never on the workers that run them.
"""

from __future__ import annotations

import itertools

import numpy as np

from .sweep_file import Sweep, Vary


def unit_points(design: str, members: int, dimensions: int, seed: int) -> np.ndarray:
    """(members, dimensions) points in [0, 1) of a sampled design."""
    if design == "latin-hypercube":
        from scipy.stats import qmc

        # seed= works on every SciPy the project allows (rng= needs SciPy >= 1.15)
        return qmc.LatinHypercube(dimensions, seed=np.random.default_rng(seed)).random(members)
    return np.random.default_rng(seed).random((members, dimensions))


def inverse_cdf(vary: Vary, u: np.ndarray) -> list[float | int | str]:
    """The values of ``vary`` at the probabilities ``u`` (formulas in the module docstring)."""
    if vary.values:
        index = np.minimum((u * len(vary.values)).astype(int), len(vary.values) - 1)
        return [vary.values[i] for i in index]
    p = vary.params
    if vary.distribution == "uniform":
        x = p[0] + u * (p[1] - p[0])
    elif vary.distribution == "log-uniform":
        x = np.exp(np.log(p[0]) + u * (np.log(p[1]) - np.log(p[0])))
    elif vary.distribution == "normal":
        from scipy.stats import norm

        x = p[0] + p[1] * norm.ppf(u)
    else:
        low, mode, high = p
        c = (mode - low) / (high - low)
        x = np.where(u < c, low + np.sqrt(u * (high - low) * (mode - low)),
                     high - np.sqrt((1.0 - u) * (high - low) * (high - mode)))
    return [float(v) for v in x]


def member_inputs(sweep: Sweep) -> list[dict[str, float | int | str]]:
    """The varied inputs of each member ({key: value in SI}), in member order."""
    keys = [v.key for v in sweep.vary]
    if sweep.design == "grid":
        return [dict(zip(keys, combo)) for combo in itertools.product(*(v.values for v in sweep.vary))]
    u = unit_points(sweep.design, sweep.members, len(sweep.vary), sweep.seed)
    columns = [inverse_cdf(v, u[:, j]) for j, v in enumerate(sweep.vary)]
    return [dict(zip(keys, row)) for row in zip(*columns)]
