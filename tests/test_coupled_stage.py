"""The proppant of a stage (hfgpu.coupled_stage, hfgpu.stage_blocks): the clusters' blocks side by side on one
grid, the slurry split among the inlets as the wellbore node split the fluid, each cluster's view of the
proppant; one cluster gives the single fracture's coupled run, two identical clusters far apart share the
proppant equally, the solid balance holds per stage and per cluster."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from hfgpu import coupled, coupled_stage
from hfgpu.errors import SceneError
from hfgpu.proppant.config import Port, ProppantClass
from hfgpu.proppant.injection import Injector
from hfgpu.proppant.sieve import SizeDistribution
from hfgpu.records import GridFrame, MemorySink, ProppantSnapshot
from hfgpu.scene import load_scene
from hfgpu.simulators import simulator_module
from hfgpu.stage_blocks import Blocks, ClusterSplit, cluster_view, clusters_of

TINY = (Path(__file__).parent / "scenes" / "tiny_coupled.toml").read_text()


def tiny_stage(completion: str, rate: str = "2e-3 m**3/s") -> str:
    return TINY.replace('rate = "2e-3 m**3/s"', f'rate = "{rate}"') + "[completion]\n" + completion


def test_blocks_tile_and_cut_back():
    frame = GridFrame(dx=2.0, dz=1.0, x0=-3.0, z0=10.0)
    blocks = Blocks(frame, (3, 4), 3)
    assert blocks.tiled_shape == (3, 14) and blocks.shift(2) == pytest.approx(20.0)
    fields = [np.full((3, 4), float(i + 1)) for i in range(3)]
    tiled = blocks.tile(fields)
    assert np.all(tiled[:, 4] == 0.0) and np.all(tiled[:, 9] == 0.0)
    labels = blocks.labels()
    assert list(labels[0]) == [0] * 4 + [-1] + [1] * 4 + [-1] + [2] * 4
    # a parcel in cluster 1's block at the plane's x = 1 m, and one in cluster 2's at x = -3 m
    parcels = {"x": np.array([1.0 + blocks.shift(1), -3.0 + blocks.shift(2)]), "z": np.array([10.5, 11.0]),
               "radius": np.array([1e-4, 2e-4])}
    grid = {"width": tiled, "cluster": labels, "fluid_u": np.arange(3 * 15.0).reshape(3, 15),
            "fluid_v": np.arange(4 * 14.0).reshape(4, 14)}
    snap = ProppantSnapshot(time=1.0, frame=frame, parcels=parcels, grid=grid)
    assert clusters_of(snap) == 3
    one = cluster_view(snap, 1)
    assert np.all(one.grid["width"] == 2.0) and one.grid["fluid_u"].shape == (3, 5)
    assert one.grid["fluid_v"].shape == (4, 4) and np.array_equal(one.grid["fluid_u"], grid["fluid_u"][:, 5:10])
    assert one.parcels["x"] == pytest.approx([1.0]) and one.parcels["radius"] == pytest.approx([1e-4])
    assert cluster_view(snap, 2).parcels["x"] == pytest.approx([-3.0])
    assert cluster_view(snap, 0).parcels["x"].size == 0
    with pytest.raises(ValueError, match="no cluster 3"):
        cluster_view(snap, 3)


def test_the_split_follows_the_clusters_volumes():
    """Shares over an interval are the clusters' volume increments over it (linear between records), equal where
    nothing is pumped."""
    split = ClusterSplit(np.array([1.0, 2.0, 3.0]), np.array([[1.0, 1.0], [3.0, 2.0], [3.0, 2.0]]))
    assert split(1.0, 2.0) == pytest.approx([2.0 / 3.0, 1.0 / 3.0], rel=1e-12)
    assert split(0.0, 1.0) == pytest.approx([0.5, 0.5], rel=1e-12)
    assert split(1.5, 2.0) == pytest.approx([2.0 / 3.0, 1.0 / 3.0], rel=1e-12)
    assert split(2.0, 3.0) == pytest.approx([0.5, 0.5])   # shut in


def test_the_injector_splits_fluid_and_solids_by_the_split():
    """Two inlets with a time-varying split: each gets its share of the fluid, and of the solids to one parcel."""
    frame = GridFrame(dx=1.0, dz=1.0, x0=0.0, z0=0.0)
    width = np.full((4, 9), 0.01)
    sand = ProppantClass("sand", 2650.0, SizeDistribution("fixed", 3e-4, 3e-4, 3e-4))
    ports = (Port("point", x=1.0, depth=1.0), Port("point", x=7.0, depth=2.0))
    share = {"now": np.array([0.7, 0.3])}
    injector = Injector(ports, frame, width, (sand,), [100.0], rate=lambda t0, t1: 1e-3,
                        loadings=lambda t: [(0, 0.1)], rng=np.random.default_rng(1),
                        split=lambda t0, t1: share["now"])
    fluid = injector.fluid_sources(0.0, 1.0)
    assert fluid[1, 1] == pytest.approx(0.7 * 0.9e-3, rel=1e-12) and fluid[2, 7] == pytest.approx(0.27e-3, rel=1e-12)
    emitted = np.zeros(2)
    for step in range(200):
        share["now"] = np.array([0.7, 0.3]) if step % 2 else np.array([0.2, 0.8])
        batch = injector.emit(float(step), step + 1.0)
        volume = batch["particles"] * math.pi / 6.0 * (2.0 * batch["radius"]) ** 3
        emitted += [volume[batch["x"] < 4.5].sum(), volume[batch["x"] >= 4.5].sum()]
    expected = 1e-3 * 0.1 * 200 * np.array([0.45, 0.55])
    parcel = 100 * math.pi / 6.0 * 3e-4**3
    assert np.all(np.abs(emitted - expected) <= parcel * 1.0001)


def test_an_inlet_whose_cells_closed_takes_no_fluid_and_says_so():
    """A starved cluster's perforation cells close on the proppant grid: its share of the fluid does not enter
    (a source in a closed cell would be refused by the fluid step), the other inlets keep theirs, one warning."""
    frame = GridFrame(dx=1.0, dz=1.0, x0=0.0, z0=0.0)
    width = np.full((4, 9), 0.01)
    sand = ProppantClass("sand", 2650.0, SizeDistribution("fixed", 3e-4, 3e-4, 3e-4))
    ports = (Port("point", x=1.0, depth=1.0), Port("point", x=7.0, depth=2.0))
    injector = Injector(ports, frame, width, (sand,), [100.0], rate=lambda t0, t1: 1e-3, loadings=lambda t: [],
                        rng=np.random.default_rng(1), split=lambda t0, t1: np.array([0.6, 0.4]))
    closed = width.copy()
    closed[2, 7] = 0.0
    with pytest.warns(RuntimeWarning, match="inlet 2's cells are closed"):
        sources = injector.fluid_sources(0.0, 1.0, closed)
    assert sources[1, 1] == pytest.approx(0.6e-3, rel=1e-12) and sources[2, 7] == 0.0 and sources.sum() == sources[1, 1]
    assert injector.fluid_sources(1.0, 2.0, width)[2, 7] == pytest.approx(0.4e-3, rel=1e-12)


def test_a_stage_with_proppant_runs_the_coupled_stage_and_refuses_two_way():
    scene = load_scene(tiny_stage("clusters = 2\nspacing = \"500 m\"\n"))
    assert simulator_module(scene) == "hfgpu.coupled_stage"
    with pytest.raises(SceneError) as error:
        load_scene(tiny_stage("clusters = 2\nspacing = \"500 m\"\n").replace(
            'fracture_every = "5 s"', 'fracture_every = "5 s"\nmode = "two-way"'))
    assert any(e.path == "coupling.mode" for e in getattr(error.value, "errors", [error.value]))


@pytest.fixture(scope="module")
def single_and_one_cluster():
    single = coupled.simulate(load_scene(TINY), MemorySink())
    sink = MemorySink()
    staged = coupled_stage.simulate(load_scene(tiny_stage("clusters = 1\n")), sink)
    return single, staged, sink


def test_one_cluster_is_the_single_fracture_coupled_run(single_and_one_cluster):
    """One cluster without perforation friction: the fracture to round-off (hfgpu.fracture.stage), the proppant
    grid the same, and the proppant's result to the fracture's round-off (the stage's fracture differs from the
    single one by ~1e-12: the cluster's volume is summed step by step)."""
    single, staged, _ = single_and_one_cluster
    for key in ("area", "injected", "stored"):
        assert staged[f"fracture_{key}"] == pytest.approx(single[f"fracture_{key}"], rel=1e-10)
    for key in ("proppant_nx", "proppant_nz", "proppant_start", "proppant_steps", "proppant_parcels"):
        assert staged[key] == single[key], key
    for key in ("proppant_injected", "proppant_in_domain", "proppant_fluid_injected", "proppant_fluid_stored"):
        assert staged[key] == pytest.approx(single[key], rel=1e-8), key
    assert staged["cluster_0_solid_share"] == 1.0
    assert staged["cluster_0_solid"] == pytest.approx(single["proppant_in_domain"], rel=1e-8)


@pytest.fixture(scope="module")
def two_far_apart(tmp_path_factory):
    import hfgpu

    path = tmp_path_factory.mktemp("stage") / "two.h5"
    scene = load_scene(tiny_stage("clusters = 2\nspacing = \"1 km\"\n", "4e-3 m**3/s"))
    return hfgpu.run(scene, path, progress=False), hfgpu.open_results(path)


def test_two_identical_clusters_far_apart_share_the_proppant_equally(two_far_apart, single_and_one_cluster):
    """Two identical clusters 1 km apart at twice the rate: the fluid splits equally (to 1e-9), so does the
    proppant (to two parcels), and each cluster holds what the single fracture at the single rate holds
    (its fracture to 1e-9; its proppant to two parcels)."""
    summary, results = two_far_apart
    single = single_and_one_cluster[0]
    assert summary["cluster_0_injected"] == pytest.approx(summary["cluster_1_injected"], rel=1e-9)
    last = results.proppant_snapshots[-1]
    parcel = float(np.max(last.parcels["particles"] * 4.0 / 3.0 * math.pi * last.parcels["radius"] ** 3))
    assert abs(summary["cluster_0_solid"] - summary["cluster_1_solid"]) <= 2 * parcel
    for i in range(2):
        assert summary[f"cluster_{i}_area"] == pytest.approx(single["fracture_area"], rel=1e-9)
        assert summary[f"cluster_{i}_solid"] == pytest.approx(single["proppant_in_domain"], abs=2 * parcel)
    assert summary["cluster_0_created_area"] == summary["cluster_1_created_area"]


def test_the_stage_solid_balance_holds_and_the_blocks_stay_apart(two_far_apart):
    """Injected = in the domain + outflow + held back at every step (1e-12 relative); no parcel on a closed column
    between the blocks; each snapshot's clusters hold the stage's proppant."""
    _, results = two_far_apart
    b = results.proppant_balance
    gap = b["injected"] - b["in_domain"] - b["outflow"] - b["screened_out"]
    assert np.all(np.abs(gap) <= 1e-12 * np.maximum(b["injected"], 1e-30))
    for snap in results.proppant_snapshots:
        labels = snap.grid["cluster"]
        f = snap.frame
        column = np.clip(np.floor((snap.parcels["x"] - f.x0) / f.dx + 0.5).astype(int), 0, labels.shape[1] - 1)
        assert np.all(labels[0, column] >= 0)
        volume = lambda p: float(np.sum(p["particles"] * 4.0 / 3.0 * math.pi * p["radius"] ** 3))  # noqa: E731
        parts = sum(volume(cluster_view(snap, i).parcels) for i in range(2))
        assert parts == pytest.approx(volume(snap.parcels), rel=1e-12)


def test_the_clusters_closure_sums_to_the_stage_and_has_its_figure(two_far_apart):
    """After closure: the clusters' propped areas sum to the stage's; the stage's half-length is the lead
    cluster's, not the width of the blocks side by side; the figures include one panel per cluster."""
    from hfgpu.io.plots import figures

    summary, results = two_far_apart
    areas = [summary[f"cluster_{i}_closure_propped_area"] for i in range(2)]
    assert sum(areas) == pytest.approx(summary["closure_propped_area"], rel=1e-12) and min(areas) > 0.0
    lead = int(np.argmax(areas))
    assert summary["closure_propped_half_length"] == summary[f"cluster_{lead}_closure_propped_half_length"]
    assert results.summary["cluster_1_closure_propped_area"] == areas[1]
    out = figures(results)
    assert len(out["stage_proppant"].subfigs[0].axes) >= 2


def test_a_stage_exports_one_map_per_cluster(two_far_apart, tmp_path):
    """``hfgpu export`` of a stage with proppant writes one file per cluster (one fracture per file, as StimPlan
    readers take them): each holds its cluster's propped cells and its own fracture's width, on the plane's x."""
    from hfgpu.io.export import export

    summary, results = two_far_apart
    files = export(results.path, "csv", tmp_path / "map.csv", units="SI")
    assert [f.name for f in files] == ["map_cluster1.csv", "map_cluster1_pressure.csv", "map_cluster2.csv",
                                       "map_cluster2_pressure.csv"]
    frame = results.proppant_snapshots[-1].frame
    for i in range(2):
        table = np.genfromtxt(tmp_path / f"map_cluster{i + 1}.csv", delimiter=",", names=True)
        assert table["propped"].sum() * frame.dx * frame.dz == pytest.approx(
            summary[f"cluster_{i}_closure_propped_area"], rel=1e-12)
        assert table["width_m"].max() == pytest.approx(float(results.stage_snapshots[i][-1].width.max()), rel=1e-9)
        assert table["x_m"].max() < frame.x0 + summary["proppant_cluster_nx"] * frame.dx
    assert len(export(results.path, "stimplan-xml", tmp_path / "map.xml")) == 2
