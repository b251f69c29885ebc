"""The closure keys of a scene: defaults, and one-line errors naming the key, the value and what is allowed."""

import pytest
from closure_fakes import box_text

from hfgpu.closure.config import LAB_LOADING
from hfgpu.errors import SceneError
from hfgpu.scene import load_scene

FRACTURE = """
[run]
end_time = "10 s"
[rock]
youngs_modulus = "40 GPa"
poisson_ratio = 0.15
[fluid]
viscosity = "0.08 Pa*s"
[injection]
schedule = [{ until = "10 s", rate = "0.05 m**3/s" }]
[mesh]
cell_size = "2 m"
[output]
every = "1 s"
"""


def test_defaults():
    scene = load_scene(box_text())
    assert scene.closure.settling == "bed"
    assert scene.closure.pack_solid_fraction == scene.proppant.params.theta_cp
    assert scene.closure.layers == 1.0 and scene.closure.embedment == 0.0
    assert scene.output.units == "SI"
    cls = scene.proppant.classes[0].closure
    assert cls.table is None and cls.factor == 1.0
    assert cls.loading == pytest.approx(9.7648552727661)  # 2 lb/ft^2
    assert LAB_LOADING == cls.loading


def test_table_and_units_parse():
    text = box_text('[closure]\nclosure_stress = "4000 psi"\nformation_permeability = "0.05 md"',
                    'conductivity = [{ stress = "2000 psi", value = "4000 md*ft" }, '
                    '{ stress = "6000 psi", value = "1500 md*ft" }]\nconductivity_loading = "1 lb/ft**2"')
    scene = load_scene(text.replace("[output]", '[output]\nunits = "field"'))
    table = scene.proppant.classes[0].closure.table
    assert table.stress == pytest.approx((2000 * 6894.757293168361, 6000 * 6894.757293168361))
    assert table.value[0] == pytest.approx(4000 * 9.869232667160130e-16 * 0.3048)
    assert not table.is_permeability
    assert scene.output.units == "field"
    assert scene.closure.formation_permeability == pytest.approx(0.05 * 9.869232667160130e-16)


@pytest.mark.parametrize("closure, extra, key, words", [
    ('[closure]\nsettling = "sink"', "", "closure.settling", ["'sink'", "'bed'", "'in_place'"]),
    ('[closure]\npack_solid_fraction = 1.2', "", "closure.pack_solid_fraction", ["1.2", "< 1"]),
    ('[closure]\nembedment = "-1 mm"', "", "closure.embedment", ["'-1 mm'", ">= 0"]),
    ('[closure]\nsetling = "bed"', "", "closure.setling", ["unknown key", "settling"]),
    ('[closure]\nformation_permeability = "3 ft"', "", "closure.formation_permeability", ["permeability"]),
    ("", 'conductivity = [{ stress = "2000 psi", value = "4000 md*ft" }]', "closure.closure_stress",
     ["required", "no [rock]"]),
    ('[closure]\nclosure_stress = "1 MPa"', 'conductivity = [{ stress = "2000 psi", value = "4000 ft" }]',
     "proppant[0].conductivity[0].value", ["'4000 ft'", "md*ft", "darcy"]),
    ('[closure]\nclosure_stress = "1 MPa"', 'conductivity = [{ stress = "4000 psi", value = "1 darcy" }, '
     '{ stress = "2000 psi", value = "2 darcy" }]', "proppant[0].conductivity", ["increase"]),
    ('[closure]\nclosure_stress = "1 MPa"', 'conductivity = [{ stress = "2000 psi", value = "1 darcy", x = 1 }]',
     "proppant[0].conductivity[0].x", ["unknown key"]),
    ('[closure]\nclosure_stress = "1 MPa"', 'conductivity = "4000 md*ft"', "proppant[0].conductivity",
     ["non-empty list"]),
    ("", "conductivity_factor = 2", "proppant[0].conductivity_factor", ["<= 1"]),
    ("", 'conductivity_loading = "2 lb"', "proppant[0].conductivity_loading", ["areal_density", "lb/ft**2"]),
])
def test_bad_keys_give_one_line_errors(closure, extra, key, words):
    with pytest.raises(SceneError) as info:
        load_scene(box_text(closure, extra))
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"scene key '{key}'")
    for word in words:
        assert word in message


def test_output_units_and_pore_pressure_errors():
    with pytest.raises(SceneError, match=r"'output.units': got 'imperial'; allowed: 'SI', 'field'"):
        load_scene(box_text().replace("[output]", '[output]\nunits = "imperial"'))
    with pytest.raises(SceneError, match=r"'rock.pore_pressure': got '10 m'; expected a pressure"):
        load_scene(FRACTURE.replace("poisson_ratio = 0.15", 'poisson_ratio = 0.15\npore_pressure = "10 m"'))
    with pytest.raises(SceneError, match=r"'rock.layers\[0\].pore_pressure'"):
        load_scene(FRACTURE + '[[rock.layers]]\ntop = "0 m"\nbottom = "5 m"\npore_pressure = "x"\n')


def test_closure_needs_proppant():
    with pytest.raises(SceneError, match=r"'closure': got '\(table\)'; this section needs \"proppant\""):
        load_scene(FRACTURE + '[closure]\nsettling = "bed"\n')
    scene = load_scene(FRACTURE.replace("poisson_ratio = 0.15", 'poisson_ratio = 0.15\npore_pressure = "9 MPa"'))
    assert scene.rock.pore_pressure == 9e6 and scene.closure is None
