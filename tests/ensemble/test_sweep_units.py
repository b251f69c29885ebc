"""A sweep in the base scene's units (issue 31): the P10/P50/P90 printed at the end, the inputs of a field scene,
summary.csv (names, then units, then values) and the figures."""

import csv
import math

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from PIL import Image

import hfgpu
from hfgpu.ensemble import load_sweep
from hfgpu.ensemble.execute import percentile_lines
from hfgpu.ensemble.members import members
from hfgpu.ensemble.plots import distribution, plot_ensemble, tornado
from hfgpu.ensemble.summary import read_csv, read_ensemble, read_units, write_csv
from hfgpu.ensemble.table_units import ColumnUnits, column_kinds
from hfgpu.scene import load_scene

from .conftest import BASE

PSI, FT = 6894.757293168361, 0.3048


def _rows():
    # 6500 psi = 44815922.4 Pa; 1000 ft^2 = 92.90304 m^2; a failed member is left out
    pressures = [44815922.405594364, 2 * 44815922.405594364, 3 * 44815922.405594364]
    rows = [{"id": f"m{i}", "status": "complete", "net_pressure_end": p, "created_area": 92.90304 * (i + 1),
             "efficiency": 0.5} for i, p in enumerate(pressures)]
    return rows + [{"id": "bad", "status": "failed: x", "net_pressure_end": 1e12, "created_area": 1e9,
                    "efficiency": math.nan}]


def _values(line):
    return [float(word) for word in line.split() if word.replace(".", "", 1).replace("e+", "", 1).isdigit()]


def test_percentiles_in_field_units():
    lines = percentile_lines(_rows(), ["net_pressure_end", "created_area", "efficiency"], "field")
    pressure, area, efficiency = lines
    assert "net_pressure_end [psi]" in pressure and "created_area [ft^2]" in area and "efficiency [-]" in efficiency
    p10, p50, p90 = _values(pressure)
    assert p50 == pytest.approx(13000, rel=1e-3) and p10 == pytest.approx(7800, rel=1e-3)
    assert p90 == pytest.approx(18200, rel=1e-3)
    assert _values(area)[1] == pytest.approx(2000, rel=1e-3)
    assert _values(efficiency) == pytest.approx([0.5, 0.5, 0.5])


def test_percentiles_in_si_units():
    (pressure,) = percentile_lines(_rows(), ["net_pressure_end"], "SI")
    assert "[MPa]" in pressure and _values(pressure)[1] == pytest.approx(89.63, rel=1e-3)


# ---------------------------------------------------------------------------------------------------------------
# a sweep over a scene written in field units: inputs, summary.csv and figures in the scene's units

FIELD_BASE = BASE + 'units = "field"\n'        # the [output] table is the base scene's last
STRESS = ('[[vary]]\nkey = "rock.layers[0].min_stress"\n')


def test_a_field_scene_takes_a_distribution_in_psi(write_sweep):
    sweep = load_sweep(write_sweep("members = 3\n" + STRESS + 'distribution = "uniform"\nlow = "8900 psi"\n'
                                   'high = "9100 psi"\n', base=FIELD_BASE))
    (vary,) = sweep.vary
    assert vary.params == pytest.approx((8900 * PSI, 9100 * PSI)) and (vary.kind, vary.unit) == ("pressure", "Pa")
    for member in members(sweep):
        assert load_scene(member.scene_text).rock.layers[0].min_stress == member.inputs[vary.key]


def test_field_sweep_tables_and_figures_are_in_field_units(write_sweep, scheduler, tmp_path):
    path = write_sweep('design = "grid"\n' + STRESS + 'values = ["8900 psi", "9000 psi", "9100 psi"]\n'
                       '[metrics]\nnames = ["created_area", "fracture_length", "net_pressure_end", "efficiency"]\n',
                       base=FIELD_BASE)
    rows = hfgpu.sweep(path, tmp_path / "out", scheduler=scheduler, progress=False)
    assert [r["status"] for r in rows] == ["complete"] * 3
    with open(tmp_path / "out" / "summary.csv", newline="", encoding="utf-8") as f:
        names, units, *lines = list(csv.reader(f))
    assert names == ["id", "status", "rock.layers[0].min_stress", "created_area", "fracture_length",
                     "net_pressure_end", "efficiency", "wall_seconds"]
    assert units == ["", "", "psi", "ft^2", "ft", "psi", "-", "s"]
    assert read_units(tmp_path / "out" / "summary.csv") == dict(zip(names, units))
    table = read_csv(tmp_path / "out" / "summary.csv")
    assert [r["rock.layers[0].min_stress"] for r in table] == pytest.approx([8900, 9000, 9100])
    for shown, stored in zip(table, rows):
        assert shown["created_area"] == pytest.approx(stored["created_area"] / FT ** 2)
        assert shown["fracture_length"] == pytest.approx(stored["fracture_length"] / FT)
        assert shown["net_pressure_end"] == pytest.approx(stored["net_pressure_end"] / PSI)
        assert shown["efficiency"] == stored["efficiency"]
    _check_figures(tmp_path / "out", tmp_path / "figs")


def _check_figures(folder, out):
    """The figures name the field units and show field numbers; the PNGs are written at their size."""
    data = read_ensemble(folder / "ensemble.h5")
    area = distribution(data["rows"], "created_area", data["percentiles"]["created_area"], data["units"])
    ax = area.axes[0]
    assert ax.get_xlabel() == "created_area [ft^2]"
    assert all(text.endswith("ft^2") for text in ax.get_legend_handles_labels()[1])
    low, high = ax.get_xlim()
    assert low > 0.5 * min(r["created_area"] for r in data["rows"]) / FT ** 2
    chart = tornado(data["rows"], data["inputs"], data["metrics"], data["units"])
    ticks = [t.get_text() for a in chart.axes for t in a.get_yticklabels()]
    assert "rock.layers[0].min_stress (8 900 to 9 100 psi)" in ticks
    _check_no_overlap(chart)
    for path in plot_ensemble(folder, out):
        with Image.open(path) as image:
            assert image.size[0] >= 600 and image.size[1] >= 300


def _check_no_overlap(fig):
    """Every text of the drawn figure lies inside it, and the x tick labels of an axes do not overlap."""
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    inside = fig.bbox.padded(1)
    for ax in fig.axes:
        texts = [ax.title, *ax.get_yticklabels(), *ax.texts]
        assert all(inside.contains(*t.get_window_extent(renderer).p0) and
                   inside.contains(*t.get_window_extent(renderer).p1) for t in texts if t.get_text())
        boxes = [t.get_window_extent(renderer) for t in ax.get_xticklabels() if t.get_text() and t.get_visible()]
        assert all(a.x1 <= b.x0 for a, b in zip(boxes, boxes[1:]))


def test_an_si_scene_keeps_si_with_si_units(tmp_path):
    header = ["id", "status", "rock.min_stress", "created_area", "efficiency", "wall_seconds"]
    units = ColumnUnits(column_kinds({"rock.min_stress": "pressure"}, ["created_area", "efficiency"]), "SI",
                        stored=True)
    row = {"id": "0000", "status": "complete", "rock.min_stress": 6.1e7, "created_area": 123.4, "efficiency": 0.5,
           "wall_seconds": 1.5}
    write_csv(tmp_path / "summary.csv", header, [row], units)
    assert (tmp_path / "summary.csv").read_text().splitlines()[1] == ",,Pa,m^2,-,s"
    assert read_csv(tmp_path / "summary.csv") == [row]


def test_kinds_without_a_display_unit_take_the_field_scene_units():
    units = ColumnUnits({"leakoff": "leakoff", "toughness": "toughness", "gradient": "stress_gradient"}, "field")
    assert [units.label(c) for c in ("leakoff", "toughness", "gradient")] == ["ft/min^0.5", "psi in^0.5", "psi/ft"]
    assert units("gradient", 0.75 * PSI / FT) == pytest.approx(0.75)
