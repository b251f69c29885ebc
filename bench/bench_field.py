"""Wall time of the field case end to end (hfgpu/scenes/five_layer.toml, or the scaled five_layer_demo.toml),
split into phases measured with time.perf_counter inside the coupled run (hfgpu.coupled.Timings):
fracture (the fracture engine), fluid (SIMPLE steps), parcels (particle sub-loops), io (results file and
other sinks), other (the rest: scatter, injection, width resampling, set-up). Prints a table; asserts nothing.

    python bench/bench_field.py [--scaled] [--backend numpy|taichi] [--out bench_field.h5]

Targets: the base case within 10 minutes and the scaled demo within 2 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "demos"))

from field_case import load  # noqa: E402

from hfgpu import run  # noqa: E402

PHASES = ("fracture", "fluid", "parcels", "io")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scaled", action="store_true")
    parser.add_argument("--backend", choices=("taichi", "numpy"), default=None)
    parser.add_argument("--out", type=Path, default=Path("bench_field.h5"))
    args = parser.parse_args()
    scene = load(args.scaled, args.backend)
    t0 = time.perf_counter()
    summary = run(scene, args.out, progress=False)
    total = time.perf_counter() - t0
    rows = [(name, summary[f"time_{name}"]) for name in PHASES]
    rows.append(("other", total - sum(t for _, t in rows)))
    rows.append(("total", total))
    print(f"field case ({'scaled' if args.scaled else 'base'}), backend {summary['proppant_backend']}: "
          f"fracture {summary['fracture_steps']} steps, {summary['fracture_cells']} cells; proppant grid "
          f"{summary['proppant_nz']} x {summary['proppant_nx']}, {summary['proppant_steps']} steps, "
          f"{summary['proppant_parcels']} parcels at the end")
    print(f"{'phase':>9} {'wall [s]':>9} {'share':>6}")
    for name, seconds in rows:
        print(f"{name:>9} {seconds:9.2f} {100 * seconds / total:5.1f}%")


if __name__ == "__main__":
    main()
