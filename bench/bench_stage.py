"""What a stage of several clusters costs: the 5-cluster stage of demos/stage.py (hfgpu/scenes/stage_demo.toml,
10 ft cells, 10 min at 40 bbl/min, 7 min of it 40/70 sand) against one of its clusters alone (the same scene with
one cluster at 8 bbl/min: the single-fracture engine's steps, hfgpu.fracture.stage runs it unchanged). Each run is
the coupled stage (hfgpu.coupled_stage: the clusters' fractures, then all their proppant in one MP-PIC engine)
timed inside one process (no process start, no results file), ``--repeats`` times, interleaved; the table gives
the median wall seconds, split into the fracture and proppant phases, the stage's time steps, its coupled
iterations (each one step of every plane, hfgpu.fracture.stage), the plane steps per second, the proppant's fluid
steps and the clusters' created-area uniformity. Target (issue 36): the 5-cluster stage within 5 minutes on
2 cores; the proppant of N clusters in one engine should cost less than N single clusters' proppant.

    python bench/bench_stage.py [--repeats 1] [--clusters 5]

``python bench/bench_elasticity.py --planes 3000`` measures the N-plane elasticity product against N^2
single-plane products. Asserts nothing.
"""

from __future__ import annotations

import argparse
import statistics
import time
import tomllib
from importlib import resources

from hfgpu import coupled_stage
from hfgpu.records import MemorySink
from hfgpu.scene import load_scene
from hfgpu.scene_text import toml_text


def scene(clusters: int):
    """The demo's stage with ``clusters`` clusters, the pump rate scaled to keep 8 bbl/min a cluster."""
    data = tomllib.loads((resources.files("hfgpu") / "scenes" / "stage_demo.toml").read_text())
    data["completion"]["clusters"] = clusters
    for pumped in data["injection"]["schedule"]:
        pumped["rate"] = f"{8 * clusters} bbl/min"
    return load_scene(toml_text(data))


def timed(clusters: int) -> tuple[float, dict]:
    start = time.perf_counter()
    summary = coupled_stage.simulate(scene(clusters), MemorySink())
    return time.perf_counter() - start, summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--clusters", type=int, default=5)
    args = parser.parse_args()
    cases = (1, args.clusters)
    walls: dict[int, list[float]] = {n: [] for n in cases}
    summaries: dict[int, dict] = {}
    for _ in range(args.repeats):
        for n in cases:
            wall, summaries[n] = timed(n)
            walls[n].append(wall)
    print(f"{'clusters':>8} {'wall [s]':>9} {'fracture [s]':>12} {'proppant [s]':>12} {'steps':>6} "
          f"{'iterations':>10} {'plane steps/s':>13} {'fluid steps':>11} {'area uniformity':>15}")
    for n in cases:
        s, wall = summaries[n], statistics.median(walls[n])
        areas = [s[f"cluster_{i}_area"] for i in range(n)]
        proppant = s["time_fluid"] + s["time_parcels"]
        print(f"{n:>8} {wall:>9.1f} {s['time_fracture']:>12.1f} {proppant:>12.1f} {s['fracture_steps']:>6} "
              f"{s['fracture_stage_iterations']:>10} {n * s['fracture_stage_iterations'] / wall:>13.1f} "
              f"{s['proppant_steps']:>11} {min(areas) / (sum(areas) / len(areas)):>15.3f}")

if __name__ == "__main__":
    main()
