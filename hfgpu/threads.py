"""BLAS threads of a run. OpenBLAS (NumPy's and SciPy's) uses every core by default; on small dense solves its
threads buy little on an idle machine and cost a great deal on a busy one, where they spin waiting for each
other (bench/bench_blas.py, 2 cores, dense LU and solve of n unknowns, 1 thread against 2):

    idle machine:           n = 300: 1.1x slower with 2,  n = 1000: 1.4x faster,  n >= 2000: 1.7x faster
    both cores busy:        n = 300: 200x slower,         n = 1000: 5x slower,    n = 2000: 1.5x slower

So a run uses one BLAS thread, except the fracture engine's Newton solves of at least ``MIN_UNKNOWNS`` unknowns,
which use the library's default. ``HFGPU_BLAS_THREADS`` overrides it: an integer is the thread count for
everything, "auto" (the default) is the rule above.
"""

from __future__ import annotations

import functools
import os
from contextlib import contextmanager
from typing import Iterator

from .errors import HfgpuError

#: Unknowns from which the fracture engine's dense solves use every BLAS thread (rule "auto").
MIN_UNKNOWNS = 2000
ENV = "HFGPU_BLAS_THREADS"


def blas_thread_limit(unknowns: int) -> int:
    """The BLAS threads for a solve of ``unknowns`` unknowns."""
    value = os.environ.get(ENV, "auto").strip().lower()
    if value == "auto":
        return _controller()[1] if unknowns >= MIN_UNKNOWNS else 1
    try:
        threads = int(value)
    except ValueError:
        threads = 0
    if threads < 1:
        raise HfgpuError(f"{ENV}: got {value!r}; allowed: 'auto' or a whole number of threads >= 1")
    return threads


@functools.lru_cache(maxsize=1)
def _controller():
    """threadpoolctl's controller of the loaded libraries and the BLAS threads they had at its creation."""
    from threadpoolctl import ThreadpoolController

    controller = ThreadpoolController()
    return controller, max([p["num_threads"] for p in controller.info() if p["user_api"] == "blas"] or [1])


@contextmanager
def blas_threads(unknowns: int = 0) -> Iterator[None]:
    """Within the block, BLAS uses :func:`blas_thread_limit` (``unknowns``) threads (0: the run's default)."""
    limit = blas_thread_limit(unknowns)
    with _controller()[0].limit(limits=limit, user_api="blas"):
        yield
