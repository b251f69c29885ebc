"""The one-way coupled run (hfgpu/coupled.py, runner dispatch): a tiny layered scene end to end (seconds), its
results file (both physics, solid balance, parcels in open cells, screen-out flags), scene checks, and the
five-layer trends (slow)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from hfgpu import load_scene, open_results, run
from hfgpu.coupled import late_start, proppant_start_time, screen_out_cells
from hfgpu.coupling import FractureHistory
from hfgpu.coupling_config import CouplingConfig
from hfgpu.errors import SceneError
from hfgpu.proppant.simulator import scheduled_solid_volume
from hfgpu.scene import Schedule, Stage

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "hfgpu" / "scenes"

#: A 12 m pay (10 MPa) between 12 MPa barriers; 20 s pad then 20 s of 10 % slurry. Small on purpose.
TINY = (Path(__file__).parent / "scenes" / "tiny_coupled.toml").read_text()


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    path = tmp_path_factory.mktemp("coupled") / "tiny.h5"
    summary = run(load_scene(TINY), path, progress=False)
    return summary, open_results(path)


def test_one_file_holds_fracture_and_proppant(tiny):
    summary, r = tiny
    assert r.status == "complete"
    assert len(r.fracture_snapshots) >= 6 and r.fracture_balance["time"].size > 5
    assert len(r.proppant_snapshots) == 3 and r.proppant_balance["time"].size > 5
    # the proppant run starts at the pad's end and keeps the scene's clock
    np.testing.assert_allclose(r.proppant_snapshots.times, [20.0, 30.0, 40.0], rtol=1e-9)
    assert r.proppant_balance["time"][0] > 20.0 and r.proppant_balance["time"][-1] == pytest.approx(40.0)
    assert summary["proppant_start"] == 20.0 and summary["fracture_time"] == pytest.approx(40.0)
    assert r.summary["proppant_nx"] == summary["proppant_nx"]


def test_the_phases_are_timed(tiny, monkeypatch):
    """Each phase's wall time is in the summary (the proppant run measures its fluid steps and parcel sub-loops);
    a measure inside another is taken out of it (the sinks' io out of the fracture's steps)."""
    import time

    from hfgpu.coupled import Timings

    summary, _ = tiny
    assert all(summary[f"time_{phase}"] > 0.0 for phase in ("fracture", "fluid", "parcels", "io"))
    clock = iter([0.0, 1.0, 3.0, 6.0])
    monkeypatch.setattr(time, "perf_counter", lambda: next(clock))
    timings = Timings()
    with timings.measure("fracture"):
        with timings.measure("io"):
            pass
    assert timings.seconds["io"] == 2.0 and timings.seconds["fracture"] == 4.0


def test_solid_balance_and_scheduled_solid(tiny):
    _, r = tiny
    b = r.proppant_balance
    np.testing.assert_allclose(b["injected"], b["in_domain"] + b["outflow"] + b["screened_out"], rtol=1e-9,
                               atol=1e-15)
    scheduled = 0.1 * 2e-3 * 20.0  # c Q t of the slurry stage [m^3]
    snap = r.proppant_snapshots[-1]
    parcel = float(np.max(snap.parcels["particles"] * 4 / 3 * np.pi * snap.parcels["radius"]**3))
    # emitted in whole parcels: at most a couple of parcels of solid still owed at the end
    assert scheduled - 3 * parcel <= b["injected"][-1] <= scheduled * (1 + 1e-9)


def test_fluid_supplied_is_the_width_histories_mismatch(tiny):
    """Conservation of the fluid on the proppant grid: what the fluid step supplied beyond the inlets
    (proppant_fluid_supplied) is the open volume the fracture history gained on the grid, plus its leak-off,
    minus the fluid injected (1 - c) Q t, the solids now occupying the fracture and the fluid of cells that
    opened (filled by the fracture's own flow), plus that of cells that closed."""
    summary, r = tiny
    history = FractureHistory(r.fracture_snapshots)
    first, last = r.proppant_snapshots[0], r.proppant_snapshots[-1]
    shape = np.shape(last.grid["width"])
    area = last.frame.dx * last.frame.dz
    thin = r.scene.coupling.min_width  # narrower cells are closed for the proppant run
    volume = [np.sum(history.fields_at(t, last.frame, shape, thin)[0]) * area for t in (20.0, 40.0)]
    times = np.linspace(20.0, 40.0, 401)
    leak = [np.sum(history.fields_at(t, last.frame, shape, thin)[1]) * area for t in times]
    leaked = float(np.sum(0.5 * (np.add(leak[1:], leak[:-1])) * np.diff(times)))
    injected = 0.9 * 2e-3 * 20.0
    assert summary["proppant_fluid_injected"] == pytest.approx(injected, rel=1e-9)
    solids = r.proppant_balance["in_domain"][-1]
    expected = (volume[1] - volume[0] + leaked - injected - solids - summary["proppant_fluid_opened"]
                + summary["proppant_fluid_dropped"])
    assert first.time == 20.0
    assert summary["proppant_fluid_supplied"] == pytest.approx(expected, abs=2e-4 * injected)


def test_parcels_stay_inside_open_cells_and_width_follows_the_fracture(tiny):
    _, r = tiny
    history = FractureHistory(r.fracture_snapshots)
    for snap in r.proppant_snapshots:
        w = snap.grid["width"]
        p = snap.parcels
        i = np.floor((p["x"] - snap.frame.x0) / snap.frame.dx + 0.5).astype(int)
        k = np.floor((p["z"] - snap.frame.z0) / snap.frame.dz + 0.5).astype(int)
        assert p["x"].size > 0 or snap.time == 20.0
        assert np.all((0 <= i) & (i < w.shape[1]) & (0 <= k) & (k < w.shape[0]))
        assert np.all(w[k, i] > 0.0)
        expected, _, _ = history.fields_at(snap.time, snap.frame, w.shape, r.scene.coupling.min_width)
        np.testing.assert_allclose(w, expected, rtol=1e-12, atol=1e-15)


def test_screen_out_flags_are_recorded_and_match_the_criterion(tiny):
    summary, r = tiny
    last = r.proppant_snapshots[-1]
    risk = last.grid["bridging_risk"].astype(bool)
    np.testing.assert_array_equal(risk, screen_out_cells(last, factor=2.0))
    assert summary["screen_out_cells"] == int(risk.sum())
    # flagged cells are open and narrower than 2 grain diameters (0.6 mm)
    assert np.all(last.grid["width"][risk] > 0.0) and np.all(last.grid["width"][risk] < 0.6e-3)


@pytest.fixture(scope="module")
def screened(tmp_path_factory):
    """TINY with 0.5 mm grains at 30 % loading: they fit the width but bridge (w < 2 d) at the perforation and
    the inlet ring packs."""
    path = tmp_path_factory.mktemp("screen") / "screened.h5"
    scene = load_scene(TINY.replace("volume_fraction = 0.1", "volume_fraction = 0.3")
                       .replace('"300 um"', '"500 um"'))
    with pytest.warns(RuntimeWarning, match="screen-out: the inlets held back"):
        summary = run(scene, path, progress=False)
    return summary, open_results(path)


def test_screen_out_holds_proppant_back_with_the_balance_exact(screened):
    summary, r = screened
    b = r.proppant_balance
    scheduled = 0.3 * 2e-3 * 20.0  # c Q t of the slurry stage [m^3]
    assert 0.0 < b["screened_out"][-1] < scheduled
    assert summary["proppant_screened_out"] == pytest.approx(b["screened_out"][-1], rel=1e-12)
    np.testing.assert_allclose(b["injected"], b["in_domain"] + b["outflow"] + b["screened_out"], rtol=1e-12,
                               atol=1e-18)
    assert b["injected"][-1] <= scheduled * (1 + 1e-9)
    # the first hold-back is reported on the scene's clock, inside the slurry stage
    first = summary["proppant_screen_out_time"]
    assert 20.0 < first < 40.0
    assert np.all(b["screened_out"][b["time"] <= first] == 0.0) and b["screened_out"][b["time"] > first + 1].min() > 0


def test_volume_fraction_stays_at_close_packing_during_screen_out(screened):
    _, r = screened
    theta = np.array([snap.grid["volume_fraction"].max() for snap in r.proppant_snapshots])
    assert theta.max() > 0.5  # the inlet ring did pack
    assert theta.max() <= 1.05 * 0.6


def test_runner_imports_both_physics_only_for_a_coupled_scene(tmp_path):
    coupled = tmp_path / "coupled.toml"
    coupled.write_text(TINY)
    code = textwrap.dedent(f"""
        import json, sys
        from hfgpu.runner import simulator_for
        from hfgpu.scene import load_scene
        out = {{}}
        for name in ("fracture", "coupled"):
            path = {str(SCENES / "radial_I.toml")!r} if name == "fracture" else {str(coupled)!r}
            simulator_for(load_scene(path))
            out[name] = sorted(m for m in ("hfgpu.fracture.simulator", "hfgpu.proppant.simulator")
                               if m in sys.modules)
        print(json.dumps(out))
    """)
    got = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                    check=True).stdout)
    assert got["fracture"] == ["hfgpu.fracture.simulator"]
    assert got["coupled"] == ["hfgpu.fracture.simulator", "hfgpu.proppant.simulator"]


# -- scene checks ---------------------------------------------------------------------------------

def test_coupling_defaults_and_keys():
    scene = load_scene(TINY.replace('fracture_every = "5 s"', 'cell_size = ["2 m", "1 m"]\n'
                                    'inlet_radius = "3 m"\nproppant_start = "10 s"\nmin_width = "2 um"'))
    assert scene.coupling == CouplingConfig(fracture_every=40.0 / 60, cell_size=(2.0, 1.0), inlet_radius=3.0,
                                            proppant_start=10.0, min_width=2e-6)
    assert load_scene(TINY).coupling.min_width == 10e-6
    assert proppant_start_time(scene) == 10.0
    assert proppant_start_time(load_scene(TINY)) == 20.0


@pytest.mark.parametrize("edit, key", [
    (lambda s: s + '[geometry]\nkind = "box"\n', "geometry"),
    (lambda s: s.replace('fracture_every = "5 s"', 'inlet_inner_radius = "2 m"\ninlet_radius = "1 m"'),
     "coupling.inlet_radius"),
    (lambda s: s.replace('fracture_every = "5 s"', 'proppant_start = "50 s"'), "coupling.proppant_start"),
    (lambda s: s.replace('fracture_every = "5 s"', 'speed = 2'), "coupling.speed"),
    (lambda s: s.replace('fracture_every = "5 s"', 'min_width = "-1 um"'), "coupling.min_width"),
])
def test_bad_coupled_scenes_name_the_key(edit, key):
    with pytest.raises(SceneError) as info:
        load_scene(edit(TINY))
    assert key in str(info.value)


def test_coupling_table_needs_both_physics():
    text = (SCENES / "radial_I.toml").read_text() + '\n[coupling]\nfracture_every = "1 s"\n'
    with pytest.raises(SceneError, match="'coupling'.*both"):
        load_scene(text)


def test_scene_without_a_proppant_stage_is_refused():
    scene = load_scene(TINY.replace(', proppant = "sand", volume_fraction = 0.1', ''))
    with pytest.raises(SceneError, match="proppant"):
        proppant_start_time(scene)


def test_a_proppant_run_from_its_start_counts_the_schedule_from_there():
    """The coupled proppant run starts at the proppant start on the scene's clock; the solids its parcel budget
    counts (hfgpu.proppant.simulator.particles_per_parcel) are those pumped from then on, a stage cut there from
    the loading it has then."""
    s = Schedule((Stage(10.0, 1.0), Stage(30.0, 2.0, "a", 0.1, 0.3)))
    assert scheduled_solid_volume(s, "a", 20.0) == pytest.approx(s.solid_volume(20.0, 30.0), rel=1e-14)
    assert scheduled_solid_volume(s, "a") == pytest.approx(s.solid_volume(0.0, 30.0), rel=1e-14)
    assert scheduled_solid_volume(s, "a", 5.0) == scheduled_solid_volume(s, "a")


# -- the five-layer treatment (section 6): trends, never the paper's numbers -----------------------

@pytest.fixture(scope="module")
def demo_runs(tmp_path_factory):
    """The scaled five-layer case with 40/70 and 100 mesh sand (numpy backend), run once for the slow tests.
    (30/50 is left out to save time; it screens out like 40/70, docs/field-case.md.)"""
    sys.path.insert(0, str(ROOT / "demos"))
    from field_case import load

    folder = tmp_path_factory.mktemp("five_layer")
    out = {}
    for size in ("40/70", "100 mesh"):
        path = folder / f"{size.replace('/', '-').replace(' ', '_')}.h5"
        run(load(True, "numpy", size), path, progress=False)
        out[size] = open_results(path)
    return out


@pytest.mark.slow
def test_five_layer_footprint_is_an_hour_glass_held_by_the_barriers(demo_runs):
    snap = demo_runs["40/70"].fracture_snapshots[-1]
    w, f = snap.width, snap.frame
    z = f.z0 + f.dz * np.arange(w.shape[0])
    length = (w > 0).sum(axis=1) * f.dx
    pay2, pay3, pay4 = ((z > a) & (z < b) for a, b in ((2972.5, 2992.5), (2992.5, 3007.5), (3007.5, 3027.5)))
    assert length[pay2].max() > length[pay3].min() and length[pay4].max() > length[pay3].min()
    assert w[pay2].max() > w[pay3].max() and w[pay4].max() > w[pay3].max()
    barrier = (z < 2962.5) | (z > 3037.5)  # 10 m into the barriers
    assert not (w[barrier] > 0).any()


@pytest.mark.slow
def test_five_layer_proppant_is_held_in_layer_3_and_props_part_of_the_area(demo_runs):
    from hfgpu.propped import propped_summary

    r = demo_runs["40/70"]
    snap = r.proppant_snapshots[-1]
    z = snap.parcels["z"]
    assert np.mean((z > 2992.5) & (z < 3007.5)) > 0.5  # most of the proppant stays in the narrow layer 3
    s = propped_summary(r)
    assert 0.0 < s["propped_fraction"] < 1.0
    assert s["packed_fraction"] > 0.5


@pytest.mark.slow
def test_finer_proppant_props_more_is_less_packed_and_screens_out_less(demo_runs):
    from hfgpu.propped import propped_summary

    coarse, fine = (propped_summary(demo_runs[k]) for k in ("40/70", "100 mesh"))
    assert fine["propped_area"] > coarse["propped_area"]
    assert fine["packed_fraction"] < coarse["packed_fraction"]
    assert fine["screen_out_cells"] <= coarse["screen_out_cells"]


def test_proppant_start_waits_for_the_first_fracture_cells():
    """A fracture that fills its first cells after the pad (coarse grid) moves the proppant start there, with a
    warning giving the solids pumped in between: 2e-3 m^3/s x 0.1 x 5 s = 1e-3 m^3."""
    scene = load_scene(TINY)
    assert late_start(scene, 20.0, 15.0) == 20.0
    with pytest.warns(RuntimeWarning, match=r"at 25 s.*\(20 s\).*0\.001 m\^3 of solids"):
        assert late_start(scene, 20.0, 25.0) == 25.0
