"""The layer table tiles its span (hfgpu.scene): a gap between ``[[rock.layers]]`` is an error naming both layers and
the boundary depths in the scene's units, unless ``[rock] min_stress`` is given (the gap then takes the rock's
values, with a warning); an overlap is an error in the scene's units; every shipped scene still loads."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hfgpu import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[1]
PSI = 4.4482216152605 / 0.0254**2  # Pa
FT = 0.3048                        # m

FIELD = """
[run]
end_time = "20 min"
[rock]
youngs_modulus = "5e6 psi"
poisson_ratio = 0.2
[[rock.layers]]
top = "7900 ft"
bottom = "8000 ft"
min_stress = "6800 psi"
[[rock.layers]]
top = "8000 ft"
bottom = "8100 ft"
min_stress = "6000 psi"
[[rock.layers]]
top = "8100 ft"
bottom = "8200 ft"
min_stress = "6800 psi"
[fluid]
viscosity = "20 cP"
[injection]
depth = "8050 ft"
schedule = [{ until = "20 min", rate = "20 bbl/min" }]
[mesh]
cell_size = "20 ft"
"""

SI = """
[run]
end_time = "20 min"
[rock]
youngs_modulus = "35 GPa"
poisson_ratio = 0.2
[[rock.layers]]
top = "2400 m"
bottom = "2450 m"
min_stress = "47 MPa"
[[rock.layers]]
top = "2450 m"
bottom = "2480 m"
min_stress = "41 MPa"
[fluid]
viscosity = "0.02 Pa*s"
[injection]
depth = "2460 m"
schedule = [{ until = "20 min", rate = "0.05 m**3/s" }]
[mesh]
cell_size = "5 m"
"""


def test_a_gap_is_an_error_in_feet_in_a_field_scene():
    with pytest.raises(SceneError) as info:
        load_scene(FIELD.replace('top = "8100 ft"', 'top = "8110 ft"'))
    assert str(info.value) == (
        "scene key 'rock.layers[2].top': got '8110 ft'; layers must tile their span: a gap of 10 ft between "
        "rock.layers[1] (bottom 8 100 ft) and rock.layers[2] (top 8 110 ft); close it, add a layer there, or give "
        "[rock] min_stress (gaps then take the rock's values)")


def test_a_gap_is_an_error_in_metres_in_an_si_scene():
    with pytest.raises(SceneError) as info:
        load_scene(SI.replace('top = "2450 m"', 'top = "2452.5 m"'))
    assert info.value.path == "rock.layers[1].top"
    assert "a gap of 2.5 m between rock.layers[0] (bottom 2 450 m) and rock.layers[1] (top 2 452.5 m)" in str(
        info.value)


def test_a_gap_takes_the_rocks_values_with_a_warning_when_rock_min_stress_is_given():
    text = FIELD.replace('poisson_ratio = 0.2\n', 'poisson_ratio = 0.2\nmin_stress = "0.7 psi/ft"\n')
    scene = load_scene(text.replace('top = "8100 ft"', 'top = "8110 ft"'))
    assert scene.warnings == ("rock.layers[2].top 8 110 ft: a gap of 10 ft between rock.layers[1] (bottom 8 100 ft) "
                              "and rock.layers[2] (top 8 110 ft) takes [rock]'s values there (min_stress 5 670 psi "
                              "at 8 100 ft)",)
    z = np.array([8099.0, 8105.0, 8110.0]) * FT
    np.testing.assert_allclose(scene.rock.min_stress_at(z), [6000 * PSI, 0.7 * PSI * 8105, 6800 * PSI], rtol=1e-12)


def test_layers_given_out_of_order_and_in_mixed_units_tile():
    # 8100 ft = 2468.88 m: a boundary within round-off is shared, in whatever order the layers are written
    head, rest = FIELD.replace('top = "8100 ft"', 'top = "2468.88 m"').split("[[rock.layers]]", 1)
    layers, tail = rest.split("[fluid]")
    blocks = layers.split("[[rock.layers]]")
    scene = load_scene(head + "".join("[[rock.layers]]" + blocks[i] for i in (2, 0, 1)) + "[fluid]" + tail)
    assert scene.warnings == () and [layer.top for layer in scene.rock.layers] == pytest.approx(
        [8100 * FT, 7900 * FT, 8000 * FT], rel=1e-12)


def test_an_overlap_is_an_error_in_the_scene_units():
    with pytest.raises(SceneError) as info:
        load_scene(FIELD.replace('top = "8100 ft"', 'top = "8090 ft"'))
    assert str(info.value) == ("scene key 'rock.layers[2].top': got '8090 ft'; layers must not overlap: "
                               "rock.layers[1] spans 8 000 ft to 8 100 ft, rock.layers[2] spans 8 090 ft to 8 200 ft")
    with pytest.raises(SceneError, match=r"rock.layers\[0\] spans 2 400 m to 2 450 m, rock.layers\[1\] spans "
                                         r"2 440 m to 2 480 m"):
        load_scene(SI.replace('top = "2450 m"', 'top = "2440 m"'))


SHIPPED = sorted([*(ROOT / "hfgpu" / "scenes").glob("*.toml"), *(ROOT / "bench" / "scenes").glob("*.toml")])


@pytest.mark.parametrize("path", SHIPPED, ids=[p.name for p in SHIPPED])
def test_every_shipped_scene_loads_without_gaps(path):
    scene = load_scene(path)
    assert not any("a gap of" in warning for warning in scene.warnings)
