"""Checkpoints and resume (hfgpu/io/checkpoint.py, ResultsWriter.write_checkpoint / reopen, run(resume=True)).

The reference is the run itself: a run interrupted after a checkpoint and resumed must end with the results of
an uninterrupted run without checkpoints, bit for bit with the NumPy backend (fracture, proppant, coupled in
either phase). Also: the engines' state round trips through HDF5, a SIGKILLed ``hfgpu run`` leaves a readable
file that ``--resume`` completes, the checkpoint swap survives a kill between its two moves, and bad resumes
stop with a clear error before any work.
"""

from __future__ import annotations

import dataclasses
import math
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import hfgpu
import hfgpu.coupled as coupled
from hfgpu import HfgpuError, SceneError, load_scene, open_results
from hfgpu.io.checkpoint import (DEFAULT_CHECKPOINTS, Checkpointer, checkpoint_interval, read_tree,
                                 scene_differences, write_tree)
from hfgpu.io.results import NEW_CHECKPOINT, ResultsWriter

ROOT = Path(__file__).resolve().parents[2]

#: Radial fracture with leak-off, 0.5 m cells: 28 steps to 100 s, two seconds.
FRACTURE = """
[run]
end_time = "100 s"
[rock]
youngs_modulus = "30 GPa"
poisson_ratio = 0.25
toughness = "0.1 MPa*m**0.5"
leakoff_coefficient = "1e-5 m/s**0.5"
min_stress = "10 MPa"
[fluid]
viscosity = "1 Pa*s"
[injection]
depth = "500 m"
schedule = [{ until = "100 s", rate = "1e-3 m**3/s" }]
[mesh]
cell_size = "0.5 m"
[output]
every = "10 s"
checkpoint_every = "7 s"
"""

#: The same with the sub-grid front, whose steps start Newton from the last step's dw/dt (grid field w_rate).
FRACTURE_SUBGRID = FRACTURE + """[fracture]
front_tracking = "subgrid"
"""

#: Slot with an inlet, an outlet and a pad after the slurry: 62 fluid steps, about a second.
PROPPANT = """
[run]
end_time = "0.6 s"
physics = ["proppant"]
seed = 5
[fluid]
viscosity = "1 cP"
[mesh]
cell_size = "10 mm"
[output]
every = "0.2 s"
checkpoint_every = "0.05 s"
[geometry]
kind = "slot"
length = "10 cm"
height = "5 cm"
width = "5 mm"
[[geometry.inlets]]
kind = "segment"
x = "1 mm"
depth = "1.5 cm"
x_end = "1 mm"
depth_end = "2.4 cm"
[[geometry.outlets]]
kind = "segment"
x = "9.9 cm"
depth = "1 cm"
x_end = "9.9 cm"
depth_end = "3.9 cm"
[injection]
schedule = [{ until = "0.3 s", rate = "2.5e-5 m**3/s", proppant = "sand", volume_fraction = 0.06 },
            { until = "0.6 s", rate = "2.5e-5 m**3/s" }]
[[proppant]]
name = "sand"
density = "2550 kg/m**3"
size = "40/70"
[mppic]
backend = "numpy"
parcels_per_cell = 4
"""


#: The tiny layered coupled scene of tests/test_coupled.py (20 s pad, 20 s of 10 % slurry), checkpoints every 3 s.
COUPLED = (Path(__file__).parents[1] / "scenes" / "tiny_coupled.toml").read_text().replace(
    "[output]\n", '[output]\ncheckpoint_every = "3 s"\n')


def _no_checkpoints(text: str) -> str:
    lines = [line for line in text.splitlines() if not line.startswith("checkpoint_every")]
    return "\n".join(lines).replace("[output]", "[output]\ncheckpoint_every = false")


class Killed(BaseException):
    """Stands for a kill in the middle of a run (BaseException, as KeyboardInterrupt)."""


def _interrupted(monkeypatch, text: str, path: Path, after: int, steps: int) -> None:
    """Run ``text`` into ``path`` and stop it ``steps`` step ends after its ``after``-th checkpoint."""
    due = Checkpointer.due
    count = [0]

    def stopping(self, t):
        if self.written >= after:
            count[0] += 1
            if count[0] > steps:
                raise Killed()
        return due(self, t)

    with monkeypatch.context() as m:
        m.setattr(Checkpointer, "due", stopping)
        with pytest.raises(Killed):
            hfgpu.run(load_scene(text), path, progress=False)


def _assert_same_results(path_a: Path, path_b: Path, rtol: float = 0.0) -> None:
    """Every snapshot and balance row of the two files equal bit for bit (NaN equal to NaN), or with ``rtol``
    to within rtol of each array's largest magnitude."""
    a, b = open_results(path_a), open_results(path_b)
    assert len(a.fracture_snapshots) + len(a.proppant_snapshots) > 1
    for physics in ("fracture", "proppant"):
        balance_a, balance_b = getattr(a, f"{physics}_balance"), getattr(b, f"{physics}_balance")
        assert balance_a.keys() == balance_b.keys()
        for name in balance_a:
            assert _close(balance_a[name], balance_b[name], rtol), (physics, name)
        snaps_a, snaps_b = getattr(a, f"{physics}_snapshots"), getattr(b, f"{physics}_snapshots")
        assert len(snaps_a) == len(snaps_b)
        for x, y in zip(snaps_a, snaps_b):
            assert x.time == y.time and x.frame == y.frame
            for name, value in _arrays(x).items():
                assert _close(value, _arrays(y)[name], rtol), (physics, x.time, name)


def _close(a: np.ndarray, b: np.ndarray, rtol: float) -> bool:
    if rtol == 0.0 or a.dtype.kind != "f" or a.shape != b.shape:
        return a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
    scale = float(np.nanmax(np.abs(a))) if a.size and not np.isnan(a).all() else 0.0
    return bool(np.allclose(a, b, rtol=rtol, atol=rtol * scale, equal_nan=True))


def _arrays(snap) -> dict:
    if hasattr(snap, "parcels"):
        return {**snap.parcels, **snap.grid}
    return dict(width=snap.width, pressure=snap.pressure, leakoff_rate=snap.leakoff_rate,
                opening_time=snap.opening_time, **snap.extras)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """Uninterrupted runs without checkpoints: {"fracture": path, "proppant": path, "coupled": path}."""
    folder = tmp_path_factory.mktemp("reference")
    paths = {}
    for name, text in (("fracture", FRACTURE), ("subgrid", FRACTURE_SUBGRID), ("proppant", PROPPANT),
                       ("coupled", COUPLED)):
        paths[name] = folder / f"{name}.h5"
        summary = hfgpu.run(load_scene(_no_checkpoints(text)), paths[name], progress=False)
        assert summary["checkpoints"] == 0
    return paths


# -- resumed runs equal uninterrupted ones ----------------------------------------------------------------


@pytest.mark.parametrize("name, after, steps", [("fracture", 3, 5), ("subgrid", 3, 5), ("proppant", 3, 4)])
def test_resumed_run_equals_the_uninterrupted_one(name, after, steps, reference, tmp_path, monkeypatch):
    text = {"fracture": FRACTURE, "subgrid": FRACTURE_SUBGRID, "proppant": PROPPANT}[name]
    kind = "proppant" if name == "proppant" else "fracture"
    path = tmp_path / "resumed.h5"
    _interrupted(monkeypatch, text, path, after, steps)
    cut = open_results(path)
    assert cut.status.startswith("failed") and cut.checkpoint_time is not None
    with h5py.File(path, "r") as f:  # records past the checkpoint, for the resume to drop
        kept = f["checkpoint"].attrs
        assert kept[f"{kind}_balance_rows"] < getattr(cut, f"{kind}_balance")["time"].size
        assert kept[f"{kind}_snapshots"] < len(getattr(cut, f"{kind}_snapshots"))
    summary = hfgpu.run(load_scene(text), path, progress=False, resume=True)
    assert summary["resumed_from"] == cut.checkpoint_time and summary["checkpoints"] >= 1
    assert open_results(path).status == "complete" and open_results(path).checkpoint_time is None
    _assert_same_results(reference[name], path)
    ref = open_results(reference[name]).summary
    for key in ("steps", "injected", "stored", "leaked", "in_domain", "outflow", "max_balance_error"):
        if key in ref:
            assert open_results(path).summary[key] == ref[key], key


def test_taichi_resumed_run_equals_the_uninterrupted_one_to_round_off(tmp_path, monkeypatch):
    """The Taichi particle kernels (CPU here): within 1e-10 (run to run they agree bit for bit on the CPU)."""
    text = PROPPANT.replace('backend = "numpy"', 'backend = "taichi"')
    text = text.replace('end_time = "0.6 s"', 'end_time = "0.3 s"')
    plain, path = tmp_path / "plain.h5", tmp_path / "resumed.h5"
    hfgpu.run(load_scene(_no_checkpoints(text)), plain, progress=False)
    _interrupted(monkeypatch, text, path, 3, 4)
    hfgpu.run(load_scene(text), path, progress=False, resume=True)
    _assert_same_results(plain, path, rtol=1e-10)


@pytest.mark.parametrize("after, phase", [(2, "fracture"), (15, "proppant")])
def test_coupled_run_resumes_in_either_phase(after, phase, reference, tmp_path, monkeypatch):
    text = COUPLED
    path = tmp_path / "coupled.h5"
    _interrupted(monkeypatch, text, path, after, 3)
    with h5py.File(path, "r", locking=False) as f:
        assert f["checkpoint/state"].attrs["phase"] == phase
    hfgpu.run(load_scene(text), path, progress=False, resume=True)
    _assert_same_results(reference["coupled"], path)
    ref, got = open_results(reference["coupled"]).summary, open_results(path).summary
    for key in ("fracture_steps", "proppant_steps", "proppant_injected", "proppant_in_domain",
                "screen_out_cells_max", "fracture_radius", "efficiency"):
        assert got[key] == ref[key], key


def test_a_coupled_checkpoint_on_the_proppant_clock_resumes(reference, tmp_path, monkeypatch):
    """A proppant-phase checkpoint without ``clock`` holds its proppant times counted from the proppant start (as
    files were written while the proppant engine's clock started at 0): it resumes with them moved onto the
    scene's clock (hfgpu.coupled._on_scene_clock), as the uninterrupted run (to round-off: t - 20 + 20 s)."""
    path = tmp_path / "coupled.h5"
    _interrupted(monkeypatch, COUPLED, path, 15, 3)
    start = open_results(reference["coupled"]).summary["proppant_start"]
    with h5py.File(path, "r+", locking=False) as f:
        state = f["checkpoint/state"]
        assert state.attrs["phase"] == "proppant" and state.attrs["clock"] == "scene"
        del state.attrs["clock"]
        state["proppant"].attrs["next_out"] -= start
        for name in ("time", "screen_out_time"):
            state["proppant/simulation"].attrs[name] -= start
    hfgpu.run(load_scene(COUPLED), path, progress=False, resume=True)
    _assert_same_results(reference["coupled"], path, rtol=1e-9)
    assert open_results(path).summary["proppant_steps"] == open_results(reference["coupled"]).summary["proppant_steps"]


#: COUPLED two-way (hfgpu.coupled.simulate_two_way): checkpoints at the 5 s interval ends only.
TWO_WAY = COUPLED.replace('fracture_every = "5 s"', 'fracture_every = "5 s"\nmode = "two-way"')


def test_two_way_run_resumes_from_an_interval_end(tmp_path, monkeypatch):
    """A two-way run killed after its checkpoint at 30 s (an interval end, the slurry handed over) resumes without
    the footprint pass and the pad and ends with the records and summary of the uninterrupted run, bit for bit:
    the fracture and the proppant restored, the fracture given the slurry of the restored proppant."""
    plain, path = tmp_path / "plain.h5", tmp_path / "resumed.h5"
    hfgpu.run(load_scene(_no_checkpoints(TWO_WAY)), plain, progress=False)
    _interrupted(monkeypatch, TWO_WAY, path, 1, 1)
    with h5py.File(path, "r", locking=False) as f:
        assert f["checkpoint/state"].attrs["phase"] == "two-way" and f["checkpoint"].attrs["time"] == 30.0
    calls = []
    with monkeypatch.context() as m:   # the resumed run builds no footprint: its only FractureRun is resumed
        init = coupled.FractureRun.__init__
        m.setattr(coupled.FractureRun, "__init__",
                  lambda self, *a, **k: calls.append(k.get("resume") is not None) or init(self, *a, **k))
        summary = hfgpu.run(load_scene(TWO_WAY), path, progress=False, resume=True)
    assert calls == [True] and summary["resumed_from"] == 30.0
    _assert_same_results(plain, path)
    ref, got = open_results(plain).summary, open_results(path).summary
    for key in ("fracture_steps", "proppant_steps", "proppant_injected", "proppant_in_domain", "packed_length",
                "tip_screen_out_time", "net_pressure_rise", "screen_out_cells_max", "efficiency"):
        assert got[key] == ref[key] or (math.isnan(got[key]) and math.isnan(ref[key])), key


#: COUPLED as a stage of two clusters 30 m apart (hfgpu.coupled_stage), twice the rate.
STAGE = COUPLED.replace('rate = "2e-3 m**3/s"', 'rate = "4e-3 m**3/s"') + '[completion]\nclusters = 2\nspacing = "30 m"\n'


@pytest.mark.parametrize("after, phase", [(2, "fracture"), (15, "proppant")])
def test_a_stage_with_proppant_resumes_in_either_phase(after, phase, tmp_path, monkeypatch):
    """A stage's checkpoint holds every plane and the wellbore node's split (hfgpu.fracture.stage), the resumed
    file's stage rows and cluster snapshots are cut back to it, and the resumed run equals the uninterrupted one bit
    for bit."""
    plain, path = tmp_path / "plain.h5", tmp_path / "stage.h5"
    hfgpu.run(load_scene(_no_checkpoints(STAGE)), plain, progress=False)
    _interrupted(monkeypatch, STAGE, path, after, 3)
    with h5py.File(path, "r", locking=False) as f:
        assert f["checkpoint/state"].attrs["phase"] == phase
        rows = f["checkpoint"].attrs["stage_balance_rows"]
    hfgpu.run(load_scene(STAGE), path, progress=False, resume=True)
    _assert_same_results(plain, path)
    a, b = open_results(plain), open_results(path)
    assert rows > 0 and a.stage_balance.keys() == b.stage_balance.keys()
    for name, column in a.stage_balance.items():
        assert np.array_equal(column, b.stage_balance[name], equal_nan=True), name
    for x, y in zip(a.stage_snapshots, b.stage_snapshots):
        assert len(x) == len(y) and all(np.array_equal(s.width, t.width) for s, t in zip(x, y))
    for key in ("fracture_steps", "fracture_stage_iterations", "proppant_steps", "proppant_in_domain",
                "cluster_0_solid", "cluster_1_solid", "cluster_1_closure_propped_area"):
        assert b.summary[key] == a.summary[key], key


def _signalled_once_checkpointed(tmp_path: Path, path: Path, number: int) -> tuple[list[str], int, str]:
    """Start ``hfgpu run`` on the fracture scene (checkpoints every 3 s) into ``path``, send it signal ``number``
    once the file holds a checkpoint; (the command, its exit code, its stderr)."""
    scene = tmp_path / "scene.toml"
    scene.write_text(FRACTURE.replace('checkpoint_every = "7 s"', 'checkpoint_every = "3 s"'))
    command = [sys.executable, "-m", "hfgpu.cli", "run", str(scene), "--out", str(path), "--no-progress"]
    proc = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_default_stop_signals)
    deadline = time.monotonic() + 120.0
    try:
        while proc.poll() is None and time.monotonic() < deadline:
            try:
                if open_results(path).checkpoint_time is not None:
                    break
            except (HfgpuError, OSError, KeyError):
                pass  # not created yet, or caught in the middle of a write
            time.sleep(0.01)
    finally:
        proc.send_signal(number)
        _, stderr = proc.communicate(timeout=60)
    return command, proc.returncode, stderr


def _default_stop_signals() -> None:
    """The run starts with its stop signals at their defaults, as from a terminal: under nohup or as a
    background job the test run would pass SIGHUP or SIGINT on ignored, and hfgpu leaves an ignored signal
    ignored."""
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        signal.signal(getattr(signal, name), signal.SIG_DFL)


def test_killed_cli_run_keeps_its_snapshots_and_resumes(reference, tmp_path):
    """``hfgpu run`` killed with SIGKILL once its file holds a checkpoint: the file opens, every snapshot in it is
    whole, and ``hfgpu run --resume`` ends it as the uninterrupted run."""
    path = tmp_path / "killed.h5"
    command, returncode, _ = _signalled_once_checkpointed(tmp_path, path, signal.SIGKILL)
    assert returncode == -signal.SIGKILL, "the run ended before it could be killed"
    cut = open_results(path)
    assert cut.status == "running" and cut.checkpoint_time is not None
    for snap in cut.fracture_snapshots:  # every snapshot the file lists reads whole
        assert np.isfinite(snap.width).all() and snap.width.shape == snap.pressure.shape
    done = subprocess.run(command + ["--resume"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    _assert_same_results(reference["fracture"], path)
    again = subprocess.run(command + ["--resume"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0 and "already complete" in again.stdout


@pytest.mark.parametrize("stop", ["SIGTERM", "SIGHUP"])
def test_sigterm_and_sighup_end_the_run_as_interrupted_and_resumable(stop, reference, tmp_path):
    """``hfgpu run`` sent SIGTERM (kill, a batch scheduler) or SIGHUP (terminal closed) once its file holds a
    checkpoint ends as Ctrl-C does: exit 128 + the signal, one line, status "interrupted" with a summary, and
    ``--resume`` ends it as the uninterrupted run."""
    number = getattr(signal, stop)
    path = tmp_path / "stopped.h5"
    command, returncode, stderr = _signalled_once_checkpointed(tmp_path, path, number)
    assert returncode == 128 + number, stderr
    assert stderr.strip().splitlines()[-1] == f"hfgpu run: interrupted ({stop})"
    cut = open_results(path)
    assert cut.status == "interrupted" and cut.summary["interrupted_by"] == stop
    assert cut.checkpoint_time is not None
    done = subprocess.run(command + ["--resume"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    _assert_same_results(reference["fracture"], path)


# -- the engines' state ---------------------------------------------------------------------------------


def _through_hdf5(tmp_path: Path, state: dict) -> dict:
    with h5py.File(tmp_path / "state.h5", "w") as f:
        write_tree(f.create_group("state"), state)
    with h5py.File(tmp_path / "state.h5", "r") as f:
        return read_tree(f["state"])


def _assert_same_tree(a: dict, b: dict, path: str = "") -> None:
    assert a.keys() == b.keys(), path
    for key in a:
        if isinstance(a[key], dict):
            _assert_same_tree(a[key], b[key], f"{path}/{key}")
        elif isinstance(a[key], np.ndarray):
            assert a[key].dtype == b[key].dtype and np.array_equal(a[key], b[key], equal_nan=True), f"{path}/{key}"
        else:
            assert a[key] == b[key] or (a[key] != a[key] and b[key] != b[key]), f"{path}/{key}"


def test_fracture_engine_state_round_trip(tmp_path):
    from hfgpu.fracture.config import FractureNumerics
    from hfgpu.fracture.engine_setup import fracture_engine_setup
    from hfgpu.fracture.simulator import _Engine

    setup = dataclasses.replace(fracture_engine_setup(load_scene(FRACTURE)), numerics=FractureNumerics())
    engine = _Engine(setup)
    dt = 0.5
    for _ in range(6):
        dt = engine.next_dt(engine.step(dt))
    state = engine.state()
    other = _Engine(setup)
    other.restore(_through_hdf5(tmp_path, state))
    _assert_same_tree(state, other.state())
    for _ in range(4):  # and both go on alike
        dt_a, dt_b = engine.step(dt), other.step(dt)
        assert dt_a == dt_b
        dt = engine.next_dt(dt_a)
    assert np.array_equal(engine.grid["w"], other.grid["w"]) and engine.balance() == other.balance()


@pytest.mark.parametrize("grain_pressure", ["last", "two-step"])
def test_proppant_simulation_state_round_trip(grain_pressure, tmp_path):
    """The restored simulation steps as the one it came from (with "two-step", the pressure of the step before
    travels in the state)."""
    from hfgpu.proppant.engine_setup import proppant_engine_setup
    from hfgpu.proppant.simulator import ProppantSimulation

    scene = load_scene(PROPPANT + f'grain_pressure = "{grain_pressure}"\n')
    sim = ProppantSimulation(proppant_engine_setup(scene))
    for _ in range(8):
        sim.step(limit=0.3 - sim.time)
    state = sim.state()
    assert sim.parcels.n > 0 and state["linear"]["data"].size > 0  # an LU to carry over
    other = ProppantSimulation(proppant_engine_setup(scene))
    other.restore(_through_hdf5(tmp_path, state))
    _assert_same_tree(state, other.state())
    for _ in range(5):  # new parcels drawn from the restored generator, the same LU reused
        a, b = sim.step(limit=0.3 - sim.time), other.step(limit=0.3 - other.time)
        assert a == b
    for name, value in sim.parcels.as_dict().items():
        assert np.array_equal(value, getattr(other.parcels, name)), name
    assert np.array_equal(sim.fluid.p, other.fluid.p) and sim.balance() == other.balance()


# -- the checkpoint in the file -------------------------------------------------------------------------


def test_checkpoint_swap_survives_a_kill_between_removal_and_move(tmp_path):
    path = tmp_path / "r.h5"
    writer = ResultsWriter(path, load_scene(FRACTURE))
    writer.write_checkpoint(1.0, {"a": np.arange(3.0), "x": 1.5})
    writer.write_checkpoint(2.0, {"a": np.arange(4.0), "x": 2.5})
    with h5py.File(path, "a", locking=False) as f:  # as if killed after removing /checkpoint, before the move
        f.move("checkpoint", NEW_CHECKPOINT)
    assert open_results(path).checkpoint_time == 2.0
    _, time_, state = ResultsWriter.reopen(path)
    assert time_ == 2.0 and state["x"] == 2.5 and np.array_equal(state["a"], np.arange(4.0))
    with h5py.File(path, "r") as f:
        assert "checkpoint" in f and NEW_CHECKPOINT not in f


def test_replaced_checkpoints_do_not_grow_the_file(tmp_path):
    path = tmp_path / "r.h5"
    writer = ResultsWriter(path, load_scene(FRACTURE))
    big = {"a": np.random.default_rng(0).random(200_000)}
    writer.write_checkpoint(1.0, big)
    size = path.stat().st_size
    for t in range(2, 12):
        writer.write_checkpoint(float(t), big)
    assert path.stat().st_size < 2.5 * size  # ten more 1.6 MB checkpoints, space reused


# -- configuration and errors ---------------------------------------------------------------------------


def test_checkpoint_interval_rule_and_scene_keys():
    assert checkpoint_interval(load_scene(FRACTURE)) == 7.0
    default = load_scene(_no_checkpoints(FRACTURE).replace("checkpoint_every = false\n", ""))
    assert default.output.checkpoint_every is None
    assert checkpoint_interval(default) == max(100.0 / DEFAULT_CHECKPOINTS, 10.0)
    assert checkpoint_interval(load_scene(_no_checkpoints(FRACTURE))) == 0.0
    assert checkpoint_interval(load_scene(FRACTURE.replace('"7 s"', '"0 s"'))) == 0.0
    with pytest.raises(SceneError, match="output.checkpoint_every"):
        load_scene(FRACTURE.replace('"7 s"', '"-1 s"'))
    with pytest.raises(SceneError, match="output.checkpoint_every"):
        load_scene(FRACTURE.replace('"7 s"', "true"))


def test_checkpointer_writes_at_the_first_step_end_past_each_interval():
    times = []
    c = Checkpointer(lambda t, state: times.append(t), 2.0)
    for t in (0.5, 1.9, 2.3, 2.9, 4.0, 7.5, 7.9, 8.1):
        if c.due(t):
            c.save(t, {})
    assert times == [2.3, 4.0, 7.5, 8.1] and c.written == 4
    assert not Checkpointer(lambda t, s: None, 0.0).due(1e30)


def test_resume_refuses_another_scene_and_a_file_without_checkpoint(tmp_path, monkeypatch):
    path = tmp_path / "r.h5"
    _interrupted(monkeypatch, FRACTURE, path, 1, 1)
    other = FRACTURE.replace('every = "10 s"', 'every = "20 s"').replace('"0.1 MPa', '"0.2 MPa')
    with pytest.raises(HfgpuError, match=r"output.every: 10\.0 in the file, 20\.0 given.*rock"):
        hfgpu.run(load_scene(other), path, progress=False, resume=True)
    # another checkpoint interval does not change the results: allowed
    assert scene_differences(load_scene(FRACTURE), load_scene(FRACTURE.replace('"7 s"', '"9 s"'))) == []
    empty = tmp_path / "no_checkpoint.h5"
    ResultsWriter(empty, load_scene(FRACTURE))
    with pytest.raises(HfgpuError, match="holds no checkpoint"):
        hfgpu.run(load_scene(FRACTURE), empty, progress=False, resume=True)
    with pytest.raises(HfgpuError, match="cannot open"):
        hfgpu.run(load_scene(FRACTURE), tmp_path / "missing.h5", progress=False, resume=True)
    assert math.isnan(hfgpu.run(load_scene(FRACTURE), tmp_path / "fresh.h5", progress=False)["resumed_from"])
