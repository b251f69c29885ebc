"""Figures a reader trusts (issue 15 item 8): the figure names per kind of results, layer boundaries on every map
of a layered scene, one colour scale across time panels, legends for outlines and markers, the held-back solids
in the balance, no 'nan' in a title, and the interface heights of a settling column."""

from __future__ import annotations

import dataclasses

import io_fakes as fakes
import numpy as np
import pytest
from hfgpu import load_scene
from hfgpu.io.plots import FIGURE_NAMES, LAYER_STYLE, SHUT_IN_FIGURES, colour_range, figures, layer_boundaries
from hfgpu.io.results import ResultsWriter, open_results
from hfgpu.records import SolidBalanceRecord

#: Three layers: boundaries at depths -4 and +4 m cross the fake fracture's maps (z from -11 to +11 m).
LAYERED = fakes.FRACTURE_SCENE.replace("[fluid]", """
[[rock.layers]]
top = "-40 m"
bottom = "-4 m"
min_stress = "65 MPa"
[[rock.layers]]
top = "-4 m"
bottom = "4 m"
min_stress = "60 MPa"
[[rock.layers]]
top = "4 m"
bottom = "40 m"
min_stress = "65 MPa"

[fluid]""")


def _titles(fig) -> list[str]:
    return [ax.get_title() for ax in fig.axes] + [fig._suptitle.get_text() if fig._suptitle else ""]


def _boundary_lines(ax) -> list[float]:
    """Depths of the horizontal layer-boundary lines (LAYER_STYLE) on ``ax``."""
    return sorted(float(line.get_ydata()[0]) for line in ax.get_lines()
                  if line.get_linestyle() == "--" and line.get_color() == LAYER_STYLE["color"])


@pytest.fixture(scope="module")
def layered(tmp_path_factory):
    path = tmp_path_factory.mktemp("layered") / "f.h5"
    scene = load_scene(LAYERED)
    with ResultsWriter(path, scene) as w:
        fakes.simulate_fracture(scene, w)
    return open_results(path)


def test_layered_maps_draw_the_boundaries(layered):
    assert layer_boundaries(layered) == [-4.0, 4.0]
    out = figures(layered)
    assert tuple(out) == tuple(n for n in FIGURE_NAMES["fracture"] if n not in SHUT_IN_FIGURES)  # no shut-in
    maps = [ax for ax in out["fracture_width"].axes if ax.get_ylabel() == "depth z [m]"]
    maps += [ax for ax in out["fracture_footprints"].axes if ax.get_ylabel() == "depth z [m]"]
    assert len(maps) >= 5
    for ax in maps:
        assert _boundary_lines(ax) == [-4.0, 4.0], ax.get_title()
    for name in ("fracture_width", "fracture_footprints"):  # one legend entry per figure
        legends = [ax.get_legend() for ax in out[name].axes if ax.get_legend() is not None] + out[name].legends
        assert ["layer boundary" in [t.get_text() for t in legend.get_texts()] for legend in legends] == [True]


def test_a_long_low_footprint_is_drawn_with_its_depth_exaggerated_and_its_legend_outside():
    """A footprint 15 times as long as high (the main demo's 2 480 x 180 ft) is drawn at 4x depth, said in the
    title, with the legend below the axes, not over the outlines; one no longer than 4 times its height to scale."""
    from types import SimpleNamespace

    from hfgpu.io.plots import vertical_exaggeration

    frame = SimpleNamespace(dx=10.0, dz=10.0)
    strip = np.zeros((20, 200))
    strip[2:12, 20:170] = 1.0   # 1 500 x 100
    assert vertical_exaggeration([SimpleNamespace(width=strip, frame=frame)]) == 4.0
    square = np.zeros((20, 20))
    square[2:12, 2:40] = 1.0    # 180 x 100
    assert vertical_exaggeration([SimpleNamespace(width=square, frame=frame)]) == 1.0
    assert vertical_exaggeration([SimpleNamespace(width=np.zeros((3, 3)), frame=frame)]) == 1.0


def test_the_status_banner_names_each_kind_once_and_fits_the_figure():
    """Unphysical-state messages hold "; " inside them (hfgpu.proppant.health); the banner keeps one entry per
    kind, "<kind> at t = <time> s", wrapped to the figure's width."""
    from types import SimpleNamespace

    from hfgpu.io.plots import BANNER_WIDTH, status_banner

    found = ("proppant in cells narrower than a grain at t = 730.8 s: theta_p 0.0111 in the cell at x = -1 160 ft, "
             "0.002556 in wide, below the smallest grain (0.004173 in); the cell is closing around its proppant; "
             "theta_p above close packing at t = 1 838 s: theta_p 0.661 (close packing 0.6) in the cell at x = 50 ft")
    banner = status_banner(SimpleNamespace(status="complete", summary={"proppant_unphysical_states": found}))
    assert banner == ("unphysical states: proppant in cells narrower than a grain at t = 730.8 s; theta_p above "
                      "close\npacking at t = 1 838 s")
    assert max(len(line) for line in banner.splitlines()) <= BANNER_WIDTH


def test_time_panels_share_one_colour_scale_and_no_nan_titles(layered):
    fig = figures(layered)["fracture_width"]
    images = [image for ax in fig.axes for image in ax.get_images()]
    assert len(images) == 4 and len({image.get_clim() for image in images}) == 1
    for figure in figures(layered).values():
        assert not any("nan" in title.lower() for title in _titles(figure))


def test_colour_range():
    assert colour_range(np.zeros((3, 3))) == (0.0, 1.0)  # not -0.1..0.1
    assert colour_range(np.full(2, np.nan)) == (0.0, 1.0)
    assert colour_range(np.array([0.5, 2.0]), np.array([np.nan, 3.0])) == (0.0, 3.0)
    assert colour_range(np.array([-2.0, 1.0])) == (-2.0, 1.0)


def test_unlayered_scene_has_no_boundaries(tmp_path):
    scene = load_scene(fakes.FRACTURE_SCENE)
    with ResultsWriter(tmp_path / "f.h5", scene) as w:
        fakes.simulate_fracture(scene, w)
    results = open_results(tmp_path / "f.h5")
    assert layer_boundaries(results) == []
    assert all(not _boundary_lines(ax) for ax in figures(results)["fracture_width"].axes)


def _column(tmp_path, nz: int = 20):
    """A settling column fake: a suspension of 0.1 whose top falls and whose bed (0.6) rises, on 1 x nz cells."""
    scene = fakes.proppant_scene()
    path = tmp_path / "column.h5"
    dz = 0.01
    with ResultsWriter(path, scene) as w:
        for n, t in enumerate((0.0, 0.5, 1.0)):
            snap = fakes.proppant_snapshot(t, nz=nz, nx=1)
            profile = np.zeros((nz, 1))
            profile[2 + 4 * n:, 0] = 0.1
            profile[nz - 2 * n - 1:, 0] = 0.6 if n else 0.1
            snap = dataclasses.replace(snap, grid={**snap.grid, "volume_fraction": profile})
            w.proppant_balance(SolidBalanceRecord(time=t, injected=1e-4, in_domain=0.8e-4, outflow=0.0,
                                                  screened_out=0.2e-4))
            w.proppant_snapshot(snap)
    return open_results(path), dz


def test_settling_column_draws_the_interface_heights(tmp_path):
    from hfgpu.io.plots import interface_heights

    results, dz = _column(tmp_path)
    out = figures(results)
    assert "proppant_interfaces" in out and "proppant_maps" not in out
    assert set(out) <= set(FIGURE_NAMES["proppant"] + FIGURE_NAMES["column"])
    h = interface_heights(results)
    height = 20 * dz
    # top of the suspension 2, 6, 10 cells below the top; bed top 0, 3, 5 cells above the bottom (a level midway
    # between two cell values falls on their shared face)
    np.testing.assert_allclose(h["suspension_top"], height - dz * np.array([2, 6, 10]), atol=1e-6 * dz)
    np.testing.assert_allclose(h["bed_top"][1:], dz * np.array([3, 5]), atol=1e-6 * dz)
    assert h["bed_top"][0] == pytest.approx(0.0, abs=1e-12)
    labels = [t.get_text() for t in out["proppant_interfaces"].axes[0].get_legend().get_texts()]
    assert labels[0].startswith("top of the suspension") and labels[1].startswith("bed top")


def test_solid_balance_shows_the_held_back_volume(tmp_path):
    results, _ = _column(tmp_path)
    ax = figures(results)["proppant_volume_balance"].axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "held back at the inlet (screened out)" in labels
    total = [line for line in ax.get_lines() if line.get_linestyle() == ":"][0]
    np.testing.assert_allclose(total.get_ydata(), 1e-4)  # in the domain + outflow + held back = injected


def test_proppant_figure_names(tmp_path):
    with ResultsWriter(tmp_path / "p.h5", fakes.proppant_scene()) as w:
        fakes.simulate_proppant(fakes.proppant_scene(), w)
    out = figures(open_results(tmp_path / "p.h5"))
    assert set(out) <= set(FIGURE_NAMES["proppant"]) and "proppant_interfaces" not in out
    for figure in out.values():
        assert not any("nan" in title.lower() for title in _titles(figure))


def test_hfgpu_plot_on_the_hindered_settling_column(tmp_path):
    """The real proppant-only column (hfgpu/scenes/settling_hindered.toml, about a second): `hfgpu plot` draws the
    interface heights; the top of the suspension falls, the bed top rises from the floor."""
    from pathlib import Path

    from hfgpu import run
    from hfgpu.io.plots import interface_heights, plot_results

    scene = Path(__file__).resolve().parents[2] / "hfgpu" / "scenes" / "settling_hindered.toml"
    run(scene, tmp_path / "column.h5", progress=False)
    written = plot_results(tmp_path / "column.h5", tmp_path / "figures")
    assert "proppant_interfaces.png" in [p.name for p in written]
    h = interface_heights(open_results(tmp_path / "column.h5"))
    assert np.all(np.diff(h["suspension_top"]) < 0) and h["bed_top"][-1] > h["bed_top"][0] == 0.0
