"""The particle-stress family (kernels/closures/particle_stress.py): the Taichi twins of the Harris-Crighton
stress (Eq. 16) and of Snider's (2001) packing limiter against their NumPy references on the CPU backend."""

import numpy as np
import pytest

from hfgpu.kernels.closures import particle_stress
from hfgpu.kernels.runtime import ti

pytestmark = pytest.mark.usefixtures("taichi_cpu")
F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)


@ti.kernel
def _stress(theta: F1, out: F1, p_s: ti.f64, beta: ti.f64, theta_cp: ti.f64, epsilon: ti.f64):
    for p in theta:
        out[p] = particle_stress.particle_stress(theta[p], p_s, beta, theta_cp, epsilon)


@ti.kernel
def _limiter(delta: F1, slip: F1, grad: F1, out: F1, restitution: ti.f64):
    for p in delta:
        out[p] = particle_stress.packing_limiter(delta[p], slip[p], grad[p], restitution)


@pytest.mark.parametrize("p_s, beta, theta_cp, epsilon", [(100.0, 2.0, 0.6, 1e-7), (5.0, 3.0, 0.63, 1e-3),
                                                           (1e3, 2.5, 0.55, 1e-8)])
def test_stress_twin_matches_numpy(p_s, beta, theta_cp, epsilon):
    """theta_p from 0 through close packing (where the eps (1 - theta_p) branch of the max takes over) to 1."""
    rng = np.random.default_rng(3)
    theta = np.concatenate([rng.uniform(0.0, 0.7, 20000), theta_cp + rng.normal(0.0, 1e-6, 200),
                            [0.0, 1e-300, theta_cp, np.nextafter(theta_cp, 0.0), np.nextafter(theta_cp, 1.0), 0.99]])
    theta = np.clip(theta, 0.0, None)
    got = np.empty_like(theta)
    _stress(theta, got, p_s, beta, theta_cp, epsilon)
    want = particle_stress.particle_stress_numpy(theta, p_s, beta, theta_cp, epsilon)
    assert np.all(np.isfinite(want)) and got[theta == 0.0].max() == 0.0
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0.0)


def test_limiter_twin_matches_numpy():
    """Both signs of grad tau, of delta and of the bound, zeros included."""
    rng = np.random.default_rng(4)
    n = 20000
    delta, slip, grad = (rng.normal(0.0, 1.0, n) for _ in range(3))
    for arr in (delta, slip, grad):
        arr[rng.random(n) < 0.05] = 0.0
    got = np.empty_like(delta)
    _limiter(delta, slip, grad, got, 0.9)
    np.testing.assert_array_equal(got, particle_stress.packing_limiter_numpy(delta, slip, grad, 0.9))
