"""[mppic] damping_scheme (hfgpu.kernels.closures.damping.DAMPING_SCHEMES): the collision damping is an exchange
between the grains of a cell, so it should not change how their mean velocity answers drag and gravity.

"relaxation" keeps that answer exactly (the mean of u^o + dt h/(1 + dt h) (<u> - u^o) is <u>); the published
"implicit" form slows it by (1 + dt (D + h)) / (1 + dt D) (docs/proppant-closures.md, "Collision damping in a
dense cell"). Drag here without its Reynolds term (drag_re_coefficient 0), so that D is the same for every grain."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu import SceneError
from hfgpu.kernels.layout import SEEN_FIELDS
from hfgpu.proppant import particle_ops_numpy as ref
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels

N, DT, RHO_F, MU, G = 64, 0.5, 1000.0, 1e-3, 9.81


def cell_of_grains(rate: float) -> tuple[Parcels, ref.ParcelFluid]:
    """N grains of one cell with scattered velocities, seeing the same fluid, their own mean and damping ``rate``."""
    rng = np.random.default_rng(3)
    parcels = Parcels.create(np.zeros(N), np.zeros(N), radius=1e-4, density=2650.0, particles=1.0)
    parcels.u[:] = rng.normal(0.0, 0.05, N)
    parcels.v[:] = rng.normal(0.02, 0.05, N)
    seen = {name: np.zeros(N) for name in SEEN_FIELDS}
    seen.update(fluid_u=np.full(N, 0.1), fluid_v=np.full(N, -0.03), dpdz=np.full(N, -2000.0),
                volume_fraction=np.full(N, 0.5), mean_u=np.full(N, parcels.u.mean()),
                mean_v=np.full(N, parcels.v.mean()), damping_rate=np.full(N, rate), width=np.full(N, 1e-3))
    return parcels, ref.ParcelFluid(**seen)


def velocities(scheme: str, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """The push's velocity step (particle_ops_numpy.velocity_step, before the limiter and the walls)."""
    parcels, seen = cell_of_grains(rate)
    params = MppicParams(damping_scheme=scheme, drag_re_coefficient=0.0)
    buoyant_g = (1.0 - RHO_F / parcels.density) * G
    return ref.velocity_step(parcels, seen, DT, params, RHO_F, MU, buoyant_g)[:2]


def test_relaxation_keeps_the_mean_answer_and_damps_the_spread():
    """The mean after the step equals the undamped one to 1e-12 at h = 1e5 1/s; the spread about it shrinks to
    at most 1/(1 + dt h) of the undamped spread."""
    u0, v0 = velocities("relaxation", 0.0)
    u, v = velocities("relaxation", 2e5)
    assert u.mean() == pytest.approx(u0.mean(), rel=1e-12) and v.mean() == pytest.approx(v0.mean(), rel=1e-12)
    assert np.std(u) <= np.std(u0) / (1.0 + DT * 1e5) * (1.0 + 1e-9)


def test_implicit_damping_slows_the_mean():
    """The published form at h = 1e5 1/s: the mean moves from <u^o> by (1 + dt D) / (1 + dt (D + h)) of the
    undamped change (D from the drag law)."""
    parcels, seen = cell_of_grains(2e5)
    drag = float(ref.closures.drag_rate(np.zeros(1), np.array([1e-4]), np.array([2650.0]), np.array([0.5]), RHO_F,
                                        MU, MppicParams(drag_re_coefficient=0.0))[0])
    free = velocities("implicit", 0.0)[0].mean() - parcels.u.mean()
    damped = velocities("implicit", 2e5)[0].mean() - parcels.u.mean()
    assert damped == pytest.approx(free * (1.0 + DT * drag) / (1.0 + DT * (drag + 1e5)), rel=1e-9)


def test_damping_scheme_key():
    assert MppicParams().damping_scheme == "relaxation"
    with pytest.raises(SceneError) as err:
        MppicParams(damping_scheme="explicit")
    assert str(err.value) == ("scene key 'mppic.damping_scheme': got 'explicit'; allowed: one of "
                              "['implicit', 'relaxation']")
