"""``[completion]`` (hfgpu.completion) and the perforation friction and wellbore node (hfgpu.perforations):
the formula against a hand computation in field units, the node's split against algebraic solutions, the bad
input refused before any work."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hfgpu.errors import SceneError
from hfgpu.perforations import (K_BERNOULLI, K_FIELD, K_SI, Entry, entry_coefficient, field_constant,
                                perforation_friction, split_rate)
from hfgpu.scene import load_scene
from hfgpu.units import convert

FIELD_SCENE = """
[run]
end_time = "600 s"
[rock]
youngs_modulus = "4e6 psi"
poisson_ratio = 0.25
min_stress = "6000 psi"
[[rock.layers]]
top = "7900 ft"
bottom = "8100 ft"
min_stress = "6000 psi"
[fluid]
viscosity = "10 cP"
density = "8.34 lb/gal"
[injection]
depth = "8000 ft"
schedule = [{ until = "600 s", rate = "60 bbl/min" }]
[mesh]
cell_size = "10 ft"
"""


def completion(text: str):
    return load_scene(FIELD_SCENE + "[completion]\n" + text)


def test_the_perforation_friction_is_the_field_formula_by_hand():
    """60 bbl/min of 8.34 lb/gal water through 6 holes of 0.42 in, C_d 0.8, in field units by hand:
    0.2369 x 8.34 x 60^2 / (6^2 x 0.42^4 x 0.8^2) = 9 921 psi (all of it through one cluster)."""
    by_hand = 0.2369 * 8.34 * 60.0**2 / (6**2 * 0.42**4 * 0.8**2)   # psi
    si = perforation_friction(convert(60.0, "bbl/min", "m**3/s"), convert(8.34, "lb/gal", "kg/m**3"), 6,
                              convert(0.42, "in", "m"), 0.8)
    assert convert(float(si), "Pa", "psi") == pytest.approx(by_hand, rel=1e-3)
    assert field_constant(K_SI) == pytest.approx(K_FIELD, rel=1e-12)
    # the Bernoulli orifice constant is 8 / pi^2, 0.23764 in field units: the published 0.2369 is 0.31 % lower
    assert field_constant(K_BERNOULLI) == pytest.approx(0.23764, abs=1e-5)
    assert K_SI / K_BERNOULLI == pytest.approx(0.99690, abs=1e-5)


def test_n_identical_clusters_split_the_rate_equally():
    q, a = 0.16, entry_coefficient(1000.0, 6, 0.0107, 0.8)
    entries = [Entry(pressure=40e6, slope=2e7, rate=q / 5)] * 5
    rates, p_w = split_rate(q, entries, [a] * 5)
    np.testing.assert_allclose(rates, q / 5, rtol=1e-10)
    assert p_w == pytest.approx(40e6 + a * (q / 5) ** 2, rel=1e-12)


def test_two_clusters_of_different_stress_split_as_equal_wellbore_pressure_says():
    """Entry pressures sigma_i + s q (no shadow) and friction a q^2: p_w equal gives
    sigma_1 + s q_1 + a q_1^2 = sigma_2 + s q_2 + a q_2^2 with q_2 = Q - q_1, so
    (q_1 - q_2) (s + a Q) = sigma_2 - sigma_1 (the q^2 terms differ by a (q_1 - q_2) Q)."""
    q, a, s = 0.1, entry_coefficient(1000.0, 8, 0.0107, 0.7), 5e7
    sigma = (40e6, 40.5e6)
    rates, p_w = split_rate(q, [Entry(sigma[0], s, 0.0), Entry(sigma[1], s, 0.0)], [a, a])
    difference = (sigma[1] - sigma[0]) / (s + a * q)
    assert rates[0] - rates[1] == pytest.approx(difference, rel=1e-9)
    assert rates.sum() == pytest.approx(q, rel=1e-14)
    for i in range(2):
        assert p_w == pytest.approx(sigma[i] + s * rates[i] + a * rates[i] ** 2, rel=1e-12)


def test_a_cluster_the_wellbore_pressure_cannot_open_takes_nothing():
    rates, p_w = split_rate(0.05, [Entry(40e6, 1e8), Entry(60e6, 1e8)], [0.0, 0.0])
    assert rates[1] == 0.0 and rates[0] == pytest.approx(0.05) and p_w == pytest.approx(40e6 + 5e6)


def test_the_completion_table_reads_field_units():
    scene = completion('clusters = 5\nspacing = "50 ft"\nperforations = 6\nperforation_diameter = "0.42 in"\n'
                       'discharge_coefficient = 0.8\n'
                       'stress_offsets = ["0 psi", "0 psi", "100 psi", "0 psi", "0 psi"]\n')
    c = scene.completion
    assert c.clusters == 5 and c.limited_entry and c.perforations == (6,) * 5
    np.testing.assert_allclose(c.positions, np.arange(5) * 50 * 0.3048)
    assert c.perforation_diameter[0] == pytest.approx(0.42 * 0.0254)
    assert c.offsets()[2] == pytest.approx(convert(100.0, "psi", "Pa"))
    listed = completion('positions = ["0 ft", "60 ft", "100 ft"]\n').completion
    assert listed.positions[1] == pytest.approx(60 * 0.3048) and not listed.limited_entry
    assert not listed.entry_coefficients(1000.0).any()


@pytest.mark.parametrize("text, key, said", [
    ('clusters = 3\nspacing = "50 ft"\nperforations = 0\nperforation_diameter = "0.4 in"\ndischarge_coefficient = 0.8',
     "completion.perforations", "allowed: >= 1"),
    ('clusters = 3\nspacing = "50 ft"\nperforations = 6\nperforation_diameter = "0 in"\ndischarge_coefficient = 0.8',
     "completion.perforation_diameter", "'0 in'"),
    ('clusters = 3\nspacing = "50 ft"\nperforations = 6\nperforation_diameter = "0.4 in"\ndischarge_coefficient = 1.2',
     "completion.discharge_coefficient", "<= 1"),
    ('clusters = 3\nspacing = "50 ft"\nperforations = 6\nperforation_diameter = "0.4 in"\ndischarge_coefficient = 0',
     "completion.discharge_coefficient", "> 0"),
    ('positions = ["0 ft", "50 ft", "50 ft"]', "completion.positions[2]", "must not overlap"),
    ('clusters = 3\nspacing = "1e-12 m"', "completion.spacing", "must not overlap"),
    ('clusters = 3\nspacing = "1e300 m"', "completion.spacing", "span more than"),
    ('clusters = 1000000000000000000\nspacing = "50 ft"', "completion.clusters", "<= 50"),
    ('clusters = 2\nspacing = "50 ft"\nperforations = 6\nperforation_diameter = "1e-100 m"\n'
     'discharge_coefficient = 0.8', "completion.perforation_diameter", "finite"),
    ('clusters = 3\nspacing = "0 ft"', "completion.spacing", "> 0"),
    ('clusters = 2\nspacing = "50 ft"\nperforations = [6, 6, 6]\nperforation_diameter = "0.4 in"\n'
     'discharge_coefficient = 0.8', "completion.perforations", "one value per cluster (2)"),
    ('clusters = 2\nspacing = "50 ft"\nperforations = 6', "completion.perforation_diameter", "required"),
])
def test_bad_completions_are_one_line_errors(text, key, said):
    with pytest.raises(SceneError) as error:
        completion(text)
    assert error.value.path == key and said in str(error.value) and "\n" not in str(error.value)


def test_clusters_outside_the_layer_table_are_refused():
    text = FIELD_SCENE.replace('depth = "8000 ft"', 'depth = "9000 ft"')
    text += '[completion]\nclusters = 2\nspacing = "60 ft"\n'
    with pytest.raises(SceneError) as error:
        load_scene(text)
    assert error.value.path == "completion.clusters" and "outside the layer table" in str(error.value)


def test_clusters_closer_than_two_cells_are_warned_about():
    scene = completion('clusters = 2\nspacing = "15 ft"\n')
    said = [w for w in scene.warnings if w.startswith("completion:")]
    assert len(said) == 1 and "closer than 2 cells" in said[0] and "15 ft" in said[0]
    assert not [w for w in completion('clusters = 2\nspacing = "25 ft"\n').warnings if w.startswith("completion")]


def test_several_clusters_are_refused_with_a_coarsened_grid():
    with pytest.raises(SceneError) as error:
        load_scene(FIELD_SCENE.replace('cell_size = "10 ft"', 'cell_size = "10 ft"\nmax_cells_across = 40')
                   + '[completion]\nclusters = 2\nspacing = "60 ft"\n')
    assert error.value.path == "mesh.max_cells_across"


def test_a_stage_needs_the_fracture():
    text = FIELD_SCENE.replace('[run]\nend_time = "600 s"', '[run]\nend_time = "600 s"\nphysics = ["proppant"]')
    with pytest.raises(SceneError) as error:
        load_scene(text + '[completion]\nclusters = 2\nspacing = "60 ft"\n')
    assert any(e.path == "completion" and "physics" in e.allowed for e in getattr(error.value, "errors", [error.value]))


def test_a_completion_runs_the_stage():
    from hfgpu.simulators import simulator_module

    assert simulator_module(completion("clusters = 1\n")) == "hfgpu.fracture.stage"
    assert simulator_module(load_scene(FIELD_SCENE)) == "hfgpu.fracture.simulator"
