"""The bed family (kernels/closures/bed.py): the Taichi twins of bed friction, of the overburden's friction and
of the threshold of motion against their NumPy references on the CPU backend: grains at rest, sliding either
way and stopped by friction; columns of dense runs broken by loose and closed cells, mixed densities; fine to
coarse grains, heavy and neutrally buoyant, fluid speeds across the threshold, both wall laws; the slope's
loads and push on the same random columns. Invariants of the overburden: a run's top cell has the own-weight
friction, a uniform run n cells deep n times it. The slope against closed forms: a bed surface at angle alpha
pushes every grain below it by g' tan alpha down the slope; a flat bed pushes none."""

import numpy as np
import pytest

from hfgpu.kernels import layout as L
from hfgpu.kernels.closures import bed
from hfgpu.kernels.runtime import ti

pytestmark = pytest.mark.usefixtures("taichi_cpu")
F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
F3 = ti.types.ndarray(dtype=ti.f64, ndim=3)
I1 = ti.types.ndarray(dtype=ti.i32, ndim=1)
RHO_F, MU, G, MU_B, DT = 1000.0, 1e-3, 9.81, 0.543, 1e-3


@ti.kernel
def _friction(u: F1, friction: F1, den: F1, out: F1):
    for p in u:
        out[p] = bed.bed_friction(u[p], friction[p], DT, den[p])


@ti.kernel
def _strength(cells: F3, dense: ti.f64, dx: ti.f64):
    for i in range(cells.shape[2]):
        bed.column_strength(cells, i, dense, dx, RHO_F, G, MU_B)


@ti.kernel
def _load(cells: F3, dense: ti.f64, dx: ti.f64):
    for i in range(cells.shape[2]):
        bed.column_load(cells, i, dense, dx, RHO_F, G)


@ti.kernel
def _slope(sx: F1, sz: F1, density: F1, cells: F3, theta_cp: ti.f64, dx: ti.f64, out: F1):
    for p in sx:
        out[p] = bed.slope_acceleration(sx[p], sz[p], density[p], cells, theta_cp, dx)


@ti.kernel
def _held(speed: F1, width: F1, diameter: F1, rho_p: F1, out: I1, code: ti.i32):
    for p in speed:
        out[p] = bed.held(speed[p], width[p], diameter[p], rho_p[p], RHO_F, MU, G, code)


def test_bed_friction_twin_matches_numpy():
    rng = np.random.default_rng(11)
    n = 20000
    u = rng.uniform(-0.05, 0.05, n)
    u[:100] = 0.0
    friction = MU_B * np.abs(1.0 - RHO_F / rng.uniform(1000.0, 3600.0, n)) * G * rng.uniform(1.0, 10.0, n)
    den = 1.0 + DT * rng.uniform(0.0, 5e3, n)
    got = np.empty_like(u)
    _friction(u, friction, den, got)
    want = bed.bed_friction_numpy(u, np.ones(n, bool), friction, DT, den)
    stopped = want == 0.0
    assert stopped[100:].any() and (~stopped).any() and np.all(np.abs(want) <= np.abs(u))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0.0)
    assert np.array_equal(bed.bed_friction_numpy(u, np.zeros(n, bool), friction, DT, den), u)


def column_cells(rng, nz, nx, dx, dz):
    """A cell array (CELL_CHANNELS, nz, nx) with random width (some closed), theta_p in [0, 0.62] (dense runs
    broken by loose cells) and grains of 1050-3600 kg/m^3: the moment channels M_MASS, M_VOLUME, THETA, WIDTH."""
    cells = np.zeros((L.CELL_CHANNELS, nz, nx))
    width = rng.uniform(1e-3, 1e-2, (nz, nx))
    width[rng.random((nz, nx)) < 0.05] = 0.0
    theta = np.where(rng.random((nz, nx)) < 0.75, rng.uniform(0.45, 0.62, (nz, nx)), rng.uniform(0.0, 0.3, (nz, nx)))
    theta[width == 0.0] = 0.0
    volume = theta * dx * dz * width
    cells[L.WIDTH], cells[L.THETA], cells[L.M_VOLUME] = width, theta, volume
    cells[L.M_MASS] = volume * rng.uniform(1050.0, 3600.0, (nz, nx))
    return cells


def test_overburden_twin_matches_numpy():
    """column_strength (one thread per column, scanning down) against bed_strength_numpy on 40 x 300 cells;
    the BED_STRENGTH channel only is written."""
    rng = np.random.default_rng(17)
    dx, dz, dense = 0.02, 0.01, 0.5
    cells = column_cells(rng, 40, 300, dx, dz)
    before = cells.copy()
    _strength(cells, dense, dx)
    want = bed.bed_strength_numpy(before[L.M_MASS], before[L.M_VOLUME], before[L.WIDTH], before[L.THETA], dense,
                                  dx, RHO_F, G, MU_B)
    network = before[L.THETA] >= dense
    assert (want[network] > 0.0).all() and not want[~network].any() and (want > 3 * MU_B * G * 0.7).any()
    np.testing.assert_allclose(cells[L.BED_STRENGTH], want, rtol=1e-12, atol=0.0)
    others = np.arange(L.CELL_CHANNELS) != L.BED_STRENGTH
    np.testing.assert_array_equal(cells[others], before[others])


def test_overburden_grows_with_depth_of_the_run():
    """A uniform dense run (theta_p 0.58, 2650 kg/m^3) below two loose cells: its j-th cell (j = 1 at the top of
    the run) has a_f = j mu_b g' exactly (its base carries j cells' submerged weight, shared by one cell's
    grains); a loose cell in the run starts it again; the loose cells have 0."""
    nz, dx, dz, w, theta, rho_p = 9, 0.02, 0.01, 5e-3, 0.58, 2650.0
    theta_col = np.array([0.0, 0.2, theta, theta, theta, 0.3, theta, theta, theta])[:, None]
    volume = theta_col * dx * dz * w
    strength = bed.bed_strength_numpy(volume * rho_p, volume, np.full((nz, 1), w), theta_col, 0.5, dx, RHO_F, G,
                                      MU_B)[:, 0]
    own = MU_B * (1.0 - RHO_F / rho_p) * G
    np.testing.assert_allclose(strength, own * np.array([0, 0, 1, 2, 3, 0, 1, 2, 3]), rtol=1e-13)


@pytest.mark.parametrize("code", [0, 1])
def test_threshold_of_motion_twin_matches_numpy(code):
    rng = np.random.default_rng(13)
    n = 20000
    diameter = rng.uniform(0.1e-3, 1.0e-3, n)
    rho_p = rng.uniform(1050.0, 3600.0, n)
    rho_p[:50] = RHO_F  # neutrally buoyant: never held
    width = rng.uniform(1e-3, 1e-2, n)
    speed = rng.uniform(-1.0, 1.0, n)
    got = np.empty(n, np.int32)
    _held(speed, width, diameter, rho_p, got, code)
    with np.errstate(divide="ignore", invalid="ignore"):
        want = bed.held_numpy(speed, width, diameter, rho_p, RHO_F, MU, G, code)
    assert want.any() and not want.all() and not want[:50].any()
    np.testing.assert_array_equal(got.astype(bool), want)


def test_slope_loads_and_push_twins_match_numpy():
    """column_load (one thread per column) against bed_load_numpy on 40 x 300 random cells (only LOAD_TOP and
    LOAD_OWN written), and slope_acceleration against slope_acceleration_numpy for 20 000 parcels anywhere in
    the grid, both at 1e-12."""
    rng = np.random.default_rng(19)
    dx, dz, dense, theta_cp = 0.02, 0.01, 0.5, 0.6
    nz, nx = 40, 300
    cells = column_cells(rng, nz, nx, dx, dz)
    before = cells.copy()
    _load(cells, dense, dx)
    top, own = bed.bed_load_numpy(before[L.M_MASS], before[L.M_VOLUME], before[L.WIDTH], before[L.THETA], dense,
                                  dx, RHO_F, G)
    loose_loaded = (own > 0.0) & (before[L.THETA] < dense)
    assert (top > 0.0).any() and loose_loaded.any() and not own[before[L.WIDTH] == 0.0].any()
    np.testing.assert_allclose(cells[L.LOAD_TOP], top, rtol=1e-12, atol=0.0)
    np.testing.assert_allclose(cells[L.LOAD_OWN], own, rtol=1e-12, atol=0.0)
    others = ~np.isin(np.arange(L.CELL_CHANNELS), [L.LOAD_TOP, L.LOAD_OWN])
    np.testing.assert_array_equal(cells[others], before[others])
    n = 20000
    sx = rng.uniform(-0.5, nx - 0.5 - 1e-9, n)
    sz = rng.uniform(-0.5, nz - 0.5 - 1e-9, n)
    density = rng.uniform(1050.0, 3600.0, n)
    got = np.empty(n)
    _slope(sx, sz, density, cells, theta_cp, dx, got)
    want = bed.slope_acceleration_numpy(sx, sz, density, top, own, before[L.THETA], before[L.WIDTH], theta_cp, dx)
    assert (want > 0.0).any() and (want < 0.0).any()
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-300)


def packed_slope(alpha_deg, nz=30, nx=40, dx=0.01, dz=0.01, theta_cp=0.6, rho_p=2650.0, w=5e-3):
    """Cells (mass, volume, width, theta) of a bed packed at theta_cp whose surface rises along x at
    ``alpha_deg`` (a cell crossed by the surface holds its packed part, as a settled layer would), and the
    surface height per column centre [m]; row 0 at the top."""
    x = (np.arange(nx) + 0.5) * dx
    height = 0.05 + np.tan(np.radians(alpha_deg)) * x
    bottom = (nz - 1 - np.arange(nz)) * dz  # each row's lower edge above the floor
    fill = np.clip((height[None, :] - bottom[:, None]) / dz, 0.0, 1.0)
    theta = theta_cp * fill
    volume = theta * dx * dz * w
    return volume * rho_p, volume, np.full((nz, nx), w), theta, height


@pytest.mark.parametrize("alpha", [5.0, 20.0, 33.0])
def test_slope_push_is_g_prime_tan_alpha_below_a_sloping_surface(alpha):
    """Below a bed surface at alpha, away from the grid's ends, every grain is pushed down the slope by
    a_s = g' tan alpha (to 1e-9 relative), the grains of the partly filled surface cells too; on a flat bed by
    nothing."""
    dx = dz = 0.01
    theta_cp, rho_p = 0.6, 2650.0
    mass, volume, width, theta, height = packed_slope(alpha)
    nz, nx = theta.shape
    top, own = bed.bed_load_numpy(mass, volume, width, theta, 0.5, dx, RHO_F, G)
    xs = np.linspace(3.0, nx - 4.0, 200)
    depth_floor = (nz - 0.5) - np.interp(xs, np.arange(nx), height) / dz  # the surface in cell rows
    # grains from just below the surface down to the floor
    sz = depth_floor + 0.01 + np.random.default_rng(3).uniform(0.0, 1.0, xs.size) * (nz - 0.51 - depth_floor)
    a = bed.slope_acceleration_numpy(xs, sz, np.full(xs.size, rho_p), top, own, theta, width, theta_cp, dx)
    g_prime = (1.0 - RHO_F / rho_p) * G
    np.testing.assert_allclose(a, -g_prime * np.tan(np.radians(alpha)), rtol=1e-9)
    flat = packed_slope(0.0)
    top0, own0 = bed.bed_load_numpy(*flat[:4], 0.5, dx, RHO_F, G)
    a0 = bed.slope_acceleration_numpy(xs, sz, np.full(xs.size, rho_p), top0, own0, flat[3], flat[2], theta_cp, dx)
    assert np.abs(a0).max() < 1e-12
