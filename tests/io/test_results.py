"""HDF5 results: writer/reader round trip, units on every dataset, status, and survival of a killed writer."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from io_fakes import FRACTURE_SCENE, fracture_snapshot, proppant_scene, proppant_snapshot
from hfgpu import load_scene, open_results
from hfgpu.errors import HfgpuError
from hfgpu.io.results import FRACTURE_BALANCE, ResultsWriter
from hfgpu.records import BalanceRecord, SolidBalanceRecord


def test_round_trip_fracture(tmp_path):
    scene = load_scene(FRACTURE_SCENE)
    path = tmp_path / "r.h5"
    written = [fracture_snapshot(t) for t in (1.0, 2.5, 5.0)]
    with ResultsWriter(path, scene) as w:
        for i in range(1, 51):
            t = 0.1 * i
            w.fracture_balance(BalanceRecord(time=t, injected=t, stored=0.7 * t, leaked=0.3 * t,
                                             injection_pressure=61e6 + t, net_pressure=1e6 + t))
            if i in (10, 25, 50):
                w.fracture_snapshot(written[(10, 25, 50).index(i)])
    r = open_results(path)
    assert r.status == "complete" and r.format_version == 1
    assert r.scene_text == FRACTURE_SCENE and r.scene == scene
    assert len(r.fracture_snapshots) == 3 and len(r.proppant_snapshots) == 0
    np.testing.assert_array_equal(r.fracture_snapshots.times, [1.0, 2.5, 5.0])
    for back, snap in zip(r.fracture_snapshots, written):
        assert back.frame == snap.frame and back.time == snap.time
        for name in ("width", "pressure", "leakoff_rate", "opening_time"):
            np.testing.assert_array_equal(getattr(back, name), getattr(snap, name))
            assert getattr(back, name).dtype == np.float64
        np.testing.assert_array_equal(back.extras["net_pressure"], snap.extras["net_pressure"])
    assert r.fracture_snapshots.at(2.4).time == 2.5
    bal = r.fracture_balance
    assert set(bal) == set(FRACTURE_BALANCE) and bal["time"].size == 50
    np.testing.assert_array_equal(bal["injection_pressure"] - bal["net_pressure"], 60e6)
    assert np.isnan(bal["area"]).all()  # not given: NaN
    np.testing.assert_allclose(bal["stored"] + bal["leaked"], bal["injected"], rtol=1e-15)
    assert r.summary["status"] == "complete" and r.summary["fracture_snapshots"] == 3
    assert r.summary["sim_time"] == pytest.approx(5.0)
    assert r.proppant_balance == {}


def test_round_trip_proppant_and_units(tmp_path):
    scene = proppant_scene()
    path = tmp_path / "p.h5"
    snaps = [proppant_snapshot(t) for t in (0.5, 1.0)]
    with ResultsWriter(path, scene) as w:
        for snap in snaps:
            w.proppant_balance(SolidBalanceRecord(time=snap.time, injected=2.0, in_domain=1.5, outflow=0.5))
            w.proppant_snapshot(snap)
    r = open_results(path)
    for back, snap in zip(r.proppant_snapshots, snaps):
        assert set(back.parcels) == set(snap.parcels) and set(back.grid) == set(snap.grid)
        for name, value in {**snap.parcels, **snap.grid}.items():
            got = back.parcels.get(name, back.grid.get(name))
            np.testing.assert_array_equal(got, value)
        assert back.parcels["class_id"].dtype.kind == "i"
    assert r.proppant_balance["outflow"].tolist() == [0.5, 0.5]
    with h5py.File(path) as f:
        missing = []
        f.visititems(lambda name, obj: missing.append(name)
                     if isinstance(obj, h5py.Dataset) and "units" not in obj.attrs else None)
        assert missing == []
        assert f["proppant/snapshots/000001"].attrs["n_parcels"] == 50
        assert f["proppant/snapshots/000000/u"].attrs["units"] == "m/s"


def test_failure_status_and_buffered_balance_written(tmp_path):
    path = tmp_path / "f.h5"
    with pytest.raises(RuntimeError):
        with ResultsWriter(path, load_scene(FRACTURE_SCENE)) as w:
            w.fracture_balance(BalanceRecord(time=0.5, injected=1.0, stored=1.0, leaked=0.0))
            raise RuntimeError("NaN in width")
    r = open_results(path)
    assert r.status == "failed: NaN in width" and r.summary["status"] == r.status
    assert r.fracture_balance["time"].tolist() == [0.5]


def test_not_a_results_file(tmp_path):
    with h5py.File(tmp_path / "other.h5", "w") as f:
        f["x"] = 1
    with pytest.raises(HfgpuError, match="not an hfgpu results file"):
        open_results(tmp_path / "other.h5")
    with pytest.raises(HfgpuError, match="cannot open"):
        open_results(tmp_path / "absent.h5")


def _copies(monkeypatch) -> list:
    """Record every whole-file copy the writer makes."""
    import hfgpu.io.results as results

    copies = []
    real = results.shutil.copyfile
    monkeypatch.setattr(results.shutil, "copyfile", lambda a, b: copies.append(a) or real(a, b))
    return copies


@pytest.mark.skipif(not sys.platform.startswith("linux"),
                    reason="the spare is reused only where a write lease tells that no reader holds it (Linux)")
def test_writes_do_not_copy_the_file_and_spare_readers_are_safe(tmp_path, monkeypatch):
    """Snapshot after snapshot the writer copies the file once (its spare), not once per write; the spare is
    gone at close. A reader holding the file open across writes makes the writer copy afresh, and what the
    reader holds does not change under it."""
    copies = _copies(monkeypatch)
    path = tmp_path / "r.h5"
    w = ResultsWriter(path, load_scene(FRACTURE_SCENE))
    for k in range(20):
        w.fracture_balance(BalanceRecord(time=k + 1.0, injected=1.0, stored=1.0, leaked=0.0))
        w.fracture_snapshot(fracture_snapshot(k + 1.0))
    assert len(copies) == 1 and (tmp_path / "r.h5.writing").exists()
    with h5py.File(path, "r", locking=False) as held:   # a reader opens version 20 and keeps it open
        w.fracture_snapshot(fracture_snapshot(21.0))    # on the spare (19, free); 20 becomes the spare
        w.fracture_snapshot(fracture_snapshot(22.0))    # 20 is held: a fresh copy of 21 takes 22
        assert sorted(held["fracture/snapshots"]) == [f"{k:06d}" for k in range(20)]
        np.testing.assert_array_equal(held["fracture/snapshots/000019/width"][()], fracture_snapshot(20.0).width)
    assert len(copies) == 2
    w.close()
    assert not (tmp_path / "r.h5.writing").exists() and not (tmp_path / "r.h5.previous").exists()
    r = open_results(path)
    np.testing.assert_array_equal(r.fracture_snapshots.times, np.arange(1.0, 23.0))
    np.testing.assert_array_equal(r.fracture_balance["time"], np.arange(1.0, 21.0))


def test_replayed_writes_hold_their_own_data(tmp_path):
    """A write is replayed on the spare at the next write: what it stores is the data of the moment it was
    made, even if the caller changes its arrays afterwards (checkpoint state, snapshot fields)."""
    path = tmp_path / "r.h5"
    w = ResultsWriter(path, load_scene(FRACTURE_SCENE))
    state = {"engine": {"w": np.arange(5.0), "t": 1.0}}
    snap = fracture_snapshot(1.0)
    w.write_checkpoint(1.0, state)
    w.fracture_snapshot(snap)
    state["engine"]["w"][:] = -1.0
    snap.width[:] = -1.0
    for t in (2.0, 3.0):   # each replays the previous write on the spare, which then becomes the file
        w.fracture_snapshot(fracture_snapshot(t))
    with h5py.File(path, "r") as f:
        np.testing.assert_array_equal(f["checkpoint/state/engine/w"][()], np.arange(5.0))
        np.testing.assert_array_equal(f["fracture/snapshots/000000/width"][()], fracture_snapshot(1.0).width)
    w.close()


WRITER = textwrap.dedent("""
    import dataclasses, sys
    from io_fakes import FRACTURE_SCENE, fracture_snapshot
    from hfgpu import load_scene
    from hfgpu.io.results import ResultsWriter
    from hfgpu.records import BalanceRecord
    w = ResultsWriter(sys.argv[1], load_scene(FRACTURE_SCENE))
    snap = fracture_snapshot(1.0, n=301)  # made once: the loop spends its time writing
    for k in range(100000):
        t = 0.01 * (k + 1)
        for j in range(50):
            w.fracture_balance(BalanceRecord(time=t, injected=t, stored=t, leaked=0.0))
        w.fracture_snapshot(dataclasses.replace(snap, time=t))
        print(k, flush=True)
""")


@pytest.mark.parametrize("delay", [0.0, 0.013, 0.029, 0.041, 0.077])
def test_killed_writer_leaves_every_completed_snapshot(tmp_path, delay):
    """SIGKILL a process that writes snapshots back to back (the file is open most of the time) at
    various moments: every snapshot it reported is intact, with the balance rows written before it."""
    path = tmp_path / "killed.h5"
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parent) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(path)], stdout=subprocess.PIPE, text=True, env=env)
    try:
        done = -1
        while done < 2:
            line = proc.stdout.readline()
            assert line, "writer ended early"
            done = int(line)
        time.sleep(delay)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    done = max([done] + [int(x) for x in proc.stdout.read().split()])
    r = open_results(path)
    assert r.status == "running"
    n = len(r.fracture_snapshots)
    assert n in (done + 1, done + 2)  # reported ones, plus possibly one completed before its print
    expected = fracture_snapshot(1.0, n=301)
    for k in (0, n - 1):
        snap = r.fracture_snapshots[k]
        assert snap.time == pytest.approx(0.01 * (k + 1), rel=1e-12)
        np.testing.assert_array_equal(snap.width, expected.width)
        np.testing.assert_array_equal(snap.opening_time, expected.opening_time)
    assert r.fracture_balance["time"].size == 50 * n


@pytest.mark.slow
def test_many_random_kills_never_corrupt_the_file(tmp_path):
    """40 SIGKILLs at random moments of a back-to-back writer: every file opens, every snapshot reads."""
    rng = np.random.default_rng(7)
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parent) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    for trial in range(40):
        path = tmp_path / f"k{trial}.h5"
        proc = subprocess.Popen([sys.executable, "-c", WRITER, str(path)], stdout=subprocess.PIPE, text=True,
                                env=env)
        while int(proc.stdout.readline()) < 1:
            pass
        time.sleep(rng.uniform(0.0, 0.3))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        r = open_results(path)
        assert all(np.isfinite(s.width).all() for s in r.fracture_snapshots)
        assert r.fracture_balance["time"].size == 50 * len(r.fracture_snapshots)
