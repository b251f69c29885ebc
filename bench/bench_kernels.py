"""Parcel updates per second of the MP-PIC particle operations, Taichi vs the NumPy reference.

    python bench/bench_kernels.py [--sizes 1e4 1e5 1e6] [--arch cpu] [--repeats 5] [--threads 2] [--profile]

Grid 200 x 100 cells (nx x nz), a random open/closed width field, random parcels in open cells, random fluid.
Columns: M parcel-updates/s (best of ``repeats`` timed calls after one warm-up call: the machine may be shared)
for scatter of parcels in random order, and, on parcels sorted by cell (Parcels.sort_by_cell, as a simulator
does every few steps), scatter, gather, push, gather + push, exchange, the whole particle step (scatter, grid
fields, gather, push, exchange), and the re-sort of nearly sorted parcels; speed-up of Taichi over NumPy.
Prints a table per size; asserts nothing. ``--profile``: before each table, the Taichi kernel profiler's table
(min / avg / max time per kernel: kernel time only, without Python, launch and ndarray overhead).
``--threads``: Taichi CPU threads (default all cores).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hfgpu.kernels.runtime import init, ti
from hfgpu.proppant.backend import get_backend, grid_fields
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

NX, NZ = 200, 100
RHO_F, MU, G, DT = 1000.0, 1e-3, 9.81, 1e-4


def make_case(n: int, seed: int = 0):
    """Grid, fluid fields and ``n`` parcels (uniform over the open cells)."""
    rng = np.random.default_rng(seed)
    frame = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)
    width = rng.uniform(2e-3, 5e-3, (NZ, NX))
    width[:, -10:] = 0.0
    x = rng.uniform(0.0, (NX - 10) * frame.dx, n)
    z = rng.uniform(0.0, NZ * frame.dz, n)
    solid = 0.1 * frame.dx * frame.dz * 3e-3 * NX * NZ / n
    r = rng.uniform(1e-4, 3e-4, n)
    parcels = Parcels.create(x, z, radius=r, density=2650.0, particles=solid / (4 / 3 * np.pi * r ** 3),
                             u=rng.normal(0, 0.01, n), v=rng.normal(0, 0.01, n))
    fluid = (rng.normal(0, 0.05, (NZ, NX + 1)), rng.normal(0, 0.05, (NZ + 1, NX)), rng.normal(0, 10, (NZ, NX)))
    return frame, width, parcels, fluid


def timed(fn, repeats: int) -> float:
    """Best wall time of fn() over ``repeats`` calls after one warm-up call."""
    fn()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def measure(backend, n: int, repeats: int) -> dict[str, float]:
    """Seconds per call of each operation for ``n`` parcels."""
    params = MppicParams()
    frame, width, parcels, (u, v, p) = make_case(n)
    random_order = timed(lambda: backend.scatter(parcels, frame, width), repeats)
    parcels.sort_by_cell(frame, width.shape)
    moments = backend.scatter(parcels, frame, width)
    fields = grid_fields(frame, width, u, v, p, moments, params)
    work = parcels.copy()
    seen = backend.gather(work, frame, fields)
    drag = backend.push(work.copy(), seen, frame, fields, DT, params, RHO_F, MU, G)

    def gather_push():
        seen = backend.gather(work, frame, fields)
        backend.push(work, seen, frame, fields, DT, params, RHO_F, MU, G)

    def step():
        m = backend.scatter(work, frame, width)
        f = grid_fields(frame, width, u, v, p, m, params)
        seen = backend.gather(work, frame, f)
        drag = backend.push(work, seen, frame, f, DT, params, RHO_F, MU, G)
        backend.exchange(work, seen, drag, frame, width)

    return {"scatter (random order)": random_order,
            "scatter": timed(lambda: backend.scatter(work, frame, width), repeats),
            "gather": timed(lambda: backend.gather(work, frame, fields), repeats),
            "push": timed(lambda: backend.push(work, seen, frame, fields, DT, params, RHO_F, MU, G), repeats),
            "gather+push": timed(gather_push, repeats),
            "exchange": timed(lambda: backend.exchange(work, seen, drag, frame, width), repeats),
            "step": timed(step, repeats),
            "re-sort": timed(lambda: work.sort_by_cell(frame, width.shape), repeats)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e4, 1e5, 1e6])
    ap.add_argument("--arch", default=None, help="Taichi arch (default HFGPU_ARCH or cpu)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--skip-numpy-above", type=float, default=1e7)
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--profile", action="store_true")
    args = ap.parse_args()
    init(args.arch, kernel_profiler=args.profile, cpu_threads=args.threads)
    ti_backend = get_backend("taichi", arch=args.arch)
    np_backend = get_backend("numpy")
    print(f"grid {NX} x {NZ}, Taichi arch {ti_backend.arch}; M parcel-updates/s (best of {args.repeats})")
    head = f"{'parcels':>9} | {'op':<22} | {'taichi':>9} | {'numpy':>9} | {'speed-up':>8}"
    for size in args.sizes:
        n = int(size)
        if args.profile:
            ti.profiler.clear_kernel_profiler_info()
        t_ti = measure(ti_backend, n, args.repeats)
        if args.profile:
            print(f"Taichi kernel profiler, {n} parcels (min: the fastest call, kernel time only)")
            ti.profiler.print_kernel_profiler_info()
        t_np = measure(np_backend, n, max(1, args.repeats // 2)) if n <= args.skip_numpy_above else None
        print(head)
        print("-" * len(head))
        for op, seconds in t_ti.items():
            rate = n / seconds / 1e6
            if t_np is None:
                print(f"{n:>9} | {op:<22} | {rate:9.2f} | {'-':>9} | {'-':>8}")
            else:
                np_rate = n / t_np[op] / 1e6
                print(f"{n:>9} | {op:<22} | {rate:9.2f} | {np_rate:9.2f} | {rate / np_rate:8.1f}")


if __name__ == "__main__":
    main()
