"""Dense LU solves (scipy.linalg.lu_factor + lu_solve, what the fracture engine's Newton does below its Krylov
switch) with 1 and with all BLAS threads, on an idle machine and with busy processes competing for the cores
(a laptop running other work, or a shared node): where BLAS threads pay.

    python bench/bench_blas.py [--sizes 300 1000 2000 3000] [--busy 0 1 2] [--repeats 5]

For each count of busy processes (pure-Python loops, one core each) and each size: the best wall ms of
``repeats`` factorisations and solves with 1 thread and with the BLAS default, and their ratio. Asserts nothing.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import time

import numpy as np
import scipy.linalg
from threadpoolctl import threadpool_info, threadpool_limits


def spin(stop) -> None:
    """Keep one core busy until ``stop`` is set."""
    while not stop.is_set():
        sum(range(10000))


def solve_ms(a: np.ndarray, b: np.ndarray, threads: int | None, repeats: int) -> float:
    best = np.inf
    with threadpool_limits(limits=threads, user_api="blas"):
        for _ in range(repeats):
            t = time.perf_counter()
            scipy.linalg.lu_solve(scipy.linalg.lu_factor(a, check_finite=False), b, check_finite=False)
            best = min(best, time.perf_counter() - t)
    return 1e3 * best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[300, 1000, 2000, 3000])
    ap.add_argument("--busy", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    blas = [p for p in threadpool_info() if p["user_api"] == "blas"]
    default = blas[0]["num_threads"] if blas else None
    print(f"{os.cpu_count()} cores; BLAS {blas[0]['internal_api'] if blas else '?'} with {default} threads by default")
    print(f"{'busy':>4} | {'n':>5} | {'1 thread ms':>11} | {f'{default} threads ms':>11} | {'ratio':>5}")
    rng = np.random.default_rng(0)
    for busy in args.busy:
        stop = multiprocessing.Event()
        spinners = [multiprocessing.Process(target=spin, args=(stop,)) for _ in range(busy)]
        for p in spinners:
            p.start()
        try:
            for n in args.sizes:
                a = rng.normal(size=(n, n)) + n * np.eye(n)
                b = rng.normal(size=n)
                one = solve_ms(a, b, 1, args.repeats)
                many = solve_ms(a, b, None, args.repeats)
                print(f"{busy:>4} | {n:>5} | {one:11.1f} | {many:11.1f} | {many / one:5.2f}", flush=True)
        finally:
            stop.set()
            for p in spinners:
                p.join()


if __name__ == "__main__":
    main()
