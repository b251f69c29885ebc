"""Finite-volume lubrication (Eq. 22-24, 29): Poiseuille flux, conservation, no flux to inactive cells."""

import numpy as np
import pytest

from hfgpu.fracture.lubrication import build_faces, conductance, divergence_matrix, face_fluxes, net_inflow


def _block(nx, nz):
    ix, iz = np.meshgrid(np.arange(nx), np.arange(nz))
    return ix.ravel(), iz.ravel()


def test_uniform_width_and_linear_pressure_give_the_poiseuille_flux():
    # q = -w^3/mu' dp/dx per unit height (Eq. 23): for a uniform channel the discrete face flux is exact.
    dx, dz, mu_prime, w0, grad = 0.5, 0.25, 12 * 0.1, 1e-3, -2e3
    ix, iz = _block(6, 3)
    faces = build_faces(ix, iz, dx, dz, mu_prime)
    w = np.full(ix.size, w0)
    p = 1e6 + grad * ix * dx
    q = face_fluxes(faces, w, p)
    x_faces = np.isclose(faces.g, dz / dx / (8 * mu_prime))
    # flux from b (east) into a (west) = -(q_x) dz with q_x = -w^3/mu' dp/dx
    np.testing.assert_allclose(q[x_faces], -(-(w0**3) / mu_prime * grad) * dz, rtol=1e-12)
    np.testing.assert_allclose(q[~x_faces], 0.0, atol=1e-20)


def test_face_conductance_is_the_mean_width_cubed():
    ix, iz = np.array([0, 1]), np.array([0, 0])
    faces = build_faces(ix, iz, 1.0, 1.0, 1.0)
    t, dt_a, dt_b = conductance(faces, np.array([1e-3, 3e-3]))
    assert t[0] == pytest.approx((4e-3) ** 3 / 8)
    assert dt_a[0] == dt_b[0] == pytest.approx(3 * (4e-3) ** 2 / 8)
    # a closed (negative-width) cell conducts nothing; smoothing rounds the kink only within delta
    assert conductance(faces, np.array([-1e-3, 3e-3]))[0][0] == pytest.approx((3e-3) ** 3 / 8)
    assert conductance(faces, np.array([-1e-3, 3e-3]), 1e-6)[0][0] == pytest.approx((3e-3) ** 3 / 8, rel=1e-3)


def test_divergence_conserves_volume_and_ignores_inactive_neighbours():
    rng = np.random.default_rng(1)
    ix, iz = _block(5, 4)
    keep = (ix - 2) ** 2 + (iz - 1.5) ** 2 < 5          # an irregular active set
    ix, iz = ix[keep], iz[keep]
    faces = build_faces(ix, iz, 1.0, 2.0, 0.3)
    cells = set(zip(ix.tolist(), iz.tolist()))
    for a, b in zip(faces.a, faces.b):
        assert abs(ix[a] - ix[b]) + abs(iz[a] - iz[b]) == 1
    n_expected = sum((i + 1, k) in cells for i, k in cells) + sum((i, k + 1) in cells for i, k in cells)
    assert faces.a.size == n_expected
    t = conductance(faces, rng.uniform(1e-4, 1e-3, ix.size))[0]
    lap = divergence_matrix(faces, t, ix.size)
    np.testing.assert_allclose(np.asarray(lap.sum(axis=0)).ravel(), 0.0, atol=1e-12 * t.max())   # columns: conservation
    np.testing.assert_allclose(np.asarray(lap.sum(axis=1)).ravel(), 0.0, atol=1e-12 * t.max())   # uniform p: no flow
    p = rng.uniform(1e6, 2e6, ix.size)   # the residual's assembly-free L p equals the matrix's
    np.testing.assert_allclose(net_inflow(faces, t, p), lap @ p, rtol=1e-12, atol=1e-12 * np.abs(lap @ p).max())
