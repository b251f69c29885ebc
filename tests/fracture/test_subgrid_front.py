"""Sub-grid front (``front_tracking = "subgrid"``, hfgpu.fracture.tip_cells): level set, tip cells' fill and
width, pinned widths in Newton, and the radial cases of the paper's Table 2 against Dontsov (2016)."""

import dataclasses

import numpy as np
import pytest

from hfgpu.fracture.elasticity import ElasticityOperator
from hfgpu.fracture.front import TipModel, edge_cells
from hfgpu.fracture.lubrication import build_faces
from hfgpu.fracture.newton import Elasticity, StepProblem, solve_step
from hfgpu.fracture.tip_cells import fill_and_width, level_set, ribbon_distances, wetted_fraction

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
    advance, nx, nz, _ = level_set(s, channel, 1.0, 1.0, layers=1)
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


@pytest.mark.parametrize("angle", [0.0, 30.0, 45.0])
def test_level_set_marches_layers_outward(angle):
    """Layer n out from the ribbons comes from layer n - 1: away from the box's edges (where a cell has a
    known neighbour on one side only) the plane front's distances and normal stay exact through three
    layers, and nowhere is the error above n (1 - cos) h (one first-order step per layer); the source of
    every marched cell is a ribbon cell."""
    d, channel, normal = _plane_front(angle)
    s = np.where(edge_cells(channel), -d, np.nan)
    advance, nx, nz, source = level_set(s, channel, 1.0, 1.0, layers=3)
    layer = np.zeros(d.shape, int)
    for n in (3, 2, 1):
        layer[np.isfinite(level_set(s, channel, 1.0, 1.0, layers=n)[0])] = n
    assert (layer == 3).sum() > 5
    err = np.abs(advance + d)[layer > 0]
    assert np.all(err <= layer[layer > 0] * (1.0 - np.cos(np.radians(angle))) + 1e-12)
    inner = np.zeros(d.shape, bool)
    inner[3:-3, 3:-3] = True
    if angle in (0.0, 45.0):   # a front along the grid or its diagonal: every inner cell leans on exact values
        sel = inner & (layer > 1)
        assert sel.any()
        np.testing.assert_allclose(advance[sel], -d[sel], atol=1e-12)
        np.testing.assert_allclose(np.c_[nx[sel], nz[sel]], np.broadcast_to(normal, (sel.sum(), 2)), atol=1e-12)
    assert np.all(np.isfinite(s.ravel()[source[layer > 0]]))


def test_fill_and_width_of_a_straight_toughness_front():
    """Front normal to x, a = h/4 past the centre: 3/4 of the cell wetted; the mean of the K asymptote
    (K'/E') s^(1/2) over the wetted part, (2/3) (K'/E') l^(3/2) / h with l = 3h/4 (midpoint rule: 1 %)."""
    model = TipModel(e_prime=1e10, mu_prime=1e-3, mode="olson")
    k, h = 1e6, 0.1
    fill, width = fill_and_width(model, np.array([0.25 * h]), np.array([1.0]), np.array([0.0]), np.array([k]),
                                 np.array([0.0]), np.array([0.0]), h, h)
    assert fill[0] == pytest.approx(0.75)
    assert width[0] == pytest.approx(2 / 3 * k / 1e10 * (0.75 * h) ** 1.5 / h, rel=1e-2)


@pytest.mark.parametrize("angle", [0.0, 20.0, 45.0, 70.0, 90.0, 135.0])
def test_wetted_fraction_is_the_area_behind_the_front(angle):
    """The closed form (sum of two uniform variables) against counting 400 x 400 points of a 2 x 1 cell,
    across the whole cell: 0 before the nearest corner, 1 past the farthest."""
    dx, dz = 2.0, 1.0
    nx, nz = np.cos(np.radians(angle)), np.sin(np.radians(angle))
    reach = 0.5 * (abs(nx) * dx + abs(nz) * dz)
    a = np.linspace(-1.1 * reach, 1.1 * reach, 23)
    f = wetted_fraction(a, np.full(a.shape, nx), np.full(a.shape, nz), dx, dz)
    ox, oz = np.meshgrid((np.arange(400) + 0.5) / 400 * dx - dx / 2, (np.arange(400) + 0.5) / 400 * dz - dz / 2)
    counted = ((nx * ox.ravel() + nz * oz.ravel())[None, :] < a[:, None]).mean(axis=1)
    np.testing.assert_allclose(f, counted, atol=4e-3)
    assert f[0] == 0.0 and f[-1] == 1.0 and np.all(np.diff(f) >= 0.0)


@pytest.mark.parametrize("angle", [0.0, 30.0, 45.0, 80.0])
def test_tip_cell_width_is_the_mean_of_the_toughness_asymptote(angle):
    """The K asymptote w = (K'/E') s^(1/2) averaged over a 2 x 1 cell cut by a plane front (8 x 8 midpoints),
    against the closed form for a power law s^b of the distance behind the front (the depth sigma = n.x is the
    sum of two uniform variables of widths P, Q; integrating s^b twice against their box densities):

        mean = (K'/E') [G(y) - G(y - P) - G(y - Q) + G(y - P - Q)] / (P Q (b + 1) (b + 2)),  G(u) = u+^(b + 2),

    y the front's distance past the nearest corner: within 3 % of the cell's full width, and positive as
    soon as the cell is wetted (before its first midpoint, the corner triangle's estimate)."""
    model = TipModel(e_prime=1e10, mu_prime=1e-3, mode="olson")
    k, dx, dz, b = 1e6, 2.0, 1.0, 0.5
    nx, nz = np.cos(np.radians(angle)), np.sin(np.radians(angle))
    p, q = max(abs(nx) * dx, 1e-7), max(abs(nz) * dz, 1e-7)
    y = np.linspace(1e-3, 1.2 * (p + q), 41)
    a = y - 0.5 * (p + q)
    ones = np.ones(a.shape)
    fill, width = fill_and_width(model, a, nx * ones, nz * ones, k * ones, 0 * ones, 0 * ones, dx, dz)
    G = lambda u: np.maximum(u, 0.0) ** (b + 2)
    exact = k / 1e10 * (G(y) - G(y - p) - G(y - q) + G(y - p - q)) / (p * q * (b + 1) * (b + 2))
    assert np.all(fill > 0) and np.all(width > 0)
    np.testing.assert_allclose(width, exact, atol=0.03 * exact[-1])


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


def test_ribbon_distance_with_the_step_speed_is_bounded_by_the_step():
    """With the step's start distances s_0 and step dt, a ribbon's distance solves s = s_M(w, V) at
    V = max(V_fluid, (s - s_0) / dt) (M asymptote w = beta_m (mu' V / E')^(1/3) s^(2/3), i.e.
    s^2 (s - s_0) = (w / beta_m)^3 E' dt / mu' where the step's speed wins): with no inflow (V_fluid = 0, which
    alone puts the front at the toughness distance, here 1e4 m) a step moves the front by that cubic's root."""
    from hfgpu.fracture.tip_universal import m_scale
    model = TipModel(e_prime=1e10, mu_prime=1.0, mode="km", velocity="fluid")
    channel = np.zeros((5, 5), bool)
    channel[1:4, 1:4] = True
    w = np.where(channel, 1e-3, 0.0)
    p = np.where(channel, 1e6, 0.0)   # uniform pressure: no inflow anywhere
    zero, k = np.zeros(w.shape), np.full(w.shape, 1e5)
    s_0 = np.full(w.shape, 0.2)
    args = (model, channel, w, p, k, zero, zero, 1.0, 0.5, 0.5)
    s_free, _ = ribbon_distances(*args)
    assert s_free[1, 1] == pytest.approx((1e-3 * 1e10 / 1e5) ** 2)   # V = 0: the toughness distance, 1e4 m
    for dt in (1e-3, 1.0):
        s, v = ribbon_distances(*args, start=(s_0, dt))
        c = (1e-3 / m_scale(1e10, 1.0, 1.0)) ** 3 * dt   # s^2 (s - s_0) = c, m_scale at V = 1
        root = np.roots([1.0, -0.2, 0.0, -c]).real.max()
        assert s[1, 1] == pytest.approx(root, rel=1e-9) and v[1, 1] == pytest.approx((root - 0.2) / dt, rel=1e-6)
        assert np.isnan(s[2, 2])


def _disc_ribbons(radius: float, cells_per_radius: int):
    """Cell centres of a grid around a disc, its channel (cells wholly inside) and each cell's distance to the
    circle."""
    h = radius / cells_per_radius
    x = (np.arange(2 * cells_per_radius + 7) - cells_per_radius - 3) * h
    xx, zz = np.meshgrid(x, x)
    r = np.hypot(xx, zz)
    far = r + 0.5 * h * (np.abs(xx) + np.abs(zz)) / np.maximum(r, 1e-30)   # the cell's farthest corner
    return h, r, far < radius


def _ribbon_errors(model, radius, h, r, channel, w, k_prime, t=1.0, speed=0.0):
    """Front-position errors (s - true distance) / R at the ribbons, with the asymptote alone and the fit."""
    zero = np.zeros(w.shape)
    reached = np.full(w.shape, t - h / speed if speed > 0.0 else np.nan)
    errors = {}
    for fit in ("asymptote", "two_term"):
        s, _ = ribbon_distances(model, channel, w, zero, k_prime, zero, reached, t, h, h, fit=fit)
        ribbon = np.isfinite(s)
        errors[fit] = (s[ribbon] - (radius - r[ribbon])) / radius
    return errors


@pytest.mark.parametrize("cells", [10, 15])
def test_two_term_ribbon_fit_on_the_m_vertex_profile(cells):
    """The exact M-vertex widths (Savitski & Detournay 2002) at the cell centres, V = dR/dt = 4 R / (9 t):
    the asymptote alone puts the front short by O((h / R)^2) (measured at 10 / 15 cells per radius: mean
    -0.44 / -0.16 % of R, worst -0.79 / -0.31 %), the two-term fit within +0.11 / +0.05 % (worst +0.21 /
    +0.11 %)."""
    from hfgpu.reference.radial import m_vertex, m_vertex_profile
    e_prime, mu_prime, rate, t = 3.5e10, 12 * 1.1e-3, 1e-3, 1e4
    radius = float(m_vertex(e_prime, mu_prime, rate, t).R)
    h, r, channel = _disc_ribbons(radius, cells)
    w = np.where(r < radius, m_vertex_profile(e_prime, mu_prime, rate, t, np.clip(r / radius, 1e-6, 1 - 1e-9))[0],
                 0.0)
    model = TipModel(e_prime=e_prime, mu_prime=mu_prime, mode="universal", velocity="front")
    errors = _ribbon_errors(model, radius, h, r, channel, w, np.zeros(w.shape), t, 4.0 * radius / (9.0 * t))
    one, two = errors["asymptote"], errors["two_term"]
    scale = (10.0 / cells) ** 2
    assert one.mean() < -0.003 * scale and one.min() < -0.005 * scale   # the deficit, second order in h / R
    assert abs(two.mean()) < 0.35 * abs(one.mean()) and np.abs(two).max() < 0.003


def test_two_term_ribbon_fit_on_a_penny_crack():
    """A penny crack under uniform pressure p, w = 8 p / (pi E') sqrt(R^2 - r^2), K' = 8 p sqrt(2 R) / pi: the
    toughness asymptote w = K'/E' s^(1/2) alone misses the front by -s^2 / (4 R) (relative correction
    -s / (4 R)); the fit removes most of it (10 cells per radius: worst -1.06 % of R alone, 0.27 % fitted)."""
    e_prime, p, radius = 3.5e10, 1e6, 10.0
    h, r, channel = _disc_ribbons(radius, 10)
    w = np.where(r < radius, 8.0 * p / (np.pi * e_prime) * np.sqrt(np.maximum(radius**2 - r**2, 0.0)), 0.0)
    k_prime = np.full(w.shape, 8.0 * p * np.sqrt(2.0 * radius) / np.pi)
    model = TipModel(e_prime=e_prime, mu_prime=1e-3, mode="olson")
    errors = _ribbon_errors(model, radius, h, r, channel, w, k_prime)
    one, two = errors["asymptote"], errors["two_term"]
    assert one.max() < 0.0 and np.abs(two).max() < 0.3 * np.abs(one).max(), (one, two)


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


@pytest.mark.parametrize("name", ["I", "III"])
def test_subgrid_front_storage_cases(name):
    # measured: I (5 m cells) R from the area -0.64 % (front's mean radius -0.67 %, min/max -3.1 / +0.7 %),
    # w0 +0.99 %; III (0.25 m cells) R from the area -0.52 % (front -0.53 %, -2.1 / +1.2 %), w0 +0.50 %
    # (ribbon_fit = "asymptote": I -1.64 / -1.66 %, w0 +2.52 %; III -1.79 / -1.86 %, w0 +3.62 %)
    out, _, err, _ = _subgrid(name)
    assert abs(err["R_area"]) < 0.02 and abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.05, err
    assert out["max_balance_error"] < 1e-9


@pytest.mark.slow
def test_subgrid_front_storage_viscosity_converges_under_refinement():
    """Case I at 5, 3.5 and 2.5 m cells: w(0)'s error falls at each refinement and the radius (from the area
    and the front's mean) stays within 0.7 %, 0.3 % at the finest. Measured: R from the area -0.64 / -0.12 /
    +0.19 %, the front's mean radius -0.67 / -0.42 / +0.14 %, w0 +0.99 / +0.78 / +0.51 %; with
    ``ribbon_fit = "asymptote"`` -1.64 / -0.94 / -0.47 %, -1.66 / -0.95 / -0.48 %, +2.52 / +1.65 / +1.13 % (about
    first order in the cell size)."""
    errors = [_subgrid("I", cell)[2] for cell in (5.0, 3.5, 2.5)]
    e = [abs(err["w0"]) for err in errors]
    assert e[0] > e[1] > e[2], e
    for err in errors:
        assert abs(err["R_area"]) < 0.007 and abs(err["R"]) < 0.007, err
    assert abs(errors[-1]["R_area"]) < 0.003 and abs(errors[-1]["R"]) < 0.003 and abs(errors[-1]["w0"]) < 0.01


@pytest.mark.slow
def test_subgrid_front_leakoff_viscosity_meets_the_goal():
    # measured at 0.5 m cells: R +1.49 % (front min/max +0.5 / +2.9 %), w0 -1.3 % (cell-by-cell front: +3.6 %,
    # -4.4 %); 411 steps, 20 Newton retries, 30 CPU s (without the failed-step bound of next_dt: 217 retries,
    # 46 s). Without the step's own front speed in the tip
    # asymptote (tip_cells._implicit_distance) the step collapsed to 2e-8 s at t = 64.4 s with one BLAS thread.
    # (output-independent steps, 425 steps: R from the area +1.24 %, front's mean radius +1.31 %, w0 -0.83 %;
    # the two-term ribbon fit, 392 steps: +1.38 / +1.43 %, w0 -1.14 %)
    out, _, err, _ = _subgrid("II")
    assert abs(err["R_area"]) < 0.02 and abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.05, err
    assert out["max_balance_error"] < 1e-9


@pytest.mark.slow
def test_subgrid_front_leakoff_toughness_meets_the_goal():
    """Case IV (2 cm cells): measured R +0.92 % (front min/max +0.2 / +2.4 %), w0 -0.4 % (the cell-by-cell
    front: R +0.7 %, w0 -57 %); 284 steps, 4 retries, 86 CPU s. With other time-step rules and round-off (no
    failed-step bound, a different summation of L p, output every 20 s) w0 was -0.5 % to +3.8 %, R +0.7 to
    +1.0 %. The stored volume is 0.8 % of the injected; w0 stayed
    within +2..+10 % from 5 s on, +2..+6 % from 60 s. With the previous sub-grid front it dipped by 20-26 % for a step, -9.2 % at the end, while
    cells crossed within a step joined the channel at once (their width jumping from the asymptote's mean to
    the elastic solution)."""
    # (output-independent steps, 295 steps: R from the area +0.85 %, front's mean radius +0.81 %, w0 +1.13 %;
    # the two-term ribbon fit, 272 steps: +0.95 / +0.92 %, w0 +1.47 %)
    out, _, err, _ = _subgrid("IV")
    assert abs(err["R_area"]) < 0.02 and abs(err["R"]) < 0.02 and abs(err["w0"]) < 0.05, err
    assert out["max_balance_error"] < 1e-9


def test_subgrid_front_through_a_coarsening_with_snapshots_at_every_step():
    """Right after a 3x3 coarsening every cell is a channel cell (no tip cells yet): the front summary of a
    snapshot taken then falls back to the channel's edge (it used to fail on an empty set). Case I on 5 m cells
    coarsened at 12 cells across (15 m cells, ~3.5 per final radius), 200 snapshots: finishes, volume balance
    exact, radius within 10 % of Dontsov (measured -8.3 %; -7.4 % with one snapshot: at 3.5 cells per radius
    the coarse grid's own error)."""
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
    assert out["radius"] == pytest.approx(ref.R[-1], rel=0.10)


@pytest.mark.parametrize("angle", [0.0, 0.2, np.pi / 4, 1.3, 3.0])
def test_advance_for_fill_inverts_the_wetted_fraction(angle):
    """tip_cells.advance_for_fill is the inverse of wetted_fraction: the same advance back to 1e-9 of a
    cell wherever the front crosses the cell (0 < f < 1, where the inverse is unique)."""
    from hfgpu.fracture.tip_cells import advance_for_fill

    dx, dz = 0.9, 1.6
    n = (np.full(41, np.cos(angle)), np.full(41, np.sin(angle)))
    reach = 0.5 * (abs(np.cos(angle)) * dx + abs(np.sin(angle)) * dz)
    advance = np.linspace(-0.999, 0.999, 41) * reach
    fill = wetted_fraction(advance, *n, dx, dz)
    np.testing.assert_allclose(advance_for_fill(fill, *n, dx, dz), advance, rtol=0, atol=1e-9 * dx)
