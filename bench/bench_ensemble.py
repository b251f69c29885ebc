"""Ensemble throughput on Dask (docs/ensembles.md): the same sweep of the scaled field demo
(hfgpu/scenes/five_layer_demo.toml, leak-off coefficient varied on a Latin hypercube) run with 1 and with 2 local
worker processes; prints the wall times, the parallel efficiency and the expected wall time of a 200-member
study on N cores.

    python bench/bench_ensemble.py [--members 16] [--workers 1 2] [--preset fast] [--base-case 64]

Wall time counts everything ``hfgpu.sweep`` does: checking the members, starting and closing the local
cluster (each worker process also compiles the Taichi kernels once, about 3 s), the runs, summary.csv and
ensemble.h5. Parallel efficiency with N workers = T_1 / (N T_N); on a machine whose cores other work uses
too, it says more about that work. The 200-member estimate is 200 t_member / (N e), with t_member =
T_1 / members (or ``--base-case`` seconds for the field base case, hfgpu/scenes/five_layer.toml) and e the
efficiency measured with the most workers. Asserts nothing.
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

import hfgpu

SCENE = Path(hfgpu.__file__).parent / "scenes" / "five_layer_demo.toml"

SWEEP = """scene = "base.toml"
members = {members}
seed = 1
[[vary]]
key = "rock.leakoff_coefficient"
distribution = "log-uniform"
low = "1e-7 m/s**0.5"
high = "1e-6 m/s**0.5"
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--members", type=int, default=16)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--preset", choices=("fast", "balanced", "accurate"), help="default: the scene's own")
    parser.add_argument("--out", type=Path, default=Path("bench_ensemble_output"))
    parser.add_argument("--base-case", type=float, default=64.0, help="wall seconds of one run of the 3600 s "
                        "base case (docs/field-case.md: 64 s)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    scene = hfgpu.load_scene(SCENE)
    if args.preset:
        scene = hfgpu.edit_scene(scene, {"run.preset": args.preset})
    (args.out / "base.toml").write_text(scene.source, encoding="utf-8")
    (args.out / "sweep.toml").write_text(SWEEP.format(members=args.members), encoding="utf-8")
    walls = {}
    for workers in args.workers:
        folder = args.out / f"workers_{workers}"
        shutil.rmtree(folder, ignore_errors=True)
        start = time.perf_counter()
        rows = hfgpu.sweep(args.out / "sweep.toml", folder, workers=workers, progress=False)
        walls[workers] = time.perf_counter() - start
        done = sum(r["status"] == "complete" for r in rows)
        print(f"{args.members} members, {workers} worker(s): {walls[workers]:.1f} s wall ({done} complete)")
    first = min(walls)
    for workers, wall in walls.items():
        print(f"parallel efficiency with {workers} worker(s): {walls[first] * first / (workers * wall):.2f}")
    most = max(walls)
    member = walls[first] * first / args.members
    efficiency = walls[first] * first / (most * walls[most])
    print(f"one member: {member:.1f} s of one core; 200 members at efficiency {efficiency:.2f}, of this scene and "
          f"of the {args.base_case:g} s base case (five_layer.toml):")
    for cores in (2, 8, 32, 128):
        print(f"  {cores:>4} cores: {200 * member / (cores * efficiency) / 60:8.1f} min"
              f"{200 * args.base_case / (cores * efficiency) / 3600:8.1f} h")


if __name__ == "__main__":
    main()
