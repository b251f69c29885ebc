"""The fracture grid serves the layers (hfgpu.fracture.mesh.fit_layers): layer boundaries on cell faces, the
perforation inside the injection cell, at every refinement; a boundary that cannot be on a face gets one warning
naming a cell height that puts it there; scenes without layers, or already on faces, keep their grid."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest

from hfgpu.fracture.config import FractureNumerics
from hfgpu.fracture.mesh import fit_layers, injection_cell_centre, layer_boundaries, scene_layer_fit
from hfgpu.fracture.engine_setup import fracture_engine_setup
from hfgpu.fracture.simulator import _Engine
from hfgpu.scene import load_scene
from hfgpu.scene_checks import validate

from .helpers import SCENES, scene

FT = 0.3048
PSI = 6894.757293168361

# issue 30's five-layer column: perforation at 9 500 ft, boundaries at 9 400 / 9 460 / 9 540 / 9 600 ft, 20 ft cells
FIVE = """
[run]
end_time = "10 min"
[rock]
youngs_modulus = "4.5e6 psi"
poisson_ratio = 0.25
toughness = "1000 psi*in**0.5"
min_stress = "6650 psi"
[[rock.layers]]
top = "9200 ft"
bottom = "9400 ft"
min_stress = "7550 psi"
[[rock.layers]]
top = "9400 ft"
bottom = "9460 ft"
min_stress = "6650 psi"
[[rock.layers]]
top = "9460 ft"
bottom = "9540 ft"
min_stress = "6800 psi"
[[rock.layers]]
top = "9540 ft"
bottom = "9600 ft"
min_stress = "6700 psi"
[[rock.layers]]
top = "9600 ft"
bottom = "9800 ft"
min_stress = "7500 psi"
[fluid]
viscosity = "2 cP"
[injection]
depth = "9500 ft"
schedule = [{ until = "10 min", rate = "80 bbl/min" }]
[mesh]
cell_size = "20 ft"
refinement = REFINEMENT
"""


def five(refinement: float) -> str:
    return FIVE.replace("REFINEMENT", str(refinement))


def rows_of(text: str):
    """(top face, bottom face, stress at the row's centre in the engine) of every row of the engine's first grid."""
    sc = load_scene(text)
    eng = _Engine(dataclasses.replace(fracture_engine_setup(sc), numerics=FractureNumerics()))
    _, z = eng.grid.centres()
    centre = z[:, 0]
    return sc, centre - 0.5 * eng.dz, centre + 0.5 * eng.dz, eng.sigma_box[:, 0], eng


@pytest.mark.parametrize("refinement", [1, 2])
def test_five_layers_on_faces_at_every_refinement(refinement):
    assert validate(five(refinement)).warnings == ()
    sc, top, bottom, sigma, eng = rows_of(five(refinement))
    # no row straddles a boundary: the stress at both faces (just inside) is the row's, i.e. its layer's
    margin = 1e-6 * eng.dz
    assert np.array_equal(sc.rock.min_stress_at(top + margin), sigma)
    assert np.array_equal(sc.rock.min_stress_at(bottom - margin), sigma)
    # the perforation (on a face here) is in the injection cell, the one below it: 9500 ft .. 9500 ft + dz
    z_inj = eng.grid.z_inj
    assert z_inj - 0.5 * eng.dz <= sc.injection.depth < z_inj + 0.5 * eng.dz
    assert z_inj == pytest.approx(9500 * FT + 0.5 * eng.dz, abs=1e-9)
    # the injection cell is in the perforated bench (9460..9540 ft, 6800 psi)
    assert float(sc.rock.min_stress_at(np.array(z_inj))) == pytest.approx(6800 * PSI, rel=1e-12)


def test_coarser_cells_honour_the_nearest_boundaries_and_warn_for_the_others():
    # 40 ft cells (refinement 0.5): 9460 and 9540 ft (2 cells apart) on faces; 9400 and 9600 ft (1.5 cells further)
    # cannot be with the perforation's bounds on faces: one warning each, naming 20 ft cells (10 ft / 0.5)
    found = [w for w in validate(five(0.5)).warnings if "cell face" in w]
    assert found == [
        f"rock.layers[{i}].bottom = rock.layers[{i + 1}].top {d} ft is not on a cell face: the grid's faces (cells "
        "40 ft tall) are placed on the boundary at 9 460 ft, the nearest to injection.depth 9 500 ft, so a row "
        f"straddles {d} ft with the properties at its centre; cells 20 ft tall ([mesh] cell_size height 10 ft / "
        "refinement 0.5) put every layer boundary on a face" for i, d in ((0, "9 400"), (3, "9 600"))]
    sc, top, bottom, sigma, eng = rows_of(five(0.5))
    straddling = sc.rock.min_stress_at(top + 1e-6 * eng.dz) != sc.rock.min_stress_at(bottom - 1e-6 * eng.dz)
    crossed = sorted(round(float(b) / FT) for b in layer_boundaries(sc.rock.layers)
                     if np.any(straddling & (top < b) & (b < bottom)))
    assert crossed == [9400, 9600]


def test_fit_names_the_largest_cell_height_that_honours_every_boundary():
    # the corpus stage's column: 9400 / 9470 / 9530 / 9600 ft, gaps 70, 60, 70 ft
    bounds = tuple(b * FT for b in (9400.0, 9470.0, 9530.0, 9600.0))
    fit = fit_layers(9500 * FT, 20 * FT, bounds)
    assert fit.anchor == pytest.approx(9470 * FT)
    assert fit.shift == pytest.approx(0.0, abs=1e-9)   # 9470 ft is 1.5 cells above 9500 ft: a face already
    assert fit.off_face == (bounds[0], bounds[3])
    assert fit.honouring == pytest.approx(10 * FT, rel=1e-12)
    assert fit_layers(9500 * FT, 10 * FT, bounds).off_face == ()
    # gaps 1 and sqrt(2): no cell height from dz / 100 to dz puts both on faces
    odd = fit_layers(0.2, 1.0, (0.0, 1.0, 1.0 + 2**0.5))
    assert (odd.anchor, odd.off_face, odd.honouring) == (0.0, (1.0 + 2**0.5,), None)


@pytest.mark.parametrize("depth, shift", [(0.3, -0.3), (0.5, 0.5), (-0.49, 0.49), (1.2, -0.2)])
def test_the_perforation_is_inside_the_injection_cell(depth, shift):
    # one boundary at 0.5 (a face), cells 1 tall: the injection cell holds the depth, -1/2 < shift <= 1/2
    fit = fit_layers(depth, 1.0, (0.5,))
    assert fit.shift == pytest.approx(shift, abs=1e-12)
    assert depth + fit.shift - 0.5 <= depth < depth + fit.shift + 0.5


def test_scenes_without_layers_or_already_on_faces_keep_their_grid():
    radial = scene()
    assert scene_layer_fit(radial).shift == 0.0
    assert injection_cell_centre(radial) == (radial.injection.x, radial.injection.depth)
    for name in ("five_layer.toml", "five_layer_demo.toml", "wu2008.toml", "slickwater_demo.toml"):
        sc = load_scene(SCENES / name)
        fit = scene_layer_fit(sc)
        assert (fit.shift, fit.off_face) == (0.0, ()), name
        assert injection_cell_centre(sc) == (sc.injection.x, sc.injection.depth), name


def test_check_of_the_five_layer_stage_prints_no_warning(tmp_path):
    path = tmp_path / "five.toml"
    path.write_text(five(2))
    done = subprocess.run([sys.executable, "-m", "hfgpu.cli", "check", str(path)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "warning" not in done.stderr
