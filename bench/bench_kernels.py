"""The MP-PIC particle engine: time per fluid step against the time its kernels take, and parcel-updates/s.

    python bench/bench_kernels.py [--sizes 1e4 1e5 1e6] [--arch cpu] [--threads 2] [--substeps 4]
                                  [--steps 5] [--numpy-up-to 1e5] [--averaging dual moment]

Grid 200 x 100 cells (nx x nz), a random open/closed width field, random parcels in open cells, random fluid.
A fluid step is what the run loop does with the engine: begin_step (sort by cell, compaction, fluid in),
``substeps`` sub-steps, moments (theta_p out), commit. Columns per size (best of ``steps`` fluid steps after
one warm-up step; the machine may be shared): wall ms per fluid step, the kernels' own ms in it (Taichi's
kernel profiler: device time without Python, launch and argument overhead), their ratio (the overhead
target: <= 2 at 1e4-1e5 parcels), the launches per fluid step, the whole sub-step in M parcel-updates/s from
its kernel time and from wall time, and the NumPy engine's wall ms per fluid step (the oracle) up to
``--numpy-up-to`` parcels; one table per ``--averaging`` name (hfgpu.kernels.closures.averaging). Asserts
nothing. bench/bench_gpu.py runs the same on CUDA.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hfgpu.kernels.runtime import init, ti
from hfgpu.proppant.engine import make_engine
from hfgpu.proppant.grid import StaggeredGrid
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

NX, NZ = 200, 100
RHO_F, MU, G, DT = 1000.0, 1e-3, 9.81, 4e-4


def make_case(n: int, seed: int = 0):
    """Grid, fluid fields (u, v, p) and ``n`` parcels (uniform over the open cells)."""
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
    return StaggeredGrid.from_width(frame, width), parcels, fluid


def fluid_step(engine, fluid, substeps: int, profile: bool = False) -> tuple[float, float]:
    """One fluid step of the run loop's particle side; returns (kernel seconds of the whole step, of its
    sub-steps) from Taichi's profiler when ``profile``."""
    clock = Profiler(profile)
    engine.begin_step(*fluid)
    before = clock.read()
    engine.substeps(DT, substeps, 0.0)
    during = clock.read()
    engine.moments()
    engine.commit()
    return before + during + clock.read(), during


class Profiler:
    """Kernel seconds since the last read (Taichi's kernel profiler; 0 when off)."""

    def __init__(self, on: bool):
        self.on = on
        self.read()

    def read(self) -> float:
        if not self.on:
            return 0.0
        ti.sync()
        total = ti.profiler.get_kernel_profiler_total_time()
        ti.profiler.clear_kernel_profiler_info()
        return total


def measure(name: str, n: int, substeps: int, steps: int, profile: bool, averaging: str = "dual") -> dict[str, float]:
    """Wall and kernel seconds per fluid step, launches per fluid step and the sub-steps' kernel seconds of
    engine ``name`` at ``n`` parcels with ``averaging`` (the fluid step of least wall time)."""
    grid, parcels, fluid = make_case(n)
    engine = make_engine(name, grid, MppicParams(averaging=averaging), RHO_F, MU, G,
                         np.zeros(grid.shape, dtype=bool))
    engine.set_parcels(parcels)
    fluid_step(engine, fluid, substeps)
    rows = []
    for _ in range(steps):
        launches = getattr(engine, "launches", 0)
        t = time.perf_counter()
        kernels, sub = fluid_step(engine, fluid, substeps, profile)
        rows.append((time.perf_counter() - t, kernels, sub, getattr(engine, "launches", 0) - launches))
    wall, kernels, sub, launches = min(rows)
    return dict(wall=wall, kernels=kernels, substep=sub / substeps, launches=launches)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e4, 1e5, 1e6])
    ap.add_argument("--arch", default=None, help="Taichi arch: cpu or cuda (default HFGPU_ARCH or cpu)")
    ap.add_argument("--threads", type=int, default=None, help="Taichi CPU threads (default: all cores)")
    ap.add_argument("--substeps", type=int, default=4)
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--numpy-up-to", type=float, default=1e5)
    ap.add_argument("--averaging", nargs="+", default=["dual"], help="averaging names, one table each")
    args = ap.parse_args()
    arch = init(args.arch, kernel_profiler=True, cpu_threads=args.threads)
    threads = ti.lang.impl.current_cfg().cpu_max_num_threads if arch == "cpu" else "-"
    for averaging in args.averaging:
        print(f"grid {NX} x {NZ}, {args.substeps} sub-steps per fluid step, Taichi on {arch} ({threads} threads); "
              f"best of {args.steps} fluid steps; averaging {averaging!r}")
        head = (f"{'parcels':>9} | {'wall ms':>9} | {'kernel ms':>9} | {'wall/kernel':>11} | {'launches':>8} | "
                f"{'sub-step M/s (kernel)':>21} | {'(wall)':>7} | {'numpy ms':>9}")
        print(head)
        print("-" * len(head))
        for size in args.sizes:
            n = int(size)
            t = measure("taichi", n, args.substeps, args.steps, profile=True, averaging=averaging)
            numpy_ms = (f"{1e3 * measure('numpy', n, args.substeps, 2, False, averaging)['wall']:9.1f}"
                        if n <= args.numpy_up_to else f"{'-':>9}")
            print(f"{n:>9} | {1e3 * t['wall']:9.2f} | {1e3 * t['kernels']:9.2f} | {t['wall'] / t['kernels']:11.2f} | "
                  f"{t['launches']:8.0f} | {n / t['substep'] / 1e6:21.1f} | "
                  f"{n * args.substeps / t['wall'] / 1e6:7.1f} | {numpy_ms}")


if __name__ == "__main__":
    main()
