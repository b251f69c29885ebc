"""A stage of several clusters (hfgpu.fracture.stage): one cluster is the single fracture, far-apart identical
clusters split the rate equally, the wellbore node holds at every step, the shadow of a tight uniform array
suppresses its inner fractures (Peirce & Bunger 2015, SPE J 20(2)) and entry friction well above the shadow evens
them out."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu.fracture import simulator, stage
from hfgpu.perforations import entry_coefficient
from hfgpu.records import MemorySink
from hfgpu.scene import load_scene

from .helpers import scene_text

BASE = dict(end_time="200 s", rate="5e-3 m**3/s", cell="1.5 m")
LIMITED = 'perforations = 2\nperforation_diameter = "0.3 in"\ndischarge_coefficient = 0.8\n'


class StageSink(MemorySink):
    def __init__(self):
        super().__init__()
        self.stage_records = []

    def stage_record(self, record):
        self.stage_records.append(record)


def run(completion: str, **kw):
    scene = load_scene(scene_text(**(BASE | kw)) + "[completion]\n" + completion)
    sink = StageSink()
    return stage.simulate(scene, sink), sink, scene


def test_one_cluster_without_friction_is_the_single_fracture():
    """To round-off (1e-10 relative; measured 4e-12: the cluster's injected volume is summed step by step)."""
    single_sink = MemorySink()
    single = simulator.simulate(load_scene(scene_text(**BASE)), single_sink)
    staged, sink, _ = run("clusters = 1\n")
    assert staged["steps"] == single["steps"] and staged["stage_iterations"] == single["steps"]
    for key in ("area", "injected", "stored", "leaked"):
        assert staged[key] == pytest.approx(single[key], rel=1e-10)
    (cluster,) = staged["clusters"]
    assert cluster["p_inlet"] == pytest.approx(single["p_inlet"], rel=1e-10)
    assert cluster["w_inlet"] == pytest.approx(single["w_inlet"], rel=1e-10)
    assert staged["wellbore_pressure"] == pytest.approx(single["p_inlet"], rel=1e-10)
    np.testing.assert_allclose([r.injection_pressure for r in sink.fracture_balances],
                               [r.injection_pressure for r in single_sink.fracture_balances], rtol=1e-10)
    np.testing.assert_allclose(sink.fracture_snapshots[-1].width, single_sink.fracture_snapshots[-1].width,
                               rtol=1e-10, atol=1e-16)


def test_identical_clusters_far_apart_split_the_rate_equally():
    summary, sink, _ = run('positions = ["0 m", "1000 m", "2000 m"]\n' + LIMITED)
    rates = np.array([c["rate"] for c in summary["clusters"]])
    np.testing.assert_allclose(rates, rates.mean(), rtol=5e-3)
    np.testing.assert_allclose([c["area"] for c in summary["clusters"]], summary["clusters"][0]["area"], rtol=5e-3)
    assert rates.sum() == pytest.approx(5e-3, rel=1e-12)
    assert summary["max_balance_error"] < 1e-12 and summary["unconverged_steps"] == 0


def test_two_clusters_of_different_stress_meet_one_wellbore_pressure():
    """No shadow (1 km apart), 0.5 MPa more stress on the second: it takes less, and at every step
    p_w = p_i + a q_i^2 for both (the iteration's tolerance: within 1e-3 of the net pressure; measured 1.3e-4 of
    p_w)."""
    summary, sink, scene = run('positions = ["0 m", "1000 m"]\nstress_offsets = ["0 MPa", "0.5 MPa"]\n' + LIMITED)
    a = entry_coefficient(1000.0, 2, 0.3 * 0.0254, 0.8)
    for record in sink.stage_records:
        q = record.rates
        assert q.sum() == pytest.approx(5e-3, rel=1e-12) and q[1] < q[0]
        for i in range(2):
            p_i = record.clusters[i].injection_pressure
            assert record.wellbore_pressure == pytest.approx(p_i + a * q[i] ** 2, rel=2e-3)
    assert summary["unconverged_steps"] == 0


def areas(spacing: str, extra: str = ""):
    summary, _, _ = run(f'clusters = 5\nspacing = "{spacing}"\n' + extra)
    return np.array([c["area"] for c in summary["clusters"]]), summary


def test_a_tight_uniform_array_without_entry_friction_suppresses_its_inner_fractures():
    """Peirce & Bunger (2015, SPE J 20(2), 'Interference fracturing: nonuniform distributions of perforation
    clusters that promote simultaneous growth'): in a uniform 5-cluster array with negligible entry friction the
    outer fractures take the fluid and the inner ones are suppressed (qualitative; their figures were not
    digitised here). Spacing 6 m, about 0.6 of the final radius."""
    area, summary = areas("6 m")
    assert area[0] == pytest.approx(area[4], rel=1e-6) and area[1] == pytest.approx(area[3], rel=1e-6)
    assert area[1] < 0.5 * area[0] and area[2] < 0.5 * area[0]
    rates = [c["rate"] for c in summary["clusters"]]
    assert rates[0] > 0.4 * 5e-3 / 2 and max(rates[1:4]) < 0.1 * 5e-3
    assert summary["max_balance_error"] < 1e-12


def test_entry_friction_well_above_the_shadow_evens_out_the_fractures():
    """The same array with 1 perforation of 0.15 in per cluster: dp_perf 5.3 to 6.8 MPa, well above the shadow
    (the inner inlet's pressure over sigma_0 exceeds the outer's by 1.5 MPa): every fracture within 10 % of the
    mean area (measured: 0.07 %)."""
    area, summary = areas("6 m", 'perforations = 1\nperforation_diameter = "0.15 in"\ndischarge_coefficient = 0.8\n')
    assert np.max(np.abs(area / area.mean() - 1.0)) < 0.10
    assert summary["unconverged_steps"] == 0


def test_the_results_file_holds_each_clusters_history(tmp_path):
    """``hfgpu run`` of a 3-cluster stage with a shut-in: /stage/balance rows sum to the pump rate, p_w is each
    pumping cluster's inlet pressure plus its perforation friction, the fracture balance carries p_w and the
    per-cluster summary scalars."""
    from hfgpu.io.results import open_results
    from hfgpu.runner import run as hfgpu_run

    text = scene_text(**(BASE | dict(schedule='[{ until = "150 s", rate = "5e-3 m**3/s" }, '
                                              '{ until = "200 s", rate = "0 m**3/s" }]', every="100 s")))
    text += '[completion]\nclusters = 3\nspacing = "6 m"\n' + LIMITED
    hfgpu_run(load_scene(text), tmp_path / "stage.h5", progress=False)
    r = open_results(tmp_path / "stage.h5")
    b, f = r.stage_balance, r.fracture_balance
    assert r.status == "complete" and b["rate"].shape == (b["time"].size, 3)
    pumping = b["time"] <= 150.0
    np.testing.assert_allclose(b["rate"][pumping].sum(axis=1), 5e-3, rtol=1e-12)
    assert np.all(b["rate"][~pumping] == 0.0) and np.all(np.isnan(b["wellbore_pressure"][~pumping]))
    a = entry_coefficient(1000.0, 2, 0.3 * 0.0254, 0.8)
    heads = b["injection_pressure"][pumping] + a * b["rate"][pumping] ** 2
    np.testing.assert_allclose(heads, np.repeat(b["wellbore_pressure"][pumping][:, None], 3, axis=1), rtol=2e-3)
    np.testing.assert_allclose(f["injection_pressure"][pumping], b["wellbore_pressure"][pumping], rtol=1e-15)
    np.testing.assert_allclose(f["stored"], b["stored"].sum(axis=1), rtol=1e-12)
    assert r.summary["cluster_1_area"] == pytest.approx(b["area"][-1, 1], rel=1e-12)
    assert [len(c) for c in r.stage_snapshots] == [len(r.fracture_snapshots)] * 3
    np.testing.assert_array_equal(r.stage_snapshots[0][-1].width, r.fracture_snapshots[-1].width)
    last = [c[-1] for c in r.stage_snapshots]
    np.testing.assert_allclose([float(s.extras["area"]) for s in last], b["area"][-1], rtol=1e-12)
    assert float(last[0].extras["injected_volume"]) == pytest.approx(b["injected"][-1, 0], rel=1e-12)


def test_hfgpu_plot_draws_the_split(tmp_path):
    from hfgpu.io.plots import plot_results
    from hfgpu.runner import run as hfgpu_run

    text = scene_text(**(BASE | dict(end_time="80 s", every="80 s"))) + '[completion]\nclusters = 2\nspacing = "6 m"\n'
    hfgpu_run(load_scene(text), tmp_path / "stage.h5", progress=False)
    written = {p.name for p in plot_results(tmp_path / "stage.h5", tmp_path / "figures")}
    assert {"stage_split.png", "stage_widths.png", "pressure_history.png"} <= written


def test_the_summary_table_has_a_row_per_cluster():
    from hfgpu.io.summary import cluster_rows

    summary, _, _ = run('clusters = 3\nspacing = "6 m"\n' + LIMITED)
    rows = cluster_rows(summary, "SI")
    shares = [float(text.split(" %")[0]) for _, _, text in rows]
    assert [label for _, label, _ in rows] == ["cluster 1", "cluster 2", "cluster 3"]
    assert sum(shares) == pytest.approx(100.0, abs=0.2) and shares[0] == shares[2] > shares[1]
    assert cluster_rows({"cluster_0_area": 1.0}, "SI") == []


@pytest.mark.slow
def test_the_demo_stage_runs_within_its_budget(tmp_path):
    """demos/stage.py's stage with its proppant (hfgpu/scenes/stage_demo.toml, hfgpu.coupled_stage): complete well
    within issue 36's 5 minutes on 2 cores (measured 30 s), every cluster's balance exact, the outer clusters take
    the most fluid, the limited entry keeps every cluster's area within 15 % of the mean (measured: 0.934 to
    1.076), and each cluster's share of the sand within 0.01 of its share of the fluid (measured within 0.001)."""
    import time
    from importlib import resources

    from hfgpu import coupled_stage

    scene = load_scene((resources.files("hfgpu") / "scenes" / "stage_demo.toml").read_text())
    start = time.perf_counter()
    summary = coupled_stage.simulate(scene, MemorySink())
    assert time.perf_counter() - start < 300.0
    area = np.array([summary[f"cluster_{i}_area"] for i in range(5)])
    fluid = np.array([summary[f"cluster_{i}_injected"] for i in range(5)])
    sand = np.array([summary[f"cluster_{i}_solid_share"] for i in range(5)])
    assert summary["fracture_max_balance_error"] < 1e-10 and summary["fracture_unconverged_steps"] == 0
    assert fluid[0] == pytest.approx(fluid[4], rel=1e-9) and fluid[0] > fluid[1] > fluid[2]
    assert np.max(np.abs(area / area.mean() - 1.0)) < 0.15
    assert np.max(np.abs(sand - fluid / fluid.sum())) < 0.01
