"""Scene keys changed as text (hfgpu/scene_text.py): the edited scene's values and its stored text agree."""

from __future__ import annotations

import dataclasses
import warnings
from importlib.resources import files

import pytest

from hfgpu import edit_scene, load_scene
from hfgpu.errors import SceneError
from hfgpu.runner import warn_edited
from hfgpu.scene_text import assignment

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib  # type: ignore[no-redef]

FIELD = files("hfgpu") / "scenes" / "five_layer.toml"
PYFRAC = files("hfgpu") / "scenes" / "pyfrac_height_contained.toml"


def test_edit_sets_nested_array_and_new_keys_and_keeps_the_text_true():
    scene = load_scene(FIELD)
    edited = edit_scene(scene, {"coupling.cell_size": "2.5 m", "proppant[0].size": "30/50",
                                "rock.layers[2].min_stress": "62 MPa", "mppic.backend": "numpy"})
    assert edited.coupling.cell_size == (2.5, 2.5)
    assert edited.proppant.classes[0].sieve == "30/50"
    assert edited.proppant == dataclasses.replace(scene.proppant.with_sieve("30/50"), numerics=dataclasses.replace(
        scene.proppant.numerics, backend="numpy"))
    assert edited.rock.layers[2].min_stress == pytest.approx(62e6)
    assert edited.run == scene.run and edited.fluid == scene.fluid
    assert load_scene(edited.source) == edited
    assert edited.source.splitlines()[0].startswith('# edited: coupling.cell_size = "2.5 m"')


@pytest.mark.parametrize("key, value, named", [
    ("coupling.cell_sise", "2.5 m", "coupling.cell_sise"),        # unknown key: the scene's own error
    ("couplings.cell_size", "2.5 m", "couplings.cell_size"),      # no such table
    ("proppant[3].size", "30/50", "proppant[3].size"),             # past the end
    ("coupling.cell_size", "-1 m", "coupling.cell_size"),          # out of range
])
def test_a_bad_key_or_value_names_the_key(key, value, named):
    with pytest.raises(SceneError) as info:
        edit_scene(load_scene(FIELD), {key: value})
    assert named in str(info.value)


def test_an_array_valued_key_takes_an_array_and_its_text_round_trips():
    edited = edit_scene(load_scene(PYFRAC), {"mesh.cell_size": ["1 m", "0.5 m"]})
    assert edited.mesh.scene_cell_size == (1.0, 0.5)
    assert tomllib.loads(edited.source)["mesh"]["cell_size"] == ["1 m", "0.5 m"]
    assert edited.source.splitlines()[0] == '# edited: mesh.cell_size = ["1 m", "0.5 m"]'
    assert load_scene(edited.source) == edited
    field = edit_scene(load_scene(FIELD), {"run.physics": ["proppant", "fracture"], "mesh.cell_size": ["5 m", "2.5 m"]})
    assert tomllib.loads(field.source)["run"]["physics"] == ["proppant", "fracture"]
    assert field.run.physics == ("fracture", "proppant")
    assert field.mesh.scene_cell_size == (5.0, 2.5)


@pytest.mark.parametrize("key, kind", [
    ("rock", "a table"), ("proppant[0]", "a table"),
    ("rock.layers", "an array of tables"), ("injection.schedule", "an array of tables"),   # [[...]] and inline
])
@pytest.mark.parametrize("value", [1, ["1 m"], None])
def test_a_table_or_an_array_of_tables_is_refused_naming_the_key(key, kind, value):
    with pytest.raises(SceneError) as info:
        edit_scene(load_scene(FIELD), {key: value})
    assert str(info.value) == (f"scene key '{key}': got '{key}'; expected a key holding one value or an array of "
                               f"values, not {kind}")


def test_none_removes_a_key_so_its_default_applies():
    scene = load_scene(FIELD)
    assert scene.coupling.inlet_radius == 7.5
    edited = edit_scene(scene, {"coupling.inlet_radius": None, "proppant[0].size": None,
                                "proppant[0].diameter": "300 um"})
    assert edited.coupling.inlet_radius is None
    assert "inlet_radius" not in tomllib.loads(edited.source)["coupling"]
    assert tomllib.loads(edited.source)["proppant"][0] == {"name": "40/70", "density": "2650 kg/m**3",
                                                          "diameter": "300 um"}
    assert edited.proppant.classes[0].sieve is None
    assert edited.proppant.classes[0].size.mean == pytest.approx(300e-6)
    assert edited.source.splitlines()[0] == ('# edited: coupling.inlet_radius removed, proppant[0].size removed, '
                                             'proppant[0].diameter = "300 um"')
    assert load_scene(edited.source) == edited


@pytest.mark.parametrize("key", ["run.preset", "rock.layers[0].toughness"])
def test_removing_a_key_the_scene_does_not_hold_names_it(key):
    with pytest.raises(SceneError) as info:
        edit_scene(load_scene(FIELD), {key: None})
    assert info.value.path == key
    assert str(info.value) == (f"scene key '{key}': got (missing); the scene does not hold this key, so it cannot "
                               "be removed")


def test_none_inside_a_value_is_refused_naming_the_key():
    with pytest.raises(SceneError) as info:
        edit_scene(load_scene(FIELD), {"run.physics": ["fracture", None]})
    assert info.value.path == "run.physics"
    assert "TOML has no null" in str(info.value)


def test_run_warns_when_the_scene_no_longer_matches_its_text():
    scene = load_scene(FIELD)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warn_edited(scene)
        warn_edited(edit_scene(scene, {"run.end_time": "60 s"}))
    with pytest.warns(UserWarning, match="edit_scene"):
        warn_edited(scene.replace(run=dataclasses.replace(scene.run, end_time=60.0)))


@pytest.mark.parametrize("text, expected", [
    ("run.seed=2", ("run.seed", 2)), ("mppic.shields_deposition = false", ("mppic.shields_deposition", False)),
    ('coupling.cell_size="2.5 m"', ("coupling.cell_size", "2.5 m")),
    ("rock.layers[0].bottom=2967.5 m", ("rock.layers[0].bottom", "2967.5 m")),
])
def test_assignment_reads_toml_values_and_plain_text(text, expected):
    assert assignment(text) == expected
