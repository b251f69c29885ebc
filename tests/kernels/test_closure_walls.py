"""The walls family (kernels/closures/walls.py): the Taichi twin ``blocked`` against blocked_numpy on the CPU
backend, exactly (boolean equality), over many random moves on a small grid with closed cells, packed cells, dense
cells next to a wall or the domain's edge and narrow cells; each rule (leaving the grid, a closed cell, a narrow
cell, a raised weight on a packed cell, a dense cell's move towards a wall) is the only one that fires somewhere."""

from types import SimpleNamespace

import numpy as np
import pytest

from hfgpu.kernels import layout as L
from hfgpu.kernels.closures import walls
from hfgpu.kernels.runtime import ti
from hfgpu.kernels.stencil_numpy import owning_cell

pytestmark = pytest.mark.usefixtures("taichi_cpu")
F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)
F3 = ti.types.ndarray(dtype=ti.f64, ndim=3)
I1 = ti.types.ndarray(dtype=ti.i32, ndim=1)
THETA_CP, DENSE = 0.6, 0.55
FRAME = SimpleNamespace(x0=0.1, z0=-0.2, dx=0.5, dz=0.25)


@ti.kernel
def _blocked(x: F1, z: F1, xn: F1, zn: F1, gap: F1, own: F1, C: F3, out: I1, x0: ti.f64, z0: ti.f64,
             dx: ti.f64, dz: ti.f64, theta_cp: ti.f64, dense: ti.f64):
    for p in x:
        out[p] = walls.blocked((x[p] - x0) / dx, (z[p] - z0) / dz, (xn[p] - x0) / dx, (zn[p] - z0) / dz, C,
                               theta_cp, dense, gap[p], own[p] / (dx * dz))


def _grid():
    """(width, volume_fraction) (nz, nx): closed cells inside and at the edges, narrow cells, packed cells,
    dense cells beside a closed cell, the bottom edge and a corner."""
    rng = np.random.default_rng(11)
    nz, nx = 6, 8
    width = np.full((nz, nx), 5e-3)
    width[0, 5] = width[3, 7] = width[5, 0] = width[2, 4] = 0.0
    width[2, 2] = 1e-4
    width[4, 5] = 2e-4
    theta = rng.uniform(0.0, 0.5, (nz, nx))
    theta[2, 5] = 0.65
    theta[4, 1] = THETA_CP
    theta[3, 6] = 0.58  # beside the closed cell (3, 7)
    theta[5, 3] = 0.56  # on the bottom edge
    theta[0, 0] = DENSE  # in a corner
    theta[1, 4] = 0.57  # above the closed cell (2, 4)
    theta[width <= 0.0] = 0.0
    return width, theta


def _moves(shape, n=60000):
    """Start points inside the grid (some on cell centres and faces) and moves along x, along z or both, up to
    1.5 cells, some of zero length; the bridging gap per parcel."""
    rng = np.random.default_rng(3)
    nz, nx = shape
    sx = rng.uniform(-0.5, nx - 0.5, n)
    sz = rng.uniform(-0.5, nz - 0.5, n)
    snap = rng.random(n) < 0.2
    sx[snap] = np.clip(np.round(sx[snap] * 4.0) / 4.0, -0.5, nx - 0.5 - 1e-9)
    sz[snap] = np.clip(np.round(sz[snap] * 4.0) / 4.0, -0.5, nz - 0.5 - 1e-9)
    dsx = rng.uniform(-1.5, 1.5, n)
    dsz = rng.uniform(-1.5, 1.5, n)
    kind = rng.integers(0, 3, n)
    dsx[kind == 1] = 0.0
    dsz[kind == 0] = 0.0
    still = rng.random(n) < 0.02
    dsx[still] = dsz[still] = 0.0
    x = FRAME.x0 + sx * FRAME.dx
    z = FRAME.z0 + sz * FRAME.dz
    gap = rng.uniform(0.0, 1e-3, n)
    return x, z, x + dsx * FRAME.dx, z + dsz * FRAME.dz, gap


def _taichi(x, z, xn, zn, gap, width, theta, theta_cp, dense, own=None):
    C = np.zeros((L.CELL_CHANNELS, *width.shape))
    C[L.WIDTH] = width
    C[L.CELL] = (width > 0.0).astype(np.float64)
    C[L.THETA] = theta
    out = np.empty(x.shape, dtype=np.int32)
    _blocked(x, z, xn, zn, gap, np.zeros_like(x) if own is None else own, C, out, FRAME.x0, FRAME.z0, FRAME.dx,
             FRAME.dz, theta_cp, dense)
    return out.astype(bool)


def _numpy(x, z, xn, zn, gap, width, theta, theta_cp, dense, own=None):
    return walls.blocked_numpy(x, z, xn, zn, FRAME, width, (width > 0.0).astype(np.float64), theta, theta_cp,
                               dense, gap, own)


def test_twin_matches_numpy_each_rule():
    width, theta = _grid()
    x, z, xn, zn, gap = _moves(width.shape)
    inf = np.inf
    # the rules one at a time (the others switched off: theta_cp, dense = inf, gap = 0), then all together
    cases = {"edge_or_closed": (inf, inf, 0.0 * gap), "narrow": (inf, inf, gap), "packed": (THETA_CP, inf, 0.0 * gap),
             "wall": (inf, DENSE, 0.0 * gap), "all": (THETA_CP, DENSE, gap)}
    got = {}
    for name, (theta_cp, dense, g) in cases.items():
        want = _numpy(x, z, xn, zn, g, width, theta, theta_cp, dense)
        have = _taichi(x, z, xn, zn, g, width, theta, theta_cp, dense)
        mismatch = np.flatnonzero(want != have)
        assert mismatch.size == 0, (name, mismatch[:10])
        got[name] = want
    k, i, inside = owning_cell(xn, zn, FRAME, width.shape)
    leaves = ~inside
    closed = inside & (width[k, i] <= 0.0)
    assert np.array_equal(got["edge_or_closed"], leaves | closed)
    rules = {"leave": leaves, "closed": closed, "narrow": got["narrow"] & ~got["edge_or_closed"],
             "packed": got["packed"] & ~got["edge_or_closed"],
             "wall": walls.toward_wall_dense_numpy(x, z, xn, zn, FRAME, width, theta, DENSE)}
    assert np.array_equal(got["wall"], got["edge_or_closed"] | rules["wall"])
    for name, fires in rules.items():
        alone = fires & ~np.logical_or.reduce([other for key, other in rules.items() if key != name])
        assert alone.sum() >= 10, name
    assert np.array_equal(got["all"], np.logical_or.reduce(list(rules.values())))
    assert 0 < got["all"].sum() < x.size


def test_packing_cap_without_the_parcels_own_deposit():
    """With ``own`` (bed_slope) a packed cell is judged without the moving parcel's own deposit, theta_p - I_old
    n V_p / (dx dz w): the twin matches the reference move by move; it blocks a subset of what the plain cap
    blocks, and lets through some moves the plain cap stops (a parcel whose own weight makes a cell packed);
    own = 0 is the plain cap."""
    width, theta = _grid()
    theta = np.where(width > 0.0, np.maximum(theta, np.random.default_rng(5).uniform(0.55, 0.7, theta.shape)), 0.0)
    x, z, xn, zn, gap = _moves(width.shape)
    own = np.random.default_rng(7).uniform(0.0, 6e-5, x.size)  # up to 0.1 of a cell's volume, 6.25e-4 m^3
    inf = np.inf
    plain = _numpy(x, z, xn, zn, 0.0 * gap, width, theta, THETA_CP, inf)
    want = _numpy(x, z, xn, zn, 0.0 * gap, width, theta, THETA_CP, inf, own)
    have = _taichi(x, z, xn, zn, 0.0 * gap, width, theta, THETA_CP, inf, own)
    assert np.array_equal(want, have)
    assert not (want & ~plain).any() and (plain & ~want).sum() >= 100
    assert np.array_equal(_numpy(x, z, xn, zn, 0.0 * gap, width, theta, THETA_CP, inf, 0.0 * own), plain)
