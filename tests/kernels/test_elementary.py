"""Inline exp and log of the Taichi kernels (kernels/elementary.py) against NumPy's (glibc / SIMD libm, correctly
rounded to within an ulp) over the ranges the particle kernels use and beyond."""

import numpy as np
import pytest

from hfgpu.kernels.runtime import init, ti

init("cpu")

from hfgpu.kernels import elementary  # noqa: E402  (after init: the module defines Taichi functions)

F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)


@ti.kernel
def _exp_log(x: F1, out_exp: F1, out_log: F1):
    for p in x:
        out_exp[p] = elementary.exp(x[p])
        out_log[p] = elementary.log(ti.abs(x[p]))


def _error_in_eps(got, want):
    """Largest relative error |got - want| / |want| in units of the float64 epsilon 2^-52."""
    return np.max(np.abs(got - want) / np.abs(want)) / np.finfo(np.float64).eps


def _evaluate(x):
    e, lg = np.empty_like(x), np.empty_like(x)
    _exp_log(x, e, lg)
    return e, lg


def test_exp_within_a_few_epsilon():
    rng = np.random.default_rng(0)
    x = np.concatenate([rng.uniform(-700.0, 700.0, 100000), rng.uniform(-5.0, 5.0, 100000),
                        rng.normal(0.0, 1e-3, 10000), [0.0, 1.0, -1.0, np.log(2.0), 709.0, -700.0]])
    got, _ = _evaluate(x)
    assert _error_in_eps(got, np.exp(x)) <= 4.0  # measured 1.97 over 2e6 points
    assert got[x == 0.0][0] == 1.0


def test_log_within_a_few_epsilon():
    rng = np.random.default_rng(1)
    x = np.concatenate([10.0 ** rng.uniform(-300.0, 300.0, 100000), rng.uniform(0.3, 2.0, 100000),
                        1.0 + rng.normal(0.0, 1e-6, 10000), [1.0, 2.0, np.sqrt(2.0), 0.5, 5e-324, 1e-310]])
    _, got = _evaluate(x)
    want = np.log(x)
    near_one = np.abs(x - 1.0) < 1e-3
    assert _error_in_eps(got[~near_one & (want != 0)], want[~near_one & (want != 0)]) <= 4.0  # measured 1.8
    # near 1 log(x) is small: error relative to the ulp of log(x) itself
    assert _error_in_eps(got[near_one & (want != 0)], want[near_one & (want != 0)]) <= 4.0
    assert got[x == 1.0][0] == 0.0


def test_exp_clamps_outside_normal_range():
    got, _ = _evaluate(np.array([-800.0, 1e4]))
    assert 0.0 < got[0] <= np.exp(-708.0) * (1 + 1e-15)
    assert got[1] == pytest.approx(np.exp(709.0), rel=1e-15)
