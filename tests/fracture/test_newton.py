"""Newton step (Eq. 28-32): analytic Jacobian vs finite differences, conservation, convergence."""

import numpy as np
import pytest

from hfgpu.fracture.elasticity import ElasticityOperator
from hfgpu.fracture.lubrication import build_faces
from hfgpu.fracture.newton import Elasticity, StepProblem, dense_jacobian, residual, solve_step


def _problem(dense=True, demand=0.0):
    ix, iz = np.meshgrid(np.arange(-3, 4), np.arange(-3, 4))
    keep = ix**2 + iz**2 <= 9
    ix, iz = ix[keep].astype(np.int64), iz[keep].astype(np.int64)
    dx = dz = 1.0
    op = ElasticityOperator(dx, dz, 3.2e10)
    r = np.hypot(ix, iz)
    w_old = 1e-3 * np.sqrt(np.clip(1 - (r / 3.5) ** 2, 0, None))
    source = np.where((ix == 0) & (iz == 0), 1e-3 * 5.0, 0.0)
    prob = StepProblem(ix, iz, w_old, np.full(ix.size, 1e7), build_faces(ix, iz, dx, dz, 12.0), dx * dz, 5.0,
                       source, np.full(ix.size, demand), np.full(ix.size, max(0.01 * demand, 1e-300)))
    return prob, Elasticity(op, ix, iz, dense)


@pytest.mark.parametrize("demand", [0.0, 2e-4])
def test_analytic_jacobian_matches_finite_differences(demand):
    prob, el = _problem(demand=demand)
    rng = np.random.default_rng(0)
    w = prob.w_old + rng.uniform(1e-5, 2e-4, prob.w_old.size)
    jac = dense_jacobian(prob, el, w)
    h = 1e-9
    fd = np.empty_like(jac)
    for k in range(w.size):
        e = np.zeros_like(w)
        e[k] = h
        fd[:, k] = (residual(prob, el, w + e)[0] - residual(prob, el, w - e)[0]) / (2 * h)
    np.testing.assert_allclose(jac, fd, rtol=1e-5, atol=1e-7 * np.abs(jac).max())


@pytest.mark.parametrize("dense", [True, False])
def test_step_converges_and_conserves_volume(dense):
    prob, el = _problem(dense=dense, demand=1e-5)
    res = solve_step(prob, el, 1e-8, 30)
    assert res.converged and res.iterations < 15
    stored = prob.area * (res.w.sum() - prob.w_old.sum())
    # injected = stored + leaked over the step; flux terms cancel exactly (Eq. 29 summed over cells)
    assert stored + res.leaked.sum() == pytest.approx(prob.source.sum(), rel=1e-7)
    assert np.all(res.w >= -1e-12)


def test_direct_and_krylov_paths_agree():
    a = solve_step(*_problem(dense=True), 1e-9, 30)
    b = solve_step(*_problem(dense=False), 1e-9, 30)
    np.testing.assert_allclose(a.w, b.w, rtol=1e-5, atol=1e-9)


def test_krylov_preconditioner_of_an_earlier_solve_is_reused():
    """A second Newton-Krylov solve on the same cells given the first's preconditioner (the sub-grid front's
    iterations within a step) builds none of its own while GMRES converges with it, and lands on the same
    widths to the Newton tolerance."""
    prob, el = _problem(dense=False, demand=1e-5)
    first = solve_step(prob, el, 1e-9, 30)
    again = solve_step(prob, el, 1e-9, 30, preconditioner=first.preconditioner)
    assert first.converged and again.converged and first.preconditioner is not None
    assert first.work.factorisations >= 1 and again.work.factorisations == 0
    np.testing.assert_allclose(again.w, first.w, rtol=1e-7, atol=1e-12)


def _leakoff_dominated_step(dense):
    """A long step of radial case IV's start (Table 2: E' 6.07 GPa, mu' 0.012 Pa s, 3.5 cm cells): the step's
    Carter demand is 4x the widths and the widths must triple. A line search on ||F|| stalled here (the cubic
    conductance makes ||F|| grow along the Newton direction; 30 iterations, 8 % volume error)."""
    ix, iz = np.meshgrid(np.arange(-3, 4), np.arange(-3, 4))
    keep = np.hypot(ix, iz) < 2.5
    ix, iz = ix[keep].astype(np.int64), iz[keep].astype(np.int64)
    h = 0.035
    op = ElasticityOperator(h, h, 6.07e9)
    shape = np.linalg.solve(op.dense(ix, iz), np.ones(ix.size))      # uniform net pressure shape
    demand = np.full(ix.size, 6.5e-4)
    prob = StepProblem(ix, iz, 1.5e-4 * shape / shape.max(), np.full(ix.size, 6e6),
                       build_faces(ix, iz, h, h, 0.012), h * h, 0.8,
                       np.where((ix == 0) & (iz == 0), 3e-5 * 0.8, 0.0), demand, 0.01 * demand, 1.5e-7)
    return prob, Elasticity(op, ix, iz, dense)


@pytest.mark.parametrize("dense", [True, False])
def test_leakoff_dominated_long_step_converges_fast(dense):
    # natural monotonicity damping (Deuflhard): 3 iterations, direct and GMRES alike
    prob, el = _leakoff_dominated_step(dense)
    res = solve_step(prob, el, 1e-6, 30)
    assert res.converged and res.iterations <= 6, res.iterations
    stored = prob.area * (res.w.sum() - prob.w_old.sum())
    assert stored + res.leaked.sum() == pytest.approx(prob.source.sum(), rel=1e-8)
    assert res.w.min() > prob.w_old.max()          # every cell at least doubles (measured 3.3e-4 .. 5.2e-4 m)



@pytest.mark.parametrize("dense", [True, False])
@pytest.mark.parametrize("tolerance", [1e-3, 1e-6])
def test_accepted_step_conserves_volume_to_round_off_at_any_tolerance(dense, tolerance):
    """The accepted widths balance the step's volume exactly (newton._volume_conserving): injected = stored +
    leaked to round-off however loose Newton's tolerance. Here Carter's demand over the step (1 mm) drains the
    outer cells to near their ramp width, where the ramp's curvature over Newton's last update left sum F at
    the tolerance's level: measured without the shift 6.8e-5 (dense) and 1.9e-5 (GMRES) of the injected volume
    at 1e-3, 1.9e-11 (dense) at 1e-6."""
    prob, el = _problem(dense=dense, demand=1e-3)
    res = solve_step(prob, el, tolerance, 30)
    assert res.converged
    stored = prob.area * (res.w.sum() - prob.w_old.sum())
    assert abs(stored + res.leaked.sum() - prob.source.sum()) <= 1e-13 * prob.source.sum()
    assert abs(res.residual.sum()) <= 1e-13 * prob.source.sum()
