"""The drag family (kernels/closures/drag.py): the Taichi twin (hindered_stokes, then drag_rate, composed as the
push composes them) against drag_rate_numpy on the CPU backend, both laws, Re across 1000, theta_p from 0 to
beyond close packing."""

import numpy as np
import pytest

from hfgpu.kernels.closures import drag
from hfgpu.kernels.runtime import ti

pytestmark = pytest.mark.usefixtures("taichi_cpu")
F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
RHO_F, MU, THETA_CP, RE_COEFFICIENT = 1000.0, 1e-3, 0.6, 0.15


@ti.kernel
def _drag(slip: F1, radius: F1, rho_p: F1, theta: F1, out: F1, law: ti.i32):
    for p in slip:
        stokes = drag.STOKES_FACTOR * MU * (1.0 / rho_p[p]) / (radius[p] * radius[p])
        hinder, snider = drag.hindered_stokes(stokes, theta[p], THETA_CP, law)
        re = (2.0 * RHO_F / MU) * radius[p] * slip[p]
        out[p] = drag.drag_rate(re, hinder, snider, law, RE_COEFFICIENT)


def inputs():
    """Random parcels and slips with Re_p from 0 to ~1e4 (both sides of Re = 1000) and theta_p at 0, at and past
    close packing."""
    rng = np.random.default_rng(7)
    n = 20000
    radius = rng.uniform(0.05e-3, 1e-3, n)
    re = np.concatenate([10.0 ** rng.uniform(-6.0, 4.0, n - 8), [0.0, 1e-300, 999.0, 999.999, 1000.001, 1001.0,
                                                                    1e4, 0.0]])
    slip = re * MU / (2.0 * RHO_F * radius)
    theta = rng.uniform(0.0, 0.65, n)
    theta[:200] = 0.0
    theta[200:400] = THETA_CP
    theta[400:500] = 0.7
    return slip, radius, rng.uniform(1050.0, 3500.0, n), theta


@pytest.mark.parametrize("law", drag.DRAG_LAWS)
def test_twin_matches_numpy(law):
    code = drag.DRAG_LAWS.index(law)
    slip, radius, rho_p, theta = inputs()
    got = np.empty_like(slip)
    _drag(slip, radius, rho_p, theta, got, code)
    want = drag.drag_rate_numpy(slip, radius, rho_p, theta, RHO_F, MU, THETA_CP, code, RE_COEFFICIENT)
    assert np.all(np.isfinite(want))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0.0)
