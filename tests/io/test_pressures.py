"""The pressures an engineer reads (issue 31): BHTP, the state at the end of pumping and the ISIP, in the summary a
user sees and in ``pressure_history.png`` (log-log panel while pumping only, no minor tick labels)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from hfgpu import load_scene, open_results
from hfgpu.io.plots import pressure_history
from hfgpu.io.summary import pump_end, treatment_pressures
from hfgpu.units import convert, format_number

TINY = (Path(__file__).parent.parent / "scenes" / "tiny_coupled.toml").read_text()
#: The tiny coupled scene with 10 s of shut-in after its 40 s of pumping, in field units.
SHUT_IN = (TINY.replace('end_time = "40 s"', 'end_time = "50 s"')
           .replace("volume_fraction = 0.1 }]", 'volume_fraction = 0.1 },\n  { until = "50 s", rate = "0 m**3/s" }]')
           .replace("[output]", '[output]\nunits = "field"'))
HFGPU = [sys.executable, "-c", "import sys; from hfgpu.cli import main; sys.exit(main())"]


def test_treatment_pressures_read_the_records_either_side_of_the_stop():
    balance = {"time": np.array([0.0, 10.0, 20.0, 25.0, 30.0]), "length": np.array([1.0, 2.0, 3.0, 3.0, 3.0]),
               "area": np.array([1.0, 3.0, 6.0, 6.5, 6.5]),
               "height": np.array([1.0, 1.5, 2.0, 2.0, 2.0]), "net_pressure": np.array([5.0, 4.0, 3.0, 1.0, -1.0]),
               "injection_pressure": np.array([15.0, 14.0, 13.0, 11.0, 9.0])}
    p = treatment_pressures(balance, 20.0)
    assert p == dict(pumping_time=20.0, pumping_area=6.0, pumping_length=3.0, pumping_height=2.0, pumping_net_pressure=3.0,
                     pumping_bhtp=13.0, isip=11.0, isip_time=25.0)
    assert treatment_pressures(balance, 30.0) == {}   # pumping to the end: no shut-in record
    assert treatment_pressures(balance, None) == {}
    assert pump_end(load_scene(SHUT_IN)) == pytest.approx(40.0)
    assert pump_end(load_scene(TINY)) == pytest.approx(40.0)


@pytest.fixture(scope="module")
def shut_in(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pressures")
    (folder / "shut.toml").write_text(SHUT_IN)
    done = subprocess.run([*HFGPU, "run", "shut.toml", "--out", "shut.h5"], cwd=folder, capture_output=True,
                          text=True, timeout=300)
    return done, open_results(folder / "shut.h5")


def test_summary_shows_bhtp_isip_and_the_end_of_pumping(shut_in):
    done, results = shut_in
    assert done.returncode == 0, done.stderr
    b = results.fracture_balance
    first_after = int(np.argmax(b["time"] > 40.0))
    last_pumping = first_after - 1
    psi = convert(1.0, "Pa", "psi")
    out = done.stdout
    section = out[out.index("end of pumping"):out.index("\nfluid")]
    isip = next(line for line in section.splitlines() if line.strip().startswith("ISIP"))
    assert f" {format_number(b['injection_pressure'][first_after] * psi)} psi (first record after" in isip
    assert f"{format_number(b['injection_pressure'][last_pumping] * psi)} psi" in section
    assert f"{format_number(b['length'][last_pumping] * convert(1.0, 'm', 'ft'))} ft" in section
    assert "BHTP (bottom-hole treating pressure), end" in out
    # the shut-in length differs from the end-of-pumping one, and both are shown
    assert f"{format_number(results.summary['fracture_length'] * convert(1.0, 'm', 'ft'))} ft" in out
    assert "start [min]" in out and "Kozeny-Carman, independent of closure stress" in out


def _tick_labels(fig, ax) -> list[tuple[int, bool]]:
    """(labels drawn, whether two of them overlap) of the x and the y axis of ``ax``, the figure drawn."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    out = []
    for axis, (lo, hi), k in ((ax.xaxis, frame.intervalx, 0), (ax.yaxis, frame.intervaly, 1)):
        boxes = [label.get_window_extent(renderer) for label in axis.get_ticklabels(which="both") if label.get_text()]
        boxes = [b for b in boxes if lo - 1 <= (b.get_points()[:, k].mean()) <= hi + 1]   # the labels drawn
        out.append((len(boxes), any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])))
    return out


def test_log_ticks_keep_labels_apart_where_the_defaults_overlap():
    from matplotlib.figure import Figure

    from hfgpu.io.plots import _log_ticks

    t, net = np.geomspace(60.0, 540.0, 50), np.geomspace(300.0, 180.0, 50)   # a pumping period under a decade
    figures = []
    for fixed in (False, True):
        fig = Figure(figsize=(14, 4), layout="constrained")
        ax = fig.subplots(1, 3)[2]
        ax.loglog(t, net)
        if fixed:
            _log_ticks(ax.xaxis, t)
            _log_ticks(ax.yaxis, net)
        figures.append(_tick_labels(fig, ax))
    assert figures[0][0][1]                                   # matplotlib's own minor labels overlap here
    assert all(count >= 2 and not overlap for count, overlap in figures[1])


def test_pressure_figure_logs_only_positive_pumping_net_pressure_with_labels_apart(shut_in):
    _, results = shut_in
    fig = pressure_history(results)
    left, middle, right = fig.axes
    t, net = right.get_lines()[0].get_xdata(), right.get_lines()[0].get_ydata()
    assert t.size > 2 and t.max() <= 40.0 and np.all(net > 0.0)
    assert len(left.get_lines()[0].get_xdata()) == results.fracture_balance["time"].size   # shut-in: linear panel
    for count, overlap in _tick_labels(fig, right):
        assert count >= 2 and not overlap                                     # labelled, no two labels overlap
    assert any(line.get_label().startswith("ISIP ") for line in middle.get_lines())
    assert middle.get_ylabel() == "treating pressure [psi]"


WELLBORE = '[wellbore]\nmeasured_depth = "2000 ft"\ninner_diameter = "4 in"\n'


def test_surface_pressure_is_bhtp_less_the_column_plus_friction():
    from hfgpu.wellbore import pipe_friction, surface_pressure

    scene = load_scene(SHUT_IN + WELLBORE)
    depth, rho_f = scene.injection.depth, scene.fluid.density
    # shut-in: no friction, a clean-fluid column
    assert surface_pressure(scene, np.array([45.0]), np.array([20e6]))[0] == pytest.approx(
        20e6 - rho_f * 9.81 * depth, rel=1e-12)
    # slurry stage at its 10 % fraction: slurry column, laminar Fanning friction 16 / Re
    rho_s = 0.9 * rho_f + 0.1 * 2650.0
    d, q, mu, length = 4 * 0.0254, 2e-3, 0.02, 2000 * 0.3048
    v = q / (np.pi * d * d / 4)
    reynolds = rho_s * v * d / mu
    assert reynolds < 2100.0
    friction = 2 * (16 / reynolds) * rho_s * v * v * length / d
    assert surface_pressure(scene, np.array([30.0]), np.array([20e6]))[0] == pytest.approx(
        20e6 - rho_s * 9.81 * depth + friction, rel=1e-9)
    # turbulent: Blasius 0.0791 Re^-1/4; a given gradient replaces the closed form
    fast = pipe_friction(scene.wellbore, np.array([0.1]), np.array([1000.0]), 1e-3)[0]
    v = 0.1 / (np.pi * d * d / 4)
    re = 1000.0 * v * d / 1e-3
    assert fast == pytest.approx(2 * 0.0791 * re**-0.25 * 1000.0 * v * v * length / d, rel=1e-12)
    given = load_scene(SHUT_IN + '[wellbore]\nmeasured_depth = "2000 ft"\nfriction_gradient = "0.1 psi/ft"\n')
    assert surface_pressure(given, np.array([30.0]), np.array([0.0]))[0] + rho_s * 9.81 * depth == pytest.approx(
        0.1 * convert(1.0, "psi", "Pa") / 0.3048 * length, rel=1e-9)


@pytest.mark.parametrize("text, key, words", [
    ('[wellbore]\nmeasured_depth = "2000 ft"\n', "wellbore.inner_diameter", "unless [wellbore] friction_gradient"),
    ('[wellbore]\nmeasured_depth = "1000 ft"\ninner_diameter = "4 in"\n', "wellbore.measured_depth",
     "at least the perforations' true vertical depth"),
    ('[wellbore]\nmeasured_depth = "2000 ft"\ninner_diameter = "-4 in"\n', "wellbore.inner_diameter", "'-4 in'"),
])
def test_bad_wellbore_names_the_key(tmp_path, text, key, words):
    (tmp_path / "bad.toml").write_text(SHUT_IN + text)
    done = subprocess.run([*HFGPU, "check", "bad.toml"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode != 0
    assert f"'{key}'" in done.stderr + done.stdout and words in done.stderr + done.stdout


def test_run_with_a_wellbore_prints_surface_pressures(tmp_path):
    (tmp_path / "wb.toml").write_text(SHUT_IN + WELLBORE)
    done = subprocess.run([*HFGPU, "run", "wb.toml", "--out", "wb.h5"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    results = open_results(tmp_path / "wb.h5")
    from hfgpu.io.summary import surface_history

    stp = surface_history(results.fracture_balance, results.scene)
    psi = convert(1.0, "Pa", "psi")
    line = next(x for x in done.stdout.splitlines() if "STP (surface treating pressure), end" in x)
    assert line.endswith(f" {format_number(stp[-1] * psi)} psi")
    assert "ISIP at surface" in done.stdout
    fig = pressure_history(results)
    assert any(line.get_label() == "STP (surface, [wellbore])" for line in fig.axes[1].get_lines())
