"""The one place hfgpu imports Taichi; initialises it once with the chosen architecture in float64.

The architecture comes from the caller (scene or CLI) or the environment variable ``HFGPU_ARCH``: "cpu" (the
default) or "cuda". Every kernel computes in float64, which Taichi's Vulkan, Metal and OpenGL backends do not
offer, so those are refused. Where CUDA is asked for but no CUDA device is there, Taichi runs on the CPU, and
:func:`init` returns the architecture that actually runs. CPU threads: ``cpu_threads``, else the environment
variable ``HFGPU_THREADS``, else one per core. Tests run on the CPU backend.

Taichi's banners ("[Taichi] version ..." at import, "[Taichi] Starting on arch=..." at init) are not printed:
they would land inside a run's progress bar, and the results' summary names the arch that ran. Setting
ENABLE_TAICHI_HEADER_PRINT=1 brings back the first.
"""

from __future__ import annotations

import contextlib
import io
import os

os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "False")
import taichi as ti  # noqa: E402 (after the banner setting)

from hfgpu.kernels.arches import ARCHES

_state: dict[str, str] = {}


def _position(self, node) -> str:
    """File, line and function of an AST node, for Taichi's compile messages."""
    return f'File "{self.file}", line {node.lineno + self.lineno_offset}, in {self.func.func.__name__}:\n'


def _lean_positions() -> None:
    """Taichi 1.7.4 formats, for every node of a kernel's Python AST while building it (in every process,
    offline cache or not), a source excerpt with a caret line for its messages (textwrap on each line): half
    of the time a process spends preparing the MP-PIC kernels (bench/bench_startup.py). Its messages keep the
    file, line and function, without the excerpt."""
    from taichi.lang.ast import ast_transformer_utils as utils

    if ti.__version__ == (1, 7, 4) and hasattr(utils.ASTTransformerContext, "get_pos_info"):
        utils.ASTTransformerContext.get_pos_info = _position


def init(arch: str | None = None, kernel_profiler: bool = False, cpu_threads: int | None = None) -> str:
    """Initialise Taichi once (float64 default); returns the architecture that runs, "cpu" or "cuda" (later
    calls return it without initialising again).

    fast_math is off: it lets LLVM reassociate, which breaks the split ln 2 reduction of the kernels' inline
    exp (kernels/elementary.py; 400 ulp at x = 700) and costs nothing measurable when on. The offline cache
    keeps compiled kernels across processes (~/.cache/taichi). ``kernel_profiler`` records kernel times
    (ti.profiler; bench/bench_kernels.py --profile)."""
    if "arch" in _state:
        return _state["arch"]
    name = (arch or os.environ.get("HFGPU_ARCH") or "cpu").lower()
    if name not in ARCHES:
        raise ValueError(f"HFGPU_ARCH / arch: got {name!r}; allowed: one of {list(ARCHES)} (the kernels "
                         "compute in float64, which Taichi's vulkan, metal and opengl backends lack)")
    threads = cpu_threads or int(os.environ.get("HFGPU_THREADS", "0") or 0) or None
    _lean_positions()
    with contextlib.redirect_stdout(io.StringIO()):  # Taichi prints "Starting on arch=..." there
        ti.init(arch=getattr(ti, name), default_fp=ti.f64, default_ip=ti.i32,
                log_level=ti.WARN, offline_cache=True, fast_math=False, kernel_profiler=kernel_profiler,
                **({} if threads is None else {"cpu_max_num_threads": threads}))
    _state["arch"] = "cuda" if ti.lang.impl.current_cfg().arch == ti.cuda else "cpu"
    return _state["arch"]


def thread_count() -> int | None:
    """CPU threads of the Taichi runtime (None on CUDA)."""
    if _state.get("arch") != "cpu":
        return None
    return int(ti.lang.impl.current_cfg().cpu_max_num_threads)


__all__ = ["ti", "init", "thread_count"]
