"""Sweeps on a local Dask cluster of 2 worker processes: member files, the summary against members run one by one
without Dask, percentiles, figures, a failing member, a killed worker, a resumed sweep."""

from __future__ import annotations

import os
import shutil
import signal
import threading
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import hfgpu
from hfgpu.cli import main
from hfgpu.ensemble.execute import metrics_of
from hfgpu.ensemble.members import members
from hfgpu.ensemble.summary import read_csv, read_ensemble
from hfgpu.ensemble.sweep_file import load_sweep
from hfgpu.errors import HfgpuError
from hfgpu.io.results import open_results

SWEEP = """scene = "base.toml"
members = 4
seed = 2
[[vary]]
key = "rock.leakoff_coefficient"
distribution = "log-uniform"
low = "1e-7 m/s**0.5"
high = "1e-5 m/s**0.5"
[[vary]]
key = "rock.layers[0].min_stress"
distribution = "uniform"
low = "61 MPa"
high = "64 MPa"
"""


def _write(folder: Path, base: str, sweep: str = SWEEP) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "base.toml").write_text(base, encoding="utf-8")
    (folder / "sweep.toml").write_text(sweep, encoding="utf-8")
    return folder / "sweep.toml"


def _same(a: dict, b: dict) -> bool:
    """Rows equal in everything but wall time (NaN equal to NaN)."""
    keys = set(a) | set(b)
    return all(a[k] == b[k] or (isinstance(a[k], float) and np.isnan(a[k]) and np.isnan(b[k]))
               for k in keys - {"wall_seconds"})


@pytest.fixture(scope="module")
def done(tmp_path_factory, base_text):
    """(sweep file, out folder, returned rows) of one 4-member sweep on 2 local workers."""
    folder = tmp_path_factory.mktemp("sweep")
    path = _write(folder, base_text)
    rows = hfgpu.sweep(path, folder / "out", workers=2, progress=False)
    return path, folder / "out", rows


def test_member_files_are_complete_results_files_with_their_scene(done):
    path, out, rows = done
    built = members(load_sweep(path))
    assert [r["id"] for r in rows] == [m.id for m in built] == ["0000", "0001", "0002", "0003"]
    for m in built:
        results = open_results(out / "members" / f"{m.id}.h5")
        assert results.status == "complete"
        assert results.scene_text == m.scene_text
        assert results.scene.rock.layers[0].min_stress == m.inputs["rock.layers[0].min_stress"]


def test_summary_equals_members_run_one_by_one(done, tmp_path):
    path, out, rows = done
    names = list(load_sweep(path).metrics)
    for m, got in zip(members(load_sweep(path)), rows):
        alone = tmp_path / f"{m.id}.h5"
        hfgpu.run(hfgpu.load_scene(m.scene_text), alone, progress=False)
        expected = {"id": m.id, "status": "complete", **m.inputs, **metrics_of(alone, names)}
        assert _same(got, {**expected, "wall_seconds": 0.0})
        assert np.isfinite(got["created_area"]) and np.isnan(got["propped_area"])   # no proppant in the scene
    assert all(_same(a, b) for a, b in zip(read_csv(out / "summary.csv"), rows))
    header = (out / "summary.csv").read_text().splitlines()[0].split(",")
    assert header == ["id", "status", "rock.leakoff_coefficient", "rock.layers[0].min_stress", *names,
                      "wall_seconds"]


def test_percentiles_are_numpy_percentiles_of_the_summary(done):
    _, out, rows = done
    data = read_ensemble(out / "ensemble.h5")
    assert data["propped"] is None
    for metric in data["metrics"]:
        values = np.array([r[metric] for r in rows])
        if np.isfinite(values).all():
            np.testing.assert_array_equal(data["percentiles"][metric], np.percentile(values, [10, 50, 90]))
        else:
            assert np.isnan(values).all() and np.isnan(data["percentiles"][metric]).all()
    assert all(_same(a, b) for a, b in zip(data["rows"], rows))


def test_plot_writes_the_ensemble_figures(done, tmp_path, capsys):
    _, out, _ = done
    assert main(["plot", str(out), "--out", str(tmp_path / "figs")]) == 0
    names = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert "tornado.png" in names and "distribution_efficiency.png" in names
    assert "propped_maps.png" not in names     # no member has proppant
    assert "distribution_propped_area.png" not in names


def test_a_failing_member_is_recorded_and_the_others_go_on(tmp_path, base_text, scheduler):
    # 6 m cells: the starting fracture would need most of the 60 s to form, which the engine refuses at its start
    sweep = 'scene = "base.toml"\ndesign = "grid"\n[[vary]]\nkey = "mesh.cell_size"\nvalues = ["2 m", "6 m"]\n'
    rows = hfgpu.sweep(_write(tmp_path, base_text, sweep), tmp_path / "out", scheduler=scheduler, progress=False)
    assert rows[0]["status"] == "complete"
    assert rows[1]["status"].startswith("failed: scene key 'fracture.initial_radius_cells'")
    assert np.isnan([rows[1][m] for m in ("created_area", "efficiency")]).all()
    assert read_csv(tmp_path / "out" / "summary.csv")[1]["status"] == rows[1]["status"]


def test_resume_reruns_only_what_is_not_complete(done, tmp_path, scheduler):
    path, out, rows = done
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    shutil.copy(path, tmp_path / "sweep.toml")
    shutil.copy(path.with_name("base.toml"), tmp_path / "base.toml")
    (copy / "members" / "0001.h5").unlink()
    with h5py.File(copy / "members" / "0002.h5", "r+") as f:
        f.attrs["status"] = "running"                 # as a member killed mid-run leaves it
    (copy / "ensemble.h5").unlink()
    kept = {mid: os.stat(copy / "members" / f"{mid}.h5").st_mtime_ns for mid in ("0000", "0003")}
    with pytest.raises(HfgpuError, match="--resume"):
        hfgpu.sweep(tmp_path / "sweep.toml", copy, workers=1, progress=False)
    again = hfgpu.sweep(tmp_path / "sweep.toml", copy, scheduler=scheduler, resume=True, progress=False)
    assert all(_same(a, b) for a, b in zip(again, rows))
    assert {mid: os.stat(copy / "members" / f"{mid}.h5").st_mtime_ns for mid in kept} == kept
    assert [open_results(copy / "members" / f"{m}.h5").status for m in ("0001", "0002")] == ["complete"] * 2
    assert (copy / "ensemble.h5").is_file()


@pytest.mark.parametrize("allowed_failures", [2, 0])
def test_a_killed_worker_is_replaced_and_its_member_rerun(tmp_path, base_text, allowed_failures):
    """allowed_failures = 2 (the local cluster's MEMBER_RETRIES): the member runs again and completes; 0: it is
    recorded as failed (KilledWorker) and the sweep goes on. The cluster is reached by its address, and by its
    scheduler file."""
    import dask
    from dask.distributed import Client, LocalCluster

    base = base_text.replace('cell_size = "2.0 m"', 'cell_size = "0.8 m"')      # about 1.5 s a member
    path = _write(tmp_path, base, SWEEP.replace("members = 4", "members = 3"))
    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):   # as the sweep's own cluster
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                               scheduler_kwargs={"allowed_failures": allowed_failures})
    with cluster, Client(cluster) as client:
        result = {}
        client.write_scheduler_file(str(tmp_path / "scheduler.json"))
        scheduler = cluster.scheduler_address if allowed_failures else str(tmp_path / "scheduler.json")
        thread = threading.Thread(target=lambda: result.update(rows=hfgpu.sweep(
            path, tmp_path / "out", scheduler=scheduler, progress=False)))
        thread.start()
        deadline = time.monotonic() + 60
        killed = None
        while killed is None and time.monotonic() < deadline:
            for address, keys in client.processing().items():
                running = [k for k in keys if str(k).startswith("hfgpu-member-")]
                if running:
                    time.sleep(0.5)                               # well inside the member's run
                    pid = client.run(os.getpid, workers=[address])[address]
                    os.kill(pid, signal.SIGKILL)
                    killed = running[0]
                    break
            time.sleep(0.05)
        thread.join(timeout=240)
    assert killed is not None and not thread.is_alive()
    rows = {r["id"]: r for r in result["rows"]}
    assert len(rows) == 3
    if allowed_failures:
        assert [r["status"] for r in rows.values()] == ["complete"] * 3
    else:   # the killed member, and any the scheduler had queued on that worker, failed; the others completed
        assert rows[str(killed).split("-")[2]]["status"].startswith("failed: KilledWorker: Attempted to run task")
        assert all(r["status"] == "complete" or r["status"].startswith("failed: KilledWorker") for r in rows.values())
        assert any(r["status"] == "complete" for r in rows.values())
    for mid, r in rows.items():
        if r["status"] == "complete":
            assert open_results(tmp_path / "out" / "members" / f"{mid}.h5").status == "complete"


def test_an_unreachable_scheduler_is_one_line(tmp_path, base_text, monkeypatch, capsys):
    from hfgpu.ensemble import execute

    monkeypatch.setattr(execute, "CONNECT_TIMEOUT", 1)
    path = _write(tmp_path, base_text)
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--scheduler", "tcp://127.0.0.1:9"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("hfgpu sweep: error: cannot reach the Dask scheduler 'tcp://127.0.0.1:9': ")
    assert err.count("\n") == 1


def test_a_sweep_stopped_by_sigterm_keeps_its_finished_members_and_resumes(tmp_path, base_text, scheduler):
    import subprocess
    import sys

    script = Path(sys.executable).with_name("hfgpu")
    command = [str(script)] if script.exists() else [sys.executable, "-m", "hfgpu.cli"]
    path = _write(tmp_path, base_text.replace('cell_size = "2.0 m"', 'cell_size = "1.0 m"'),   # ~1 s a member
                  SWEEP.replace("members = 4", "members = 8"))
    out = tmp_path / "out"
    proc = subprocess.Popen(command + ["sweep", str(path), "--out", str(out), "--workers", "2", "--no-progress"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    finished = []
    deadline = time.monotonic() + 120
    while not finished and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
        for file in sorted((out / "members").glob("*.h5")):
            try:
                if open_results(file).status == "complete":
                    finished.append(file)
            except (HfgpuError, OSError, KeyError):   # being created
                pass
    assert proc.poll() is None, proc.communicate()
    os.kill(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM and "hfgpu sweep: interrupted (SIGTERM)" in err
    assert finished and all(open_results(f).status == "complete" for f in finished)
    kept = {f: os.stat(f).st_mtime_ns for f in finished}
    rows = hfgpu.sweep(path, out, scheduler=scheduler, resume=True, progress=False)
    assert [r["status"] for r in rows] == ["complete"] * 8
    assert {f: os.stat(f).st_mtime_ns for f in finished} == kept
