"""The bed family (kernels/closures/bed.py): the Taichi twins of bed friction, of the overburden's friction and
of the threshold of motion against their NumPy references on the CPU backend: grains at rest, sliding either
way and stopped by friction; columns of dense runs broken by loose and closed cells, mixed densities; fine to
coarse grains, heavy and neutrally buoyant, fluid speeds across the threshold, both wall laws. Invariants of
the overburden: a run's top cell has the own-weight friction, a uniform run n cells deep n times it."""

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
