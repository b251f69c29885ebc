"""Scene parsing: units, layered properties, schedules, and error messages that name key, value and rule."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hfgpu import SceneError, load_scene
from hfgpu.scene import parse_scene
from hfgpu.units import to_si

BASE = """
[run]
end_time = "370 s"
physics = ["fracture"]
[rock]
youngs_modulus = "40 GPa"
poisson_ratio = 0.15
toughness = "1 MPa*m**0.5"
leakoff_coefficient = "2e-7 m/s**0.5"
min_stress = "60 MPa"
[[rock.layers]]
top = "-10 m"
bottom = "10 m"
min_stress = "61.7 MPa"
[fluid]
viscosity = "0.08 Pa*s"
density = "1000 kg/m**3"
[injection]
depth = "0 m"
schedule = [{ until = "370 s", rate = "0.053 m**3/s" }]
[mesh]
cell_size = "2 m"
[output]
every = "10 s"
"""


def test_contract_scene_parses_to_si():
    scene = load_scene(BASE)
    assert scene.run.end_time == 370.0 and scene.run.physics == ("fracture",)
    assert scene.rock.youngs_modulus == 40e9
    assert scene.rock.toughness == 1e6
    assert scene.rock.plane_strain_modulus == pytest.approx(40e9 / (1 - 0.15**2), rel=1e-15)
    assert scene.fluid.viscosity == 0.08
    assert scene.mesh.dx == scene.mesh.dz == 2.0
    assert scene.injection.schedule.rate(100.0) == 0.053
    assert scene.source == BASE


@pytest.mark.parametrize("text, si, kind", [
    ("20 bbl/min", 20 * 42 * 3.785411784e-3 / 60, "rate"),   # oilfield barrel = 42 US gal
    ("9000 psi", 9000 * 6894.757293168, "pressure"),
    ("2 MPa*m**0.5", 2e6, "toughness"),
    ("1 cP", 1e-3, "viscosity"),
    ("198 um", 198e-6, "length"),
    ("6 gpm", 6 * 3.785411784e-3 / 60, "rate"),
    ("2 ppa", 2 * 0.45359237 / 3.785411784e-3, "concentration"),
])
def test_field_units(text, si, kind):
    assert to_si(text, kind) == pytest.approx(si, rel=1e-12)


def test_layers_and_outermost_layers_extend():
    scene = load_scene(BASE.replace('[fluid]', '''[[rock.layers]]
top = "10 m"
bottom = "30 m"
min_stress = "55 MPa"
toughness = "2 MPa*m**0.5"
[fluid]'''))
    z = np.array([-100.0, -10.0, 0.0, 9.99, 10.0, 29.0, 1000.0])
    # the shallowest layer extends upward to infinity and the deepest downward
    np.testing.assert_array_equal(scene.rock.min_stress_at(z),
                                  [61.7e6, 61.7e6, 61.7e6, 61.7e6, 55e6, 55e6, 55e6])
    np.testing.assert_array_equal(scene.rock.toughness_at(z), [1e6] * 4 + [2e6] * 3)


def test_schedule_volume_is_exact_and_shut_in():
    scene = load_scene(BASE.replace('schedule = [{ until = "370 s", rate = "0.053 m**3/s" }]',
                                    'schedule = [{ until = "10 s", rate = 1.0 }, '
                                    '{ duration = "20 s", rate = 2.0 }, { until = "40 s", rate = 0 }]'))
    s = scene.injection.schedule
    assert s.breakpoints() == (10.0, 30.0, 40.0)
    assert s.volume(5.0) == 5.0 and s.volume(20.0) == 30.0 and s.volume(100.0) == 50.0
    assert s.mean_rate(5.0, 15.0) == pytest.approx(1.5)
    assert s.rate(35.0) == 0.0 and s.rate(50.0) == 0.0


@pytest.mark.parametrize("old, new, path, words", [
    ('youngs_modulus = "40 GPa"', 'youngs_modulus = "40 GPA"', "rock.youngs_modulus", "pressure"),
    ('youngs_modulus = "40 GPa"', 'youngs_modulus = "40 m"', "rock.youngs_modulus", "dimension"),
    ('poisson_ratio = 0.15', 'poisson_ratio = 0.7', "rock.poisson_ratio", "< 0.5"),
    ('viscosity = "0.08 Pa*s"', 'viscosity = "-1 Pa*s"', "fluid.viscosity", "> 0"),
    ('bottom = "10 m"', 'bottom = "-20 m"', "rock.layers[0].bottom", "below its top"),
    ('until = "370 s"', 'untill = "370 s"', "injection.schedule[0].until", "required"),
    ('cell_size = "2 m"', 'cell_size = ["2 m"]', "mesh.cell_size", "two"),
    ('physics = ["fracture"]', 'physics = ["fracture", "magma"]', "run.physics", "distinct names"),
    ('every = "10 s"', 'every = "10 s"\nevry = 3', "output.evry", "unknown key"),
])
def test_errors_name_key_value_and_rule(old, new, path, words):
    with pytest.raises(SceneError) as info:
        load_scene(BASE.replace(old, new))
    message = str(info.value)
    assert f"'{path}'" in message and words in message


def test_missing_section_and_bad_toml():
    with pytest.raises(SceneError, match="'fluid'.*required"):
        load_scene(BASE.replace("[fluid]", "[fluids]"))
    with pytest.raises(SceneError, match="'rock.youngs_modulus'.*required"):
        load_scene(BASE.replace("[rock]", "[rocks]"))
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene("[run\nend_time = 3")
    with pytest.raises(SceneError, match="cannot read"):
        load_scene("no_such_scene.toml")


def test_scene_is_frozen():
    scene = load_scene(BASE)
    with pytest.raises(AttributeError):
        scene.rock.toughness = 0.0


# property-based: any malformed or out-of-range scene gives a SceneError, never another exception

VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12), st.sampled_from(["40 GPa", "-3 MPa", "1e400 m", "nan s", "2 bbl/min", "0 s",
                                           "5 furlongs", "3 m/s**0.5", "", "1 Pa*s"]),
    st.lists(st.integers(), max_size=3), st.dictionaries(st.text(max_size=5), st.integers(), max_size=2),
)


def _leaves(data, path=()):
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _leaves(value, path + (key,))
    elif isinstance(data, list) and data and all(isinstance(v, dict) for v in data):
        for i, value in enumerate(data):
            yield from _leaves(value, path + (i,))
    else:
        yield path


LEAVES = list(_leaves(tomllib.loads(BASE)))


def _set(data, path, value):
    for key in path[:-1]:
        data = data[key]
    data[path[-1]] = value


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.sampled_from(LEAVES), VALUES), min_size=1, max_size=3))
def test_corrupted_values_raise_scene_error_only(changes):
    data = tomllib.loads(BASE)
    for path, value in changes:
        if value is None:
            parent = data
            for key in path[:-1]:
                parent = parent[key]
            parent.pop(path[-1], None)
        else:
            _set(data, path, value)
    try:
        parse_scene(data)
    except SceneError as exc:
        assert "scene key '" in str(exc)


def test_a_long_bad_value_is_shortened_in_the_message():
    """A pasted value of hundreds of characters is shown by its first 29 and '...', so the one-line message
    (key, value, what is allowed) stays readable; the error keeps the whole value."""
    long = "x" * 500
    with pytest.raises(SceneError) as caught:
        load_scene(BASE.replace('youngs_modulus = "40 GPa"', f'youngs_modulus = "{long}"'))
    message = str(caught.value)
    assert "'rock.youngs_modulus'" in message and f"got '{'x' * 28}..." in message and len(message) < 200
    assert caught.value.value == long


def test_scene_slots_are_typed_with_the_sections_configs():
    """Each section slot of Scene names its section's frozen dataclass (imported for type checking only, so that
    a scene loads no physics it does not ask for)."""
    import typing

    from hfgpu.closure.config import ClosureConfig
    from hfgpu.completion import Completion
    from hfgpu.coupling_config import CouplingConfig
    from hfgpu.defaults import Derived
    from hfgpu.estimate import Estimate
    from hfgpu.fracture.config import FractureNumerics
    from hfgpu.proppant.config import ProppantSetup
    from hfgpu.scene import Scene
    from hfgpu.wellbore import Wellbore

    types = {"fracture": FractureNumerics, "proppant": ProppantSetup, "coupling": CouplingConfig,
             "closure": ClosureConfig, "wellbore": Wellbore, "completion": Completion, "expected": Estimate}
    hints = typing.get_type_hints(Scene, localns={t.__name__: t for t in (*types.values(), Derived)})
    assert {name: hints[name] for name in types} == {name: t | None for name, t in types.items()}
    assert hints["derived"] == tuple[Derived, ...]
