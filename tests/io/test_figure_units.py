"""Figures in the user's units (issue 15 item 2): ``hfgpu plot`` draws in the results' ``[output] units``; field
units give ft, in, psi, bbl, ft^3, ft^2 and ft/s on every axis and colour bar with the values converted, SI
results files keep their labels (m, mm, MPa, m^3, m^2, m/s, um)."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import io_fakes as fakes
import numpy as np
import pytest
from hfgpu import load_scene
from hfgpu.io.display_units import FigureUnits
from hfgpu.io.plots import FIGURE_NAMES, LAYER_STYLE, SHUT_IN_FIGURES, figures
from hfgpu.io.results import ResultsWriter, open_results
from hfgpu.records import SolidBalanceRecord
from hfgpu.units import convert
from test_figures_trust import LAYERED

FT, IN, PSI = convert(1.0, "m", "ft"), convert(1.0, "mm", "in"), convert(1.0, "MPa", "psi")
SI_UNITS = re.compile(r"\[(m|mm|um|MPa|m\^2|m\^3|m/s|kg)\]|x = [-\d.e]+ m ")
FIELD_UNITS = re.compile(r"\[(ft|in|psi|ft\^2|ft\^3|bbl|ft/s|lb)\]")
COUPLED = (Path(__file__).resolve().parents[1] / "scenes" / "tiny_coupled.toml").read_text()


def _with_units(text: str, system: str) -> str:
    return text.replace("[output]", f'[output]\nunits = "{system}"')


def _fracture(tmp_path, text: str, name: str):
    scene = load_scene(text)
    with ResultsWriter(tmp_path / name, scene) as w:
        fakes.simulate_fracture(scene, w)
    return open_results(tmp_path / name)


def _coupled(tmp_path, system: str):
    """Fake fracture and proppant records under the tiny coupled scene (one proppant class) in ``system``."""
    scene = load_scene(_with_units(COUPLED, system))
    path = tmp_path / f"coupled_{system}.h5"
    with ResultsWriter(path, scene) as w:
        fakes.simulate_fracture(scene, w)
        for t in (10.0, 20.0, 30.0, 40.0):
            snap = fakes.proppant_snapshot(t / 40)
            grid = {**snap.grid, "fluid_v": np.full(snap.grid["fluid_v"].shape, 0.01)}
            parcels = {**snap.parcels, "class_id": np.zeros_like(snap.parcels["class_id"])}
            w.proppant_balance(SolidBalanceRecord(time=t, injected=1e-4 * t, in_domain=0.9e-4 * t,
                                                  outflow=0.1e-4 * t))
            w.proppant_snapshot(dataclasses.replace(snap, time=t, grid=grid, parcels=parcels))
    return open_results(path)


def _labels(fig) -> list[str]:
    return [text for ax in fig.axes for text in (ax.get_xlabel(), ax.get_ylabel())]


def _boundaries(ax) -> list[float]:
    return sorted(float(line.get_ydata()[0]) for line in ax.get_lines()
                  if line.get_linestyle() == "--" and line.get_color() == LAYER_STYLE["color"])


@pytest.fixture(scope="module")
def layered(tmp_path_factory):
    """The layered fracture fake in SI and in field units: {system: (results, figures)}."""
    folder = tmp_path_factory.mktemp("units")
    out = {}
    for system in ("SI", "field"):
        results = _fracture(folder, _with_units(LAYERED, system), f"{system}.h5")
        assert results.scene.output.units == system
        out[system] = results, figures(results)
    return out


def test_field_fracture_figures_name_and_convert_their_units(layered):
    (_, si), (_, field) = layered["SI"], layered["field"]
    assert tuple(field) == tuple(n for n in FIGURE_NAMES["fracture"] if n not in SHUT_IN_FIGURES)  # no shut-in
    for name, fig in field.items():
        assert not any(SI_UNITS.search(label) for label in _labels(fig)), (name, _labels(fig))
    width_si, width_field = si["fracture_width"], field["fracture_width"]
    assert width_field.axes[0].get_xlabel() == "x [ft]" and width_field.axes[0].get_ylabel() == "depth z [ft]"
    assert width_field.axes[-1].get_ylabel() == "width [in]"  # the colour bar
    assert width_field.axes[4].get_xlabel() == "width at x = 0 ft [in]"
    # the map values and extent, the cross-section line, and the layer boundaries, converted
    image_si, image_field = width_si.axes[3].get_images()[0], width_field.axes[3].get_images()[0]
    np.testing.assert_allclose(image_field.get_array(), image_si.get_array() * IN, rtol=1e-12)
    np.testing.assert_allclose(image_field.get_extent(), np.array(image_si.get_extent()) * FT, rtol=1e-12)
    np.testing.assert_allclose(image_field.get_clim(), np.array(image_si.get_clim()) * IN, rtol=1e-12)
    profile_si, profile_field = width_si.axes[7].get_lines()[0], width_field.axes[7].get_lines()[0]
    np.testing.assert_allclose(profile_field.get_xdata(), profile_si.get_xdata() * IN, rtol=1e-12)
    np.testing.assert_allclose(profile_field.get_ydata(), profile_si.get_ydata() * FT, rtol=1e-12)
    for ax in (width_field.axes[0], width_field.axes[4], field["fracture_footprints"].axes[0]):
        np.testing.assert_allclose(_boundaries(ax), [-4.0 * FT, 4.0 * FT], rtol=1e-12)
    # net pressure in psi, volumes in bbl, area in ft^2
    pressure_si, pressure_field = si["pressure_history"].axes[0], field["pressure_history"].axes[0]
    assert pressure_field.get_ylabel() == "net pressure at injection [psi]"
    np.testing.assert_allclose(pressure_field.get_lines()[0].get_ydata(),
                               pressure_si.get_lines()[0].get_ydata() * PSI, rtol=1e-12)
    np.testing.assert_array_equal(pressure_field.get_lines()[0].get_xdata(), pressure_si.get_lines()[0].get_xdata())
    balance = field["fracture_volume_balance"].axes[0]
    assert balance.get_ylabel() == "volume [bbl]" and balance.get_xlabel() == "time [s]"
    np.testing.assert_allclose(balance.get_lines()[0].get_ydata(),
                               si["fracture_volume_balance"].axes[0].get_lines()[0].get_ydata()
                               * convert(1.0, "m**3", "bbl"), rtol=1e-12)
    assert field["fracture_area_efficiency"].axes[0].get_ylabel() == "fracture area [ft^2]"
    assert field["fracture_area_efficiency"].axes[1].get_ylabel() == "efficiency stored/injected [-]"


def test_si_fracture_figures_keep_their_labels(layered):
    results, si = layered["SI"]
    assert si["fracture_width"].axes[0].get_xlabel() == "x [m]"
    assert si["fracture_width"].axes[0].get_ylabel() == "depth z [m]"
    assert si["fracture_width"].axes[-1].get_ylabel() == "width [mm]"
    assert si["pressure_history"].axes[0].get_ylabel() == "net pressure at injection [MPa]"
    assert si["fracture_volume_balance"].axes[0].get_ylabel() == "volume [m^3]"
    assert si["fracture_area_efficiency"].axes[0].get_ylabel() == "fracture area [m^2]"
    assert _boundaries(si["fracture_width"].axes[0]) == [-4.0, 4.0]
    # the values as stored: width in mm, net pressure in MPa
    np.testing.assert_array_equal(si["pressure_history"].axes[0].get_lines()[0].get_ydata(),
                                  results.fracture_balance["net_pressure"] / 1e6)
    last = results.fracture_snapshots[-1]
    np.testing.assert_array_equal(si["fracture_width"].axes[3].get_images()[0].get_array(), last.width * 1e3)
    for fig in si.values():
        assert not any(FIELD_UNITS.search(label) for label in _labels(fig))


def test_scene_written_in_field_units_plots_in_field_units(tmp_path):
    """No ``[output] units``: the units most of the scene is written in."""
    text = (fakes.FRACTURE_SCENE.replace('"40 GPa"', '"5.8e6 psi"').replace('"60 MPa"', '"8700 psi"')
            .replace('"0.08 Pa*s"', '"80 cP"').replace('"0 m"', '"0 ft"').replace('"2 m"', '"6.5 ft"')
            .replace('"0.05 m**3/s"', '"19 bbl/min"'))
    results = _fracture(tmp_path, text, "f.h5")
    assert results.scene.output.units == "field"
    assert figures(results)["fracture_footprints"].axes[0].get_xlabel() == "x [ft]"


def test_coupled_field_figures(tmp_path):
    si, field = figures(_coupled(tmp_path, "SI")), figures(_coupled(tmp_path, "field"))
    assert set(field) == set(FIGURE_NAMES["fracture"] + FIGURE_NAMES["proppant"] + FIGURE_NAMES["coupled"]) - set(
        SHUT_IN_FIGURES)   # the fake pumps to the end
    for name, fig in field.items():
        assert not any(SI_UNITS.search(label) for label in _labels(fig)), (name, _labels(fig))
        assert any(FIELD_UNITS.search(label) for label in _labels(fig)), (name, _labels(fig))
    for name, fig in si.items():
        assert not any(FIELD_UNITS.search(label) for label in _labels(fig)), (name, _labels(fig))
    assert _labels(field["proppant_radius"])[-1] == "radius [in]" and _labels(si["proppant_radius"])[-1] == "radius [um]"
    assert field["proppant_volume_balance"].axes[0].get_ylabel() == "mass [lb]"   # as the summary: one density
    assert field["propped_area"].axes[0].get_ylabel() == "area [ft^2]"
    assert field["closure_maps"].axes[0].get_ylabel() == "depth z [ft]"
    assert "fluid speed [ft/s]" in _labels(field["proppant_streamlines"])
    # the solid balance in ft^3, the parcel positions in ft, the packed threshold in ft/s
    np.testing.assert_allclose(field["proppant_volume_balance"].axes[0].get_lines()[0].get_ydata(),
                               si["proppant_volume_balance"].axes[0].get_lines()[0].get_ydata()
                               * convert(1.0, "kg", "lb"), rtol=1e-12)
    np.testing.assert_allclose(field["proppant_radius"].axes[0].collections[0].get_offsets(),
                               si["proppant_radius"].axes[0].collections[0].get_offsets() * FT, rtol=1e-12)
    np.testing.assert_allclose(field["proppant_radius"].axes[0].get_xlim(),
                               np.array(si["proppant_radius"].axes[0].get_xlim()) * FT, rtol=1e-12)
    packed = [line for line in field["proppant_speed_probability"].axes[0].get_lines() if line.get_linestyle() == ":"]
    assert packed[0].get_xdata()[0] == pytest.approx(1e-3 * FT)
    assert packed[0].get_label() == "packed below 0.00328 ft/s"


def test_units_override_and_figure_units():
    units = FigureUnits("field")
    assert units("width", 1e-3) == pytest.approx(IN)
    assert units("pressure", np.array([1e6])) == pytest.approx([PSI])
    assert units("volume", 1.0) == pytest.approx(6.2898, rel=1e-4)  # 42-gallon barrels
    assert units("time", 5.0) == 5.0 and units.label("area") == "ft^2"
    si = FigureUnits()
    assert si("width", 2e-3) == 2.0 and si("pressure", 3e6) == 3.0 and si.label("radius") == "um"
    with pytest.raises(ValueError):
        FigureUnits("imperial")


def test_snapshot_figures_take_units(tmp_path):
    """A proppant-only file whose scene does not parse draws SI; ``figures(..., units=)`` overrides that."""
    with ResultsWriter(tmp_path / "p.h5", fakes.proppant_scene()) as w:
        fakes.simulate_proppant(fakes.proppant_scene(), w)
    results = open_results(tmp_path / "p.h5")
    assert figures(results)["proppant_speed"].axes[-1].get_ylabel() == "mean parcel speed [m/s]"
    field = figures(results, units=FigureUnits("field"))
    assert field["proppant_speed"].axes[-1].get_ylabel() == "mean parcel speed [ft/s]"
    assert field["proppant_volume_fraction"].axes[0].get_xlabel() == "x [ft]"
