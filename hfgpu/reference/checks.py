"""Argument checks shared by the reference solutions: clear errors naming the argument, before any work."""

from __future__ import annotations

import numpy as np


def positive(name: str, value) -> np.ndarray:
    """Return value as a float64 array; raise ValueError naming the argument unless all finite and > 0."""
    a = np.asarray(value, dtype=np.float64)
    if a.size == 0 or not np.all(np.isfinite(a)) or np.any(a <= 0.0):
        raise ValueError(f"{name}: got {value!r}; must be finite and > 0")
    return a


def non_negative(name: str, value) -> np.ndarray:
    """Return value as a float64 array; raise ValueError naming the argument unless all finite and >= 0."""
    a = np.asarray(value, dtype=np.float64)
    if a.size == 0 or not np.all(np.isfinite(a)) or np.any(a < 0.0):
        raise ValueError(f"{name}: got {value!r}; must be finite and >= 0")
    return a


def fraction(name: str, value, upper: float = 1.0) -> np.ndarray:
    """Return value as a float64 array; raise ValueError naming the argument unless all in [0, upper)."""
    a = np.asarray(value, dtype=np.float64)
    if a.size == 0 or not np.all(np.isfinite(a)) or np.any(a < 0.0) or np.any(a >= upper):
        raise ValueError(f"{name}: got {value!r}; must be in [0, {upper:g})")
    return a
