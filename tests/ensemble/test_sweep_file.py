"""Sweep files: the documented example parses; every bad value is one line naming the sweep key, the value and
what is allowed, before any member runs."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from hfgpu.ensemble import MemberError, SweepError, load_sweep
from hfgpu.ensemble.members import members
from hfgpu.scene import load_scene
from hfgpu.scene_text import toml_text

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = Path(sys.executable).with_name("hfgpu")
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "hfgpu.cli"]

VARY = '[[vary]]\nkey = "rock.min_stress"\n'


def test_documented_example_parses(tmp_path):
    text = (ROOT / "docs" / "ensembles.md").read_text(encoding="utf-8")
    example = re.search(r"```toml\n(.*?)```", text, re.S).group(1)
    shutil.copy(ROOT / "hfgpu" / "scenes" / "five_layer.toml", tmp_path / "five_layer.toml")
    (tmp_path / "study.toml").write_text(example, encoding="utf-8")
    sweep = load_sweep(tmp_path / "study.toml")
    assert (sweep.design, sweep.members, sweep.seed) == ("latin-hypercube", 64, 1)
    assert [v.key for v in sweep.vary] == ["rock.leakoff_coefficient", "rock.layers[0].min_stress"]
    assert sweep.vary[0].params == pytest.approx((1e-7, 1e-6))
    assert sweep.vary[1].params == pytest.approx((65e6, 1e6))
    assert "propped_area" in sweep.metrics
    built = members(sweep)
    assert len(built) == 64
    scene = load_scene(built[5].scene_text)
    assert scene.rock.layers[0].min_stress == built[5].inputs["rock.layers[0].min_stress"]
    assert scene.rock.leakoff_coefficient == built[5].inputs["rock.leakoff_coefficient"]


@pytest.mark.parametrize("body, message", [
    ("members = 4\nseeds = 1\n" + VARY + "values = [6e7]\n",
     "sweep key 'seeds': got 1; unknown key; keys allowed here: design, members, metrics, scene, seed, vary"),
    ("members = 4\n" + VARY + 'distribution = "gauss"\nlow = "60 MPa"\nhigh = "61 MPa"\n',
     "sweep key 'vary[0].distribution': got 'gauss'; allowed: 'uniform', 'log-uniform', 'normal', 'triangular'"),
    ('members = 4\n[[vary]]\nkey = "rock.leakoff_coefficient"\ndistribution = "log-uniform"\nlow = "1e-7 MPa"\n'
     'high = "1e-6 m/s**0.5"\n',
     "sweep key 'vary[0].low': got '1e-7 MPa'; expected a leakoff in m/s**0.5, e.g. \"2e-7 m/s**0.5\"; "
     "'1e-7 MPa' has dimension [mass] / [length] / [time] ** 2"),
    ('members = 4\n[[vary]]\nkey = "rock.leakof_coefficient"\ndistribution = "uniform"\nlow = 1e-7\nhigh = 2e-7\n',
     "sweep key 'vary[0].key': got 'rock.leakof_coefficient'; unknown key; did you mean 'leakoff_coefficient'? "
     "keys allowed here: layers, leakoff_coefficient, min_stress, poisson_ratio, pore_pressure, toughness, "
     "youngs_modulus"),
    ('members = 4\n[[vary]]\nkey = "rocks.min_stress"\nvalues = [1e6]\n',
     "sweep key 'vary[0].key': got 'rocks.min_stress'; the base scene has no 'rocks'"),
    ('members = 4\n[[vary]]\nkey = "rock.layers[3].min_stress"\nvalues = ["1 MPa"]\n',
     "sweep key 'vary[0].key': got 'rock.layers[3].min_stress'; index 3 is past the end of 'layers' in the base "
     "scene (1 entry, the first is [0])"),
    ('members = 4\n[[vary]]\nkey = "rock.layers[0]"\nvalues = [1]\n',
     "sweep key 'vary[0].key': got 'rock.layers[0]'; expected a key holding one value, not a table"),
    ("members = 4\n" + VARY + 'distribution = "uniform"\nlow = "61 MPa"\nhigh = "60 MPa"\n',
     "sweep key 'vary[0].high': got '60 MPa'; allowed: > low (6.1e+07 in SI)"),
    ('members = 4\n[[vary]]\nkey = "rock.leakoff_coefficient"\ndistribution = "log-uniform"\nlow = 0\nhigh = 1e-6\n',
     "sweep key 'vary[0].low': got 0; allowed: > 0 (a log-uniform range is positive)"),
    ("members = 4\n" + VARY + 'distribution = "normal"\nmean = "60 MPa"\nstd = "1 m"\n',
     "sweep key 'vary[0].std': got '1 m'; expected a quantity in the units of mean ('1 m' is not of the "
     "dimension of mean '60 MPa')"),
    ("members = 4\n" + VARY + 'distribution = "normal"\nmean = "60 MPa"\n',
     "sweep key 'vary[0].std': got (missing); this key is required"),
    ("members = 4\n" + VARY + 'distribution = "triangular"\nlow = "60 MPa"\nmode = "70 MPa"\nhigh = "65 MPa"\n',
     "sweep key 'vary[0].mode': got '70 MPa'; allowed: between low and high (6e+07 and 6.5e+07 in SI)"),
    ('design = "grid"\n' + VARY + 'distribution = "uniform"\nlow = "60 MPa"\nhigh = "61 MPa"\n',
     "sweep key 'vary[0].distribution': got 'uniform'; a \"grid\" design needs values = [...]"),
    ('design = "grid"\nmembers = 3\n' + VARY + 'values = ["60 MPa", "61 MPa"]\n',
     "sweep key 'members': got 3; allowed only for sampled designs; a \"grid\" has one member per combination "
     "of the values"),
    ('members = 4\ndesign = "sobol"\n' + VARY + "values = [6e7]\n",
     "sweep key 'design': got 'sobol'; allowed: 'latin-hypercube', 'grid', 'random'"),
    ("members = 4\n" + VARY + "values = [6e7]\n" + VARY + "values = [6.1e7]\n",
     "sweep key 'vary[1].key': got 'rock.min_stress'; each key may be varied once (also vary[0])"),
    ("members = 4\n" + VARY + 'values = [6e7]\ndistribution = "uniform"\n',
     "sweep key 'vary[0].distribution': got 'uniform'; give either values or a distribution, not both"),
    ("members = 4\n" + VARY + "values = [6e7, true]\n",
     "sweep key 'vary[0].values[1]': got True; expected a number (SI) or a string with units, e.g. \"65 MPa\""),
    ("members = 4\n",
     "sweep key 'vary': got (missing); at least one [[vary]] table is required"),
    ("members = 0\n" + VARY + "values = [6e7]\n",
     "sweep key 'members': got 0; allowed: >= 1"),
    ("members = 4\n" + VARY + 'values = [6e7]\n[metrics]\nnames = ["propped_area", "height"]\n',
     "sweep key 'metrics.names[1]': got 'height'; allowed: 'propped_area', 'propped_area_in_place', "
     "'created_area', 'propped_fraction', 'fracture_height', 'fracture_length', 'net_pressure_end', "
     "'efficiency', 'screened_out', 'cluster_area_uniformity', 'cluster_propped_uniformity'"),
])
def test_bad_sweep_names_the_key(write_sweep, body, message):
    with pytest.raises(SweepError) as info:
        load_sweep(write_sweep(body))
    assert str(info.value) == message


def test_bad_member_scene_is_found_before_any_run(write_sweep):
    path = write_sweep('members = 20\nseed = 0\n[[vary]]\nkey = "rock.poisson_ratio"\ndistribution = "normal"\n'
                       "mean = 0.4\nstd = 0.2\n")
    with pytest.raises(MemberError) as info:
        members(load_sweep(path))
    assert re.fullmatch(r"sweep member 00\d\d \(rock\.poisson_ratio = [0-9.e-]+\): scene key 'rock\.poisson_ratio': "
                        r"got [0-9.e-]+; allowed: >= 0 and < 0\.5", str(info.value)), str(info.value)


def test_cli_reports_one_line_and_exit_2(write_sweep, tmp_path):
    path = write_sweep("members = 4\n" + VARY + 'distribution = "gauss"\nlow = "60 MPa"\nhigh = "61 MPa"\n')
    done = subprocess.run(COMMAND + ["sweep", str(path), "--out", str(tmp_path / "out")], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 2
    assert done.stderr == ("hfgpu sweep: error: sweep key 'vary[0].distribution': got 'gauss'; allowed: 'uniform', "
                           "'log-uniform', 'normal', 'triangular'\n")
    assert not (tmp_path / "out").exists()


def test_member_scene_text_round_trips_every_bundled_scene():
    for path in sorted((ROOT / "hfgpu" / "scenes").glob("*.toml")) + [ROOT / "tests" / "scenes" / "tiny_coupled.toml"]:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        assert tomllib.loads(toml_text(data)) == data, path.name


def test_text_values_for_a_key_that_takes_text(tmp_path):
    shutil.copy(ROOT / "hfgpu" / "scenes" / "five_layer.toml", tmp_path / "five_layer.toml")
    path = tmp_path / "sizes.toml"
    path.write_text('scene = "five_layer.toml"\ndesign = "grid"\n[[vary]]\nkey = "proppant[0].size"\n'
                    'values = ["30/50", "40/70", "100 mesh"]\n', encoding="utf-8")
    built = members(load_sweep(path))
    assert [m.inputs["proppant[0].size"] for m in built] == ["30/50", "40/70", "100 mesh"]
    assert 'size = "100 mesh"' in built[2].scene_text
    path.write_text('scene = "five_layer.toml"\nmembers = 3\n[[vary]]\nkey = "proppant[0].size"\n'
                    'distribution = "uniform"\nlow = "30/50"\nhigh = "100 mesh"\n', encoding="utf-8")
    with pytest.raises(SweepError) as info:
        load_sweep(path)
    assert str(info.value) == ("sweep key 'vary[0].low': got '30/50'; a distribution needs numbers; list text "
                               "values as values = [...]")
