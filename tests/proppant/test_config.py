"""The proppant scene tables: [geometry], [[proppant]], [mppic] -- values in SI, errors naming key and rule."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu import SceneError, load_scene

BOX = """
[run]
end_time = "10 s"
physics = ["proppant"]
[fluid]
viscosity = "1 cP"
[mesh]
cell_size = "1 cm"
[output]
every = "1 s"
[geometry]
kind = "box"
length = "5 cm"
height = "1 m"
width = "5 cm"
[[proppant]]
name = "heavy"
density = "2990 kg/m**3"
diameter = "198 um"
initial_volume_fraction = 0.01
[[proppant]]
name = "sand"
density = 2550
size = "30/50"
[mppic]
backend = "numpy"
theta_cp = 0.62
damping = false
"""


def test_box_scene_to_si():
    setup = load_scene(BOX).proppant
    assert setup.geometry.kind == "box" and setup.geometry.height == 1.0 and setup.geometry.width == 0.05
    heavy, sand = setup.classes
    assert heavy.size.kind == "fixed" and heavy.size.mean == pytest.approx(198e-6)
    assert sand.size.kind == "normal" and (sand.size.d_min, sand.size.d_max) == pytest.approx((3e-4, 6e-4))
    assert setup.class_densities() == {"heavy": 2990.0, "sand": 2550.0}
    assert setup.params.theta_cp == 0.62 and setup.params.damping is False
    assert setup.numerics.backend == "numpy"


def test_injection_concentration_uses_class_density():
    text = BOX.replace('kind = "box"', 'kind = "slot"').replace("[[proppant]]", """
[[geometry.inlets]]
kind = "segment"
x = 0
depth = "10 cm"
x_end = 0
depth_end = "12 cm"
[[geometry.outlets]]
kind = "point"
x = "5 cm"
depth = "10 cm"
[injection]
schedule = [{ until = "10 s", rate = "6 gpm", proppant = "sand", concentration = "1.5 ppg" }]
[[proppant]]""", 1)
    scene = load_scene(text)
    # Chun et al. (2020): 1.5 ppg of 2550 kg/m^3 sand -> slurry fraction (c/rho)/(1 + c/rho) = 0.065845
    assert scene.injection.schedule.proppant_fraction(1.0) == ("sand", pytest.approx(0.065845, abs=2e-6))
    inlet = scene.proppant.geometry.inlets[0]
    assert inlet.kind == "segment" and inlet.depth_end == pytest.approx(0.12) and inlet.jet == "none"
    jet = load_scene(text.replace('depth_end = "12 cm"', 'depth_end = "12 cm"\njet = "+x"'))
    assert jet.proppant.geometry.inlets[0].jet == "+x"
    with pytest.raises(SceneError) as err:
        load_scene(text.replace('depth_end = "12 cm"', 'depth_end = "12 cm"\njet = "x"'))
    assert err.value.path == "geometry.inlets[0].jet" and "'+x'" in str(err.value)


def test_stage_ends_by_clean_volume():
    """A stage given by clean volume V_c lasts V_c / (Q (1 - mean phi)): 100 bbl of clean fluid at
    20 bbl/min of slurry ramped 0.1 -> 0.3 (mean 0.2) takes 100 / (20 * 0.8) min = 375 s."""
    text = BOX.replace('kind = "box"', 'kind = "slot"').replace("[[proppant]]", """
[[geometry.inlets]]
kind = "point"
x = 0
depth = "10 cm"
[[geometry.outlets]]
kind = "point"
x = "5 cm"
depth = "10 cm"
[injection]
schedule = [{ until = "60 s", rate = "20 bbl/min" },
            { clean_volume = "100 bbl", rate = "20 bbl/min", proppant = "sand", volume_fraction = 0.1, end_volume_fraction = 0.3 }]
[[proppant]]""", 1)
    schedule = load_scene(text).injection.schedule
    assert schedule.breakpoints() == pytest.approx((60.0, 60.0 + 375.0), rel=1e-12)
    q = 20 * 0.158987294928 / 60  # 20 bbl/min in m^3/s
    # solids: Q x mean fraction 0.2 x 375 s over the ramp; the pad carries none; half the ramp: mean 0.15
    assert schedule.solid_volume(0.0, 1000.0) == pytest.approx(q * 0.2 * 375.0, rel=1e-12)
    assert schedule.solid_volume(0.0, 60.0 + 187.5) == pytest.approx(q * 0.15 * 187.5, rel=1e-12)
    with pytest.raises(SceneError) as err:
        load_scene(text.replace('clean_volume = "100 bbl"', 'clean_volume = "100 bbl", duration = "5 s"'))
    assert err.value.path == "injection.schedule[1].clean_volume" and "not" in str(err.value)
    with pytest.raises(SceneError) as err:
        load_scene(text.replace('"100 bbl", rate = "20 bbl/min"', '"100 bbl", rate = 0'))
    assert err.value.path == "injection.schedule[1].clean_volume" and "rate > 0" in str(err.value)


@pytest.mark.parametrize("old, new, path", [
    ('kind = "box"', 'kind = "tube"', "geometry.kind"),
    ('width = "5 cm"', 'width = "-5 cm"', "geometry.width"),
    ('diameter = "198 um"', 'diameter = "198 um"\nsize = "30/50"', "proppant[0].diameter"),
    ('size = "30/50"', 'size = "50/30"', "proppant[1].size"),
    ('initial_volume_fraction = 0.01', 'initial_volume_fraction = 0.7', "proppant[0].initial_volume_fraction"),
    ('backend = "numpy"', 'backend = "cuda"', "mppic.backend"),
    ('theta_cp = 0.62', 'theta_cp = 1.5', "mppic.theta_cp"),
    ('damping = false', 'damping = 3', "mppic.damping"),
    ('damping = false', 'c_max = 1.2', "mppic.c_max"),
    ('damping = false', 'substeps = 3', "mppic.substeps"),
    ('damping = false', 'slurry_viscosity = "no"', "mppic.slurry_viscosity"),
    ('damping = false', 'particle_substeps = 0', "mppic.particle_substeps"),
    ('kind = "box"', 'kind = "slot"', "geometry.inlets"),
])
def test_errors_name_key_path(old, new, path):
    with pytest.raises(SceneError) as err:
        load_scene(BOX.replace(old, new))
    assert err.value.path == path


def test_field_geometry_from_npz(tmp_path):
    x = 0.005 + 0.01 * np.arange(4)
    z = 0.005 + 0.01 * np.arange(3)
    w = np.full((3, 4), 2e-3)
    w[0, 0] = 0.0
    np.savez(tmp_path / "w.npz", x=x, z=z, w=w)
    text = BOX.replace('kind = "box"\nlength = "5 cm"\nheight = "1 m"\nwidth = "5 cm"',
                       f'kind = "field"\nfile = "{tmp_path / "w.npz"}"')
    g = load_scene(text).proppant.geometry
    assert g.length == pytest.approx(0.04) and g.height == pytest.approx(0.03)
    np.testing.assert_array_equal(g.field_w, w)
    with pytest.raises(SceneError, match="spacing"):
        load_scene(text.replace('cell_size = "1 cm"', 'cell_size = "2 cm"'))
    with pytest.raises(SceneError, match="no such width file"):
        load_scene(text.replace("w.npz", "missing.npz"))


def test_grain_pressure_key():
    """[mppic] grain_pressure: default "two-step", "last" accepted, another value refused in one line naming the
    key, the value and the allowed ones."""
    assert load_scene(BOX).proppant.numerics.grain_pressure == "two-step"
    assert load_scene(BOX + 'grain_pressure = "last"\n').proppant.numerics.grain_pressure == "last"
    with pytest.raises(SceneError) as err:
        load_scene(BOX + 'grain_pressure = "mean"\n')
    assert "mppic.grain_pressure" in str(err.value) and "'mean'" in str(err.value) and "two-step" in str(err.value)
