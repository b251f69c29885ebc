"""The Warp pressure-correction solver (Jacobi-preconditioned CG, hfgpu.proppant.correction_warp) on Warp's CPU
device against SciPy: the correction matrix of a real SIMPLE step solved to the requested tolerance (reference:
a direct sparse solve, scipy.sparse.linalg.spsolve), whole fluid steps equal to those of the SciPy solver,
checkpoints that continue identically, and the choice of solver.
"""

import sys

import numpy as np
import pytest
from scipy.sparse.linalg import spsolve

from hfgpu.proppant.fluid import FluidNumerics, FluidSolver, _CorrectionSolver, correction_solver
from hfgpu.proppant.grid import StaggeredGrid
from hfgpu.proppant.params import MppicParams
from hfgpu.records import GridFrame

RHO, MU = 1000.0, 0.05
RTOL = 1e-10
FRAME = GridFrame(dx=0.02, dz=0.02, x0=0.01, z0=0.01)


@pytest.fixture
def warp():
    """warp, or the test skips (warp-lang is the optional extra hfgpu[gpu])."""
    return pytest.importorskip("warp")


def scene(steps: int):
    """A small fracture-like case: random widths with an island, an inlet, an outlet, a suspension and a
    vertical force; from step 3 on a closed strip opens (the unknown cells and the matrix pattern change).
    Yields (width, step keyword arguments) per step."""
    rng = np.random.default_rng(3)
    nz, nx = 8, 11
    width = rng.uniform(0.8e-3, 3e-3, (nz, nx))
    width[2, 4] = 0.0
    width[:, 9:] = 0.0
    sources = np.zeros((nz, nx))
    sources[3:5, 0] = 2e-6
    outlets = np.zeros((nz, nx), dtype=bool)
    outlets[0, 6] = True
    suspension = rng.uniform(0.0, 0.3, (nz, nx))
    for n in range(steps):
        if n == 3:
            width[:, 9:] = 1e-3
        theta_p = np.where(width > 0.0, suspension * (1.0 + 0.01 * np.cos(n + suspension)), 0.0)
        yield width.copy(), dict(theta_p=theta_p, sources=sources, outlets=outlets,
                                 force_z=rng.normal(0.0, 10.0, (nz + 1, nx)))


def run(solver: FluidSolver, state, steps):
    """Advance ``state`` through ``steps`` (from :func:`scene`), dt 0.01 s or 0.9 x the Courant limit."""
    for width, kwargs in steps:
        solver.set_grid(StaggeredGrid.from_width(FRAME, width))
        solver.step(state, min(0.01, 0.9 * solver.stable_dt(state)), **kwargs)
    return state


def start(kind: str):
    """A FluidSolver with pressure-correction solver ``kind`` on the first step's grid, and its fluid at rest."""
    width, kwargs = next(scene(1))
    solver = FluidSolver(StaggeredGrid.from_width(FRAME, width), RHO, MU, FluidNumerics(linear_rtol=RTOL),
                         params=MppicParams(), linear_solver=kind)
    return solver, solver.initial_state(kwargs["theta_p"])


def captured_system():
    """The correction matrix and first right-hand side of a real step (the SciPy solver's input)."""
    solver, state = start("scipy")
    linear, seen = solver.linear, {}

    def begin(matrix, unknown, begin=linear.begin):
        seen["matrix"] = matrix
        begin(matrix, unknown)

    def solve(rhs, solve=linear.solve):
        seen.setdefault("rhs", rhs)
        return solve(rhs)

    linear.begin, linear.solve = begin, solve
    run(solver, state, scene(1))
    return seen["matrix"], seen["rhs"]


def test_matches_a_direct_solve_of_a_real_correction_matrix(warp):
    """||b - A x|| <= rtol ||b|| and |x - x_direct| < 1e-8 |x_direct| (rtol 1e-10), for the step's first
    right-hand side and a second, smaller one (held to the first one's norm); the device matrix is reused
    for a new step on the same pattern."""
    matrix, rhs = captured_system()
    solver = correction_solver("warp", RTOL, 0)
    assert solver.device.is_cpu and solver.factorisations == 0
    for step in range(2):
        matrix = matrix * (1.0 + 0.1 * step)
        solver.begin(matrix, np.ones(matrix.shape[0], dtype=bool))
        cg = solver._cg
        for b in (rhs, 1e-3 * np.cos(np.arange(rhs.size)) * np.linalg.norm(rhs)):
            x = solver.solve(b)
            exact = spsolve(matrix.tocsc(), b)
            assert np.linalg.norm(b - matrix @ x) <= RTOL * np.linalg.norm(rhs)
            assert np.max(np.abs(x - exact)) < 1e-8 * np.max(np.abs(exact))
        assert solver._cg is cg   # same pattern: the device arrays and CG work space were reused
    assert solver.iterations > 0


def test_fluid_steps_equal_the_scipy_solver(warp):
    """Five steps (an island, an outlet, a suspension, cells that open) give the SciPy solver's fields to
    10 x rtol."""
    states = {}
    for kind in ("scipy", "warp"):
        solver, state = start(kind)
        states[kind] = run(solver, state, scene(5))
    scipy_state, warp_state = states["scipy"], states["warp"]
    for name in ("p", "u", "v"):
        reference = getattr(scipy_state, name)
        np.testing.assert_allclose(getattr(warp_state, name), reference, rtol=0,
                                   atol=10 * RTOL * np.max(np.abs(reference)))


def test_checkpoint_continues_identically(warp):
    """state() after three steps, restore() into a fresh solver (new device arrays): the next two steps repeat
    those of the uninterrupted run bit for bit; a SciPy solver's state restores too (a CPU run resumed on a
    GPU), and this state into a SciPy solver (the other way) gives the same fields to 10 x rtol."""
    steps = list(scene(5))
    solver, state = start("warp")
    state = run(solver, state, steps[:3])
    saved, linear = FluidSolver.copy_state(state), solver.linear.state()
    run(solver, state, steps[3:])
    for checkpoint in (linear, start("scipy")[0].linear.state()):
        resumed = start("warp")[0]
        resumed.linear.restore(checkpoint)
        again = run(resumed, FluidSolver.copy_state(saved), steps[3:])
        for name in ("p", "u", "v"):
            np.testing.assert_array_equal(getattr(again, name), getattr(state, name))
    on_cpu = start("scipy")[0]
    on_cpu.linear.restore(linear)
    again = run(on_cpu, saved, steps[3:])
    for name in ("p", "u", "v"):
        reference = getattr(state, name)
        np.testing.assert_allclose(getattr(again, name), reference, rtol=0,
                                   atol=10 * RTOL * np.max(np.abs(reference)))


def test_choice_of_solver(warp):
    """scipy and auto on the CPU give the SciPy solver; warp gives Warp's solver, on its CPU device unless the
    architecture is CUDA; auto on CUDA gives Warp only where Warp sees a CUDA device."""
    assert type(correction_solver("scipy", RTOL, 20, arch="cuda")) is _CorrectionSolver
    assert type(correction_solver("auto", RTOL, 20)) is _CorrectionSolver
    assert correction_solver("warp", RTOL, 20, arch="cpu").device.is_cpu
    cuda = warp.is_cuda_available()
    auto = correction_solver("auto", RTOL, 20, arch="cuda")
    assert (type(auto).__name__ == "WarpCorrectionSolver") == cuda
    assert type(start("auto")[0].linear) is _CorrectionSolver


def test_bad_choice_and_missing_warp_are_explained(monkeypatch):
    """An unknown kind names itself and the allowed ones; "warp" without warp-lang says what to install, and
    "auto" falls back to SciPy."""
    with pytest.raises(ValueError, match=r"'cusparse'.*'auto', 'scipy', 'warp'"):
        correction_solver("cusparse", RTOL, 20)
    with pytest.raises(ValueError, match="'cusparse'"):
        start("cusparse")
    monkeypatch.setitem(sys.modules, "warp", None)   # import warp now raises ImportError
    with pytest.raises(ImportError, match=r"pip install 'hfgpu\[gpu\]'"):
        correction_solver("warp", RTOL, 20)
    assert type(correction_solver("auto", RTOL, 20, arch="cuda")) is _CorrectionSolver
