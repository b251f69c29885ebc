"""The fall-off outputs of a run with a shut-in (hfgpu.fracture.falloff): the ``fall_off`` figure, the summary's
fall-off group and the G columns of the CSV pressure history; none of them for a run without a shut-in."""

from __future__ import annotations

import csv
import dataclasses
import math

import io_fakes as fakes
import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.fracture.falloff import G_function, efficiency_at_closure, fracture_stiffness, leakoff_coefficient
from hfgpu.io.export import export
from hfgpu.io.plots import FIGURE_NAMES, SHUT_IN_FIGURES, fall_off, figures, plot_results
from hfgpu.io.results import ResultsWriter, open_results
from hfgpu.io.summary import falloff_of, summary_table
from hfgpu.records import BalanceRecord
from hfgpu.units import convert, format_number

#: The fake fracture scene pumping 10 s, then shut in for 40 s.
SHUT_IN = (fakes.FRACTURE_SCENE.replace('end_time = "10 s"', 'end_time = "50 s"')
           .replace('schedule = [{ until = "10 s", rate = "0.05 m**3/s" }]',
                    'schedule = [{ until = "10 s", rate = "0.05 m**3/s" }, { until = "50 s", rate = "0 m**3/s" }]'))
T_P, SIGMA, ISIP, M = 10.0, 60e6, 61.5e6, 3e5
G_C = 0.5 * float(G_function(4.0))   # closure at half the last G


def _bhtp(t: float) -> float:
    """Linear in G (slope M) until G_C, then twice as steep."""
    G = float(G_function((t - T_P) / T_P))
    return ISIP - M * G - M * max(G - G_C, 0.0)


def _simulate_shut_in(scene, sink):
    """The fake pumping (0.25 s steps to 10 s), then 0.1 s steps of fall-off; snapshots every 10 steps."""
    times = np.concatenate([np.arange(1, 41) * 0.25, T_P + np.arange(1, 401) * 0.1])
    for i, t in enumerate(times, 1):
        pumping = t <= T_P
        p = SIGMA + 2e6 * t ** -0.2 if pumping else _bhtp(t)
        injected = fakes.RATE * min(t, T_P)
        sink.fracture_balance(BalanceRecord(time=t, injected=injected, stored=0.8 * injected, leaked=0.2 * injected,
                                            injection_pressure=p, net_pressure=p - SIGMA, efficiency=0.8,
                                            area=10.0 * min(t, T_P), length=3.0, height=3.0))
        if i % 10 == 0:  # the opening stays as it was at shut-in
            sink.fracture_snapshot(dataclasses.replace(fakes.fracture_snapshot(min(t, T_P)), time=t))


@pytest.fixture(scope="module", params=["SI", "field"])
def shut_in(request, tmp_path_factory):
    path = tmp_path_factory.mktemp("falloff") / f"{request.param}.h5"
    scene = load_scene(SHUT_IN.replace("[output]", f'[output]\nunits = "{request.param}"'))
    with ResultsWriter(path, scene) as w:
        _simulate_shut_in(scene, w)
    return request.param, path, open_results(path)


def test_the_analysis_reads_the_constructed_closure(shut_in):
    _, _, results = shut_in
    a = falloff_of(results.fracture_balance, T_P)
    assert a.isip == pytest.approx(_bhtp(10.1), rel=1e-12) and a.sigma_min == pytest.approx(SIGMA, rel=1e-12)
    assert a.G_c == pytest.approx(G_C, rel=0.02) and a.slope == pytest.approx(M, rel=1e-6)
    assert a.closure.side == "above" and a.efficiency == pytest.approx(efficiency_at_closure(a.G_c, 1.0))


def test_fall_off_figure_in_scene_units(shut_in):
    system, _, results = shut_in
    out = figures(results)
    assert tuple(out) == FIGURE_NAMES["fracture"] and "fall_off" in SHUT_IN_FIGURES
    fig = out["fall_off"]
    left, right = fig.axes
    unit = "MPa" if system == "SI" else "psi"
    assert left.get_ylabel() == f"bottom-hole pressure [{unit}]" and right.get_ylabel() == f"G dP/dG [{unit}]"
    assert left.get_xlabel() == "G (alpha = 1) [-]" and "closure at G = " in left.get_title()
    to = 1e-6 if system == "SI" else convert(1.0, "Pa", "psi")
    a = falloff_of(results.fracture_balance, T_P)
    np.testing.assert_allclose(left.get_lines()[0].get_ydata(), a.pressure * to, rtol=1e-12)
    np.testing.assert_allclose(right.get_lines()[0].get_ydata(), a.derivative * to, rtol=1e-12)
    closure = [line for line in left.get_lines() if line.get_label().startswith("closure ")]
    assert len(closure) == 1 and closure[0].get_xdata()[0] == a.G_c
    assert closure[0].get_ydata()[0] == pytest.approx(a.closure_pressure * to, rel=1e-12)


def test_summary_has_the_fall_off_group(shut_in):
    system, path, results = shut_in
    table = summary_table({**results.summary, "out": str(path)}, system, results.scene)
    section = table[table.index("\nfall-off"):table.index("\nrun")]
    a = falloff_of(results.fracture_balance, T_P)
    to, unit = (1e-6, "MPa") if system == "SI" else (convert(1.0, "Pa", "psi"), "psi")
    assert "closure pressure  " in section and f"{format_number(a.closure_pressure * to)} {unit}" in section
    assert f"{format_number(a.closure_time)} s" in section
    assert "G at closure (alpha = 1)" in section and f"{format_number(100 * a.efficiency, 3)} %" in section
    # the footprint at shut-in is 100 m^2, 3 m by 3 m: radial, R = sqrt(100 / pi)
    stiffness = fracture_stiffness("radial", results.scene.rock.plane_strain_modulus, math.sqrt(100.0 / math.pi))
    c_l = leakoff_coefficient(M, T_P, stiffness)
    to, unit = (1.0, "m/s^0.5") if system == "SI" else (convert(1.0, "m/s**0.5", "ft/min**0.5"), "ft/min^0.5")
    assert f"apparent leak-off coefficient (radial, R = 5.642 m)  {format_number(c_l * to)} {unit}" in section


def test_csv_history_has_G_columns(shut_in, tmp_path):
    system, path, results = shut_in
    out = tmp_path / "m.csv"
    written = export(path, "csv", out, system)
    with open(written[1], newline="") as f:
        rows = list(csv.reader(f))
    unit = "Pa" if system == "SI" else "psi"
    assert rows[0][4:] == ["G [-]", f"G_dP/dG [{unit}]"]
    table = np.array(rows[1:], dtype=float)
    pumping = table[:, 0] <= T_P
    assert np.isnan(table[pumping, 4:]).all()
    np.testing.assert_allclose(table[~pumping, 4], G_function((table[~pumping, 0] - T_P) / T_P), rtol=1e-9)
    a = falloff_of(results.fracture_balance, T_P)
    to = 1.0 if system == "SI" else convert(1.0, "Pa", "psi")
    expected = np.interp(table[~pumping, 4], a.G, a.derivative) * to
    np.testing.assert_allclose(table[~pumping, 5], expected, rtol=1e-9)


def test_no_shut_in_no_fall_off(tmp_path):
    scene = load_scene(fakes.FRACTURE_SCENE)
    with ResultsWriter(tmp_path / "f.h5", scene) as w:
        fakes.simulate_fracture(scene, w)
    results = open_results(tmp_path / "f.h5")
    assert "fall_off" not in figures(results)
    assert "fall_off.png" not in [p.name for p in plot_results(tmp_path / "f.h5", tmp_path / "png")]
    assert "fall-off" not in summary_table({**results.summary, "out": str(tmp_path / "f.h5")}, "SI", scene)
    with open(export(tmp_path / "f.h5", "csv", tmp_path / "m.csv", "SI")[1]) as f:
        assert "G [-]" not in f.readline()
    from hfgpu.errors import HfgpuError

    with pytest.raises(HfgpuError, match="no fall-off"):
        fall_off(results)
