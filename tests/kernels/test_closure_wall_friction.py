"""The wall-friction family (kernels/closures/wall_friction.py): the Taichi twin of f_t against
wall_friction_factor_numpy on the CPU backend, laminar and Dean, across the transition at Re = 899."""

import numpy as np
import pytest

from hfgpu.kernels.closures import wall_friction
from hfgpu.kernels.runtime import ti

pytestmark = pytest.mark.usefixtures("taichi_cpu")
F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
RHO, MU = 1000.0, 1e-3


@ti.kernel
def _factor(speed: F1, width: F1, out: F1, code: ti.i32):
    for p in speed:
        out[p] = wall_friction.wall_friction_factor(speed[p], width[p], MU, RHO, code)


@pytest.mark.parametrize("law", wall_friction.WALL_FRICTION_LAWS)
def test_twin_matches_numpy(law):
    rng = np.random.default_rng(3)
    width = rng.uniform(1e-4, 2e-2, 20000)
    speed = 10.0 ** rng.uniform(-4.0, 1.0, width.size)  # Re from ~1e-5 to 2e5
    speed[:100] = 0.0
    code = wall_friction.wall_friction_code(law)
    got = np.empty_like(speed)
    _factor(speed, width, got, code)
    want = wall_friction.wall_friction_factor_numpy(speed, width, MU, RHO, code)
    assert (np.any(want > 1.0) and np.any(want == 1.0)) if law == "dean" else np.all(want == 1.0)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0.0)
