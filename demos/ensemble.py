"""A small ensemble study of the five-layer treatment (docs/ensembles.md): the scaled field demo
(hfgpu/scenes/five_layer_demo.toml, 90 s) at the fast preset with the leak-off coefficient, both barrier
stresses and the proppant diameter varied on a Latin hypercube; runs it on a local Dask cluster, prints the
P10 / P50 / P90 of each metric and writes the figures.

    python demos/ensemble.py [--out ensemble_output] [--members 8] [--workers N] [--resume]

A member takes about 30 s on one core, so the default 8 members take about 2 minutes on 2 cores. The base
scene is the demo scene with ``preset = "fast"`` and its 40/70 sieve class replaced by a single diameter
(300 um, the class's middle) so that the diameter can vary; it is written to ``<out>/base.toml`` beside the
sweep file ``<out>/sweep.toml``; the sweep goes to ``<out>/study`` and the figures to ``<out>/study/plots``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import hfgpu
from hfgpu.ensemble.plots import plot_ensemble
from hfgpu.ensemble.summary import read_ensemble

SCENE = Path(hfgpu.__file__).parent / "scenes" / "five_layer_demo.toml"

SWEEP = """scene = "base.toml"
members = {members}
design = "latin-hypercube"
seed = 1
[[vary]]
key = "rock.leakoff_coefficient"
distribution = "log-uniform"
low = "1e-7 m/s**0.5"
high = "1e-6 m/s**0.5"
[[vary]]
key = "rock.layers[0].min_stress"     # upper barrier
distribution = "triangular"
low = "63 MPa"
mode = "65 MPa"
high = "67 MPa"
[[vary]]
key = "rock.layers[4].min_stress"     # lower barrier
distribution = "triangular"
low = "63 MPa"
mode = "65 MPa"
high = "67 MPa"
[[vary]]
key = "proppant[0].diameter"
distribution = "uniform"
low = "212 um"
high = "420 um"
"""


def base_scene() -> str:
    """TOML text of the demo scene at the fast preset, its sieve class replaced by one diameter."""
    edited = hfgpu.edit_scene(hfgpu.load_scene(SCENE), {"run.preset": "fast", "proppant[0].size": None,
                                                        "proppant[0].diameter": "300 um"})
    return edited.source


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("ensemble_output"))
    parser.add_argument("--members", type=int, default=8)
    parser.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    parser.add_argument("--resume", action="store_true", help="keep the complete members of an earlier run")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "base.toml").write_text(base_scene(), encoding="utf-8")
    (args.out / "sweep.toml").write_text(SWEEP.format(members=args.members), encoding="utf-8")
    study = args.out / "study"
    rows = hfgpu.sweep(args.out / "sweep.toml", study, workers=args.workers, resume=args.resume)
    failed = [r for r in rows if r["status"] != "complete"]
    print(f"{len(rows) - len(failed)} of {len(rows)} members complete" + "".join(
        f"\n  {r['id']}: {r['status']}" for r in failed))
    data = read_ensemble(study / "ensemble.h5")
    print(f"{'metric':<20}{'P10':>14}{'P50':>14}{'P90':>14}")
    for name, (p10, p50, p90) in data["percentiles"].items():
        print(f"{name:<20}{p10:>14.4g}{p50:>14.4g}{p90:>14.4g}")
    for path in plot_ensemble(study, study / "plots"):
        print(path)


if __name__ == "__main__":
    main()
