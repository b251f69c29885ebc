"""Benchmark of the pressure-correction solve (hfgpu.proppant.fluid): SciPy on the CPU against Warp CG.

The systems are real ones: the correction matrices and first right-hand sides of two successive SIMPLE steps
(FluidSolver, NumPy predictor) on a slot of about N cells (2:1, widths uniform in 1-3 mm, theta_p uniform in
0-0.3, inflow at the left edge, outlet column at the right), at the runs' tolerance (FluidNumerics.linear_rtol,
1e-12: ||b - A x|| <= rtol ||b||). Rows per N:

- scipy LU: SuperLU factorisation (setup) and solve of step 1 (what _CorrectionSolver does on a new pattern);
- scipy reuse-CG: step 2 by CG preconditioned with step 1's LU factors (_CorrectionSolver's usual step);
- numpy Jacobi-CG: step 2 by the same preconditioned CG code with M^-1 = diag(A)^-1 (the Warp method on the
  host, for its iteration count);
- warp Jacobi-CG on "cpu" and, where Warp sees one, "cuda": WarpCorrectionSolver; setup = allocation and the
  first step (kernel compilation or cache load included), solve = step 2 (values copied in, preconditioner,
  CG, result copied back). Warp's CPU device runs about 7 us per unknown and iteration here (its tiled dot
  products), so above --warp-cpu-max unknowns it runs 20 iterations only and the solve column projects
  s/iteration x the numpy Jacobi-CG iterations (marked ~).

Usage: ``python bench/bench_correction.py`` (N = 1e3, 1e4, 1e5; about 4.5 minutes on 2 CPU cores, most of it
Warp's CPU device at 1e4; runs unchanged on a CUDA machine) or ``--sizes 1000 10000``. Best of 3 below
N = 1e4, else one run. No test asserts these timings.
"""

from __future__ import annotations

import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from hfgpu.errors import SimulationError  # noqa: E402
from hfgpu.proppant.correction_warp import WarpCorrectionSolver, cuda_available  # noqa: E402
from hfgpu.proppant.fluid import FluidNumerics, FluidSolver, _CorrectionSolver, _preconditioned_cg  # noqa: E402
from hfgpu.proppant.grid import StaggeredGrid  # noqa: E402
from hfgpu.proppant.params import MppicParams  # noqa: E402

RTOL = FluidNumerics().linear_rtol
CAPPED_ITERATIONS = 20


def systems(n_cells: int):
    """[(matrix, first rhs)] of two successive steps on a slot of about ``n_cells`` cells."""
    nz = max(2, round(np.sqrt(n_cells / 2)))
    nx = round(n_cells / nz)
    rng = np.random.default_rng(1)
    grid = StaggeredGrid.from_width(StaggeredGrid.slot(2.0, 1.0, 1e-3, nx=nx, nz=nz).frame,
                                    rng.uniform(1e-3, 3e-3, (nz, nx)))
    solver = FluidSolver(grid, 1000.0, 1e-3, params=MppicParams())
    linear, seen = solver.linear, []

    def begin(matrix, unknown, begin=linear.begin):
        seen.append([matrix])
        begin(matrix, unknown)

    def solve(rhs, solve=linear.solve):
        if len(seen[-1]) == 1:
            seen[-1].append(rhs)
        return solve(rhs)

    linear.begin, linear.solve = begin, solve
    theta_p = rng.uniform(0.0, 0.3, grid.shape)
    state = solver.initial_state(theta_p)
    sources = np.zeros(grid.shape)
    sources[:, 0] = 1e-4 / nz
    outlets = np.zeros(grid.shape, dtype=bool)
    outlets[:, -1] = True
    for _ in range(2):
        solver.step(state, min(1e-2, 0.9 * solver.stable_dt(state)), theta_p=theta_p, sources=sources,
                    outlets=outlets)
    return seen


class Counted:
    """A preconditioner that counts its applications (CG: iterations + 1)."""

    def __init__(self, apply):
        self.apply, self.calls = apply, 0

    def solve(self, r):
        self.calls += 1
        return self.apply(r)


def best(call, repeats):
    """(result of the last call, best wall time in s)."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = call()
        times.append(time.perf_counter() - start)
    return result, min(times)


def residual(matrix, x, rhs):
    return float(np.linalg.norm(rhs - matrix @ x) / np.linalg.norm(rhs))


def scipy_rows(steps, repeats):
    (a1, b1), (a2, b2) = steps

    def direct():
        solver = _CorrectionSolver(RTOL, 0)
        start = time.perf_counter()
        solver._factorise(a1)
        factor = time.perf_counter() - start
        start = time.perf_counter()
        x = solver.lu.solve(b1)
        return solver, factor, time.perf_counter() - start, x

    runs = [direct() for _ in range(repeats)]
    solver, x = runs[-1][0], runs[-1][3]
    rows = [("scipy LU", "cpu", min(r[1] for r in runs), min(r[2] for r in runs), "", residual(a1, x, b1))]
    lu = Counted(solver.lu.solve)
    (x, converged), seconds = best(lambda: _preconditioned_cg(a2, b2, lu.solve, RTOL * np.linalg.norm(b2), 10_000),
                                   repeats)
    rows.append(("scipy reuse-CG", "cpu", "", seconds, f"{lu.calls // repeats - 1}" + ("" if converged else "!"),
                 residual(a2, x, b2)))
    inverse = 1.0 / a2.diagonal()
    jacobi = Counted(lambda r: r * inverse)
    (x, converged), seconds = best(lambda: _preconditioned_cg(a2, b2, jacobi.solve, RTOL * np.linalg.norm(b2),
                                                              100 * a2.shape[0]), repeats)
    iterations = jacobi.calls // repeats - 1
    rows.append(("numpy Jacobi-CG", "cpu", "", seconds, f"{iterations}" + ("" if converged else "!"),
                 residual(a2, x, b2)))
    return rows, iterations


def warp_row(steps, device, repeats, capped, host_iterations):
    (a1, b1), (a2, b2) = steps
    unknown = np.ones(a1.shape[0], dtype=bool)
    solver = WarpCorrectionSolver(RTOL, device, max_iterations=CAPPED_ITERATIONS if capped else None)

    def step(matrix, rhs):
        solver.begin(matrix, unknown)
        try:
            return solver.solve(rhs)
        except SimulationError:
            if not capped:
                raise
            return None

    _, setup = best(lambda: step(a1, b1), 1)
    before = solver.iterations
    x, seconds = best(lambda: step(a2, b2), repeats)
    iterations = (solver.iterations - before) // repeats
    per_iteration = seconds / max(iterations, 1)
    if capped:
        return ("warp Jacobi-CG", device, setup, f"~{per_iteration * host_iterations:.3g}",
                f"{iterations} (capped)", "", per_iteration)
    return ("warp Jacobi-CG", device, setup, seconds, iterations, residual(a2, x, b2), per_iteration)


def cell(value, width):
    text = f"{value:.3g}" if isinstance(value, float) else str(value)
    return text.rjust(width)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1_000, 10_000, 100_000])
    parser.add_argument("--warp-cpu-max", type=int, default=20_000,
                        help="unknowns above which Warp's CPU device runs capped (default 20000)")
    args = parser.parse_args()
    devices = ["cpu"] + (["cuda"] if cuda_available() else [])
    header = ("unknowns", "method", "device", "setup s", "solve s", "iterations", "rel. residual", "s/iteration")
    widths = (9, 16, 7, 9, 10, 13, 13, 11)
    print(f"pressure-correction solve, rtol {RTOL:g}; Warp devices: {', '.join(devices)}")
    print(" ".join(h.rjust(w) for h, w in zip(header, widths, strict=True)))
    for n_cells in args.sizes:
        steps = systems(n_cells)
        n = steps[0][0].shape[0]
        repeats = 3 if n < 10_000 else 1
        rows, host_iterations = scipy_rows(steps, repeats)
        rows = [row + ("",) for row in rows]
        for device in devices:
            capped = device == "cpu" and n > args.warp_cpu_max
            rows.append(warp_row(steps, device, repeats, capped, host_iterations))
        for row in rows:
            print(" ".join(cell(v, w) for v, w in zip((n, *row), widths, strict=True)), flush=True)


if __name__ == "__main__":
    main()
