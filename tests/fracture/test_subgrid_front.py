"""Sub-grid front (``front_tracking = "subgrid"``, hfgpu.fracture.tip_cells): level set, tip cells' fill and
width, pinned widths in Newton, and the radial cases of the paper's Table 2 against Dontsov (2016)."""

import dataclasses

import numpy as np
import pytest

from hfgpu.fracture.elasticity import ElasticityOperator
from hfgpu.fracture.front import TipModel, edge_cells
from hfgpu.fracture.lubrication import build_faces
from hfgpu.fracture.newton import Elasticity, StepProblem, solve_step
from hfgpu.fracture.tip_cells import fill_and_width, level_set, ribbon_distances

from .test_radial_validation import run_case


def _plane_front(angle_deg: float, h: float = 1.0, n: int = 14):
    x, z = np.meshgrid(np.arange(n) * h, np.arange(n) * h)
    normal = np.array([np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))])
    d = x * normal[0] + z * normal[1] - 9.0 * h          # signed distance to the plane, negative inside
    channel = d < -0.75 * h
    return d, channel, normal


@pytest.mark.parametrize("angle", [0.0, 30.0, 45.0])
def test_level_set_of_a_plane_front(angle):
    """Ribbon distances of a plane front: the eikonal update is exact where both an x- and a z-ribbon
    neighbour are known and the front's normal is then exact; first order ((1 - cos) h) elsewhere."""
    d, channel, normal = _plane_front(angle)
    s = np.where(edge_cells(channel), -d, np.nan)
    advance, nx, nz, _ = level_set(s, channel, 1.0, 1.0)
    cand = np.isfinite(advance)
    assert cand.sum() > 5
    ds = np.where(np.isfinite(s), -s, np.inf)
    a = np.minimum(np.roll(ds, 1, axis=1), np.roll(ds, -1, axis=1))   # smallest d of the x-neighbours
    b = np.minimum(np.roll(ds, 1, axis=0), np.roll(ds, -1, axis=0))
    with np.errstate(invalid="ignore"):
        exact = cand & np.isfinite(a) & np.isfinite(b) & (np.abs(a - b) < 1.0)   # the two-neighbour update holds
    if angle > 0.0:
        assert exact.any()
        np.testing.assert_allclose(advance[exact], -d[exact], atol=1e-12)
        np.testing.assert_allclose(nx[exact], normal[0], atol=1e-12)
        np.testing.assert_allclose(nz[exact], normal[1], atol=1e-12)
    assert np.max(np.abs(advance[cand] + d[cand])) <= (1.0 - np.cos(np.radians(angle))) + 1e-12


def test_fill_and_width_of_a_straight_toughness_front():
    """Front normal to x, a = h/4 past the centre: 3/4 of the cell wetted; the mean of the K asymptote
    (K'/E') s^(1/2) over the wetted part, (2/3) (K'/E') l^(3/2) / h with l = 3h/4 (midpoint rule: 1 %)."""
    model = TipModel(e_prime=1e10, mu_prime=1e-3, mode="olson")
    k, h = 1e6, 0.1
    fill, width = fill_and_width(model, np.array([0.25 * h]), np.array([1.0]), np.array([0.0]), np.array([k]),
                                 np.array([0.0]), np.array([0.0]), h, h)
    assert fill[0] == pytest.approx(0.75)
    assert width[0] == pytest.approx(2 / 3 * k / 1e10 * (0.75 * h) ** 1.5 / h, rel=1e-2)


def test_ribbon_distance_inverts_the_toughness_asymptote_without_olson():
    """A ribbon cell of width w is s = (w E' / K')^2 from the front (K asymptote, no 0.806)."""
    model = TipModel(e_prime=1e10, mu_prime=1e-3, mode="olson")
    channel = np.zeros((5, 5), bool)
    channel[1:4, 1:4] = True
    w = np.where(channel, 2e-5, 0.0)
    k = np.full(w.shape, 1e6)
    s, _ = ribbon_distances(model, channel, w, np.zeros(w.shape), k, np.zeros(w.shape), np.zeros(w.shape), 1.0,
                            0.05, 0.05)
    assert np.isnan(s[2, 2]) and np.isfinite(s[1, 1])
    assert s[1, 1] == pytest.approx((2e-5 * 1e10 / 1e6) ** 2)


def test_pinned_cells_keep_their_width_and_the_volume_balance():
    """Tip cells enter Newton with their width prescribed and their fluid pressure as the unknown: the
    step keeps their widths and conserves volume (injected = stored + leaked)."""
    ix, iz = np.meshgrid(np.arange(-3, 4), np.arange(-3, 4))
    keep = ix**2 + iz**2 <= 9
    ix, iz = ix[keep].astype(np.int64), iz[keep].astype(np.int64)
    op = ElasticityOperator(1.0, 1.0, 3.2e10)
    r = np.hypot(ix, iz)
    w_old = 1e-3 * np.sqrt(np.clip(1 - (r / 3.5) ** 2, 0, None))
    edge = r > 2.5
    pinned = np.where(edge, 1.2 * w_old, np.nan)
    wetted = np.where(edge, 0.5, 1.0)
    demand = np.full(ix.size, 1e-5)
    prob = StepProblem(ix, iz, w_old, np.full(ix.size, 1e7), build_faces(ix, iz, 1.0, 1.0, 12.0), 1.0, 5.0,
                       np.where((ix == 0) & (iz == 0), 5e-3, 0.0), demand, 0.01 * demand, 0.0, pinned, wetted)
    res = solve_step(prob, Elasticity(op, ix, iz, True), 1e-9, 30)
    assert res.converged
    np.testing.assert_allclose(res.w[edge], pinned[edge], rtol=1e-14)
    assert res.w.sum() - w_old.sum() + res.leaked.sum() == pytest.approx(5e-3, rel=1e-8)
    # the wetted fraction halves the tip cells' leak-off
    assert res.leaked[edge] == pytest.approx(0.5 * demand[edge], rel=1e-6)


def _subgrid(name, cell=None):
    return run_case(name, cell, front_tracking="subgrid")


@pytest.mark.parametrize("name, tol_r, tol_w", [("I", 0.02, 0.02), ("III", 0.02, 0.05)])
def test_subgrid_front_storage_cases(name, tol_r, tol_w):
    # measured: I (5 m cells) R +0.50 % (front min/max -0.5 / +1.6 %), w0 +0.02 %; III (0.25 m cells)
    # R -1.4 % (-4.3 / +0.8 %), w0 +2.7 %
    out, _, err, _ = _subgrid(name)
    assert abs(err["R"]) < tol_r and abs(err["w0"]) < tol_w, err
    assert out["max_balance_error"] < 1e-9


@pytest.mark.slow
def test_subgrid_front_leakoff_viscosity_meets_the_goal():
    # measured at 0.5 m cells: R +1.65 %, w0 -1.9 % (cell-by-cell front: +3.6 %, -4.4 %)
    out, _, err, _ = _subgrid("II")
    assert abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.05, err
    assert out["max_balance_error"] < 1e-9


@pytest.mark.slow
def test_subgrid_front_leakoff_toughness():
    """Case IV (2 cm cells): measured R +0.97 % (front min/max -1.0 / +2.4 %), w0 -9.2 % -- the goal's 5 % on
    w(0) is not met (the cell-by-cell front: R +0.7 %, w0 -57 %); the stored volume is 0.7 % of the injected,
    and w0 still dips by 20-26 % for a step when many cells are crossed at once."""
    out, _, err, _ = _subgrid("IV")
    assert abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.10, err
    assert out["max_balance_error"] < 1e-9


def test_subgrid_front_through_a_coarsening_with_snapshots_at_every_step():
    """Right after a 3x3 coarsening every cell is a channel cell (no tip cells yet): the front summary of a
    snapshot taken then falls back to the channel's edge (it used to fail on an empty set). Case I on 5 m cells
    coarsened at 12 cells across (15 m cells, ~3.5 per final radius), 200 snapshots: finishes, volume balance
    exact, radius within 8 % of Dontsov (measured -5.8 %)."""
    from hfgpu.fracture.simulator import simulate
    from hfgpu.records import MemorySink
    from hfgpu.reference.radial import dontsov_radial
    from hfgpu.scene import Mesh, load_scene

    from .helpers import SCENES

    sc = load_scene(SCENES / "radial_I.toml")
    sc = sc.replace(mesh=Mesh(5.0, 5.0, max_cells_across=12),
                    fracture=dataclasses.replace(sc.fracture, front_tracking="subgrid"),
                    output=dataclasses.replace(sc.output, every=sc.run.end_time / 200))
    out = simulate(sc, MemorySink())
    assert out["coarsenings"] >= 1 and out["max_balance_error"] < 1e-9
    rock = sc.rock
    ref = dontsov_radial(rock.plane_strain_modulus, np.sqrt(32 / np.pi) * rock.toughness, 12 * sc.fluid.viscosity,
                         2 * rock.leakoff_coefficient, sc.injection.schedule.stages[0].rate, sc.run.end_time)
    assert out["radius"] == pytest.approx(ref.R[-1], rel=0.08)
