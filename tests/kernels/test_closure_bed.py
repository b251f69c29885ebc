"""The bed family (kernels/closures/bed.py): the Taichi twins of bed friction and of the threshold of motion
against their NumPy references on the CPU backend: grains at rest, sliding either way and stopped by friction;
fine to coarse grains, heavy and neutrally buoyant, fluid speeds across the threshold, both wall laws."""

import numpy as np
import pytest

from hfgpu.kernels.closures import bed
from hfgpu.kernels.runtime import ti

pytestmark = pytest.mark.usefixtures("taichi_cpu")
F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
I1 = ti.types.ndarray(dtype=ti.i32, ndim=1)
RHO_F, MU, G, MU_B, DT = 1000.0, 1e-3, 9.81, 0.543, 1e-3


@ti.kernel
def _friction(u: F1, buoyant_g: F1, den: F1, out: F1):
    for p in u:
        out[p] = bed.bed_friction(u[p], buoyant_g[p], DT, den[p], MU_B)


@ti.kernel
def _held(speed: F1, width: F1, diameter: F1, rho_p: F1, out: I1, code: ti.i32):
    for p in speed:
        out[p] = bed.held(speed[p], width[p], diameter[p], rho_p[p], RHO_F, MU, G, code)


def test_bed_friction_twin_matches_numpy():
    rng = np.random.default_rng(11)
    n = 20000
    u = rng.uniform(-0.05, 0.05, n)
    u[:100] = 0.0
    buoyant_g = (1.0 - RHO_F / rng.uniform(1000.0, 3600.0, n)) * G
    den = 1.0 + DT * rng.uniform(0.0, 5e3, n)
    got = np.empty_like(u)
    _friction(u, buoyant_g, den, got)
    want = bed.bed_friction_numpy(u, np.ones(n, bool), buoyant_g, DT, den, MU_B)
    stopped = want == 0.0
    assert stopped[100:].any() and (~stopped).any() and np.all(np.abs(want) <= np.abs(u))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0.0)
    assert np.array_equal(bed.bed_friction_numpy(u, np.zeros(n, bool), buoyant_g, DT, den, MU_B), u)


@pytest.mark.parametrize("code", [0, 1])
def test_threshold_of_motion_twin_matches_numpy(code):
    rng = np.random.default_rng(13)
    n = 20000
    diameter = rng.uniform(0.1e-3, 1.0e-3, n)
    rho_p = rng.uniform(1050.0, 3600.0, n)
    rho_p[:50] = RHO_F  # neutrally buoyant: never held
    width = rng.uniform(1e-3, 1e-2, n)
    speed = rng.uniform(-1.0, 1.0, n)
    got = np.empty(n, np.int32)
    _held(speed, width, diameter, rho_p, got, code)
    with np.errstate(divide="ignore", invalid="ignore"):
        want = bed.held_numpy(speed, width, diameter, rho_p, RHO_F, MU, G, code)
    assert want.any() and not want.all() and not want[:50].any()
    np.testing.assert_array_equal(got.astype(bool), want)
