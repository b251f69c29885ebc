"""The runner: physics dispatch imports only what is needed, sinks fan out, failures end the file."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import types
from pathlib import Path

import pytest

import io_fakes as fakes
from hfgpu import SimulationError, load_scene, open_results, run
from hfgpu.records import BalanceRecord
from hfgpu.runner import FanOut, NotSupportedError
from hfgpu.scene import RunConfig


def _fake(monkeypatch, physics, simulate):
    module = types.ModuleType(f"hfgpu.{physics}.simulator")
    module.simulate = simulate
    monkeypatch.setitem(sys.modules, module.__name__, module)


def test_fracture_run_writes_results_and_prints_summary(tmp_path, monkeypatch, capsys):
    _fake(monkeypatch, "fracture", fakes.simulate_fracture)
    summary = run(load_scene(fakes.FRACTURE_SCENE), tmp_path / "r.h5", rrd=tmp_path / "r.rrd")
    assert summary["status"] == "complete" and summary["steps"] == 40 and summary["note"] == "fake"
    assert summary["fracture_steps"] == 40 and summary["fracture_snapshots"] == 4
    assert summary["efficiency"] == pytest.approx(0.8, rel=1e-12)
    assert summary["sim_time"] == pytest.approx(10.0)
    r = open_results(tmp_path / "r.h5")
    assert r.status == "complete" and len(r.fracture_snapshots) == 4
    assert r.summary["efficiency"] == pytest.approx(0.8, rel=1e-12) and r.summary["note"] == "fake"
    assert r.fracture_balance["time"].size == 40
    assert (tmp_path / "r.rrd").stat().st_size > 0
    out = capsys.readouterr().out
    assert "fluid efficiency" in out and "80 %" in out   # the grouped table of hfgpu.io.summary


def test_simulation_error_is_recorded_and_reraised(tmp_path, monkeypatch):
    _fake(monkeypatch, "fracture", lambda scene, sink, progress=None, **checkpoints:
          fakes.simulate_fracture(scene, sink, progress, fail_at=25))
    with pytest.raises(SimulationError, match="Newton"):
        run(load_scene(fakes.FRACTURE_SCENE), tmp_path / "r.h5", progress=False)
    r = open_results(tmp_path / "r.h5")
    assert r.status.startswith("failed: Newton did not converge (t = 6.25 s, cell (3, 4)")
    assert len(r.fracture_snapshots) == 2 and r.fracture_balance["time"].size == 24
    assert r.summary["error_type"] == "SimulationError" and r.summary["fracture_steps"] == 24


def test_coupled_physics_dispatch_to_the_coupled_model_and_unknown_sets_are_refused(tmp_path):
    import hfgpu.coupled
    from hfgpu.runner import simulator_for

    scene = fakes.proppant_scene().replace(run=RunConfig(end_time=1.0, physics=("fracture", "proppant")))
    assert simulator_for(scene) is hfgpu.coupled.simulate
    with pytest.raises(NotSupportedError, match="allowed sets"):
        run(scene.replace(run=RunConfig(end_time=1.0, physics=("proppant", "fracture"))), tmp_path / "r.h5")
    assert not (tmp_path / "r.h5").exists()


def test_fan_out_calls_every_sink_that_has_the_method():
    got = []

    class Only:
        def fracture_balance(self, record):
            got.append(("only", record.time))

    class Other:
        def proppant_balance(self, record):
            got.append(("other", record.time))

    FanOut([Only(), Other(), Only()]).fracture_balance(BalanceRecord(1.0, 1.0, 1.0, 0.0))
    assert got == [("only", 1.0), ("only", 1.0)]
    with pytest.raises(AttributeError):
        FanOut([]).close


DISPATCH = textwrap.dedent("""
    import json, sys, types
    import io_fakes as fakes
    physics = sys.argv[1]
    module = types.ModuleType(f"hfgpu.{physics}.simulator")
    module.simulate = getattr(fakes, f"simulate_{physics}")
    sys.modules[module.__name__] = module
    from hfgpu import load_scene, run
    scene = load_scene(fakes.FRACTURE_SCENE) if physics == "fracture" else fakes.proppant_scene()
    run(scene, sys.argv[2], progress=False)
    print(json.dumps(sorted(m for m in sys.modules if m.startswith("hfgpu") or m in ("taichi", "rerun"))))
""")


@pytest.mark.parametrize("physics, absent", [("fracture", "hfgpu.proppant"), ("proppant", "hfgpu.fracture")])
def test_runner_imports_only_the_physics_asked_for(tmp_path, physics, absent):
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parent) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", DISPATCH, physics, str(tmp_path / "r.h5")], env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    modules = json.loads(done.stdout.splitlines()[-1])
    assert f"hfgpu.{physics}.simulator" in modules
    assert not [m for m in modules if m == absent or m.startswith(absent + ".")], modules
    assert "taichi" not in modules and "rerun" not in modules  # neither is needed by the runner itself
    assert len(getattr(open_results(tmp_path / "r.h5"), f"{physics}_snapshots")) == 4
