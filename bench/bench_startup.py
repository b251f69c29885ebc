"""What a process pays before its first MP-PIC step: Taichi's preparation (import, init, the engine's kernels
built or loaded from the offline cache), measured in fresh processes.

    python bench/bench_startup.py [--runs 3] [--arch cpu]

Each run is a new Python process that imports hfgpu's Taichi runtime, initialises it, builds a Taichi engine
on a 20 x 10 grid with 100 parcels and runs one fluid step of 4 sub-steps (every kernel of a run then
compiled or loaded). The first run of a machine (or after a kernel changed) compiles and fills Taichi's
offline cache (~/.cache/taichi); the later ones load from it. Prints seconds per phase and run; asserts
nothing.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
from hfgpu.kernels.runtime import init
arch = init(sys.argv[1])
t1 = time.perf_counter()
import numpy as np
from hfgpu.proppant.engine import make_engine
from hfgpu.proppant.grid import StaggeredGrid
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
grid = StaggeredGrid.box(0.2, 0.1, 2e-3, 20, 10)
rng = np.random.default_rng(0)
parcels = Parcels.create(rng.uniform(0, 0.2, 100), rng.uniform(0, 0.1, 100), radius=1e-4, density=2650.0,
                         particles=10.0)
engine = make_engine("taichi", grid, MppicParams(), 1000.0, 1e-3, 9.81, np.zeros(grid.shape, bool), arch)
engine.set_parcels(parcels)
t2 = time.perf_counter()
engine.begin_step(np.zeros((10, 21)), np.zeros((11, 20)), np.zeros((10, 20)))
engine.substeps(1e-3, 4, 0.0)
engine.moments()
engine.commit()
t3 = time.perf_counter()
print(json.dumps(dict(init=t1 - t0, engine=t2 - t1, step=t3 - t2, total=t3 - t0)))
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--arch", default="cpu")
    args = ap.parse_args()
    print(f"{'run':>4} | {'import + init s':>15} | {'engine s':>8} | {'first step s':>12} | {'total s':>8}")
    for run in range(args.runs):
        out = subprocess.run([sys.executable, "-c", CHILD, args.arch], capture_output=True, text=True,
                             check=True).stdout.strip().splitlines()[-1]
        t = json.loads(out)
        print(f"{run + 1:>4} | {t['init']:15.2f} | {t['engine']:8.2f} | {t['step']:12.2f} | {t['total']:8.2f}")


if __name__ == "__main__":
    main()
