"""Packing limiter of the push: a suspension settling onto the floor of a slot builds a bed that does not
over-pack and then stays at rest (Snider 2001 eqs. 39-41, as in MFIX's integrate_time_pic.f90, plus the push's
packing cap); Coulomb bed friction holds grains resting on a bed or floor against a weak tangential flow and
slows sliding ones."""

import numpy as np
import pytest

from hfgpu.proppant import closures
from hfgpu.kernels.stencil_numpy import weights
from hfgpu.proppant.interpolation import active_nodes, interpolate
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

from .engine_step import MU, RHO_F, G, engine_for, particle_step

DT = 1e-3


def settle(backend_name, steps, theta0=0.2, nz=16, nx=4, rows=8, per_cell=20, seed=0):
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
    still = dict(u=np.zeros((nz, nx + 1)), v=np.zeros((nz + 1, nx)), pressure=np.zeros((nz, nx)))
    history = []
    for _ in range(steps):
        _, engine = particle_step(backend_name, frame, width, parcels, still, params, dt=DT)
        history.append((engine.moments().volume_fraction.max(), parcels.z.mean(),
                        np.sqrt(np.mean(parcels.u ** 2 + parcels.v ** 2))))
    return np.array(history), params, frame, parcels


@pytest.mark.parametrize("backend_name", ["numpy", "taichi"])
def test_settled_bed_does_not_overpack_and_stays_at_rest(backend_name):
    history, params, frame, parcels = settle(backend_name, steps=3000)
    theta_max, depth, speed = history.T
    # theta_p <= theta_cp (+ one step's inflow) for the whole run, impact of the falling cloud included
    assert theta_max.max() <= 1.01 * params.theta_cp
    # a dense bed formed ...
    assert theta_max[-1] >= 0.95 * params.theta_cp
    # ... and is at rest: no creep of the mean depth over the last 0.5 s, nearly all parcels exactly still
    assert abs(depth[-1] - depth[-500]) < 1e-3 * frame.dz
    assert speed[-1] < 0.01 * 0.067
    assert np.mean(np.hypot(parcels.u, parcels.v) < 1e-6) > 0.95


@pytest.mark.parametrize("backend_name", ["numpy", "taichi"])
def test_bed_friction_holds_resting_grains_and_slows_sliding_ones(backend_name):
    """Coulomb bed friction in the push (hfgpu.kernels.closures.bed): parcels at rest in a dense bottom
    row (theta_p = 0.55 >= friction_volume_fraction 0.5, uniform: parcels at cell centres) and light ones in
    the row above it (the cell below is dense) under a uniform fluid velocity U along the bed. From rest with
    one drag solve and no damping, Eq. 43 gives u = dt D U / (1 + dt D); friction removes
    dt mu_b (1 - rho_f/rho_p) g / (1 + dt D) of it, or all of it (static friction: held where D U < mu_b g').
    In a loose bottom row (theta_p = 0.3) it does nothing to parcels at the cell centres, but acts on the same
    parcels lying on the floor (within one diameter of it). D is Eq. 13-15 at the slip U and the theta_p the
    parcel sees (the scatter before the push)."""
    d, w, r, rho_p = 5e-3, 2e-3, 0.225e-3, 2550.0
    frame = GridFrame(d, d, d / 2, d / 2)
    width = np.full((2, 3), w)
    g_sub = (1.0 - RHO_F / rho_p) * G
    for theta, dense, bottom in ((0.55, True, 1.5 * d), (0.3, False, 1.5 * d), (0.3, True, 2 * d - 1.5 * r)):
        n = 60
        x = np.concatenate([np.tile([0.5 * d, 1.5 * d, 2.5 * d], n // 3), [0.5 * d, 1.5 * d, 2.5 * d]])
        z = np.concatenate([np.full(n, bottom), np.full(3, 0.5 * d)])  # bottom row, row above
        per = theta * 3 * d * d * w / (4 / 3 * np.pi * r ** 3) / n
        particles = np.concatenate([np.full(n, per), np.full(3, 1e-3)])
        for velocity in (0.002, 0.1):
            u = np.full((2, 4), velocity)
            v, p = np.zeros((3, 3)), np.zeros((2, 3))
            result = {}
            for mu_b in (0.0, 0.543):
                params = MppicParams(damping=False, drag_iterations=1, bed_friction=mu_b, shields_deposition=False)
                parcels = Parcels.create(x, z, radius=r, density=rho_p, particles=particles)
                engine = engine_for(backend_name, frame, width, params)
                engine.set_parcels(parcels)
                theta_seen = interpolate(engine.moments().volume_fraction,
                                         *weights(x, z, frame, "cell", active_nodes(width)[0]))
                drag = closures.drag_rate(velocity, r, rho_p, theta_seen, RHO_F, MU, params)
                particle_step(backend_name, frame, width, parcels, dict(u=u, v=v, pressure=p), params, dt=DT)
                result[mu_b] = parcels.u.copy(), drag
            free, drag = result[0.0]
            held, _ = result[0.543]
            np.testing.assert_allclose(free, DT * drag * velocity / (1 + DT * drag), rtol=1e-12)
            rests = np.full(n + 3, dense)
            rests[n:] = theta > 0.5  # the light parcels above rest on the bottom row only if it is dense
            np.testing.assert_array_equal(held[~rests], free[~rests])
            if velocity == 0.002:
                assert np.all(drag * velocity < 0.543 * g_sub) and np.all(held[rests] == 0.0)
            else:
                expected = free - DT * 0.543 * g_sub / (1 + DT * drag)
                assert np.all(expected > 0.0)
                np.testing.assert_allclose(held[rests], expected[rests], rtol=1e-12)
