"""The one place hfgpu imports Taichi; initialises it once with the chosen architecture in float64.

The architecture comes from the caller (scene or CLI) or the environment variable ``HFGPU_ARCH``
("cpu", "gpu", "cuda", "vulkan", "metal"); default "cpu". Tests run on the CPU backend.
"""

from __future__ import annotations

import os

import taichi as ti

_ARCHES = {"cpu": "cpu", "gpu": "gpu", "cuda": "cuda", "vulkan": "vulkan", "metal": "metal"}
_state: dict[str, str] = {}


def init(arch: str | None = None, kernel_profiler: bool = False, cpu_threads: int | None = None) -> str:
    """Initialise Taichi once (float64 default); later calls return the architecture in use.

    fast_math is off: it lets LLVM reassociate, which breaks the split ln 2 reduction of the kernels' inline
    exp (kernels/elementary.py; 400 ulp at x = 700) and costs nothing measurable when on. ``kernel_profiler``
    records kernel times (ti.profiler; bench/bench_kernels.py --profile); ``cpu_threads`` caps the CPU thread
    pool (default: all cores)."""
    if "arch" in _state:
        return _state["arch"]
    name = (arch or os.environ.get("HFGPU_ARCH") or "cpu").lower()
    if name not in _ARCHES:
        raise ValueError(f"HFGPU_ARCH / arch {name!r}: allowed {sorted(_ARCHES)}")
    ti.init(arch=getattr(ti, _ARCHES[name]), default_fp=ti.f64, default_ip=ti.i64,
            log_level=ti.WARN, offline_cache=True, fast_math=False, kernel_profiler=kernel_profiler,
            **({} if cpu_threads is None else {"cpu_max_num_threads": cpu_threads}))
    _state["arch"] = name
    return name


__all__ = ["ti", "init"]
