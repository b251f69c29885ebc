"""The field case's size study over several random seeds: mean and spread of what the paper reports.

Runs ``demos/size_study.py`` once per seed (``--set run.seed=N``, each into ``<out>/seed<N>/``; ``--reuse`` keeps
complete runs), then for each sieve size at the paper's Fig. 16 times (1260, 1800, 3600 s of the base case,
hfgpu.propped.results_times) prints the mean and the range over the seeds of

- the packed share of the parcels (|u_p| below hfgpu.propped.PACKED_SPEED, or bridged),
- the propped area in place (one packed grain layer, grains where they are) and its share of the created area,
- the share of the parcels bridged (state BRIDGED: a cell narrower than bridging_factor x the grain),
- the propped area after closure (``/closure``; the last time only),

beside the paper's section 6.2 numbers. Asserts nothing.

    python bench/field_seeds.py                          # seeds 1 2 3, sizes 30/50 40/70 "100 mesh"
    python bench/field_seeds.py --seeds 1 2 3 4 5 --sizes 40/70 --out seeds_output --reuse
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

from hfgpu import open_results
from hfgpu.kernels.layout import BRIDGED
from hfgpu.propped import packed_fraction, propped_cells, results_times

ROOT = Path(__file__).resolve().parents[1]
PAPER = ("paper (section 6.2, Figs. 15-16): propped 30.9 % of the area for 30/50, 100 mesh +59.3 % over 30/50; "
         "packed share at 3600 s ~0.71 (30/50) to ~0.18 (100 mesh)")


def result_path(out: Path, size: str) -> Path:
    """demos/size_study.py's file name for ``size`` in ``out``."""
    return out / f"{size.replace('/', '-').replace(' ', '_')}.h5"


def measures(path: Path) -> dict[float, dict[str, float]]:
    """{time: {packed, propped, propped_share, bridged}} at the Fig. 16 times, and the closure's propped area."""
    results = open_results(path)
    theta_cp = results.scene.proppant.params.theta_cp
    out = {}
    for t in results_times(results):
        snap = results.proppant_snapshots.at(t)
        cells = propped_cells(snap, theta_cp)
        created = float(np.count_nonzero(np.asarray(snap.grid["width"]) > 0.0)) * snap.frame.dx * snap.frame.dz
        propped = float(cells.sum()) * snap.frame.dx * snap.frame.dz
        state = np.asarray(snap.parcels["state"])
        out[float(snap.time)] = dict(packed=packed_fraction(snap.parcels), propped=propped,
                                     propped_share=propped / created if created > 0 else float("nan"),
                                     bridged=float(np.mean(state == BRIDGED)) if state.size else float("nan"))
    closure = results.summary.get("closure_propped_area", float("nan"))
    return {"runs": out, "closure": float(closure)}


def spread(values: list[float], scale: float = 1.0, decimals: int = 2) -> str:
    """'mean (min-max)' of ``values`` times ``scale``, with ``decimals`` decimals."""
    v = np.asarray(values, dtype=float) * scale
    return f"{np.mean(v):.{decimals}f} ({np.min(v):.{decimals}f}-{np.max(v):.{decimals}f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--sizes", nargs="+", default=["30/50", "40/70", "100 mesh"])
    parser.add_argument("--out", type=Path, default=Path("seeds_output"))
    parser.add_argument("--reuse", action="store_true", help="keep complete runs already in --out")
    args = parser.parse_args()
    for seed in args.seeds:
        out = args.out / f"seed{seed}"
        if args.reuse and all(result_path(out, s).exists() for s in args.sizes):
            continue
        subprocess.run([sys.executable, str(ROOT / "demos" / "size_study.py"), "--out", str(out), "--sizes",
                        *args.sizes, "--set", f"run.seed={seed}"] + (["--reuse"] if args.reuse else []),
                       check=True, stdout=subprocess.DEVNULL)
    print(f"seeds {args.seeds}; mean (min-max) over the seeds")
    print("| size | time [s] | packed share | propped in place [m^2] | of the created area | bridged parcels | "
          "propped after closure [m^2] |")
    print("|---|---|---|---|---|---|---|")
    for size in args.sizes:
        runs = [measures(result_path(args.out / f"seed{seed}", size)) for seed in args.seeds]
        times = sorted(runs[0]["runs"])
        for j, t in enumerate(times):
            rows = [r["runs"][sorted(r["runs"])[j]] for r in runs]
            closure = spread([r["closure"] for r in runs], decimals=0) if j == len(times) - 1 else ""
            print(f"| {size} | {t:.0f} | {spread([r['packed'] for r in rows])} | "
                  f"{spread([r['propped'] for r in rows], decimals=0)} | "
                  f"{spread([r['propped_share'] for r in rows], 100, 1)} % | "
                  f"{spread([r['bridged'] for r in rows], 100, 2)} % | {closure} |")
    print(PAPER)


if __name__ == "__main__":
    main()
