"""One-way against two-way coupling on a scene (``[coupling] mode``): wall time split by phase and what moves
(created and propped area, net pressure at the end and its largest value, tip screen-out, packed length).
Prints a table; asserts nothing. Each mode runs in its own results file.

    python bench/bench_two_way.py [SCENE ...] [--out DIR] [--modes two-way]   # default: the five-layer base
                                                                                # case and the demo, both modes

Phases (hfgpu.coupled.Timings): fracture, fluid, parcels, io, and for two-way footprint (the clean-fluid pass
that sizes the proppant grid) and feedback (the slurry fields handed to the fracture); other is the rest.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from hfgpu import load_scene, open_results, run
from hfgpu.scene_text import edit_scene

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = [ROOT / "hfgpu" / "scenes" / "five_layer.toml", ROOT / "hfgpu" / "scenes" / "slickwater_demo.toml"]
PHASES = ("fracture", "footprint", "feedback", "fluid", "parcels", "io")


def measure(path: Path, mode: str, out: Path) -> dict:
    """The run of ``path`` in ``mode``: its summary, total wall time and largest net pressure."""
    scene = edit_scene(load_scene(path), {"coupling.mode": mode})
    t0 = time.perf_counter()
    summary = run(scene, out, progress=False)
    summary["wall"] = time.perf_counter() - t0
    summary["net_pressure_max"] = float(np.max(open_results(out).fracture_balance["net_pressure"]))
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", type=Path, default=DEFAULT)
    parser.add_argument("--out", type=Path, default=Path("bench_two_way"))
    parser.add_argument("--modes", nargs="+", choices=("one-way", "two-way"), default=["one-way", "two-way"])
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for path in args.scenes:
        rows = {mode: measure(path, mode, args.out / f"{path.stem}_{mode}.h5") for mode in args.modes}
        print(f"{path.name}")
        print(f"{'':>24} " + " ".join(f"{mode:>12}" for mode in rows))
        for name in PHASES:
            print(f"{'time ' + name + ' [s]':>24} " + " ".join(f"{r.get(f'time_{name}', 0.0):12.1f}"
                                                              for r in rows.values()))
        for label, key, scale in (("wall [s]", "wall", 1.0), ("created area [m^2]", "fracture_area", 1.0),
                                  ("propped area [m^2]", "closure_propped_area", 1.0),
                                  ("net pressure end [MPa]", "net_pressure_end", 1e-6),
                                  ("net pressure max [MPa]", "net_pressure_max", 1e-6),
                                  ("tip screen-out [s]", "tip_screen_out_time", 1.0),
                                  ("net pressure rise [MPa]", "net_pressure_rise", 1e-6),
                                  ("packed length [m]", "packed_length", 1.0),
                                  ("fracture balance", "fracture_max_balance_error", 1.0)):
            print(f"{label:>24} " + " ".join(f"{r.get(key, float('nan')) * scale:12.4g}" for r in rows.values()))
        print(flush=True)


if __name__ == "__main__":
    main()
