"""The collision-damping family (kernels/closures/damping.py): the Taichi twin of O'Rourke & Snider's (2010)
damping rate against damping_rate_numpy on the CPU backend, damping on and off, theta_p from 0 through the
threshold and close packing, zero and negative variance, zero Sauter radius."""

import numpy as np
import pytest

from hfgpu.kernels.closures import damping
from hfgpu.kernels.runtime import ti

pytestmark = pytest.mark.usefixtures("taichi_cpu")
F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
THETA_CP, EPSILON, RESTITUTION, THRESHOLD = 0.6, 1e-7, 0.9, 0.8


@ti.kernel
def _damping(theta: F1, variance: F1, sauter: F1, out: F1, enabled: ti.f64):
    for p in theta:
        out[p] = damping.damping_rate(theta[p], variance[p], sauter[p], enabled, RESTITUTION, THRESHOLD, THETA_CP,
                                      EPSILON)


@pytest.mark.parametrize("enabled", [True, False])
def test_twin_matches_numpy(enabled):
    rng = np.random.default_rng(5)
    n = 20000
    theta = rng.uniform(0.0, 0.7, n)
    theta[:100] = 0.0
    theta[100:200] = THETA_CP
    theta[200:300] = THRESHOLD * THETA_CP
    variance = rng.uniform(-1e-6, 1e-3, n)
    variance[300:400] = 0.0
    sauter = rng.uniform(0.05e-3, 1e-3, n)
    sauter[400:500] = 0.0
    got = np.empty_like(theta)
    _damping(theta, variance, sauter, got, 1.0 if enabled else 0.0)
    want = damping.damping_rate_numpy(theta, variance, sauter, enabled, RESTITUTION, THRESHOLD, THETA_CP, EPSILON)
    assert np.any(want > 0.0) == enabled
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0.0)
