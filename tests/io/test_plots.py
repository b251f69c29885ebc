"""Figures from a results file alone."""

from __future__ import annotations

import io_fakes as fakes
from hfgpu import load_scene
from hfgpu.io.plots import plot_results
from hfgpu.io.results import ResultsWriter

PNG = b"\x89PNG\r\n\x1a\n"


def test_fracture_and_proppant_figures(tmp_path):
    with ResultsWriter(tmp_path / "f.h5", load_scene(fakes.FRACTURE_SCENE)) as w:
        fakes.simulate_fracture(load_scene(fakes.FRACTURE_SCENE), w)
    with ResultsWriter(tmp_path / "p.h5", fakes.proppant_scene()) as w:
        fakes.simulate_proppant(fakes.proppant_scene(), w)
    fracture = plot_results(tmp_path / "f.h5", tmp_path / "f")
    proppant = plot_results(tmp_path / "p.h5", tmp_path / "p")
    assert [p.name for p in fracture] == ["fracture_width.png", "fracture_footprints.png",
                                          "fracture_area_efficiency.png", "fracture_volume_balance.png",
                                          "pressure_history.png"]
    assert [p.name for p in proppant] == ["proppant_volume_fraction.png", "proppant_speed.png",
                                          "proppant_radius.png", "proppant_volume_balance.png"]
    for path in fracture + proppant:
        assert path.read_bytes()[:8] == PNG and path.stat().st_size > 5000
