"""Grains rising in dense cells: the check of issue 34 ("no grain in a dense cell faster than 1 mm/s upward over
the five-layer run"), read from the proppant snapshots of results files, or from a scene run first.

A parcel is in a dense cell where theta_p of the cell that owns it is at least ``--dense`` (0.5, the
``friction_volume_fraction`` at which the model treats a cell as a contact network); it rises where its depth
velocity v < -``--speed`` (1 mm/s; depth grows downwards). For each file the table gives the parcel-snapshots in
dense cells, those rising, the fastest, the snapshot and cell (row k, column i) that holds the most, and how far the
last snapshot's packing alternates from cell to cell (hfgpu.proppant.analysis.alternation).

    python bench/rising_grains.py results.h5 [more.h5 ...]
    python bench/rising_grains.py --scene hfgpu/scenes/five_layer.toml --out rising_output   # runs it (~1 min)
    python bench/rising_grains.py --scene hfgpu/scenes/five_layer.toml --set mppic.damping=false --out rising_output
    python bench/rising_grains.py --scene hfgpu/scenes/five_layer.toml --seeds 1 2 3   # one run per random seed

The counts follow the run's path: on the five-layer base case they vary several-fold from seed to seed.
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

import numpy as np

from hfgpu import load_scene, open_results, run
from hfgpu.kernels.stencil_numpy import owning_cell
from hfgpu.scene_text import assignment, edit_scene
from hfgpu.proppant.analysis import alternation


def rising(path: Path, dense: float, speed: float) -> dict:
    """Counts over every proppant snapshot of the results file ``path``."""
    total, up, fastest, where, theta = 0, 0, 0.0, Counter(), None
    for snap in open_results(path).proppant_snapshots:
        theta = np.asarray(snap.grid["volume_fraction"])
        p = snap.parcels
        if p["x"].size == 0:
            continue
        k, i, inside = owning_cell(p["x"], p["z"], snap.frame, theta.shape)
        in_dense = inside & (theta[k, i] >= dense)
        lifted = in_dense & (p["v"] < -speed)
        total += int(in_dense.sum())
        up += int(lifted.sum())
        if lifted.any():
            fastest = max(fastest, float(-p["v"][lifted].min()))
            where.update((snap.time, int(a), int(b)) for a, b in zip(k[lifted], i[lifted]))
    return dict(total=total, up=up, fastest=fastest, where=where.most_common(1),
                alternation=alternation(theta) if theta is not None else (0, 0.0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", nargs="*", type=Path, help="results files (HDF5) to read")
    parser.add_argument("--scene", type=Path, help="run this scene first (its results file goes to --out)")
    parser.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE", type=assignment,
                        help="scene keys of the --scene run, e.g. mppic.damping=false")
    parser.add_argument("--seeds", nargs="+", type=int, default=[], help="run the scene once per run.seed")
    parser.add_argument("--out", type=Path, default=Path("rising_output"))
    parser.add_argument("--dense", type=float, default=0.5, help="theta_p of a dense cell")
    parser.add_argument("--speed", type=float, default=1e-3, help="rising speed counted [m/s]")
    args = parser.parse_args()
    paths = list(args.results)
    if args.scene is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        for seed in args.seeds or [None]:
            changes = dict(args.set) | ({} if seed is None else {"run.seed": seed})
            paths.append(args.out / f"{args.scene.stem}{'' if seed is None else f'_seed{seed}'}.h5")
            run(edit_scene(load_scene(args.scene), changes), paths[-1], progress=False)
    if not paths:
        parser.error("give results files or --scene")
    print(f"parcels in cells at theta_p >= {args.dense:g} rising faster than {args.speed * 1e3:g} mm/s, "
          "over the proppant snapshots")
    print("| results | dense parcel-snapshots | rising | fastest [mm/s] | most at (time [s], k, i): count | "
          "alternating at the end |")
    print("|---|---|---|---|---|---|")
    for path in paths:
        r = rising(path, args.dense, args.speed)
        most = "; ".join(f"({t:g}, {k}, {i}): {n}" for (t, k, i), n in r["where"]) or "-"
        cells, share = r["alternation"]
        print(f"| {path} | {r['total']} | {r['up']} | {1e3 * r['fastest']:.1f} | {most} | "
              f"{100 * share:.0f} % of {cells} |", flush=True)


if __name__ == "__main__":
    main()
