"""Benchmark of the elasticity operator (Eq. 20-21): FFT vs dense matvec, and solves of C w = p.

Radial (penny-shaped) active sets of N cells on a unit square grid. Prints two tables:

1. matvec: time and peak memory (tracemalloc) of ``ElasticityOperator.matvec`` (zero-padded rfft2, kernel
   FFT cached) vs building the dense C and multiplying by it; dense only up to N = 1e4 (N^2 memory).
2. solve: direct dense LU (numpy.linalg.solve) vs restarted GMRES on the FFT operator, unpreconditioned and
   left-preconditioned by SuperLU of C's near field of radius 1, 2, 3 (3x3, 5x5, 7x7 stencils): setup
   (factorisation) time, iterations to a relative residual of 1e-10, solve time, and the error against
   the direct solution where there is one.

3. planes (``--planes``): N parallel planes 10 cells apart, each with the same radial set of M cells, through
   ``hfgpu.fracture.shadow.PlanesOperator.matvec`` (N forward FFTs, N^2 spectral products, N inverse) against
   N^2 single-plane ``ElasticityOperator.matvec`` calls (what the product costs done block by block).

Usage: ``python bench/bench_elasticity.py`` (N = 1e3 .. 3e4, about 20 s) or ``--full`` (adds N = 1e5
and the dense LU at N = 1e4; about 1 minute). Everything runs on one thread (BLAS threads are set to 1
unless OPENBLAS_NUM_THREADS / OMP_NUM_THREADS / MKL_NUM_THREADS are set; scipy.fft uses one worker), so
the columns compare per core and a loaded machine does not make multithreaded BLAS spin. No test asserts
these timings.
"""

from __future__ import annotations

import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402

import numpy as np  # noqa: E402

from hfgpu.fracture.elasticity import ElasticityOperator
from hfgpu.fracture.krylov import elasticity_preconditioner, gmres_solve
from hfgpu.fracture.shadow import PlanesOperator

E_PRIME = 2.0e10
RTOL = 1e-10


def radial_cells(n_target: int) -> tuple[np.ndarray, np.ndarray]:
    """Cells of a unit grid whose centres lie inside the disc of area n_target (about n_target cells)."""
    m = int(np.ceil(np.sqrt(n_target / np.pi))) + 1
    k = np.arange(-m, m + 1)
    x, z = np.meshgrid(k, k)
    inside = x * x + z * z < n_target / np.pi
    return x[inside], z[inside]


def timed(call, repeats: int = 1):
    """(result, best wall time over repeats in s, peak traced memory of one call in MB)."""
    tracemalloc.start()
    result = call()
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        result = call()
        best = min(best, time.perf_counter() - start)
    return result, best, peak


def matvec_table(sizes, dense_max: int) -> None:
    print("\n## matvec: C @ w (radial set, dx = dz = 1)")
    print(f"{'N':>8} {'box':>9} {'fft ms':>9} {'fft MB':>8} {'cache MB':>9} "
          f"{'dense build s':>14} {'dense ms':>9} {'dense MB':>9} {'rel diff':>9}")
    rng = np.random.default_rng(0)
    for n_target in sizes:
        ix, iz = radial_cells(n_target)
        w = rng.standard_normal(ix.size)
        op = ElasticityOperator(1.0, 1.0, E_PRIME)
        op.matvec(ix, iz, w)                                   # build the kernel cache once
        cache = (op._table.nbytes + op._table_hat.nbytes) / 2**20
        fast, t_fft, m_fft = timed(lambda: op.matvec(ix, iz, w), repeats=5)
        box = f"{iz.max() - iz.min() + 1}x{ix.max() - ix.min() + 1}"
        if ix.size <= dense_max:
            c, t_build, m_dense = timed(lambda: op.dense(ix, iz))
            slow, t_dense, _ = timed(lambda: c @ w, repeats=3)
            diff = np.linalg.norm(fast - slow) / np.linalg.norm(slow)
            dense = f"{t_build:14.3f} {1e3 * t_dense:9.2f} {m_dense:9.1f} {diff:9.1e}"
            del c
        else:
            dense = f"{'skipped: N^2 x 8 B = ' + format(8 * ix.size**2 / 2**30, '.1f') + ' GiB':>44}"
        print(f"{ix.size:8d} {box:>9} {1e3 * t_fft:9.2f} {m_fft:8.1f} {cache:9.1f} {dense}", flush=True)


def solve_table(sizes, direct_max: int) -> None:
    print(f"\n## solve C w = p (p = 1 MPa uniform; GMRES to relative residual {RTOL:g}, restart 60)")
    print(f"{'N':>8} {'method':>16} {'setup s':>9} {'iters':>6} {'solve s':>9} {'residual':>9} "
          f"{'err vs LU':>10}")
    for n_target in sizes:
        ix, iz = radial_cells(n_target)
        op = ElasticityOperator(1.0, 1.0, E_PRIME)
        b = np.full(ix.size, 1.0e6)
        a = op.linear_operator(ix, iz)
        a @ b                                                  # build the kernel cache once
        reference = None
        if ix.size <= direct_max:
            start = time.perf_counter()
            reference = np.linalg.solve(op.dense(ix, iz), b)
            elapsed = time.perf_counter() - start
            print(f"{ix.size:8d} {'dense LU':>16} {'':>9} {'':>6} {elapsed:9.3f}", flush=True)
        for radius in (None, 1, 2, 3):
            start = time.perf_counter()
            pre = None if radius is None else elasticity_preconditioner(op, ix, iz, radius)
            setup = time.perf_counter() - start
            start = time.perf_counter()
            result = gmres_solve(a, b, pre, rtol=RTOL)
            solve = time.perf_counter() - start
            err = ("" if reference is None
                   else f"{np.linalg.norm(result.x - reference) / np.linalg.norm(reference):10.1e}")
            name = "gmres" if radius is None else f"gmres+near r={radius}"
            print(f"{ix.size:8d} {name:>16} {setup:9.3f} {result.iterations:6d} {solve:9.3f} "
                  f"{result.residual:9.1e} {err}", flush=True)
        if ix.size > direct_max:
            print(f"{ix.size:8d} {'dense LU':>16}   skipped: O(N^3) time, N^2 memory "
                  f"(limit N <= {direct_max})")


def planes_table(cells: int, counts=(1, 2, 3, 5, 8)) -> None:
    """Table 3 of the module docstring, at ``cells`` cells a plane."""
    ix, iz = radial_cells(cells)
    print(f"\n# planes: {ix.size} cells a plane, 10 cells apart; best of 3 (s)")
    print(f"{'planes':>6} {'PlanesOperator':>15} {'N^2 single':>11} {'ratio':>6}")
    single = ElasticityOperator(1.0, 1.0, E_PRIME)
    w = np.random.default_rng(1).random(ix.size)
    single.matvec(ix, iz, w)
    for n in counts:
        op = PlanesOperator(1.0, 1.0, E_PRIME, 10.0 * np.arange(n))
        cells_n, w_n = [(ix, iz)] * n, [w] * n
        op.matvec(cells_n, w_n)   # the kernel tables
        _, fast, _ = timed(lambda: op.matvec(cells_n, w_n), repeats=3)
        _, block, _ = timed(lambda: [single.matvec(ix, iz, w) for _ in range(n * n)], repeats=3)
        print(f"{n:6d} {fast:15.4f} {block:11.4f} {block / fast:6.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="add N = 1e5 (and dense up to 1e4)")
    parser.add_argument("--planes", type=int, metavar="M", help="only table 3, N planes of M cells each")
    args = parser.parse_args()
    if args.planes:
        planes_table(args.planes)
        return
    sizes = [1_000, 3_000, 10_000, 30_000] + ([100_000] if args.full else [])
    threads = os.environ["OPENBLAS_NUM_THREADS"]
    print(f"# bench_elasticity ({'full' if args.full else 'default'}): numpy {np.__version__}, "
          f"BLAS threads {threads}")
    matvec_table(sizes, dense_max=10_500)
    solve_table(sizes, direct_max=10_500 if args.full else 3_500)


if __name__ == "__main__":
    main()
