"""Local workers leave their compiled kernels in Taichi's offline cache before the cluster closes them (issue 31).
Taichi writes that cache when it is finalised; left to the worker's exit, the finalisation overran the 4 s Dask's
nanny gives a closing worker ("Worker process still alive after 4.0 seconds, killing"), and a worker killed before
it had written the cache left nothing for the next sweep."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: A process that compiles a kernel and ends as a killed worker does (os._exit: no atexit handler runs);
#: with "release", it first does what every local worker does once its members are done.
PROCESS = textwrap.dedent("""
    import os, sys
    from kernels.runtime import init, ti
    init("cpu")

    @ti.kernel
    def twice(x: ti.f64) -> ti.f64:
        return 2.0 * x

    assert twice(2.0) == 4.0
    if sys.argv[1] == "release":
        from hfgpu.ensemble.execute import release_kernels
        release_kernels()
    os._exit(0)
""")


def _cached(tmp_path: Path, mode: str) -> bool:
    """Whether the process left compiled kernels in an empty offline cache folder of its own."""
    cache, script = tmp_path / mode, tmp_path / "process.py"   # Taichi reads a kernel's source from its file
    script.write_text(PROCESS, encoding="utf-8")
    env = {**os.environ, "TI_OFFLINE_CACHE_FILE_PATH": str(cache), "HFGPU_THREADS": "1",
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    subprocess.run([sys.executable, str(script), mode], cwd=ROOT, env=env, check=True, timeout=300,
                   capture_output=True)
    return any(cache.glob("*.tic"))


def test_released_workers_leave_their_kernels_in_the_cache(tmp_path):
    assert _cached(tmp_path, "release")


def test_a_worker_killed_without_release_leaves_none(tmp_path):
    assert not _cached(tmp_path, "kill")
