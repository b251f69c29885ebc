"""Designs: Latin-hypercube strata, distribution bounds and moments, grids of every combination, and the same
members from the same file and seed."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from hfgpu.ensemble import load_sweep
from hfgpu.ensemble.design import member_inputs
from hfgpu.ensemble.members import members

SAMPLED = """
members = {n}
design = "{design}"
seed = {seed}
[[vary]]
key = "rock.min_stress"
distribution = "uniform"
low = "60 MPa"
high = "64 MPa"
[[vary]]
key = "rock.leakoff_coefficient"
distribution = "log-uniform"
low = "1e-7 m/s**0.5"
high = "1e-5 m/s**0.5"
[[vary]]
key = "rock.layers[0].min_stress"
distribution = "normal"
mean = "65 MPa"
std = "1 MPa"
[[vary]]
key = "rock.toughness"
distribution = "triangular"
low = "0.5 MPa*m**0.5"
mode = "1 MPa*m**0.5"
high = "2 MPa*m**0.5"
[[vary]]
key = "fluid.viscosity"
values = ["10 cP", "80 cP", 0.2]
"""


def _columns(path):
    rows = member_inputs(load_sweep(path))
    return {key: np.array([r[key] for r in rows]) for key in rows[0]}


def test_latin_hypercube_has_one_sample_per_stratum(write_sweep):
    n = 50
    c = _columns(write_sweep(SAMPLED.format(n=n, design="latin-hypercube", seed=3)))
    strata = {
        "rock.min_stress": (c["rock.min_stress"] - 60e6) / 4e6,
        "rock.leakoff_coefficient": np.log(c["rock.leakoff_coefficient"] / 1e-7) / np.log(100.0),
    }
    from scipy.stats import norm

    strata["rock.layers[0].min_stress"] = norm.cdf((c["rock.layers[0].min_stress"] - 65e6) / 1e6)
    for key, u in strata.items():
        assert sorted(np.floor(u * n).astype(int)) == list(range(n)), key


def test_distribution_bounds_and_moments(write_sweep):
    c = _columns(write_sweep(SAMPLED.format(n=4000, design="random", seed=1)))
    leakoff = c["rock.leakoff_coefficient"]
    assert leakoff.min() >= 1e-7 and leakoff.max() <= 1e-5
    assert np.mean(np.log10(leakoff)) == pytest.approx(-6.0, abs=0.05)   # uniform in the logarithm
    assert np.mean(c["rock.layers[0].min_stress"]) == pytest.approx(65e6, abs=0.1e6)
    assert np.std(c["rock.layers[0].min_stress"]) == pytest.approx(1e6, rel=0.05)
    toughness = c["rock.toughness"]
    assert toughness.min() >= 0.5e6 and toughness.max() <= 2e6
    assert np.mean(toughness) == pytest.approx((0.5e6 + 1e6 + 2e6) / 3, rel=0.02)
    assert set(c["fluid.viscosity"]) == {0.01, 0.08, 0.2}


def test_grid_is_every_combination(write_sweep):
    path = write_sweep('design = "grid"\n[[vary]]\nkey = "rock.min_stress"\nvalues = ["60 MPa", "61 MPa", '
                       '"62 MPa"]\n[[vary]]\nkey = "fluid.viscosity"\nvalues = [0.01, "20 cP"]\n'
                       '[[vary]]\nkey = "output.every"\nvalues = ["30 s", "1 min"]\n')
    sweep = load_sweep(path)
    assert sweep.members == 12
    rows = member_inputs(sweep)
    combos = [tuple(r.values()) for r in rows]
    assert combos == list(itertools.product([60e6, 61e6, 62e6], [0.01, 0.02], [30.0, 60.0]))


def test_same_file_and_seed_give_the_same_members(write_sweep):
    first = members(load_sweep(write_sweep(SAMPLED.format(n=8, design="latin-hypercube", seed=7))))
    again = members(load_sweep(write_sweep(SAMPLED.format(n=8, design="latin-hypercube", seed=7), name="b.toml")))
    other = members(load_sweep(write_sweep(SAMPLED.format(n=8, design="latin-hypercube", seed=8), name="c.toml")))
    assert [m.inputs for m in first] == [m.inputs for m in again]
    assert [m.scene_text.split("\n", 1)[1] for m in first] == [m.scene_text.split("\n", 1)[1] for m in again]
    assert [m.inputs for m in first] != [m.inputs for m in other]
    assert [m.id for m in first] == [f"{i:04d}" for i in range(8)]


def test_integer_values_stay_integers(write_sweep):
    path = write_sweep('design = "grid"\n[[vary]]\nkey = "run.seed"\nvalues = [1, 2]\n')
    built = members(load_sweep(path))
    assert [m.inputs["run.seed"] for m in built] == [1, 2]
    assert "seed = 2\n" in built[1].scene_text
