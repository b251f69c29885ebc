"""A proppant step that cannot proceed stops the run at once with a message in the user's terms (what bounds the
step, where, the key that would change it), keeps the results file and its checkpoints, and ``--resume`` with a
changed numerical key continues it to the end (hfgpu.proppant.health, hfgpu.io.checkpoint.RESUME_MAY_CHANGE).
The unphysical-state checks warn once at their first occurrence (theta_p above close packing)."""

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from hfgpu import load_scene, scene_path
from hfgpu.errors import SimulationError
from hfgpu.io import plots
from hfgpu.io.plots import status_banner
from hfgpu.io.results import open_results
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.health import COLLAPSE_FLOOR, Watch
from hfgpu.records import GridFrame
from hfgpu.scene_text import edit_scene

TINY = (Path(__file__).parent / "scenes" / "tiny_coupled.toml").read_text()


def _hfgpu(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "hfgpu.cli", *args], capture_output=True, text=True, timeout=600)


def test_collapsed_step_stops_the_run_and_resume_with_a_changed_key_finishes_it(tmp_path):
    """c_max = 1e-9 makes the fluid Courant limit ~1e-9 of the step: the first step past a moving fluid stops the
    run naming the fluid Courant and [mppic] c_max; the file says "failed" and keeps its checkpoints; the same
    scene with c_max = 0.5 resumes from the last checkpoint and completes."""
    scene = tmp_path / "tiny.toml"
    scene.write_text(TINY.replace('dt_max = "0.25 s"', 'dt_max = "0.25 s"\nc_max = 1e-9'))
    out = tmp_path / "run.h5"
    failed = _hfgpu("run", str(scene), "--out", str(out))
    assert failed.returncode != 0
    assert "the proppant step collapsed" in failed.stderr
    assert "bounded by the fluid Courant ([mppic] c_max" in failed.stderr
    kept = open_results(out)
    assert kept.status.startswith("failed")
    assert len(kept.fracture_snapshots) > 0
    banner = status_banner(kept)
    assert banner.startswith("NOT COMPLETE: failed: the proppant step collapsed")
    figures = plots.figures(kept)
    assert figures and all(any(t.get_text() == banner for t in fig.texts) for fig in figures.values())
    scene.write_text(TINY.replace('dt_max = "0.25 s"', 'dt_max = "0.25 s"\nc_max = 0.5'))
    resumed = _hfgpu("run", str(scene), "--out", str(out), "--resume")
    assert resumed.returncode == 0, resumed.stderr
    done = open_results(out)
    assert done.status == "complete"
    assert status_banner(done) is None
    assert done.summary["proppant_time"] == pytest.approx(40.0)


def _watch() -> tuple[Watch, GridFrame]:
    return Watch(theta_cp=0.6, smallest_grain=100e-6, units="field"), GridFrame(6.0, 6.0, 0.0, 3000.0)


def test_overpacked_cell_warns_once_with_place_and_width():
    watch, frame = _watch()
    width = np.full((3, 4), 2e-3)
    theta = np.zeros((3, 4))
    theta[1, 2] = 0.7
    with pytest.warns(RuntimeWarning, match=r"theta_p above close packing at t = 1 000 s: theta_p 0.7 .* "
                                            r"x = 39.37 ft, depth 9 862 ft, 0.07874 in wide"):
        watch.after_step(1000.0, frame, width, theta)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        watch.after_step(1010.0, frame, width, theta)  # reported once
    assert watch.summary()["unphysical_states"].startswith("theta_p above close packing at t = 1 000 s")
    assert "fracture history closes it" in watch.summary()["unphysical_states"]


def test_overpacked_cell_of_a_fixed_width_names_placement_or_inflow():
    """Without a width history (a slot, a box) the message does not blame the fracture's closing."""
    watch = Watch(theta_cp=0.6, smallest_grain=100e-6, units="SI", width_history=False)
    theta = np.zeros((3, 4))
    theta[1, 2] = 0.78
    with pytest.warns(RuntimeWarning, match=r"the width is fixed, so its parcels were placed there above close "
                                            r"packing or one step's inflow overfilled it$"):
        watch.after_step(2e-3, GridFrame(0.005, 0.005, 0.0, 0.0), np.full((3, 4), 5e-3), theta)
    assert "fracture" not in watch.summary()["unphysical_states"]


def test_close_packing_within_the_packing_cap_is_not_reported():
    """The push's packing cap lets a cell exceed theta_cp by one step's inflow (0.66 < 1.1 x 0.6)."""
    watch, frame = _watch()
    theta = np.full((2, 2), 0.65)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        watch.after_step(1.0, frame, np.full((2, 2), 1e-3), theta)
    assert watch.summary()["unphysical_states"] == ""


def test_step_collapse_warns_then_stops():
    watch, frame = _watch()
    width, theta = np.full((2, 2), 1e-3), np.zeros((2, 2))
    limits = {"dt_max": 9.0, "output": 50.0, "fluid Courant": 1e-3, "parcel Courant": 4.0}
    with pytest.warns(RuntimeWarning, match=r"collapsing step .* bounded by the fluid Courant"):
        watch.check_step(5.0, 1e-3, 9.0, limits, frame, lambda: (1, 1), width, theta)
    with pytest.raises(SimulationError, match=r"collapsed: step 1e-06 s against 9 s, bounded by the fluid Courant"):
        watch.check_step(6.0, COLLAPSE_FLOOR * 9.0 / 9.0, 9.0, limits, frame, lambda: (1, 1), width, theta)


def test_proppant_in_a_cell_narrower_than_a_grain_warns_but_a_deposit_trace_does_not():
    watch, frame = _watch()
    width = np.full((2, 3), 2e-3)
    width[0, 2] = 80e-6  # below the smallest grain, 100 um
    theta = np.zeros((2, 3))
    theta[0, 2] = 0.005  # a neighbour's deposit share
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        watch.after_step(901.0, frame, width, theta)
    theta[0, 2] = 0.05
    with pytest.warns(RuntimeWarning, match=r"proppant in cells narrower than a grain at t = 902 s: theta_p 0.05 "
                                            r"in the cell at x = 39.37 ft"):
        watch.after_step(902.0, frame, width, theta)
    assert '"two-way" does' in watch.summary()["unphysical_states"]


def test_a_two_way_run_is_not_told_to_run_two_way():
    """In a two-way run ([coupling] mode = "two-way") the narrow-cell warning does not suggest that mode."""
    _, frame = _watch()
    watch = Watch(theta_cp=0.6, smallest_grain=100e-6, units="field", two_way=True)
    width = np.full((2, 3), 2e-3)
    width[0, 2] = 80e-6
    theta = np.zeros((2, 3))
    theta[0, 2] = 0.05
    with pytest.warns(RuntimeWarning, match=r"the cell is closing around its proppant$"):
        watch.after_step(902.0, frame, width, theta)


def test_the_engine_setup_knows_a_two_way_scene():
    scene = load_scene(scene_path("frac_pack_tso.toml"))
    assert proppant_engine_setup(edit_scene(scene, {"coupling.mode": "two-way"})).two_way
    assert not proppant_engine_setup(edit_scene(scene, {"coupling.mode": "one-way"})).two_way
