"""Two runs never write one results file: the second is refused before any work (hfgpu.io.results.acquire_lock)."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from hfgpu.errors import HfgpuError
from hfgpu.io.results import ResultsWriter, open_results

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "hfgpu" / "scenes" / "radial_I.toml"
HOLDER = """
import sys, time
from hfgpu.io.results import ResultsWriter
from hfgpu.scene import load_scene
writer = ResultsWriter(sys.argv[1], load_scene(sys.argv[2]))
print("holding", flush=True)
time.sleep(60)
"""


def _holder(out: Path) -> subprocess.Popen:
    """A process that opened ``out`` as a results writer and keeps it (a run in progress)."""
    proc = subprocess.Popen([sys.executable, "-c", HOLDER, str(out), str(SCENE)], stdout=subprocess.PIPE, text=True,
                            cwd=ROOT, env={**os.environ, "OMP_NUM_THREADS": "1"})
    assert proc.stdout.readline().strip() == "holding"
    return proc


def test_second_writer_is_refused_by_the_cli(tmp_path):
    out = tmp_path / "mix.h5"
    first = _holder(out)
    try:
        assert (tmp_path / "mix.h5.lock").read_text() == str(first.pid)
        started = time.monotonic()
        second = subprocess.run([sys.executable, "-m", "hfgpu.cli", "run", str(SCENE), "--out", str(out),
                                 "--no-progress"], capture_output=True, text=True, cwd=ROOT, timeout=120,
                                env={**os.environ, "OMP_NUM_THREADS": "1"})
        assert second.returncode == 2, second.stderr
        assert "being written by another run" in second.stderr and f"process {first.pid}" in second.stderr
        assert "Traceback" not in second.stderr
        assert open_results(out).status == "running"   # the first run's file, untouched
        assert time.monotonic() - started < 60
    finally:
        first.kill()
        first.wait()


def test_a_dead_writers_lock_is_stale(tmp_path):
    out = tmp_path / "mix.h5"
    first = _holder(out)
    first.send_signal(signal.SIGKILL)
    first.wait()
    assert (tmp_path / "mix.h5.lock").exists()   # a killed run cannot remove it
    from hfgpu.scene import load_scene

    writer = ResultsWriter(out, load_scene(SCENE))   # taken over
    assert (tmp_path / "mix.h5.lock").read_text() == str(os.getpid())
    writer.close()
    assert not (tmp_path / "mix.h5.lock").exists()
    assert open_results(out).status == "complete"


def test_a_live_lock_refuses_resume_and_create_in_process(tmp_path):
    out = tmp_path / "mix.h5"
    first = _holder(out)
    try:
        from hfgpu.scene import load_scene

        with pytest.raises(HfgpuError, match="being written by another run"):
            ResultsWriter(out, load_scene(SCENE))
        with pytest.raises(HfgpuError, match="being written by another run"):
            ResultsWriter.reopen(out)
    finally:
        first.kill()
        first.wait()
