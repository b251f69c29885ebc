"""The prepared GPU check: the MP-PIC engine on CUDA at 1e5, 1e6 and 1e7 parcels, then the kernel tests on CUDA.

    python bench/bench_gpu.py [--sizes 1e5 1e6 1e7] [--tests]

Run as it is on a machine with a CUDA GPU (it refuses to run where Taichi falls back to the CPU). Prints, per
size, bench_kernels' table (wall and kernel ms per fluid step of 4 sub-steps, launches, whole sub-step in
parcel-updates/s) with the device memory the engine holds per parcel and in all, then Taichi's kernel
profiler table of the last size: on CUDA it lists each pass of a launch (scatter, cell fields, gather, push,
exchange, face means) as its own task. ``--tests`` then runs tests/kernels with HFGPU_ARCH=cuda (the Taichi
engine against the NumPy oracle on the GPU, atomics included). Target (issue 14): >= 2e9 parcel-updates/s
at 1e7 parcels in float64 on an H200-class GPU.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

from bench_kernels import NX, NZ, make_case, measure

from hfgpu.kernels.runtime import init, ti


def engine_bytes(n: int) -> tuple[int, int]:
    """Device bytes per parcel of capacity and in all of a Taichi engine holding ``n`` parcels."""
    from hfgpu.proppant.engine import make_engine
    from hfgpu.proppant.params import MppicParams

    grid, parcels, _ = make_case(n)
    engine = make_engine("taichi", grid, MppicParams(), 1000.0, 1e-3, 9.81, grid.width == -1.0)
    engine.set_parcels(parcels)
    return engine.device_bytes()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e5, 1e6, 1e7])
    ap.add_argument("--tests", action="store_true")
    args = ap.parse_args()
    if init("cuda", kernel_profiler=True) != "cuda":
        sys.exit("bench_gpu: no CUDA device (Taichi runs on the CPU); run bench/bench_kernels.py instead")
    print(f"grid {NX} x {NZ}, CUDA, 4 sub-steps per fluid step, best of 5")
    head = (f"{'parcels':>9} | {'wall ms':>9} | {'kernel ms':>9} | {'launches':>8} | {'sub-step G/s (kernel)':>21} | "
            f"{'B/parcel':>8} | {'engine MB':>9}")
    print(head)
    print("-" * len(head))
    for size in args.sizes:
        n = int(size)
        t = measure("taichi", n, 4, 5, profile=True)
        per_parcel, total = engine_bytes(n)
        print(f"{n:>9} | {1e3 * t['wall']:9.2f} | {1e3 * t['kernels']:9.2f} | {t['launches']:8.0f} | "
              f"{n / t['substep'] / 1e9:21.3f} | {per_parcel:8.0f} | {total / 2 ** 20:9.1f}")
    ti.profiler.clear_kernel_profiler_info()
    measure("taichi", int(args.sizes[-1]), 4, 1, profile=False)
    ti.profiler.print_kernel_profiler_info()
    if args.tests:
        env = {**os.environ, "HFGPU_ARCH": "cuda"}
        sys.exit(subprocess.call([sys.executable, "-m", "pytest", "-q", "tests/kernels"], env=env))


if __name__ == "__main__":
    main()
