"""Closed-form checks of the closure model: Kozeny-Carman on a uniform pack, table interpolation, exact solid
volume of the propped cells, the settling rules and the grain-mix rule."""

import math

import numpy as np
import pytest
from closure_fakes import FRAME, NX, NZ, box_text, cell_centres, join, parcels, snapshot

from hfgpu.closure.config import ConductivityTable
from hfgpu.closure.conductivity import close
from hfgpu.closure.pack import propped_width, settle
from hfgpu.closure.permeability import interpolate_log, kozeny_carman, table_permeability
from hfgpu.scene import load_scene

AREA = FRAME.dx * FRAME.dz
D = 200e-6
GRAIN = math.pi / 6 * D**3


def uniform_pack(width: float, fraction: float = 0.6, diameter: float = D) -> dict:
    """One parcel per cell holding exactly the grains of a pack of ``width`` at solid ``fraction``."""
    x, z = cell_centres()
    n = fraction * width * AREA / (math.pi / 6 * diameter**3)
    return parcels(x, z, diameter, n)


def test_uniform_pack_gives_kozeny_carman_to_round_off():
    scene = load_scene(box_text())
    result = close(snapshot(uniform_pack(0.004)), scene)
    phi = 0.4
    k = D**2 * phi**3 / (180 * (1 - phi) ** 2)
    assert result.labels["permeability_model"] == "kozeny-carman"
    np.testing.assert_allclose(result.fields["permeability"], k, rtol=1e-14)
    np.testing.assert_allclose(result.fields["propped_width"], 0.004, rtol=1e-14)
    np.testing.assert_allclose(result.fields["conductivity"], k * 0.004, rtol=1e-14)
    np.testing.assert_allclose(result.fields["sauter_diameter"], D, rtol=1e-14)
    s = result.scalars
    assert s["propped_area"] == pytest.approx(NX * NZ * AREA)
    assert s["propped_half_length"] == pytest.approx(NX * FRAME.dx / 2)
    assert s["propped_height"] == pytest.approx(NZ * FRAME.dz)
    assert s["mean_conductivity"] == pytest.approx(k * 0.004, rel=1e-14)
    assert math.isnan(s["fcd"])


def test_kozeny_carman_values():
    assert kozeny_carman(1e-3, 0.4) == pytest.approx(1e-6 * 0.064 / (180 * 0.36))
    np.testing.assert_allclose(kozeny_carman(np.array([1e-4, 2e-4]), 0.35),
                               np.array([1, 4]) * kozeny_carman(1e-4, 0.35))


def test_table_interpolation_reproduces_nodes_and_is_monotone():
    psi = 6894.757293168361
    table = ConductivityTable(stress=(2000 * psi, 4000 * psi, 6000 * psi, 8000 * psi),
                              value=(4000.0, 2500.0, 1200.0, 400.0))
    np.testing.assert_allclose(interpolate_log(table, np.array(table.stress)), table.value, rtol=1e-14)
    stress = np.linspace(0, 10000 * psi, 2001)
    values = interpolate_log(table, stress)
    assert np.all(np.diff(values) <= 0)
    assert values[0] == pytest.approx(4000) and values[-1] == pytest.approx(400)  # held at the end nodes
    mid = interpolate_log(table, np.array([3000 * psi]))[0]
    assert mid == pytest.approx(math.sqrt(4000 * 2500))  # log-linear: the geometric mean half-way


def test_table_permeability_from_lab_pack_width():
    table = ConductivityTable(stress=(1e7,), value=(1e-12,))
    k = table_permeability(table, np.array([1e7]), density=2650.0, loading=9.765, pack_fraction=0.6)
    assert k[0] == pytest.approx(1e-12 / (9.765 / (2650.0 * 0.6)))
    permeability = ConductivityTable(stress=(1e7,), value=(2e-10,), is_permeability=True)
    assert table_permeability(permeability, np.array([5e6]), 2650.0, 9.765, 0.6)[0] == pytest.approx(2e-10, rel=1e-14)


@pytest.mark.parametrize("rule", ["in_place", "bed"])
def test_solid_volume_of_propped_cells_is_exact(rule):
    rng = np.random.default_rng(7)
    n = 60
    arrays = parcels(rng.uniform(0, NX * FRAME.dx, n), rng.uniform(0, NZ * FRAME.dz, n),
                     rng.choice([1e-4, 2e-4, 4e-4], n), rng.uniform(1e2, 6e3, n))
    arrays["v"] = rng.choice([0.0, 0.02], n)
    snap = snapshot(arrays)
    pack = settle(snap, 1, rule, 0.6)
    assert pack.solid.sum() == pytest.approx(np.sum(arrays["particles"] * math.pi / 6 * (2 * arrays["radius"])**3),
                                             rel=1e-12)
    w_p, propped = propped_width(pack, AREA, 0.6, width=snap.grid["width"])
    assert 0 < propped.sum() < propped.size
    assert pack.solid[propped].sum() == pytest.approx(np.sum(w_p * AREA * 0.6), rel=1e-13)
    assert np.all(w_p[~propped] == 0)


def test_bed_settles_suspension_to_the_bottom_of_its_column():
    width = 0.005
    full = 0.6 * width * AREA / GRAIN  # grains filling one cell
    x0 = FRAME.x0
    arrays = join(parcels(x0, FRAME.z0, D, 1.5 * full, moving=True),             # suspended in the top cell
                  parcels(x0 + FRAME.dx, FRAME.z0, D, 0.5 * full))              # packed: stays
    pack = settle(snapshot(arrays, width=width), 1, "bed", 0.6)
    filled = pack.solid / (0.6 * width * AREA)
    np.testing.assert_allclose(filled[:, 0], [0, 0, 0.5, 1.0], atol=1e-12)
    np.testing.assert_allclose(filled[:, 1], [0.5, 0, 0, 0], atol=1e-12)
    in_place = settle(snapshot(arrays, width=width), 1, "in_place", 0.6).solid / (0.6 * width * AREA)
    np.testing.assert_allclose(in_place[:, 0], [1.5, 0, 0, 0], atol=1e-12)


def test_bed_keeps_what_the_column_cannot_hold():
    full = 0.6 * 0.005 * AREA / GRAIN
    arrays = parcels(FRAME.x0, FRAME.z0, D, 5.0 * full, moving=True)
    filled = settle(snapshot(arrays), 1, "bed", 0.6).solid / (0.6 * 0.005 * AREA)
    np.testing.assert_allclose(filled[:, 0], [1 + 1, 1, 1, 1], atol=1e-12)


def test_partial_monolayer_is_unpropped():
    x, z = cell_centres()
    half_layer = 0.5 * 0.6 * D * AREA / GRAIN   # grains of half a packed layer
    result = close(snapshot(parcels(x, z, D, half_layer)), load_scene(box_text('[closure]\nsettling = "in_place"')))
    assert result.scalars["propped_area"] == 0.0
    assert np.all(result.fields["conductivity"] == 0)


def test_grain_mix_sauter_mean_and_tables():
    x, z = cell_centres()
    small, large = 1e-4, 4e-4
    arrays = join(parcels(x, z, small, 0.3 * 0.004 * AREA / (math.pi / 6 * small**3)),
                  parcels(x, z, large, 0.3 * 0.004 * AREA / (math.pi / 6 * large**3), class_id=1))
    second = '[[proppant]]\nname = "coarse"\ndensity = "2650 kg/m**3"\ndiameter = "400 um"\n'
    scene = load_scene(box_text('[closure]\nsettling = "in_place"', "").replace("[mppic]", second + "[mppic]"))
    result = close(snapshot(arrays), scene)
    d32 = 1.0 / (0.5 / small + 0.5 / large)
    np.testing.assert_allclose(result.fields["sauter_diameter"], d32, rtol=1e-13)
    np.testing.assert_allclose(result.fields["permeability"], kozeny_carman(d32, 0.4), rtol=1e-13)
    tables = second + 'conductivity = [{ stress = "1000 psi", value = "200 darcy" }]\nconductivity_factor = 0.5\n'
    text = box_text('[closure]\nsettling = "in_place"\nclosure_stress = "3000 psi"',
                    'conductivity = [{ stress = "1000 psi", value = "50 darcy" }]')
    scene = load_scene(text.replace("[mppic]", tables + "[mppic]"))
    result = close(snapshot(arrays), scene)
    darcy = 9.869232667160130e-13
    expected = math.sqrt(50 * darcy * 200 * darcy) * math.sqrt(0.5)
    assert result.labels["permeability_model"] == "table"
    np.testing.assert_allclose(result.fields["permeability"], expected, rtol=1e-12)


def test_closure_stress_from_layers_and_pore_pressure():
    rock = """
[rock]
youngs_modulus = "20 GPa"
poisson_ratio = 0.2
min_stress = "30 MPa"
pore_pressure = "10 MPa"
[[rock.layers]]
top = "0 m"
bottom = "0.02 m"
min_stress = "40 MPa"
pore_pressure = "12 MPa"
"""
    scene = load_scene(box_text() + rock)
    result = close(snapshot(uniform_pack(0.004)), scene)
    stress = result.fields["closure_stress"]
    # the shallowest layer extends upward and the deepest downward (hfgpu.scene.Rock): one layer covers all
    np.testing.assert_allclose(stress, 28e6)
    layers = rock + '[[rock.layers]]\ntop = "0.02 m"\nbottom = "1 m"\nmin_stress = "35 MPa"\n'
    stress = close(snapshot(uniform_pack(0.004)), load_scene(box_text() + layers)).fields["closure_stress"]
    np.testing.assert_allclose(stress[:, 0], [28e6, 28e6, 25e6, 25e6])


def test_embedment_takes_width_from_both_faces():
    scene = load_scene(box_text('[closure]\nembedment = "0.1 mm"'))
    result = close(snapshot(uniform_pack(0.004)), scene)
    np.testing.assert_allclose(result.fields["propped_width"], 0.004 - 2e-4, rtol=1e-13)


def test_fcd_with_formation_permeability():
    scene = load_scene(box_text('[closure]\nformation_permeability = "0.1 md"'))
    s = close(snapshot(uniform_pack(0.004)), scene).scalars
    assert s["fcd"] == pytest.approx(s["mean_conductivity"] / (0.1 * 9.869232667160130e-16 * s["propped_half_length"]))
