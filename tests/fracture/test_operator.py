"""ElasticityOperator (FFT matvec, cached kernel table, near field) against the dense Eq. 21 oracle, and
the preconditioned GMRES of krylov.py against direct solves, for C alone and for an Eq. 30-shaped system."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse

from hfgpu.fracture.elasticity import ElasticityOperator, dense_matrix
from hfgpu.fracture.krylov import (coupled_operator, coupled_preconditioner, elasticity_preconditioner,
                                   gmres_solve, splu_preconditioner)

DX, DZ, E_PRIME = 0.7, 1.3, 2.1e10


def _random_mask_cells(rng, nz, nx, fill, shift):
    """Active cells of a random (non-convex, possibly disconnected) mask, shifted to include negatives."""
    iz, ix = np.nonzero(rng.random((nz, nx)) < fill)
    return ix + shift[0], iz + shift[1]


def _annulus_with_slot(m):
    """A non-convex set: a ring of outer radius m with a slot cut through it (cells in bounding box m)."""
    k = np.arange(-m, m + 1)
    x, z = np.meshgrid(k, k)
    r2 = x * x + z * z
    keep = (r2 <= m * m) & (r2 >= (m // 2) ** 2) & ~((x > 0) & (np.abs(z) <= 1))
    return x[keep], z[keep]


def _rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


def test_fft_matvec_matches_dense_on_random_and_nonconvex_sets():
    rng = np.random.default_rng(1)
    op = ElasticityOperator(DX, DZ, E_PRIME)
    cases = [_random_mask_cells(rng, 17, 23, 0.4, (-30, 5)),
             _random_mask_cells(rng, 40, 9, 0.7, (3, -50)),      # the box grows: the cache is re-built
             _random_mask_cells(rng, 5, 31, 0.2, (-2, -2)),      # smaller box: served by the grown cache
             _annulus_with_slot(12),
             (np.array([4]), np.array([-9]))]                     # a single cell
    for ix, iz in cases:
        c = dense_matrix(ix, iz, DX, DZ, E_PRIME)
        w = rng.standard_normal(ix.size)
        assert _rel(op.matvec(ix, iz, w), c @ w) < 1e-12
        assert np.array_equal(op.dense(ix, iz), c)
        w2 = rng.standard_normal((ix.size, 3))                   # several right-hand sides at once
        assert _rel(op.matvec(ix, iz, w2), c @ w2) < 1e-12
        assert _rel(op.linear_operator(ix, iz) @ w, c @ w) < 1e-12


def test_matvec_is_translation_invariant_and_cache_grows_monotonically():
    rng = np.random.default_rng(2)
    op = ElasticityOperator(DX, DZ, E_PRIME)
    ix, iz = _random_mask_cells(rng, 11, 13, 0.5, (0, 0))
    w = rng.standard_normal(ix.size)
    first = op.matvec(ix, iz, w)
    capacity = op._capacity
    assert np.allclose(op.matvec(ix - 1000, iz + 77, w), first, rtol=0, atol=1e-12 * np.abs(first).max())
    assert op._capacity == capacity                            # same box size: no rebuild
    big_x, big_z = _random_mask_cells(rng, 30, 50, 0.3, (0, 0))
    op.matvec(big_x, big_z, rng.standard_normal(big_x.size))
    assert op._capacity[0] >= 30 and op._capacity[1] >= 50
    assert op._shape[0] >= 2 * op._capacity[0] - 1 and op._shape[1] >= 2 * op._capacity[1] - 1


def test_diagonal_and_near_field_are_the_dense_matrix_restricted():
    op = ElasticityOperator(DX, DZ, E_PRIME)
    ix, iz = _annulus_with_slot(9)
    c = dense_matrix(ix, iz, DX, DZ, E_PRIME)
    assert np.array_equal(op.diagonal(ix.size), np.diag(c))
    for radius in (0, 1, 3):
        near = op.near_field(ix, iz, radius).toarray()
        keep = (np.abs(ix[:, None] - ix[None, :]) <= radius) & (np.abs(iz[:, None] - iz[None, :]) <= radius)
        assert np.array_equal(near, np.where(keep, c, 0.0))
    # The near field of C is an M-matrix: positive row sums (the dropped far field is negative).
    near = op.near_field(ix, iz, 2)
    assert np.all(np.asarray(near.sum(axis=1)).ravel() > 0.0)


@pytest.mark.parametrize("call, message", [
    (lambda: ElasticityOperator(0.0, 1.0, 1e10), "dx = 0.0"),
    (lambda: ElasticityOperator(1.0, np.nan, 1e10), "dz = nan"),
    (lambda: ElasticityOperator(1.0, 1.0, -5.0), "plane_strain_modulus = -5.0"),
    (lambda: ElasticityOperator(1.0, 1.0, 1e10).matvec([0, 1], [0], [1.0]), "equal length"),
    (lambda: ElasticityOperator(1.0, 1.0, 1e10).matvec([0.5], [0.0], [1.0]), "integer"),
    (lambda: ElasticityOperator(1.0, 1.0, 1e10).matvec([0, 1], [0, 0], [1.0]), "w must have shape"),
    (lambda: ElasticityOperator(1.0, 1.0, 1e10).near_field([0], [0], -1), "radius = -1"),
])
def test_bad_input_is_named(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def _radial(n_target):
    m = int(np.ceil(np.sqrt(n_target / np.pi))) + 1
    k = np.arange(-m, m + 1)
    x, z = np.meshgrid(k, k)
    inside = x * x + z * z < n_target / np.pi
    return x[inside], z[inside]


def test_gmres_with_near_field_preconditioner_equals_direct_solve():
    rng = np.random.default_rng(3)
    op = ElasticityOperator(DX, DZ, E_PRIME)
    ix, iz = _radial(1500)
    b = rng.standard_normal(ix.size) * 1e6
    direct = np.linalg.solve(op.dense(ix, iz), b)
    plain = gmres_solve(op.linear_operator(ix, iz), b, rtol=1e-12)
    pre = gmres_solve(op.linear_operator(ix, iz), b, elasticity_preconditioner(op, ix, iz, radius=2),
                      rtol=1e-12)
    for result in (plain, pre):
        assert result.converged and result.residual <= 1e-12
        assert _rel(result.x, direct) < 1e-9
    assert pre.iterations < plain.iterations / 2                  # measured: 20 vs 55


def _lubrication_like(ix, iz, rng):
    """A sparse 5-point stencil with random positive transmissibilities (the shape of J_ff, Eq. 24)."""
    n = ix.size
    index = {(a, b): i for i, (a, b) in enumerate(zip(ix.tolist(), iz.tolist()))}
    rows, cols, vals = [], [], []
    for i, (a, b) in enumerate(zip(ix.tolist(), iz.tolist())):
        for neighbour in ((a + 1, b), (a, b + 1)):
            j = index.get(neighbour)
            if j is not None:
                t = rng.uniform(0.5, 2.0) * 1e-9
                rows += [i, j, i, j]
                cols += [j, i, i, j]
                vals += [t, t, -t, -t]
    return scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(n, n))


def test_coupled_gmres_equals_direct_solve():
    """[[C, -I], [D, F]] x = b (the block shape of Eq. 30) by GMRES + SuperLU of the near-field blocks."""
    rng = np.random.default_rng(4)
    op = ElasticityOperator(DX, DZ, E_PRIME)
    ix, iz = _radial(600)
    n = ix.size
    upper_right = -scipy.sparse.identity(n, format="csr")                        # dR_rd/dp
    lower_left = scipy.sparse.diags(-DX * DZ * rng.uniform(0.9, 1.1, n))        # dR_ff/dw (storage)
    lower_right = _lubrication_like(ix, iz, rng) - scipy.sparse.identity(n) * 1e-12
    b = np.concatenate([rng.standard_normal(n) * 1e6, rng.standard_normal(n) * 1e-4])
    a = coupled_operator(op.linear_operator(ix, iz), upper_right, lower_left, lower_right)
    jacobian = np.block([[op.dense(ix, iz), upper_right.toarray()],
                         [lower_left.toarray(), lower_right.toarray()]])
    direct = np.linalg.solve(jacobian, b)
    assert _rel(a @ direct, jacobian @ direct) < 1e-12
    pre = coupled_preconditioner(op.near_field(ix, iz, 2), upper_right, lower_left, lower_right)
    result = gmres_solve(a, b, pre, rtol=1e-12)
    assert result.converged and result.residual <= 1e-12
    assert _rel(result.x[:n], direct[:n]) < 1e-8 and _rel(result.x[n:], direct[n:]) < 1e-8
    assert result.iterations < 40


def test_gmres_reports_non_convergence_and_zero_rhs():
    op = ElasticityOperator(DX, DZ, E_PRIME)
    ix, iz = _radial(400)
    a = op.linear_operator(ix, iz)
    capped = gmres_solve(a, np.ones(ix.size), rtol=1e-14, restart=2, maxiter=2)
    assert not capped.converged and capped.residual > 1e-14 and capped.iterations == 2
    zero = gmres_solve(a, np.zeros(ix.size))
    assert zero.converged and zero.iterations == 0 and not zero.x.any()
    with pytest.raises(ValueError, match="rtol"):
        gmres_solve(a, np.ones(ix.size), rtol=0.0)
    exact = splu_preconditioner(op.near_field(ix, iz, 10**6))   # covers the set: the full C
    assert gmres_solve(a, np.ones(ix.size), exact, rtol=1e-10).iterations <= 2
