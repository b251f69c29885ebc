"""The momentum predictor keeps a flow that is uniform along a free-slip wall uniform (hfgpu.proppant.momentum,
"Conventions": a closed corner is the mirror ghost u_g = u_P, point-implicit as the open corners are)."""

import numpy as np
import pytest

from hfgpu.proppant.fluid import momentum_predictor


def accelerating_column(nz, nx, closed=None):
    """A box whose vertical flow is the same in every column and changes in time: old v0 uniform along x,
    a pressure and a force that vary with depth only (a settling suspension's backflow under its interface)."""
    width = np.full((nz, nx), 4e-3)
    if closed is not None:
        width[closed] = 0.0
    z = np.arange(nz + 1)[:, None] * np.ones((1, nx))
    v0 = np.where((z > 0) & (z < nz), -1.6e-5 * (1.0 + 0.1 * z / nz), 0.0)
    return dict(u0=np.zeros((nz, nx + 1)), v0=v0, p=np.cumsum(np.full((nz, nx), 9.0), axis=0),
                width0=width, theta_f0=np.full((nz, nx), 0.94), width=width.copy(),
                theta_f=np.full((nz, nx), 0.94), mu=np.full((nz, nx), 0.04),
                force_x=np.zeros((nz, nx + 1)), force_z=np.where((z > 0) & (z < nz), -2.2e3 * (1.0 + z / nz), 0.0),
                rho=1000.0, dx=4e-3, dz=4e-3, dt=0.05)


@pytest.mark.parametrize("backend", ["numpy", "taichi"])
def test_uniform_flow_along_side_walls_stays_uniform(backend):
    fields = accelerating_column(12, 7)
    u, v, d_u, d_v = momentum_predictor(backend)(**fields)
    inner = v[1:-1]
    assert np.max(np.abs(inner - inner[:, 3:4])) <= 1e-12 * np.max(np.abs(inner))
    assert np.max(np.abs(d_v[1:-1] - d_v[1:-1, 3:4])) <= 1e-12 * np.max(np.abs(d_v))
    assert np.max(np.abs(u)) <= 1e-12 * np.max(np.abs(inner))
    # the flow does change: the lag is not what keeps it uniform
    assert np.max(np.abs(inner - fields["v0"][1:-1])) > 1e-3 * np.max(np.abs(inner))


@pytest.mark.parametrize("backend", ["numpy", "taichi"])
def test_uniform_flow_beside_closed_cells_stays_uniform(backend):
    """Closed cells (beyond a fracture's front) are free-slip walls too: columns 0-1 closed, 2-6 open."""
    closed = np.zeros((12, 7), dtype=bool)
    closed[:, :2] = True
    fields = accelerating_column(12, 7, closed)
    v = momentum_predictor(backend)(**fields)[1]
    inner = v[1:-1, 2:]
    assert np.max(np.abs(inner - inner[:, 2:3])) <= 1e-12 * np.max(np.abs(inner))
    assert np.all(v[:, :2] == 0.0)


def test_steady_uniform_flow_is_unchanged_by_the_ghost():
    """Free slip takes no stress: a uniform flow along the walls in steady balance (pressure drop against the
    gap's wall friction, Eq. 9) is returned unchanged."""
    nz, nx, w, mu, rho, dz = 10, 6, 1e-3, 0.01, 1000.0, 0.01
    grad = 12.0 * mu * 0.02 / w ** 2        # dp/dz that holds v = 0.02 m/s (plane Poiseuille)
    z = np.arange(nz + 1)[:, None] * np.ones((1, nx))
    v0 = np.where((z > 0) & (z < nz), 0.02, 0.0)
    fields = dict(u0=np.zeros((nz, nx + 1)), v0=v0, p=-grad * dz * np.arange(nz)[:, None] * np.ones((1, nx)),
                  width0=np.full((nz, nx), w), theta_f0=np.ones((nz, nx)), width=np.full((nz, nx), w),
                  theta_f=np.ones((nz, nx)), mu=np.full((nz, nx), mu), force_x=np.zeros((nz, nx + 1)),
                  force_z=np.zeros((nz + 1, nx)), rho=rho, dx=0.01, dz=dz, dt=0.1)
    v = momentum_predictor("numpy")(**fields)[1]
    # rows 2..nz-2: the end faces see the closed ends' zero velocity through their own faces (Eq. 62)
    np.testing.assert_allclose(v[2:-2], 0.02, rtol=1e-12)
