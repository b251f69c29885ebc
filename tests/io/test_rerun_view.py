"""Rerun recording of a fake run, read back offline from the .rrd file."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from io_fakes import FRACTURE_SCENE, proppant_scene, simulate_fracture, simulate_proppant
from hfgpu import load_scene
from hfgpu.io.rerun_view import RerunRecorder, cell_quads


def _rows(path):
    """Temporal rows per entity and the sim_time values [s] of each, from an .rrd file."""
    rows: dict[str, list[float]] = {}
    for chunk in RrdReader(path).stream().to_chunks():
        if chunk.is_static or "sim_time" not in chunk.timeline_names:
            continue
        batch = chunk.to_record_batch()
        times = batch.column(batch.schema.names.index("sim_time")).cast("int64").to_numpy()
        rows.setdefault(chunk.entity_path, []).extend((times * 1e-9).tolist())
    return {k: sorted(v) for k, v in rows.items()}


def test_fracture_recording_read_back(tmp_path):
    path = tmp_path / "f.rrd"
    recorder = RerunRecorder(load_scene(FRACTURE_SCENE), rrd=path)
    simulate_fracture(load_scene(FRACTURE_SCENE), recorder, steps=40, snapshot_every=10)
    recorder.close()
    rows = _rows(path)
    np.testing.assert_allclose(rows["/world/fracture"], [2.5, 5.0, 7.5, 10.0], rtol=1e-9)
    np.testing.assert_allclose(rows["/fracture/area"], [2.5, 5.0, 7.5, 10.0], rtol=1e-9)
    assert len(rows["/fracture/injected_volume"]) == 40 and len(rows["/fracture/efficiency"]) == 40
    # the fake's pressure at the injection cell (0, 0) is 61 MPa, sigma_0 = 60 MPa: logged at each snapshot
    assert len(rows["/fracture/net_pressure_at_injection"]) == 4


def test_proppant_recording_read_back(tmp_path):
    path = tmp_path / "p.rrd"
    recorder = RerunRecorder(proppant_scene(), rrd=path)
    simulate_proppant(proppant_scene(), recorder, steps=20, snapshot_every=5)
    recorder.close()
    rows = _rows(path)
    np.testing.assert_allclose(rows["/world/proppant/parcels"], [0.25, 0.5, 0.75, 1.0], rtol=1e-9)
    for name in ("injected", "in_domain", "outflow"):
        assert len(rows[f"/proppant/{name}"]) == 20
    assert "/world/fracture" not in rows


def test_cell_quads_cover_the_cells():
    """Two cells: 8 vertices, 4 triangles whose total area is the cells' area (depth drawn downward)."""
    vertices, triangles = cell_quads(np.array([0.0, 2.0]), np.array([10.0, 10.0]), 2.0, 1.0)
    assert vertices.shape == (8, 3) and triangles.shape == (4, 3)
    a, b, c = (vertices[triangles[:, i]] for i in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    assert area == 4.0
    assert vertices[:, 2].min() == -10.5 and vertices[:, 0].max() == 3.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.filterwarnings("ignore:RRD file has no footer")  # a live proxy's file has no footer until it ends
def test_live_stream_reaches_a_running_viewer(tmp_path):
    """``connect`` streams live: a headless Rerun gRPC proxy (``rerun --serve-grpc --save``, what a viewer
    connects to) receives the fake run's snapshots and series, saved by the proxy as it gets them."""
    rerun_exe = shutil.which("rerun", path=str(Path(sys.executable).parent)) or shutil.which("rerun")
    if rerun_exe is None:
        pytest.skip("the rerun executable (rerun-sdk) is not on PATH")
    port, saved = _free_port(), tmp_path / "live.rrd"
    # its own process group: the `rerun` script starts the viewer binary as a child, both must go at the end
    proxy = subprocess.Popen([rerun_exe, "--serve-grpc", "--port", str(port), "--save", str(saved)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.monotonic() + 30.0
        while True:  # wait for the proxy to listen
            try:
                socket.create_connection(("127.0.0.1", port), timeout=0.5).close()
                break
            except OSError:
                if time.monotonic() > deadline or proxy.poll() is not None:
                    pytest.fail("rerun --serve-grpc did not start listening")
                time.sleep(0.2)
        scene = load_scene(FRACTURE_SCENE)
        recorder = RerunRecorder(scene, connect=f"rerun+http://127.0.0.1:{port}/proxy")
        simulate_fracture(scene, recorder, steps=40, snapshot_every=10)
        recorder.close()
        rows: dict = {}
        while time.monotonic() < deadline and len(rows.get("/fracture/injected_volume", [])) < 40:
            time.sleep(0.3)  # the proxy writes what it received; read until all 40 balance rows are in
            if saved.exists() and saved.stat().st_size > 0:
                try:
                    rows = _rows(saved)
                except Exception:  # a chunk still being written
                    rows = {}
    finally:
        os.killpg(proxy.pid, signal.SIGTERM)
        proxy.wait(timeout=10)
    np.testing.assert_allclose(rows["/world/fracture"], [2.5, 5.0, 7.5, 10.0], rtol=1e-9)
    assert len(rows["/fracture/injected_volume"]) == 40
