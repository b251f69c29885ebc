"""The command line and Python API as a new user meets them: `summary`, folders that cannot be written, a
missing output folder, runs that did not complete, a self-documenting API (issue 31)."""

import inspect
import os
import subprocess
import sys
from pathlib import Path

import h5py
import pytest

import hfgpu

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "OMP_NUM_THREADS": "1"}


def hfgpu_cli(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "hfgpu.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=ENV, timeout=300)


@pytest.fixture(scope="module")
def radial(tmp_path_factory):
    """radial_I.toml run into a folder that did not exist (about 2 s)."""
    out = tmp_path_factory.mktemp("user") / "not" / "yet" / "radial.h5"
    done = hfgpu_cli("run", hfgpu.scene_path("radial_I.toml"), "--out", out, "--no-progress")
    assert done.returncode == 0, done.stderr
    return out


def test_run_creates_the_missing_output_folder(radial):
    assert radial.is_file() and hfgpu.open_results(radial).status == "complete"
    assert not radial.with_name(radial.name + ".lock").exists()


def test_summary_command_and_function_reprint_the_run_summary(radial):
    done = hfgpu_cli("summary", radial)
    assert done.returncode == 0, done.stderr
    assert "created area (one face)" in done.stdout and "status" in done.stdout and "complete" in done.stdout
    assert done.stdout.strip() == hfgpu.summary(radial).strip()
    area = float(done.stdout.split("created area (one face)")[1].split("m^2")[0].replace(" ", ""))
    assert area == pytest.approx(hfgpu.open_results(radial).summary["area"], rel=1e-3)


@pytest.mark.parametrize("command", [["plot", "--out", "{blocked}/figures"],
                                     ["export", "--format", "stimplan-xml", "--out", "{blocked}/frac.xml"]])
def test_an_output_folder_that_cannot_be_written_is_one_line_exit_2(radial, tmp_path, command):
    blocked = tmp_path / "a_file"
    blocked.write_text("not a folder")
    done = hfgpu_cli(command[0], radial, *[part.format(blocked=blocked) for part in command[1:]])
    assert done.returncode == 2
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert done.stderr.startswith(f"hfgpu {command[0]}: error:") and "a_file" in done.stderr


def test_a_run_that_did_not_complete_is_said_so(radial, tmp_path):
    cut = tmp_path / "cut.h5"
    cut.write_bytes(radial.read_bytes())
    with h5py.File(cut, "r+") as f:
        f.attrs["status"] = "interrupted"
    summary = hfgpu_cli("summary", cut)
    assert summary.returncode == 0 and 'status "interrupted"' in summary.stdout.splitlines()[0]
    plot = hfgpu_cli("plot", cut, "--out", tmp_path / "figures")
    assert plot.returncode == 0, plot.stderr
    assert "hfgpu: warning:" in plot.stderr and "not complete" in plot.stderr and "interrupted" in plot.stderr


def test_the_api_documents_itself(radial):
    parameters = inspect.signature(hfgpu.run).parameters
    assert {"progress", "rrd", "view", "connect", "resume", "viewer_required"} <= set(parameters)
    assert not any(p.kind is p.VAR_KEYWORD for p in parameters.values())
    assert {"workers", "scheduler", "resume", "progress"} <= set(inspect.signature(hfgpu.sweep).parameters)
    snapshot = hfgpu.open_results(radial).fracture_snapshots[-1]
    text = repr(snapshot)
    assert len(text) < 1000 and text.startswith("FractureSnapshot(time=370 s") and "width(25, 25)" in text
    with pytest.raises(hfgpu.HfgpuError, match="radial_I.toml"):
        hfgpu.scene_path("no_such.toml")


def test_the_readme_snippet_runs_from_any_folder(tmp_path):
    readme = (ROOT / "README.md").read_text()
    snippet = readme.split("```python\n", 1)[1].split("```", 1)[0]
    done = subprocess.run([sys.executable, "-c", snippet], cwd=tmp_path, capture_output=True, text=True, env=ENV,
                          timeout=300)
    assert done.returncode == 0, done.stderr


def test_ctrl_c_says_how_to_resume(monkeypatch, capsys, tmp_path):
    from hfgpu import cli

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "_run", interrupted)
    code = cli.main(["run", "scene.toml", "--out", str(tmp_path / "r.h5")])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 130 and lines[-1] == "hfgpu run: interrupted (SIGINT)"
    assert lines[0] == f"hfgpu run: what is done is kept; continue with: hfgpu run scene.toml --out {tmp_path / 'r.h5'} --resume"
