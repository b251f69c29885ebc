"""Fixtures of the kernel tests."""

import pytest

from hfgpu.kernels.runtime import init


@pytest.fixture(scope="module")
def taichi_cpu():
    """Taichi on the CPU backend, started when the tests run rather than when pytest collects a module (a start
    during collection makes tests/kernels/test_elementary.py's NumPy log of subnormals give -inf)."""
    init("cpu")
