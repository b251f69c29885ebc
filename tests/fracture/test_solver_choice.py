"""Which linear solver "auto" picks (solver_choice.py), the krylov_threshold contract, Jacobian reuse in Newton,
and that the choice is deterministic (same results on rerun)."""

import dataclasses

import numpy as np
import pytest

from hfgpu.fracture import newton
from hfgpu.fracture.elasticity import ElasticityOperator
from hfgpu.fracture.lubrication import build_faces
from hfgpu.fracture.newton import Elasticity, StepProblem, solve_step
from hfgpu.fracture.simulator import simulate
from hfgpu.fracture.solver_choice import MODEL, footprint_measures, use_dense
from hfgpu.records import MemorySink

from .helpers import scene


def _ellipse(n, aspect):
    b = np.sqrt(n / (np.pi * aspect))
    a = aspect * b
    ix, iz = np.meshgrid(np.arange(-int(a) - 1, int(a) + 2), np.arange(-int(b) - 1, int(b) + 2))
    keep = (ix / a) ** 2 + (iz / b) ** 2 < 1.0
    return ix[keep].astype(np.int64), iz[keep].astype(np.int64)


def test_forced_solvers_and_the_fixed_count_rule():
    ix, iz = _ellipse(1000, 20.0)
    assert use_dense("direct", None, ix, iz) and not use_dense("krylov", None, ix, iz)
    assert use_dense("direct", 10, ix, iz) and not use_dense("krylov", 10**6, ix, iz)
    assert use_dense("auto", ix.size + 1, ix, iz) and not use_dense("auto", ix.size, ix, iz)


def test_cost_model_prefers_dense_on_small_radial_and_krylov_on_elongated_footprints():
    assert use_dense("auto", None, *_ellipse(300, 1.0))
    assert not use_dense("auto", None, *_ellipse(1500, 20.0))
    assert not use_dense("auto", None, *_ellipse(8000, 1.0))
    # the crossover comes no later the more elongated the footprint (300, 320, 360 cells with the fitted model)
    def crossover(aspect):
        return next(n for n in range(20, 20000, 20) if MODEL.prefers_krylov(footprint_measures(*_ellipse(n, aspect))))
    assert crossover(20.0) <= crossover(5.0) < crossover(1.0)


def test_a_stationary_footprint_keeps_the_dense_lu_further():
    """After shut-in the footprint keeps its cells, so the dense path gathers C once: the crossover to Krylov
    moves up (bench/bench_shut_in.py: 357 radial cells, dense 9-11 ms a step against Krylov's 10-20 ms)."""
    f = footprint_measures(*_ellipse(360, 1.0))
    assert MODEL.prefers_krylov(f) and not MODEL.prefers_krylov(f, stationary=True)
    assert MODEL.dense_step_seconds(f, stationary=True) == pytest.approx(
        MODEL.dense_step_seconds(f) - MODEL.dense_gather * f.n**2, rel=1e-12)


def test_krylov_threshold_is_optional_and_still_accepted():
    assert scene().fracture.krylov_threshold is None
    assert scene(fracture="[fracture]\nkrylov_threshold = 300").fracture.krylov_threshold == 300


def _step():
    ix, iz = _ellipse(400, 5.0)
    h = 0.2
    op = ElasticityOperator(h, h, 3.7e10)
    a, b = np.abs(ix).max() + 0.5, np.abs(iz).max() + 0.5
    w_old = 1e-3 * np.sqrt(np.clip(1 - (ix / a) ** 2 - (iz / b) ** 2, 0, None))
    dt = 3e3 * 0.0132 * h**3 / (1e-9 * 3.7e10)
    source = np.where((ix == 0) & (iz == 0), 1e-3 * dt, 0.0)
    prob = StepProblem(ix, iz, w_old, np.full(ix.size, 1e6), build_faces(ix, iz, h, h, 0.0132), h * h, dt,
                       source, np.zeros(ix.size), np.full(ix.size, 1e-5), 1e-6)
    return prob, op


@pytest.mark.parametrize("dense", [True, False])
def test_jacobian_reuse_keeps_the_solution_and_saves_factorisations(dense, monkeypatch):
    prob, op = _step()
    results = {}
    for reuse in (False, True):
        monkeypatch.setattr(newton, "REUSE_JACOBIAN", reuse)
        res = solve_step(prob, Elasticity(op, prob.ix, prob.iz, dense), 1e-8, 30)
        assert res.converged
        results[reuse] = res, res.work.factorisations
    (plain, f_plain), (reused, f_reused) = results[False], results[True]
    np.testing.assert_allclose(reused.w, plain.w, rtol=0, atol=1e-6 * np.abs(plain.w).max())
    assert f_reused <= f_plain


@pytest.mark.parametrize("dense", [True, False])
def test_simplified_exit_meets_the_tolerance_in_fewer_iterations(dense):
    """Stopping on the simplified correction (Newton's exit when ||J^-1 F(x_k+1)|| < eps ||x||, its step taken):
    the widths stay within eps of a solve to 1e-12, the step's volume balance holds (residuals sum to ~0), and
    Newton takes no more iterations than when it stops on the update alone."""
    prob, op = _step()
    exact = solve_step(prob, Elasticity(op, prob.ix, prob.iz, dense), 1e-12, 30)
    runs = {}
    for exit_early in (False, True):
        res = solve_step(prob, Elasticity(op, prob.ix, prob.iz, dense), 1e-6, 30, simplified_exit=exit_early)
        assert res.converged
        np.testing.assert_allclose(res.w, exact.w, rtol=0, atol=1e-6 * np.linalg.norm(exact.w))
        assert abs(res.residual.sum()) < 1e-10 * prob.source.sum()
        runs[exit_early] = res.iterations
    assert runs[True] <= runs[False]


def test_auto_choice_is_deterministic():
    sc = scene(end_time="30 s", cell="1 m")
    a, b = simulate(sc, MemorySink()), simulate(sc, MemorySink())
    assert a == b
    forced = simulate(sc.replace(fracture=dataclasses.replace(sc.fracture, linear_solver="direct")), MemorySink())
    assert forced["cells"] == a["cells"]


def test_summary_counts_the_linear_solvers_work():
    """The run summary adds up each step's NewtonWork: the dense path factorises and runs no GMRES; the Krylov
    path runs GMRES with fewer factorisations (preconditioners) than Newton iterations."""
    sc = scene(end_time="30 s", cell="1 m")
    runs = {solver: simulate(sc.replace(fracture=dataclasses.replace(sc.fracture, linear_solver=solver)),
                             MemorySink()) for solver in ("direct", "krylov")}
    direct, krylov = runs["direct"], runs["krylov"]
    assert direct["gmres_iterations"] == 0 and 0 < direct["factorisations"] <= direct["newton_iterations"]
    assert krylov["gmres_iterations"] >= krylov["newton_iterations"] > 0
    assert 0 < krylov["factorisations"] < krylov["newton_iterations"]
