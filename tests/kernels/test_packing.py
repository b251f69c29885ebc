"""Packing limiter of the push: a suspension settling onto the floor of a slot builds a bed that does not
over-pack and then stays at rest (REFERENCE.md 6.5; Snider 2001 eqs. 39-41 plus the push's packing cap)."""

import numpy as np
import pytest

from hfgpu.proppant.backend import get_backend, grid_fields
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

RHO_F, MU, G, DT = 1000.0, 1e-3, 9.81, 1e-3


def settle(backend, steps, theta0=0.2, nz=16, nx=4, rows=8, per_cell=20, seed=0):
    """Still fluid, d = 0.45 mm sand (terminal velocity 0.067 m/s) released at theta0 in the top rows of a
    5 mm grid; returns the history of (max theta_p, mean depth, rms speed)."""
    rng = np.random.default_rng(seed)
    d = 5e-3
    frame = GridFrame(d, d, d / 2, d / 2)
    width = np.full((nz, nx), 2e-3)
    r = 0.225e-3
    n = rows * nx * per_cell
    per = theta0 * d * d * 2e-3 / (4 / 3 * np.pi * r ** 3) / per_cell
    parcels = Parcels.create(rng.uniform(0, nx * d, n), rng.uniform(0, rows * d, n), radius=r,
                             density=2550.0, particles=per)
    params = MppicParams()
    u, v, p = np.zeros((nz, nx + 1)), np.zeros((nz + 1, nx)), np.zeros((nz, nx))
    history = []
    for _ in range(steps):
        moments = backend.scatter(parcels, frame, width)
        fields = grid_fields(frame, width, u, v, p, moments, params)
        seen = backend.gather(parcels, frame, fields)
        backend.push(parcels, seen, frame, fields, DT, params, RHO_F, MU, G)
        history.append((moments.volume_fraction.max(), parcels.z.mean(),
                        np.sqrt(np.mean(parcels.u ** 2 + parcels.v ** 2))))
    return np.array(history), params, frame, parcels


@pytest.mark.parametrize("backend_name", ["numpy", "taichi"])
def test_settled_bed_does_not_overpack_and_stays_at_rest(backend_name):
    history, params, frame, parcels = settle(get_backend(backend_name), steps=3000)
    theta_max, depth, speed = history.T
    # theta_p <= theta_cp (+ one step's inflow) for the whole run, impact of the falling cloud included
    assert theta_max.max() <= 1.01 * params.theta_cp
    # a dense bed formed ...
    assert theta_max[-1] >= 0.95 * params.theta_cp
    # ... and is at rest: no creep of the mean depth over the last 0.5 s, nearly all parcels exactly still
    assert abs(depth[-1] - depth[-500]) < 1e-3 * frame.dz
    assert speed[-1] < 0.01 * 0.067
    assert np.mean(np.hypot(parcels.u, parcels.v) < 1e-6) > 0.95
