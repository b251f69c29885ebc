"""One definition per headline number (issue 31): the run summary, the sweep's metrics, ``propped_area.png`` and the
probability map of one run report the same propped area (hfgpu.propped.headline_propped), each naming it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hfgpu import load_scene, open_results, run
from hfgpu.ensemble.metrics import member_metrics, propped_map
from hfgpu.io.plots import propped_area
from hfgpu.io.summary import summary_table
from hfgpu.propped import DEFINITIONS, headline_propped, propped_cells
from hfgpu.units import format_number

TINY = (Path(__file__).parent / "scenes" / "tiny_coupled.toml").read_text()


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    scene = load_scene(TINY)
    path = tmp_path_factory.mktemp("headline") / "tiny.h5"
    summary = run(scene, path, progress=False)
    return scene, summary, open_results(path)


def test_summary_metric_and_headline_are_one_number(tiny):
    scene, summary, results = tiny
    head = headline_propped(results)
    metrics = member_metrics(results)
    assert summary["closure_propped_area"] > 0.0
    assert metrics["propped_area"] == pytest.approx(summary["closure_propped_area"], rel=1e-12)
    assert head["propped_area"] == pytest.approx(summary["closure_propped_area"], rel=1e-12)
    assert metrics["created_area"] == pytest.approx(summary["fracture_area"], rel=1e-12)
    assert metrics["propped_fraction"] == pytest.approx(summary["closure_propped_area"] / summary["fracture_area"],
                                                       rel=1e-12)
    # the one-layer rule in place is carried beside it, under its own name, on the closed snapshot
    snap = results.proppant_snapshots.at(head["time"])
    in_place = propped_cells(snap, scene.proppant.params.theta_cp).sum() * snap.frame.dx * snap.frame.dz
    assert metrics["propped_area_in_place"] == pytest.approx(in_place, rel=1e-12)


def test_probability_map_counts_the_summary_cells(tiny):
    _, summary, results = tiny
    frame, cells = propped_map(results)
    assert cells.sum() * frame.dx * frame.dz == pytest.approx(summary["closure_propped_area"], rel=1e-12)


def test_figure_and_table_show_the_summary_number_and_name_it(tiny):
    scene, summary, results = tiny
    fig = propped_area(results)
    lines = {line.get_label(): line for line in fig.axes[0].get_lines()}
    closed = lines[f"propped area, {DEFINITIONS['propped_area']}"]
    at = int(np.argmin(np.abs(closed.get_xdata() - summary["closure_time"])))
    assert closed.get_ydata()[at] == pytest.approx(summary["closure_propped_area"], rel=1e-12)
    star = lines["run summary's propped area"]
    assert star.get_ydata()[0] == pytest.approx(summary["closure_propped_area"], rel=1e-12)
    assert f"propped area, {DEFINITIONS['propped_area_in_place']}" in lines
    table = summary_table(summary, "SI", scene)
    line = next(x for x in table.splitlines() if "propped area (after closure)" in x)
    assert f" {format_number(summary['closure_propped_area'])} m^2 (" in line
    assert "created area (one face)" in table


def test_proppant_balance_figure_is_in_the_summary_mass(tiny):
    from hfgpu.io.plots import proppant_balance

    scene, summary, results = tiny
    line = proppant_balance(results).axes[0].get_lines()[0]   # injected
    assert line.get_ydata()[-1] == pytest.approx(summary["proppant_injected"] * 2650.0, rel=1e-12)
    assert proppant_balance(results).axes[0].get_ylabel() == "mass [kg]"
