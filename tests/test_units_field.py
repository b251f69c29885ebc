"""Units a stimulation engineer types (hfgpu.units, hfgpu.scene_reader): "5 bpm", "20 cp", stress gradients
("0.75 psi/ft", evaluated at each cell centre), bare numbers (an error in a field scene, a warning in an SI one),
the sanity bound on proppant concentration, and ``hfgpu --version``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import hfgpu
from hfgpu import SceneError, load_scene
from hfgpu.fracture.simulator import simulate
from hfgpu.records import MemorySink
from hfgpu.units import system_of, to_si

SCRIPT = Path(sys.executable).with_name("hfgpu")
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "hfgpu.cli"]

BBL = 42 * 3.785411784e-3          # m^3
PSI = 4.4482216152605 / 0.0254**2  # Pa
FT = 0.3048                        # m

# a coupled scene in field units (every value with units is field): 8000-8100 ft pay between two barriers
FIELD = """
[run]
end_time = "20 min"
physics = ["fracture", "proppant"]
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
min_stress = "0.75 psi/ft"
[[rock.layers]]
top = "8100 ft"
bottom = "8200 ft"
min_stress = "17 kPa/m"
[fluid]
viscosity = "20 cp"
[injection]
depth = "8050 ft"
schedule = [{ until = "10 min", rate = "5 bpm" },
            { until = "20 min", rate = "5 bpm", proppant = "sand", concentration = "2 ppa" }]
[mesh]
cell_size = "20 ft"
[[proppant]]
name = "sand"
density = "22 lb/gal"
diameter = "0.012 in"
"""


# --- units engineers type ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("text, si, kind", [
    ("5 bpm", 5 * BBL / 60, "rate"),
    ("20 cp", 0.02, "viscosity"),
    ("20 cP", 0.02, "viscosity"),
    ("0.75 psi/ft", 0.75 * PSI / FT, "stress_gradient"),
    ("17 kPa/m", 17e3, "stress_gradient"),
])
def test_oilfield_unit_words(text, si, kind):
    assert to_si(text, kind) == pytest.approx(si, rel=1e-12)


def test_cp_is_not_a_volume():
    with pytest.raises(SceneError, match="expected a volume"):
        to_si("20 cp", "volume", "x")


@pytest.mark.parametrize("text", ["5 bpm", "20 cp", "0.75 psi/ft"])
def test_the_new_words_mark_a_field_value(text):
    assert system_of(text) == "field"


def test_a_field_scene_reads_cp_bpm_and_gradients():
    scene = load_scene(FIELD)
    assert scene.warnings == () and scene.output.units == "field"
    assert scene.fluid.viscosity == pytest.approx(0.02, rel=1e-12)
    assert scene.injection.schedule.stages[0].rate == pytest.approx(5 * BBL / 60, rel=1e-12)
    pay = scene.rock.layers[1]
    assert pay.min_stress == 0.0 and pay.min_stress_gradient == pytest.approx(0.75 * PSI / FT, rel=1e-12)


def test_a_gradient_is_evaluated_at_each_depth():
    rock = load_scene(FIELD).rock
    z = np.array([7950.0, 8010.0, 8050.0, 8090.0, 8150.0, 9000.0]) * FT
    expected = [6800 * PSI, 0.75 * PSI * 8010, 0.75 * PSI * 8050, 0.75 * PSI * 8090, 17e3 * 8150 * FT,
                17e3 * 9000 * FT]   # the deepest layer's gradient extends downward with it
    np.testing.assert_allclose(rock.min_stress_at(z), expected, rtol=1e-12)
    assert rock.min_stress_at(np.array(8050 * FT)) == pytest.approx(6037.5 * PSI, rel=1e-12)


def test_the_rocks_min_stress_may_be_a_gradient_too():
    text = FIELD.replace('poisson_ratio = 0.2\n', 'poisson_ratio = 0.2\nmin_stress = "0.7 psi/ft"\n')
    text = text.replace('min_stress = "6800 psi"\n', "")     # the top barrier takes the rock's gradient
    rock = load_scene(text).rock
    assert rock.min_stress == 0.0 and rock.min_stress_gradient == pytest.approx(0.7 * PSI / FT, rel=1e-12)
    assert rock.min_stress_at(np.array(7950 * FT)) == pytest.approx(0.7 * PSI * 7950, rel=1e-12)


def test_the_fracture_engine_takes_the_stress_at_the_cell_centre():
    """A 400..700 m layer at 20 kPa/m with the injection at 500 m: the injection cell's sigma_0 is 10 MPa (its
    centre), not 11 MPa (the layer's mid-depth); net pressure = injection pressure - sigma_0 of that cell."""
    layers = '[[rock.layers]]\ntop = "400 m"\nbottom = "700 m"\nmin_stress = "20 kPa/m"\n'
    text = f"""
[run]
end_time = "100 s"
[rock]
youngs_modulus = "30 GPa"
poisson_ratio = 0.25
toughness = "0.1 MPa*m**0.5"
min_stress = "10 MPa"
{layers}
[fluid]
viscosity = "1 Pa*s"
[injection]
depth = "500 m"
schedule = [{{ until = "100 s", rate = "1e-3 m**3/s" }}]
[mesh]
cell_size = "1 m"
"""
    sink = MemorySink()
    simulate(load_scene(text), sink)
    last = sink.fracture_balances[-1]
    assert last.injection_pressure - last.net_pressure == pytest.approx(10e6, rel=1e-9)


@pytest.mark.parametrize("value, words", [
    ('"7 psi/m**2"', 'expected a stress gradient (e.g. "0.75 psi/ft") or a pressure in Pa'),
    ('"-0.1 psi/ft"', "allowed: >= 0 Pa/m"),
])
def test_a_bad_stress_is_named(value, words):
    with pytest.raises(SceneError) as info:
        load_scene(FIELD.replace('min_stress = "0.75 psi/ft"', f"min_stress = {value}"))
    assert info.value.path == "rock.layers[1].min_stress" and words in info.value.allowed


# --- bare numbers -------------------------------------------------------------------------------------------------

def test_a_bare_number_in_a_field_scene_is_an_error_naming_the_unit_to_write():
    with pytest.raises(SceneError) as info:
        load_scene(FIELD.replace('depth = "8050 ft"', "depth = 8050"))
    assert str(info.value) == ("scene key 'injection.depth': got 8050; a bare number is not read in a scene written "
                               'in field units: write its unit, e.g. "8050 ft" (or "8050 m" if SI is meant)')


@pytest.mark.parametrize("old, new, path, unit", [
    ('viscosity = "20 cp"', "viscosity = 0.02", "fluid.viscosity", '"0.02 cP"'),
    ('top = "7900 ft"', "top = 7900", "rock.layers[0].top", '"7900 ft"'),
    ('min_stress = "6800 psi"', "min_stress = 6800", "rock.layers[0].min_stress", '"6800 psi"'),
])
def test_each_dimensional_key_names_its_field_unit(old, new, path, unit):
    with pytest.raises(SceneError) as info:
        load_scene(FIELD.replace(old, new))
    assert info.value.path == path and unit in info.value.allowed


def test_bare_numbers_that_stay_allowed_in_a_field_scene():
    # 0 is the same in every unit; seconds are read the same in both systems (a warning, as in SI)
    scene = load_scene(FIELD.replace('end_time = "20 min"', "end_time = 1200"))
    assert scene.run.end_time == 1200.0
    assert scene.warnings == ("scene key 'run.end_time': bare number 1200 read as 1200 s (SI); write the unit, "
                              'e.g. "1200 s"',)
    assert load_scene(FIELD.replace('youngs_modulus = "5e6 psi"', 'youngs_modulus = "5e6 psi"\n'
                                    'pore_pressure = 0')).warnings == ()


def test_a_bare_number_in_an_si_scene_stays_a_warning():
    si = FIELD.replace('depth = "8050 ft"', "depth = 2453.64") + '[output]\nunits = "SI"\n'
    scene = load_scene(si)
    assert scene.injection.depth == 2453.64
    assert scene.warnings == ("scene key 'injection.depth': bare number 2453.64 read as 2453.64 m (SI); write the "
                              'unit, e.g. "2453.64 m"',)


def test_check_refuses_a_bare_number_in_a_field_scene(tmp_path):
    path = tmp_path / "field.toml"
    path.write_text(FIELD.replace('depth = "8050 ft"', "depth = 8050"), encoding="utf-8")
    done = subprocess.run([*COMMAND, "check", str(path)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.strip() == ("hfgpu check: error: scene key 'injection.depth': got 8050; a bare number is not "
                                   'read in a scene written in field units: write its unit, e.g. "8050 ft" (or '
                                   '"8050 m" if SI is meant)')


# --- proppant concentration ---------------------------------------------------------------------------------------

def test_a_concentration_above_12_ppa_is_warned_about():
    scene = load_scene(FIELD.replace('concentration = "2 ppa"', 'concentration = "25 ppa"'))
    # 22 lb/gal grains: c / rho_p = 25/22, fraction = (25/22) / (1 + 25/22) = 0.532
    assert scene.injection.schedule.stages[1].volume_fraction == pytest.approx(25 / 47, rel=1e-12)
    assert scene.warnings == ("scene key 'injection.schedule[1].concentration': '25 ppa' (slurry volume fraction "
                              "0.532) is more than 12 ppa, about the most a treatment pumps: check the value",)
    assert load_scene(FIELD.replace('concentration = "2 ppa"', 'concentration = "12 ppa"')).warnings == ()


def test_a_concentration_past_the_slurry_limit_is_an_error():
    with pytest.raises(SceneError) as info:   # (34/22) / (1 + 34/22) = 0.607 > 0.6
        load_scene(FIELD.replace('concentration = "2 ppa"', 'concentration = "2 ppa", end_concentration = "34 ppa"'))
    assert str(info.value) == ("scene key 'injection.schedule[1].end_concentration': got '34 ppa'; this loading "
                               "gives a slurry volume fraction 0.607; allowed: <= 0.6")


# --- hfgpu --version ----------------------------------------------------------------------------------------------

def test_version_flag_prints_the_package_version():
    done = subprocess.run([*COMMAND, "--version"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stderr == ""
    assert done.stdout.strip() == f"hfgpu {hfgpu.__version__}"
