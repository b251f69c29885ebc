"""Radial fractures of the paper's Table 2 against Dontsov's (2016) universal radial solution and the
vertex closed forms (Savitski & Detournay 2002; Dontsov 2016), via hfgpu.reference.radial.

Default runs are coarse (about 20-25 cells across the final diameter); tolerances reflect that. The
refinement series and the 2 % (radius) / 5 % (inlet width) goals are marked slow. R is the front's mean
radius (the summary's ``radius``); R_area = sqrt(area / pi), the radius of the footprint's area with tip cells
counted by their filled fraction (geometry.py).
"""

import dataclasses
import math

import pytest

from hfgpu.fracture.simulator import simulate
from hfgpu.records import MemorySink
from hfgpu.reference.radial import dontsov_radial, k_vertex, m_vertex
from hfgpu.scene import Mesh, load_scene

from .helpers import SCENES


def run_case(name: str, cell: float | None = None, **numerics):
    sc = load_scene(SCENES / f"radial_{name}.toml")
    if cell is not None:
        sc = sc.replace(mesh=Mesh(cell, cell))
    if numerics:
        sc = sc.replace(fracture=dataclasses.replace(sc.fracture, **numerics))
    sink = MemorySink()
    out = simulate(sc, sink)
    rock = sc.rock
    e_prime, mu_prime = rock.plane_strain_modulus, 12 * sc.fluid.viscosity
    k_prime, c_prime = math.sqrt(32 / math.pi) * rock.toughness, 2 * rock.leakoff_coefficient
    q, t = sc.injection.schedule.stages[0].rate, sc.run.end_time
    ref = dontsov_radial(e_prime, k_prime, mu_prime, c_prime, q, t)
    errors = dict(R=out["radius"] / ref.R[-1] - 1, w0=out["w_inlet"] / ref.w0[-1] - 1,
                  R_min=out["radius_min"] / ref.R[-1] - 1, R_max=out["radius_max"] / ref.R[-1] - 1,
                  R_area=out["area_radius"] / ref.R[-1] - 1)
    return out, sink, errors, (e_prime, mu_prime, k_prime, q, t)


def test_case_I_storage_viscosity_coarse():
    out, sink, err, (e, mu, k, q, t) = run_case("I")            # 5 m cells, ~22 across
    # measured: front's mean radius +0.22 %, from the area -0.73 % (the edge cells counted by the part behind
    # the front reconstructed from their widths, geometry.py), w0 +0.67 %
    assert abs(err["R"]) < 0.06 and abs(err["R_area"]) < 0.015 and abs(err["w0"]) < 0.04, err
    vertex = m_vertex(e, mu, q, t)                                 # the case sits at the M vertex
    assert out["radius"] == pytest.approx(float(vertex.R), rel=0.06)
    assert out["max_balance_error"] < 1e-3


def test_case_III_storage_toughness_coarse():
    out, sink, err, (e, mu, k, q, t) = run_case("III")          # 0.25 m cells, ~22 across
    assert abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.06, err
    assert abs(err["R_area"]) < 0.03, err                          # measured -2.02 %
    vertex = k_vertex(e, k, q, t)
    assert out["w_inlet"] == pytest.approx(float(vertex.w0), rel=0.07)
    assert out["max_balance_error"] < 1e-3


def test_case_II_leakoff_viscosity_coarse():
    # measured R +3.6 %, w0 -4.4 % at 0.5 m cells (~11 per final radius) with the leak-off clock (leakoff.py);
    # without it R +8.0 %, w0 -3.0 %: cells held dry by the ramp lost their Carter exposure for good
    out, sink, err, _ = run_case("II", front_tracking="cells")
    assert abs(err["R"]) < 0.05 and abs(err["R_area"]) < 0.05 and abs(err["w0"]) < 0.05, err   # R_area +3.36 %
    assert out["max_balance_error"] < 1e-3


@pytest.mark.slow
def test_case_II_refinement_reduces_the_radius_error_to_the_goal():
    # measured R +3.50 / +2.65 / +2.35 %, w0 -4.35 / -3.41 / -3.09 % at 0.5 / 0.35 / 0.25 m cells with the
    # dense solver; at 0.25 m +1.38 % with Newton-Krylov throughout and +2.97 % with "auto" (dense, then
    # Newton-Krylov from 360 cells). The whole-cell front's radius at 0.25 m depends on the solver's path: widths
    # that differ by Newton's tolerance (or the volume-conserving shift's 1e-14 m) open a ring of cells a step
    # earlier or later (docs/validation.md, note 3), so the bound is the upper end of that spread
    errors = [run_case("II", cell, front_tracking="cells", linear_solver="direct")[2] for cell in (0.5, 0.35, 0.25)]
    r = [abs(e["R"]) for e in errors]
    assert r[0] > r[1] > r[2], errors
    assert r[2] < 0.03 and abs(errors[2]["w0"]) < 0.05, errors


@pytest.mark.slow
def test_case_I_refinement_reduces_the_radius_error():
    # with the fluid velocity in the tip asymptote the error falls with the cell (+4.2 / +3.9 / +3.3 %); the
    # default "front" velocity is within 2 % on all three grids but flat (-0.2 / +0.8 / +0.8 %)
    errors = [run_case("I", cell, tip_velocity="fluid")[2] for cell in (5.0, 3.5, 2.5)]
    r = [abs(e["R"]) for e in errors]
    assert r[0] > r[1] > r[2], errors
    assert all(abs(e["w0"]) < 0.03 for e in errors), errors


@pytest.mark.slow
def test_case_III_fine_meets_the_goal():
    # measured R -0.85 % (front min/max -7.7 / +3.4 %), w0 +1.7 % at 0.18 m cells, no step retries (0.25 m:
    # -1.2 % / +2.1 %; 0.125 m: -1.5 % / +4.0 %: within the goal, but not a series with falling error)
    _, _, err, _ = run_case("III", 0.18)
    assert abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.05, err


def test_case_I_meets_the_goal_coarse():
    # tip_velocity = "front" (default): V of the viscous asymptote at least Eq. 34's front speed (measured:
    # R -0.2 %, min/max front -6.3 / +4.3 %, w0 +1.2 % at 5 m cells; "fluid" gives R +4.2 %)
    _, _, err, _ = run_case("I")
    assert abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.05, err


@pytest.mark.slow
def test_case_I_meets_the_goal_on_finer_grids():
    # measured R +0.76 % / +0.77 %, w0 +0.29 % / +0.46 % at 3.5 / 2.5 m cells: within the goal, but the
    # radius error does not fall further with refinement (see the report)
    for cell in (3.5, 2.5):
        _, _, err, _ = run_case("I", cell)
        assert abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.05, (cell, err)


@pytest.mark.slow
@pytest.mark.xfail(reason="cell-by-cell front: II radius +3.5 % at 0.5 m cells (+1.8 % at 0.25 m, see above); IV "
                          "radius +0.7 % but the inlet width swings by tens of % (-70 % to +50 %) as whole rings of "
                          "cells open (efficiency ~0.8 %: the stored volume is the small difference of injection "
                          "and leak-off). The sub-grid front meets both (test_subgrid_front.py; the IV scene "
                          "uses it)", strict=False)
@pytest.mark.parametrize("name", ["II", "IV"])
def test_leakoff_cases_meet_the_goal_with_the_cell_by_cell_front(name):
    _, _, err, _ = run_case(name, front_tracking="cells")
    assert abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.05, err


def test_case_IV_leakoff_toughness_finishes_with_the_balance_with_the_cell_by_cell_front():
    # Newton used to fail at front cells mid-run (a line search on ||F||, and just-opened cells started at
    # w = 0); now the coarse run (3.5 cm cells, ~11 per final radius) finishes (one step retry). Measured with
    # the leak-off clock: R +7.3 % (front min/max +0.3 / +16.9 %), w0 +44 % (2 cm cells: R +0.7 %, w0 -57 %;
    # without the clock R +12.1 % / +10.5 %, w0 -71 % / -71 %): the stored volume (efficiency ~0.8 %) swings
    # as whole rings of cells open, see above.
    out, _, err, _ = run_case("IV", 0.035, front_tracking="cells")
    assert out["time"] == pytest.approx(407.0) and out["max_balance_error"] < 1e-9
    assert abs(err["R"]) < 0.10, err
