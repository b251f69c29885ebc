"""How firm a designed tip screen-out is: hfgpu/scenes/frac_pack_tso.toml two-way over random seeds, cell sizes and
coupling intervals (docs/field-case.md, "A designed tip screen-out").

    python bench/screen_out_study.py                                   # seeds 0-3, the scene's cells and interval
    python bench/screen_out_study.py --cells "20 ft,5 ft" "10 ft,5 ft" "5 ft,2.5 ft" --seeds 0 1
    python bench/screen_out_study.py --every "10 s" "5 s" --seeds 0 1

One row a run: the tip screen-out time, the net-pressure rise after it, the packed length, the front's length at
the screen-out, its longest after it (a break-through) and at shut-in, the propped area after closure, the
fracture steps and the wall time. The runs are deterministic; a seed moves only the parcels' random draws.
"""

from __future__ import annotations

import argparse
import itertools
import tempfile
import time
from pathlib import Path

import numpy as np

import hfgpu
from hfgpu.scene_text import edit_scene
from hfgpu.units import in_display_units

SHUT_IN = 600.0  # [s], the scene's schedule: 2 min pad, 8 min slurry


def ft(metres: float) -> float:
    return in_display_units(metres, "length", "field")


def one(scene, folder: Path, cells: str, every: str, seed: int) -> str:
    """Run one variant of the scene; its table row."""
    edits = {"run.seed": seed, "coupling.fracture_every": every,
             "mesh.cell_size": [c.strip() for c in cells.split(",")]}
    t0 = time.perf_counter()
    path = folder / "run.h5"
    s = hfgpu.run(edit_scene(scene, edits), path, progress=False)
    wall = time.perf_counter() - t0
    b = hfgpu.open_results(path).fracture_balance
    t, length = b["time"], b["length"]
    ts = s["tip_screen_out_time"]
    if np.isnan(ts):
        at, longest = float("nan"), float("nan")
    else:
        at = length[min(int(np.searchsorted(t, ts - 1e-9)), t.size - 1)]
        longest = length[(t >= ts) & (t <= SHUT_IN + 1e-9)].max()
    shut_in = length[min(int(np.searchsorted(t, SHUT_IN - 1e-9)), t.size - 1)]
    rise = in_display_units(s["net_pressure_rise"], "pressure", "field")
    return (f"| {cells} | {every} | {seed} | {ts:.0f} | {rise:.0f} | {ft(s['packed_length']):.0f} | {ft(at):.0f} | "
            f"{ft(longest):.0f} | {ft(shut_in):.0f} | "
            f"{in_display_units(s['closure_propped_area'], 'area', 'field'):.0f} | {s['fracture_steps']} | "
            f"{wall:.0f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3])
    parser.add_argument("--cells", nargs="+", default=["10 ft,5 ft"], help="fracture cells, length,height")
    parser.add_argument("--every", nargs="+", default=["10 s"], help="[coupling] fracture_every")
    args = parser.parse_args()
    scene = hfgpu.load_scene(hfgpu.scene_path("frac_pack_tso.toml"))
    print("| cells | interval | seed | tip screen-out [s] | net-pressure rise [psi] | packed length [ft] | "
          "length then [ft] | longest after [ft] | at shut-in [ft] | propped after closure [ft^2] | "
          "fracture steps | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for cells, every, seed in itertools.product(args.cells, args.every, args.seeds):
            print(one(scene, Path(folder), cells, every, seed), flush=True)


if __name__ == "__main__":
    main()
