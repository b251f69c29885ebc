"""The hfgpu command: one clear line and exit code 2 for bad input, results and figures otherwise."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
SCRIPT = Path(sys.executable).with_name("hfgpu")
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "hfgpu.cli"]
ENV = dict(os.environ, PYTHONPATH=str(HERE / "io") + os.pathsep + os.environ.get("PYTHONPATH", ""))

SCENE = """
[run]
end_time = "10 s"
physics = ["fracture"]
[rock]
youngs_modulus = "40 GPa"
poisson_ratio = {nu}
min_stress = "60 MPa"
[fluid]
viscosity = "0.08 Pa*s"
[injection]
depth = "0 m"
schedule = [{{ until = "10 s", rate = "0.05 m**3/s" }}]
[mesh]
cell_size = "2 m"
[output]
every = "2.5 s"
"""

# runs the CLI in-process with a fake fracture simulator (argv: fail_at or "none", then CLI arguments)
WITH_FAKE = textwrap.dedent("""
    import sys, types
    import io_fakes as fakes
    from hfgpu.cli import main
    fail_at = None if sys.argv[1] == "none" else int(sys.argv[1])
    module = types.ModuleType("hfgpu.fracture.simulator")
    module.simulate = lambda scene, sink, progress=None, **checkpoints: fakes.simulate_fracture(
        scene, sink, progress, fail_at=fail_at)
    sys.modules[module.__name__] = module
    sys.exit(main(sys.argv[2:]))
""")


def _cli(*args, fake=None):
    command = [sys.executable, "-c", WITH_FAKE, fake] if fake else COMMAND
    return subprocess.run([*command, *map(str, args)], capture_output=True, text=True, env=ENV, timeout=120)


def _one_clean_line(done):
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2, done.stderr
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    return lines[0]


def test_check_bad_scene_one_line_exit_2(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(SCENE.format(nu=0.7))
    line = _one_clean_line(_cli("check", path))
    assert "rock.poisson_ratio" in line and "0.7" in line and "< 0.5" in line


def test_check_good_scene_and_missing_file(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(SCENE.format(nu=0.15))
    done = _cli("check", path)
    assert done.returncode == 0 and "ok; physics fracture" in done.stdout
    assert "cannot read the scene file" in _one_clean_line(_cli("check", tmp_path / "absent.toml"))


def test_run_bad_scene_exit_2_and_no_results_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(SCENE.format(nu="-1"))
    assert "rock.poisson_ratio" in _one_clean_line(_cli("run", path, "--out", tmp_path / "r.h5"))
    assert not (tmp_path / "r.h5").exists()


def test_run_then_plot(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(SCENE.format(nu=0.15))
    done = _cli("run", path, "--out", tmp_path / "r.h5", fake="none")
    assert done.returncode == 0, done.stderr
    assert "fluid efficiency" in done.stdout and "s simulated" in done.stderr  # table and progress bar
    done = _cli("plot", tmp_path / "r.h5")
    assert done.returncode == 0, done.stderr
    written = [Path(p) for p in done.stdout.split()]
    assert len(written) == 5 and all(p.exists() and p.parent.name == "r_plots" for p in written)


def test_failed_run_exit_2_and_status_in_file(tmp_path):
    from hfgpu import open_results

    path = tmp_path / "good.toml"
    path.write_text(SCENE.format(nu=0.15))
    done = _cli("run", path, "--out", tmp_path / "r.h5", "--no-progress", fake="25")
    line = _one_clean_line(done)
    assert line.startswith("hfgpu run: error: Newton did not converge (t = 6.25 s")
    assert done.stdout == ""
    assert open_results(tmp_path / "r.h5").status.startswith("failed: Newton did not converge")


@pytest.mark.parametrize("args", [(), ("run", "scene.toml"), ("frobnicate",)])
def test_usage_errors_exit_2(args):
    assert _cli(*args).returncode == 2


def test_plot_of_a_file_that_is_not_results(tmp_path):
    (tmp_path / "x.h5").write_bytes(b"not hdf5")
    assert "cannot open results file" in _one_clean_line(_cli("plot", tmp_path / "x.h5"))


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("viewer", ["connect", "view"])
def test_unreachable_viewer_is_found_before_the_run(viewer, tmp_path):
    """Nothing listening at --connect, or --view without a display: the run goes on without the viewer and says
    so in one line; with --viewer-required it stops before any work (exit 2, no results file)."""
    from hfgpu import open_results

    path = tmp_path / "good.toml"
    path.write_text(SCENE.format(nu=0.15))
    args = (["--connect", f"rerun+http://127.0.0.1:{_free_port()}/proxy"] if viewer == "connect" else ["--view"])
    env = {k: v for k, v in ENV.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    command = [sys.executable, "-c", WITH_FAKE, "none"]
    done = subprocess.run([*command, "run", str(path), "--out", str(tmp_path / "r.h5"), "--no-progress", *args],
                          capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    line = done.stderr.strip().splitlines()
    assert len(line) == 1 and line[0].endswith("; running without it"), done.stderr
    assert ("nothing reachable at 127.0.0.1" if viewer == "connect" else "no display") in line[0]
    assert open_results(tmp_path / "r.h5").status == "complete"
    stopped = subprocess.run([*command, "run", str(path), "--out", str(tmp_path / "s.h5"), "--viewer-required",
                              *args], capture_output=True, text=True, env=env, timeout=120)
    assert "the run needs its viewer (--viewer-required)" in _one_clean_line(stopped)
    assert not (tmp_path / "s.h5").exists()
