"""Linear-solver benchmark of the fracture Newton step: seconds per Newton iteration of the dense LU path and of
the Newton-Krylov path (GMRES with FFT products, near-field SuperLU preconditioner) on elliptic footprints, and
the cost model's prediction (hfgpu/fracture/solver_choice.py), which ``linear_solver = "auto"`` uses when a
scene does not set ``krylov_threshold``.

Footprints: ellipses of n cells with aspect ratios 1 (radial), 5 and 20 (elongated, as height-contained
fractures), on square cells of 0.2 m, E' 3.7e10 Pa, mu' 0.0132 Pa s (PyFrac's height-contained example), width
an elliptic profile of 1 mm at the centre. The step's dt makes the lubrication coupling dt w^3 E' / (mu' h^3)
equal to COUPLING (the median over the steps of the height-contained example and radial_long, measured with
--coupling-from). One iteration is timed as the engine does it (newton._newton with max_iterations 1: the
Jacobian and its factorisation or the GMRES solve, one residual and one monotonicity test); the dense C
gather (once per active set) is timed apart. Each timing is the best of --repeat runs.

Usage: OMP_NUM_THREADS=1 python bench/bench_solver.py [--sizes 100,300,1000,2000,3000,5000] [--aspects 1,5,20]
       [--repeat 3] [--fit] [--near-field-radius 1]

--fit refits the model's constants to the timings (non-negative least squares on the relative errors) and
prints them.
--near-field-radius sets how many cells of C the Newton-Krylov preconditioner keeps (newton.NEAR_FIELD_RADIUS):
the measured Krylov seconds and GMRES iterations are then that preconditioner's (the model's columns stay those of
the fitted constants).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from hfgpu.fracture import newton
from hfgpu.fracture.elasticity import ElasticityOperator
from hfgpu.fracture.lubrication import build_faces
from hfgpu.fracture.newton import Elasticity, StepProblem
from hfgpu.fracture.solver_choice import CostModel, footprint_measures

E_PRIME = 3.7e10
MU_PRIME = 0.0132
H = 0.2
W0 = 1e-3
COUPLING = 3e3


def ellipse(n: int, aspect: float) -> tuple[np.ndarray, np.ndarray]:
    """Cells (ix, iz) of an ellipse of about n cells, semi-axes a = aspect b along x and b along z."""
    b = math.sqrt(n / (math.pi * aspect))
    a = aspect * b
    ia, ib = int(math.ceil(a)) + 1, int(math.ceil(b)) + 1
    ix, iz = np.meshgrid(np.arange(-ia, ia + 1), np.arange(-ib, ib + 1))
    keep = (ix / a) ** 2 + (iz / b) ** 2 < 1.0
    return ix[keep].astype(np.int64), iz[keep].astype(np.int64)


def problem(ix: np.ndarray, iz: np.ndarray, coupling: float) -> tuple[StepProblem, ElasticityOperator, np.ndarray]:
    a = max(np.abs(ix).max(), 1) + 0.5
    b = max(np.abs(iz).max(), 1) + 0.5
    w = W0 * np.sqrt(np.clip(1.0 - (ix / a) ** 2 - (iz / b) ** 2, 0.0, None))
    dt = coupling * MU_PRIME * H**3 / (W0**3 * E_PRIME)
    op = ElasticityOperator(H, H, E_PRIME)
    n = ix.size
    source = np.where((ix == 0) & (iz == 0), 1e-3 * dt, 0.0)
    prob = StepProblem(ix, iz, w, np.full(n, 1e6), build_faces(ix, iz, H, H, MU_PRIME), H * H, dt, source,
                       np.zeros(n), np.full(n, 1e-2 * W0), 1e-3 * W0)
    return prob, op, newton.start_widths(prob)


def time_iteration(prob, op, x0, dense: bool, repeat: int) -> tuple[float, float, int]:
    """(seconds of one Newton iteration, seconds of building the Elasticity, GMRES iterations)."""
    best, build, gm = math.inf, math.inf, 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        el = Elasticity(op, prob.ix, prob.iz, dense)
        t1 = time.perf_counter()
        work = newton.NewtonWork()
        newton._newton(prob, el, x0.copy(), np.zeros(x0.size, bool), 1e-6, 1, work)
        t2 = time.perf_counter()
        best, build, gm = min(best, t2 - t1), min(build, t1 - t0), work.gmres_iterations
    return best, build, gm


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,300,1000,2000,3000,5000")
    parser.add_argument("--aspects", default="1,5,20")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--coupling", type=float, default=COUPLING)
    parser.add_argument("--fit", action="store_true")
    parser.add_argument("--near-field-radius", type=int, default=newton.NEAR_FIELD_RADIUS)
    args = parser.parse_args()
    newton.NEAR_FIELD_RADIUS = args.near_field_radius
    model = CostModel()
    print(f"{'aspect':>6} {'n':>6} {'box':>9} {'thin':>5} {'dense s':>9} {'gather s':>9} {'krylov s':>9} "
          f"{'gmres':>6} {'model d':>9} {'model k':>9} {'pick':>7} {'best':>7}")
    rows = []
    for aspect in (float(a) for a in args.aspects.split(",")):
        for n in (int(s) for s in args.sizes.split(",")):
            ix, iz = ellipse(n, aspect)
            prob, op, x0 = problem(ix, iz, args.coupling)
            m = footprint_measures(ix, iz)
            td, gather, _ = time_iteration(prob, op, x0, True, args.repeat)
            tk, _, gm = time_iteration(prob, op, x0, False, args.repeat)
            pd, pk = model.dense_seconds(m), model.krylov_seconds(m)
            rows.append((m, td, tk, gm))
            print(f"{aspect:6g} {ix.size:6d} {m.box:9d} {m.thin:5d} {td:9.4f} {gather:9.4f} {tk:9.4f} {gm:6d} "
                  f"{pd:9.4f} {pk:9.4f} {'krylov' if pk < pd else 'direct':>7} "
                  f"{'krylov' if tk < td else 'direct':>7}", flush=True)
    if args.fit:
        print(CostModel.fit(rows))


if __name__ == "__main__":
    main()
