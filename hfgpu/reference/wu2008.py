"""Digitised fracture fronts of the Wu, Bunger, Jeffrey & Siebrits (2008) layered-stress experiment.

R. Wu, A.P. Bunger, R.G. Jeffrey, E. Siebrits, "A comparison of numerical and experimental results of hydraulic
fracture growth into a zone of lower confining stress", ARMA 08-267 (2008); fronts as digitised for PyFrac
(GeoEnergyLab-EPFL/PyFrac ``examples/wu_et_al_data.csv``). The csv has 10 columns =
5 (x, y) pairs in mm for t = 665, 376, 144, 60, 22 s, padded with nan; its +y points down, into the 5 MPa
(low-stress) layer, and the injection point is the origin.

The caller passes the file's path (the data are third-party and are not shipped with hfgpu).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

FRONT_TIMES = (665.0, 376.0, 144.0, 60.0, 22.0)   # s, order of the csv's column pairs


@dataclass(frozen=True)
class Extents:
    """Front reach from the injection point [m]: up (into the high-stress layer), down (into the low-stress layer),
    left (-x), right (+x); all positive where the front passes the point on that side."""

    up: float
    down: float
    left: float
    right: float


def read_fronts(path) -> dict[float, np.ndarray]:
    """Read the digitised fronts: {time [s]: polyline, shape (n, 2), columns (x, depth) in metres}, depth positive
    DOWNWARD (into the 5 MPa layer), origin at the injection point; times ascending. nan padding is dropped."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"Wu et al. (2008) fronts csv not found at {path}")
    data = np.genfromtxt(path, delimiter=",", dtype=np.float64)
    if data.ndim != 2 or data.shape[1] != 2 * len(FRONT_TIMES):
        raise ValueError(f"{path}: got a table of shape {data.shape}; expected {2 * len(FRONT_TIMES)} columns "
                         f"(x, y pairs in mm for t = {FRONT_TIMES} s)")
    fronts = {}
    for k, t in enumerate(FRONT_TIMES):
        xy = data[:, 2 * k:2 * k + 2]
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        fronts[t] = xy * 1e-3
    return dict(sorted(fronts.items()))


def extents(polyline) -> Extents:
    """Reach of a front polyline (x, depth) [m] from the injection point at the origin:
    up = -min depth, down = max depth, left = -min x, right = max x (vertices of the digitised polyline)."""
    p = np.asarray(polyline, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 3 or not np.all(np.isfinite(p)):
        raise ValueError(f"polyline: got an array of shape {p.shape}; must be (n >= 3, 2) finite (x, depth)")
    return Extents(up=float(-p[:, 1].min()), down=float(p[:, 1].max()), left=float(-p[:, 0].min()),
                   right=float(p[:, 0].max()))


# Injection schedule, the hfgpu paper's Eq. 47 (PyFrac's deck has the same rates, without the shut-in at 701 s):
# (start time [s], rate [m^3/s]).
SCHEDULE = ((0.0, 9e-10), (31.0, 6.5e-9), (151.0, 2.3e-9), (701.0, 0.0))


def injected_volume(t):
    """Volume injected by time t [m^3] under the piecewise-constant rates of the paper's Eq. 47:
    0.0009 mL/s to 31 s, 0.0065 mL/s to 151 s, 0.0023 mL/s to 701 s, then shut in."""
    t = np.asarray(t, dtype=np.float64)
    if not np.all(np.isfinite(t)) or np.any(t < 0.0):
        raise ValueError(f"t: got {t!r}; must be finite and >= 0")
    starts = np.array([s for s, _ in SCHEDULE])
    rates = np.array([q for _, q in SCHEDULE])
    ends = np.append(starts[1:], np.inf)
    return np.sum(rates * np.clip(t[..., None] - starts, 0.0, ends - starts), axis=-1)
