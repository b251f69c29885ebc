"""One [[vary]] over several scene keys (issue 31): every key gets the member's one value; bad input names the key
and the value; the single-key form is unchanged."""

from __future__ import annotations

import pytest

from hfgpu.ensemble import SweepError, load_sweep
from hfgpu.ensemble.members import members
from hfgpu.scene import load_scene

from .conftest import BASE

TWO_STAGES = BASE.replace('schedule = [{ until = "60 s", rate = "0.053 m**3/s" }]',
                          'schedule = [{ until = "30 s", rate = "0.053 m**3/s" }, '
                          '{ until = "60 s", rate = "0.04 m**3/s" }]')
RATES = 'keys = ["injection.schedule[0].rate", "injection.schedule[1].rate"]\n'


def test_every_key_gets_the_one_value(write_sweep):
    path = write_sweep('members = 3\n[[vary]]\n' + RATES + 'name = "rate"\ndistribution = "uniform"\n'
                       'low = "20 bbl/min"\nhigh = "30 bbl/min"\n', base=TWO_STAGES)
    sweep = load_sweep(path)
    (vary,) = sweep.vary
    assert vary.key == "rate" and vary.kind == "rate" and vary.unit == "m**3/s"
    assert [key for key, _ in vary.targets] == ["injection.schedule[0].rate", "injection.schedule[1].rate"]
    for member in members(sweep):
        rate = member.inputs["rate"]
        assert 0.053 <= rate <= 0.0795                    # 20 and 30 bbl/min in m^3/s
        stages = load_scene(member.scene_text).injection.schedule.stages
        assert [stage.rate for stage in stages] == [rate, rate]


def test_default_name_joins_the_keys(write_sweep):
    sweep = load_sweep(write_sweep('design = "grid"\n[[vary]]\n' + RATES + 'values = ["20 bpm"]\n',
                                   base=TWO_STAGES))
    assert sweep.vary[0].key == "injection.schedule[0].rate+injection.schedule[1].rate"


@pytest.mark.parametrize("body, message", [
    ('[[vary]]\nkeys = ["injection.schedule[0].rate", "rock.min_stress"]\nvalues = ["20 bbl/min"]\n',
     "sweep key 'vary[0].values[0]': got '20 bbl/min'; for key 'rock.min_stress': expected a stress gradient "
     "(e.g. \"0.75 psi/ft\") or a pressure in Pa, e.g. \"60 MPa\", \"9000 psi\"; '20 bbl/min' has dimension "
     "[length] ** 3 / [time]"),
    ('[[vary]]\nkeys = ["rock.min_stress", "rock.poisson_ratio"]\nvalues = [0.2]\n',
     "sweep key 'vary[0].keys': got 'rock.poisson_ratio'; takes a plain number where 'rock.min_stress' takes a "
     "pressure (Pa): the keys of one [[vary]] get one value, so they must take the same kind"),
    ('[[vary]]\nkey = "rock.min_stress"\nkeys = ["rock.min_stress"]\nvalues = ["60 MPa"]\n',
     "sweep key 'vary[0].key': got 'rock.min_stress'; give either key or keys, not both"),
    ('[[vary]]\nkeys = []\nvalues = ["60 MPa"]\n',
     "sweep key 'vary[0].keys': got []; expected a non-empty list of scene key paths, e.g. "
     "[\"injection.schedule[0].rate\", \"injection.schedule[1].rate\"]"),
    ('[[vary]]\nkeys = ["rock.min_stress", "rock.min_stress"]\nvalues = ["60 MPa"]\n',
     "sweep key 'vary[0].keys[1]': got 'rock.min_stress'; listed twice (also keys[0])"),
    ('[[vary]]\nkeys = ["rock.min_stress", "rock.layers[0].min_stress"]\nvalues = ["60 MPa"]\n'
     '[[vary]]\nkey = "rock.layers[0].min_stress"\nvalues = ["61 MPa"]\n',
     "sweep key 'vary[1].key': got 'rock.layers[0].min_stress'; each key may be varied once (also vary[0])"),
    ('[[vary]]\nkeys = ["rock.min_stres"]\nvalues = ["60 MPa"]\n',
     "sweep key 'vary[0].keys[0]': got 'rock.min_stres'; unknown key; did you mean 'min_stress'? keys allowed "
     "here: layers, leakoff_coefficient, min_stress, poisson_ratio, pore_pressure, toughness, youngs_modulus"),
])
def test_bad_keys_name_the_key_and_the_value(write_sweep, body, message):
    with pytest.raises(SweepError) as info:
        load_sweep(write_sweep('design = "grid"\n' + body))
    assert str(info.value) == message
