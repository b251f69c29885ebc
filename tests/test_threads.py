"""BLAS threads of a run (hfgpu/threads.py): one thread below the size rule, the library's default above it,
HFGPU_BLAS_THREADS overriding both, a bad value refused before any work."""

from __future__ import annotations

import pytest
from threadpoolctl import threadpool_info

from hfgpu.errors import HfgpuError
from hfgpu.threads import ENV, MIN_UNKNOWNS, blas_thread_limit, blas_threads


def _blas_threads() -> list[int]:
    return [p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"]


def test_auto_rule(monkeypatch):
    monkeypatch.delenv(ENV, raising=False)
    default = max(_blas_threads() or [1])
    assert blas_thread_limit(0) == 1 and blas_thread_limit(MIN_UNKNOWNS - 1) == 1
    assert blas_thread_limit(MIN_UNKNOWNS) == default
    with blas_threads():
        assert set(_blas_threads()) <= {1}
        with blas_threads(MIN_UNKNOWNS):  # a large solve inside a run gets the default back
            assert max(_blas_threads() or [default]) == default
        assert set(_blas_threads()) <= {1}
    assert max(_blas_threads() or [default]) == default


def test_override(monkeypatch):
    monkeypatch.setenv(ENV, "3")
    assert blas_thread_limit(0) == 3 and blas_thread_limit(10 * MIN_UNKNOWNS) == 3


@pytest.mark.parametrize("value", ["0", "two", "-1"])
def test_bad_value_is_a_clear_error(monkeypatch, value):
    monkeypatch.setenv(ENV, value)
    with pytest.raises(HfgpuError, match=rf"HFGPU_BLAS_THREADS: got '{value}'; allowed: 'auto' or a whole number"):
        blas_thread_limit(0)
