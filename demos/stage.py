"""A plug-and-perf stage of 5 clusters (hfgpu/scenes/stage_demo.toml, field units): the split of the fluid and of the
sand among the clusters, their created and propped areas, the wellbore pressure; with ``--sweep`` the sweep of
cluster spacing and perforations per cluster (demos/stage_sweep.toml) and its tornado of the clusters' propped-area
uniformity.

    python demos/stage.py [--out stage_output] [--sweep] [--workers N]

Writes ``<out>/stage.h5``, ``<out>/figures/*.png`` (``stage_split.png``: the fluid; ``stage_proppant.png``: one
panel per cluster and the sand split) and prints one row per cluster; ``--sweep`` adds ``<out>/sweep/`` (9 runs)
and its figures in ``<out>/sweep/plots`` (``tornado.png``). The stage runs in under a minute on 2 cores
(bench/bench_stage.py).
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

import hfgpu
from hfgpu.ensemble.plots import plot_ensemble
from hfgpu.io.plots import plot_results
from hfgpu.units import convert

SWEEP = Path(__file__).resolve().parent / "stage_sweep.toml"


def cluster_rows(path: Path) -> list[dict[str, float]]:
    """One dict per cluster of a stage's results file, in field units: fluid taken [bbl] and its share of the
    stage's, rate at the end [bbl/min], created area (one face) [ft^2], length and height [ft], inlet pressure [psi],
    its share of the sand and its propped area after closure [ft^2] (NaN without proppant)."""
    s = hfgpu.open_results(path).summary
    n = 0
    while f"cluster_{n}_area" in s:
        n += 1
    total = sum(s[f"cluster_{i}_injected"] for i in range(n))
    nan = float("nan")
    return [dict(cluster=i + 1, fluid=convert(s[f"cluster_{i}_injected"], "m**3", "bbl"),
                 share=s[f"cluster_{i}_injected"] / total, rate=convert(s[f"cluster_{i}_rate"], "m**3/s", "bbl/min"),
                 area=convert(s[f"cluster_{i}_area"], "m**2", "ft**2"),
                 length=convert(s[f"cluster_{i}_length"], "m", "ft"),
                 height=convert(s[f"cluster_{i}_height"], "m", "ft"),
                 p_inlet=convert(s[f"cluster_{i}_p_inlet"], "Pa", "psi"),
                 sand=s.get(f"cluster_{i}_solid_share", nan),
                 propped=convert(s.get(f"cluster_{i}_closure_propped_area", nan), "m**2", "ft**2"))
            for i in range(n)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="stage_output")
    parser.add_argument("--sweep", action="store_true", help="also run the spacing x perforations sweep")
    parser.add_argument("--workers", type=int, default=None, help="the sweep's local workers")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scene = hfgpu.load_scene((resources.files("hfgpu") / "scenes" / "stage_demo.toml").read_text())
    hfgpu.run(scene, out / "stage.h5", progress=True)
    for path in plot_results(out / "stage.h5", out / "figures"):
        print(path)
    print(f"{'cluster':>7} {'fluid [bbl]':>11} {'share':>6} {'rate [bbl/min]':>14} {'area [ft^2]':>11} "
          f"{'length [ft]':>11} {'height [ft]':>11} {'inlet [psi]':>11} {'sand share':>10} {'propped [ft^2]':>14}")
    for r in cluster_rows(out / "stage.h5"):
        print(f"{r['cluster']:>7} {r['fluid']:>11.1f} {r['share']:>6.3f} {r['rate']:>14.2f} {r['area']:>11.0f} "
              f"{r['length']:>11.0f} {r['height']:>11.0f} {r['p_inlet']:>11.0f} {r['sand']:>10.3f} "
              f"{r['propped']:>14.0f}")
    if args.sweep:
        hfgpu.sweep(SWEEP, out / "sweep", workers=args.workers)
        for path in plot_ensemble(out / "sweep", out / "sweep" / "plots"):
            print(path)


if __name__ == "__main__":
    main()
