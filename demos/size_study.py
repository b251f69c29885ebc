"""Proppant size study of the paper's section 6.2 (Figs. 15-18): the field case with 30/50, 40/70 and 100 mesh
sand, from one command; prints a table of created area, propped area, propped fraction, packed fraction,
screen-out flags and the share of the scheduled solids held back at the packed perforation (screen-out), and
the closure values of each run (docs/closure.md): propped area after closure A_p (one face), effective propped
half-length x_p and height h_p, mean conductivity C (md ft) and F_CD = C / (k_f x_p) (needs the scene's
``[closure] formation_permeability``; NaN without it).

    python demos/size_study.py [--scaled] [--out size_output] [--sizes 30/50 40/70 "100 mesh"] [--backend numpy|taichi]

Only the sieve class changes between the runs (normal distribution over the sieve range, as the paper's
Fig. 15a-c). Each run writes ``<out>/<size>.h5`` (sizes with "/" written with "-", spaces with "_"); a run
that fails is reported with its last snapshot and the error.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from field_case import load, report  # the demos folder is on sys.path when run as a script

from hfgpu import open_results, run
from hfgpu.units import to_si

MD_FT = to_si("1 md*ft", "conductivity")  # [m^3]
PAPER = "paper (section 6.2): propped 30.9 % of the area for 30/50, 100 mesh +59.3 % over 30/50; packed " \
        "fraction at 3600 s ~0.71 (30/50) to ~0.18 (100 mesh)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scaled", action="store_true")
    parser.add_argument("--out", type=Path, default=Path("size_output"))
    parser.add_argument("--sizes", nargs="+", default=["30/50", "40/70", "100 mesh"])
    parser.add_argument("--backend", choices=("taichi", "numpy"), default=None)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for size in args.sizes:
        path = args.out / f"{size.replace('/', '-').replace(' ', '_')}.h5"
        try:
            run(load(args.scaled, args.backend, size), path, progress=False)
            status = "complete"
        except Exception as exc:  # noqa: BLE001 -- the file keeps every snapshot written before the failure
            status = f"failed: {type(exc).__name__}: {exc}"
        summary = open_results(path).summary
        held = summary.get("proppant_screened_out", 0.0) / max(summary.get("proppant_injected", 0.0), 1e-300)
        closed = {k: summary.get(f"closure_{k}", float("nan"))
                  for k in ("propped_area", "propped_half_length", "propped_height", "mean_conductivity", "fcd")}
        rows.append((size, {**report(path), "held_back": held, "closed": closed}, status))
    print(f"{'size':>8} {'t end s':>8} {'created m^2':>12} {'propped m^2':>12} {'propped %':>10} {'packed':>7} "
          f"{'screen-out':>10} {'held back %':>11} {'A_p m^2':>8} {'x_p m':>6} {'h_p m':>6} {'C md ft':>8} "
          f"{'F_CD':>6}  status")
    for size, r, status in rows:
        c = r["closed"]
        print(f"{size:>8} {r['time']:8.1f} {r['created_area']:12.0f} {r['propped_area']:12.0f} "
              f"{100 * r['propped_fraction']:10.1f} {r['packed'][-1][1]:7.2f} {r['screen_out_cells']:10d} "
              f"{100 * r['held_back']:11.1f} {c['propped_area']:8.0f} {c['propped_half_length']:6.0f} "
              f"{c['propped_height']:6.1f} {c['mean_conductivity'] / MD_FT:8.0f} {c['fcd']:6.2f}  {status}")
    base = rows[0][1]["propped_area"]
    for size, r, _ in rows[1:]:
        if base > 0:
            print(f"propped area {size} vs {rows[0][0]}: {100 * (r['propped_area'] / base - 1):+.1f} %")
    print(PAPER)


if __name__ == "__main__":
    main()
