"""``hfgpu check``'s expectations (hfgpu.estimate): the radial closed form's scales of a scene and the warnings
they lead to, on the corpus's treatments (written as engineers write them: none of these warnings) and on
treatments an engineer gets wrong (a grain too large for the opening, a rate too low for the leak-off)."""

from __future__ import annotations

import dataclasses

import subprocess
import sys
from pathlib import Path

import pytest

from hfgpu import edit_scene, load_scene
from hfgpu.estimate import MIN_EFFICIENCY, estimate, first_pumped, pumped, warnings
from hfgpu.reference.radial import dontsov_radial, scaled_parameters
from hfgpu.scene_checks import validate

SCENES = Path(__file__).resolve().parents[1] / "bench" / "scenes"
STAGE = SCENES / "corpus_permian_slickwater_stage.toml"
BBL_MIN = 0.158987294928 / 60.0


def stage(**changes):
    return validate(edit_scene(load_scene(STAGE.read_text()), changes))


def test_pumped_time_volume_and_first_proppant_of_the_stage():
    """Issue 30's stage: 50 min at 80 bbl/min (4 000 bbl); 100 mesh from 15 min, 40/70 from 30 min."""
    scene = stage()
    t, volume = pumped(scene.injection.schedule)
    assert t == pytest.approx(3000.0)
    assert volume == pytest.approx(4000 * 0.158987294928, rel=1e-9)
    assert first_pumped(scene.injection.schedule) == pytest.approx({"100 mesh": 900.0, "40/70": 1800.0})


def test_the_estimate_is_the_radial_solution_of_the_mean_rate_in_the_perforated_layer():
    scene = stage()
    e = estimate(scene)
    rock, depth = scene.rock, scene.injection.depth
    g = scaled_parameters(rock.youngs_modulus, rock.poisson_ratio, float(rock.toughness_at([depth])[0]),
                          scene.fluid.viscosity, float(rock.leakoff_at([depth])[0]))
    ref = dontsov_radial(g.E_prime, g.K_prime, g.mu_prime, g.C_prime, 80 * BBL_MIN, 3000.0)
    assert e.rate == pytest.approx(80 * BBL_MIN, rel=1e-9)
    assert e.radius == pytest.approx(float(ref.R[-1]), rel=1e-12)
    assert e.cells == pytest.approx(3.14159265 * e.radius**2 / (scene.mesh.dx * scene.mesh.dz), rel=1e-6)
    assert 0.0 < e.efficiency < 1.0 and e.opening > 0.0


@pytest.mark.parametrize("path", sorted(SCENES.glob("corpus_*.toml")), ids=lambda p: p.stem)
def test_the_corpus_treatments_get_none_of_these_warnings(path):
    scene = validate(path)
    assert warnings(scene.expected, scene, scene.output.units) == []


def test_a_grain_larger_than_the_opening_is_warned_with_its_key():
    """20/40 (grains to 0.84 mm) in slickwater at 10 bbl/min with no pad: the opening at the perforation is
    ~1 mm, less than 2 grains."""
    scene = stage(**{"proppant[1].size": "20/40", "injection.schedule[0].rate": "10 bbl/min",
                     "injection.schedule[1].rate": "10 bbl/min", "injection.schedule[2].rate": "10 bbl/min"})
    found = [w for w in scene.warnings if "bridges at the inlet" in w]
    assert len(found) == 1 and found[0].startswith("proppant[1] (40/70)") and " in " in found[0]


def test_a_rate_too_low_for_the_leakoff_is_warned():
    """5 bbl/min into 10 times the stage's leak-off coefficient: ~2.5 % of the fluid stays in the fracture."""
    rates = {f"injection.schedule[{i}].rate": "5 bbl/min" for i in range(3)}
    scene = stage(**rates, **{"rock.leakoff_coefficient": "3e-3 ft/min**0.5"})
    assert estimate(scene).efficiency < MIN_EFFICIENCY
    assert any("of the pumped fluid" in w and "leak-off takes nearly all" in w for w in scene.warnings)


def test_a_fracture_of_a_few_cells_is_warned():
    """5 bbl/min on 80 ft cells: a radius of ~230 ft, under 3 cells."""
    rates = {f"injection.schedule[{i}].rate": "5 bbl/min" for i in range(3)}
    scene = stage(**rates, **{"mesh.cell_size": "80 ft"})
    found = [w for w in scene.warnings if "does not resolve it" in w]
    assert len(found) == 1 and "fewer than 3 cells of 80 ft" in found[0]


def test_check_prints_the_expected_scales_and_work():
    out = subprocess.run([sys.executable, "-m", "hfgpu.cli", "check", str(STAGE)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    text = out.stdout
    assert "expected (a radial fracture at the mean rate 80 bbl/min" in text
    assert "fracture cells" in text and "proppant steps" in text and "parcel updates" in text
    assert "opening when 40/70 starts" in text and " in (t = 30 min)" in text


def test_a_rock_without_toughness_gets_the_viscosity_storage_radius():
    """K_Ic = 0, no leak-off: the M vertex of Savitski & Detournay (2002), R = 0.6955 (E' Q^3 t^4 / mu')^(1/9)."""
    from hfgpu.reference.radial import m_vertex

    changes = {"rock.toughness": "0 psi*in**0.5", "rock.leakoff_coefficient": "0 ft/min**0.5"}
    scene = stage(**changes)
    e = estimate(scene)
    g = scaled_parameters(scene.rock.youngs_modulus, scene.rock.poisson_ratio, 0.0, scene.fluid.viscosity, 0.0)
    assert e.radius == pytest.approx(float(m_vertex(g.E_prime, g.mu_prime, e.rate, 3000.0).R), rel=0.01)
    assert e.efficiency == pytest.approx(1.0)


def test_the_closure_after_shut_in_is_nolte_s_and_a_very_long_shut_in_is_warned():
    """closure_after solves Nolte's eta = G_c / (4 g_0 / pi + G_c) (alpha = 1/2) for the time: G at that time
    gives back the efficiency. The DFIT scene (12 bbl in 4 min, 6 h shut in) expects closure some 30 min after
    shut-in; 10^7 times the pumping time of shut-in is warned of, with that time; without leak-off, never."""
    import math

    from importlib.resources import files

    from hfgpu.estimate import closure_after
    from hfgpu.fracture.falloff import G_function, g0

    after = closure_after(0.6, 100.0)
    g_c = float(G_function(after / 100.0, 0.5))
    assert g_c / (4.0 * g0(0.5) / math.pi + g_c) == pytest.approx(0.6, rel=1e-9)
    dfit = (files("hfgpu") / "scenes" / "dfit.toml").read_text()
    e = estimate(validate(load_scene(dfit)))
    assert 10.0 * 60.0 < e.closure_after < 60.0 * 60.0
    assert not any("shut-in lasts" in w for w in validate(load_scene(dfit)).warnings)
    long = dfit.replace('end_time = "6 h"', 'end_time = "1e8 min"').replace('until = "6 h"', 'until = "1e8 min"')
    found = [w for w in validate(load_scene(long)).warnings if "shut-in lasts" in w]
    assert len(found) == 1 and "expected to close about" in found[0] and "run.end_time" in found[0]
    dry = long.replace('leakoff_coefficient = "0.0001 ft/min**0.5"', 'leakoff_coefficient = "0 ft/min**0.5"')
    assert any("never closes without leak-off" in w for w in validate(load_scene(dry)).warnings)


def test_a_pulse_that_spreads_after_shut_in_closes_over_its_arrest_area():
    """pyfrac_pulse_leakoff.toml: 0.01 s of pumping, then the pulse spreads from ~4 m to its leak-off arrest radius
    (25.7 m) before it drains. Nolte's constant-area relation would put closure ~1e9 s out; the arrest area puts it
    at 1.4e6 s. The engine closes it at 1.91e6 s (the scene run to 3e6 s): the estimate is within a factor 2."""
    from importlib.resources import files

    from hfgpu.estimate import closure_after

    text = (files("hfgpu") / "scenes" / "pyfrac_pulse_leakoff.toml").read_text()
    e = estimate(validate(load_scene(text)))
    assert e.closure_basis == "arrest" and 1.91e6 / 2.0 < e.closure_after < 1.91e6
    assert closure_after(e.efficiency, e.pumping_time) > 100.0 * e.closure_after
    dfit = estimate(validate(load_scene((files("hfgpu") / "scenes" / "dfit.toml").read_text())))
    assert dfit.closure_basis == "nolte"


def test_an_overflowing_closed_form_expects_nothing():
    """E = 1e300 Pa (tests/test_cli_fuzz.py found it): Dontsov's solution overflows to NaN; check expects nothing
    instead of failing."""
    text = (Path(__file__).resolve().parents[1] / "hfgpu" / "scenes" / "radial_I.toml").read_text()
    assert estimate(load_scene(text.replace('youngs_modulus = "40 GPa"', "youngs_modulus = 1e300"))) is None


def test_an_underflowing_time_scale_expects_nothing():
    """E = K_Ic = 6.7e128 (tests/test_cli_fuzz.py found it): the M-K time t_mk underflows to 0 and E' t_mk with it,
    so the opening scale mu' / (E' t_mk) divided by zero; check expects nothing instead of failing."""
    text = (Path(__file__).resolve().parents[1] / "hfgpu" / "scenes" / "radial_I.toml").read_text()
    scene = load_scene(text.replace('youngs_modulus = "40 GPa"', "youngs_modulus = 6.7392039258320385e+128"))
    scene = scene.replace(rock=dataclasses.replace(scene.rock, toughness=6.7392039258320385e+128))
    assert estimate(scene) is None
