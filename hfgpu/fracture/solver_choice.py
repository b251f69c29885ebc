"""Which linear solver a Newton step of the fracture engine uses: the cost model of ``linear_solver = "auto"``.

Per active set (the engine's rebuild, simulator.py) "auto" picks the dense LU (newton.py: the Jacobian gathered
dense, scipy.linalg.lu_factor) or Newton-Krylov (GMRES with C applied by FFT over the footprint's bounding box,
left-preconditioned by a SuperLU of the Jacobian with C cut to its near field, newton.NEAR_FIELD_RADIUS),
whichever the model says is cheaper per Newton iteration. When the scene sets ``[fracture] krylov_threshold``
the fixed count rule applies instead (dense below that many cells). After shut-in a draining footprint keeps its
cells from step to step, so the dense path gathers C once for all the steps (``stationary``: the engine's choice
while the pumps are stopped: the crossover to Krylov moves from 360 to 440 cells on a radial footprint, 290 to
340 at aspect 20; a pulse that goes on spreading pays the gather again at each change in that range).

The model counts work from the footprint alone (deterministic: the same scene picks the same solvers on any
machine), with constants in seconds measured on one core (bench/bench_solver.py --fit, elliptic footprints of
100-5000 cells, aspect 1, 5 and 20; OMP_NUM_THREADS=1):

    dense  = D0 + D2 n^2 + D3 n^3           (LU 2/3 n^3 flops; J = -dt L C and the solves: n^2)
    krylov = K0 + KN n + KS n t^2            (Jacobian, near field, SuperLU factorisation)
             + I (KG + KF P log2 P + KP n t)  (I GMRES iterations: an FFT matvec on P points, a preconditioner
                                               solve, KG the fixed cost of an iteration)

with n the active cells, t the footprint's thickness in cells (the smaller side of its bounding box: the
bandwidth the sparse factorisation fills, so SuperLU costs ~ n t^2 and its solve ~ n t), P = (2 n_x - 1)
(2 n_z - 1) the FFT size of the bounding box and I the GMRES iterations of a Newton iteration (hardly changing
with n or shape, measured). An elongated footprint (t small) makes the factorisation cheap while the dense LU
still costs n^3, which is why Newton-Krylov pays there from a few hundred cells and only past a few thousand
on radial footprints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Footprint:
    """What the cost model reads of an active set."""

    n: int        # active cells (unknowns)
    box: int      # FFT points of the bounding box's zero-padded convolution, (2 nx - 1)(2 nz - 1)
    thin: int     # the bounding box's smaller side, in cells


def footprint_measures(ix: np.ndarray, iz: np.ndarray) -> Footprint:
    nx = int(np.ptp(ix)) + 1 if ix.size else 1
    nz = int(np.ptp(iz)) + 1 if iz.size else 1
    return Footprint(int(ix.size), (2 * nx - 1) * (2 * nz - 1), min(nx, nz))


@dataclass(frozen=True)
class CostModel:
    """Seconds of each path per Newton iteration and per time step (module docstring); constants from
    bench/bench_solver.py --fit (one core)."""

    d0: float = 4.9e-4        # dense: fixed cost of a factorised iteration [s]
    d2: float = 9.2e-9        # dense: n^2 work of a factorised iteration (J = -dt L C, solves) [s]
    d3: float = 1.23e-11      # dense: n^3 work (the LU) [s]
    k0: float = 1.0e-3        # Krylov: fixed cost of a factorisation [s]
    kn: float = 3.5e-6        # Krylov: n work of a factorisation (Jacobian, near field) [s]
    ks: float = 9.5e-10       # Krylov: n t^2 work of a factorisation (SuperLU fill) [s]
    kg: float = 1.4e-4        # Krylov: fixed cost of a GMRES iteration [s]
    kf: float = 0.0           # Krylov: P log2 P work of a GMRES iteration (FFT matvec; the fit gives it to kg, kp) [s]
    kp: float = 1.26e-8       # Krylov: n t work of a GMRES iteration (preconditioner solve) [s]
    gmres_iterations: float = 7.5      # GMRES iterations of a fresh iteration in the benchmark (rtol 1e-3)
    # per time step, with Jacobian reuse (Krylov: the height-contained example to 145 s, 290 steps, 399
    # factorisations, 12 644 GMRES iterations; dense: the same example to 6 s and radial_long):
    dense_factorisations: float = 2.2  # LU factorisations a step
    dense_extra: float = 7.0e-8        # n^2 work a step besides them: C gathered once per active set (~2.5e-8)
                                       # and ~8 chord iterations (a residual and an LU solve each)
    dense_gather: float = 2.5e-8       # the gather's share of dense_extra, not paid by a stationary footprint
    krylov_factorisations: float = 1.4  # SuperLU factorisations a step (the preconditioner is reused)
    krylov_gmres: float = 44.0         # GMRES iterations a step (~6.2 Newton iterations of ~7 at rtol 1e-3)

    @staticmethod
    def dense_terms(f: Footprint) -> list[float]:
        return [1.0, f.n**2, f.n**3]

    @staticmethod
    def factorisation_terms(f: Footprint) -> list[float]:
        return [1.0, f.n, f.n * f.thin**2]

    @staticmethod
    def gmres_terms(f: Footprint) -> list[float]:
        return [1.0, f.box * math.log2(max(f.box, 2)), f.n * f.thin]

    def dense_seconds(self, f: Footprint) -> float:
        """One Newton iteration with a new LU."""
        return float(np.dot([self.d0, self.d2, self.d3], self.dense_terms(f)))

    def factorisation_seconds(self, f: Footprint) -> float:
        return float(np.dot([self.k0, self.kn, self.ks], self.factorisation_terms(f)))

    def gmres_seconds(self, f: Footprint) -> float:
        """One GMRES iteration."""
        return float(np.dot([self.kg, self.kf, self.kp], self.gmres_terms(f)))

    def krylov_seconds(self, f: Footprint) -> float:
        """One Newton iteration with a new preconditioner and ``gmres_iterations`` GMRES iterations."""
        return self.factorisation_seconds(f) + self.gmres_iterations * self.gmres_seconds(f)

    def dense_step_seconds(self, f: Footprint, stationary: bool = False) -> float:
        """A step's dense work; ``stationary``: on a footprint that keeps its cells from step to step (a shut-in),
        which gathers C once for all its steps."""
        extra = self.dense_extra - (self.dense_gather if stationary else 0.0)
        return self.dense_factorisations * self.dense_seconds(f) + extra * f.n**2

    def krylov_step_seconds(self, f: Footprint) -> float:
        return self.krylov_factorisations * self.factorisation_seconds(f) + self.krylov_gmres * self.gmres_seconds(f)

    def prefers_krylov(self, f: Footprint, stationary: bool = False) -> bool:
        return self.krylov_step_seconds(f) < self.dense_step_seconds(f, stationary)

    @staticmethod
    def fit(rows) -> "CostModel":
        """The per-iteration constants fitted to ``rows`` of (Footprint, dense s, Krylov s, GMRES iterations)
        of fresh iterations: non-negative least squares on the relative error of each path."""
        from scipy.optimize import nnls
        its = float(np.median([r[3] for r in rows]))
        a = np.array([np.array(CostModel.dense_terms(f)) / td for f, td, _, _ in rows])
        d = nnls(a, np.ones(len(rows)))[0]
        b = np.array([np.concatenate([CostModel.factorisation_terms(f), gm * np.array(CostModel.gmres_terms(f))])
                      / tk for f, _, tk, gm in rows])
        k = nnls(b, np.ones(len(rows)))[0]
        return CostModel(*(float(v) for v in (*d, *k)), gmres_iterations=its)


MODEL = CostModel()


def use_dense(solver: str, threshold: int | None, ix: np.ndarray, iz: np.ndarray, stationary: bool = False) -> bool:
    """Whether the active set (ix, iz) is solved with the dense LU: ``solver`` "direct" / "krylov" force it;
    "auto" follows the fixed count rule when ``threshold`` is set (dense below it), else the cost model
    (``stationary``: the footprint keeps its cells, as after shut-in, CostModel.dense_step_seconds)."""
    if solver != "auto":
        return solver == "direct"
    if threshold is not None:
        return ix.size < threshold
    return not MODEL.prefers_krylov(footprint_measures(ix, iz), stationary)
