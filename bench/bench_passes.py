"""The passes of one MP-PIC sub-step (kernels/engine.py ``substep``) timed one by one on the CPU: what bounds
the sub-step. On the CPU Taichi's profiler sees a launch, not its passes, so each pass runs here as its own
kernel on the engine's arrays after a warm-up fluid step (bench_kernels.py's case: grid 200 x 100, random
parcels), and the whole ``substep`` launch is timed beside them for comparison.

    python bench/bench_passes.py [--sizes 1e4 1e5 1e6] [--threads 2] [--repeats 5]

Prints, per size, the best of ``repeats`` wall times of each pass (a launch with its synchronisation, ~0.1 ms
of which is the launch itself: read the small sizes with that in mind) in ms and in ns per parcel. Asserts
nothing.
"""

import argparse
import time

import numpy as np
from bench_kernels import DT, G, MU, RHO_F, fluid_step, make_case

from hfgpu.kernels import engine as launches
from hfgpu.kernels import grid, particles
from hfgpu.kernels.engine import F1, F2, F3, F4, I2
from hfgpu.kernels.layout import MOMENT_COUNT, P_DX, P_DZ
from hfgpu.kernels.runtime import init, ti
from hfgpu.proppant.engine import make_engine
from hfgpu.proppant.params import MppicParams

# the sub-step's passes as separate kernels (same arguments and order as kernels.engine.substep); annotations
# are evaluated by Taichi, so this file does not use `from __future__ import annotations`


@ti.kernel
def zero(CD: F4, XD: F4, ZD: F4, copies: ti.i32):
    grid.zero_copies(CD, copies, MOMENT_COUNT)
    grid.zero_copies(XD, copies, 2)
    grid.zero_copies(ZD, copies, 2)


@ti.kernel
def scatter(P: F2, S: I2, C: F3, FLAGS: I2, CD: F4, BS: F2, PR: F1, ST: F1, n: ti.i32, blocks: ti.i32,
            private: ti.template()):
    particles.scatter_pass(P, S, n, C, FLAGS, CD, BS, blocks, private, PR, ST)


@ti.kernel
def cells(C: F3, CD: F4, XF: F3, ZF: F3, FLAGS: I2, PR: F1, copies: ti.i32):
    grid.finish_cells(C, CD, copies, PR)
    grid.flags_pass(C, FLAGS, PR)
    grid.stress_gradient(C, XF, PR[P_DX], 1)
    grid.stress_gradient(C, ZF, PR[P_DZ], 0)


@ti.kernel
def gather(P: F2, S: I2, W: F2, C: F3, XF: F3, ZF: F3, FLAGS: I2, PR: F1, n: ti.i32):
    particles.gather_pass(P, S, W, n, C, XF, ZF, FLAGS, PR, 0)


@ti.kernel
def push(P: F2, S: I2, W: F2, C: F3, FLAGS: I2, PR: F1, n: ti.i32, h: ti.f64):
    particles.push_pass(P, S, W, n, C, FLAGS, h, PR)


@ti.kernel
def exchange(P: F2, S: I2, W: F2, C: F3, XF: F3, ZF: F3, XD: F4, ZD: F4, BS: F2, PR: F1,
             ST: F1, n: ti.i32, blocks: ti.i32, private: ti.template()):
    particles.exchange_pass(P, S, W, n, C, XF, ZF, XD, ZD, BS, blocks, private, PR, ST, 1)


@ti.kernel
def faces(C: F3, XF: F3, ZF: F3, XD: F4, ZD: F4, PR: F1, copies: ti.i32):
    grid.finish_faces(C, XF, XD, copies, 4.0, 0, PR, 1)
    grid.finish_faces(C, ZF, ZD, copies, 4.0, 0, PR, 0)



def calls(engine) -> dict:
    """name -> a call of that pass on ``engine``'s arrays (and the whole sub-step launch)."""
    e, h = engine, DT / 4
    P, S = e._buffers[e._current]
    blocks, copies = e._blocks()
    return {
        "zero copies": lambda: zero(e._cd, e._xd, e._zd, copies),
        "scatter": lambda: scatter(P, S, e._cells, e._flags, e._cd, e._block_sums, e._params, e._stats, e.n,
                                   blocks, e.private),
        "cell fields": lambda: cells(e._cells, e._cd, e._xf, e._zf, e._flags, e._params, copies),
        "gather": lambda: gather(P, S, e._work_rows, e._cells, e._xf, e._zf, e._flags, e._params, e.n),
        "push": lambda: push(P, S, e._work_rows, e._cells, e._flags, e._params, e.n, h),
        "exchange": lambda: exchange(P, S, e._work_rows, e._cells, e._xf, e._zf, e._xd, e._zd,
                                     e._block_sums, e._params, e._stats, e.n, blocks, e.private),
        "face means": lambda: faces(e._cells, e._xf, e._zf, e._xd, e._zd, e._params, copies),
        "whole substep": lambda: launches.substep(P, S, e._work_rows, e._cells, e._xf, e._zf, e._flags, e._cd,
                                                  e._xd, e._zd, e._block_sums, e._params, e._stats, e.n, blocks,
                                                  copies, e.private, h, 1, 4.0),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e4, 1e5, 1e6])
    ap.add_argument("--threads", type=int, default=None, help="Taichi CPU threads (default: all cores)")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    init("cpu", cpu_threads=args.threads)
    print(f"Taichi CPU, {ti.lang.impl.current_cfg().cpu_max_num_threads} threads; best of {args.repeats}")
    for size in args.sizes:
        n = int(size)
        grid, parcels, fluid = make_case(n)
        engine = make_engine("taichi", grid, MppicParams(), RHO_F, MU, G, np.zeros(grid.shape, dtype=bool))
        engine.set_parcels(parcels)
        fluid_step(engine, fluid, 4)
        engine.begin_step(*fluid)
        blocks, copies = engine._blocks()
        print(f"\n{n} parcels on {grid.shape[0]} x {grid.shape[1]} cells ({copies} deposit copies)")
        print(f"{'pass':<14} | {'ms':>8} | {'ns/parcel':>9}")
        for name, call in calls(engine).items():
            call()
            ti.sync()
            best = np.inf
            for _ in range(args.repeats):
                t = time.perf_counter()
                call()
                ti.sync()
                best = min(best, time.perf_counter() - t)
            print(f"{name:<14} | {1e3 * best:8.2f} | {1e9 * best / n:9.1f}")


if __name__ == "__main__":
    main()
