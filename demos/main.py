"""The main demo: a slickwater treatment of a layered reservoir, fracture then proppant, with results and figures.

    python demos/main.py                      # the embedded scene, output in ./demo_output/
    python demos/main.py --scene SCENE.toml   # any coupled scene file
    python demos/main.py --view               # also stream live to a spawned Rerun viewer (needs a display)

The embedded scene (hfgpu/scenes/slickwater_demo.toml, field units): five layers, 40 bbl/min of slickwater, a
pad, 100 mesh then 40/70 sand ramped 0.5 -> 2 ppa, a shut-in; docs/field-case.md ("The main demo") says what
the figures show. Afterwards: ``rerun demo_output/main.rrd`` replays the run, ``demo_output/figures/*.png`` are
the figures (``hfgpu plot demo_output/main.h5`` redraws them from the results file alone).
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

import numpy as np

import hfgpu
from hfgpu.io.plots import plot_results
from hfgpu.io.results import open_results
from hfgpu.units import format_number

DEFAULT_SCENE = "slickwater_demo.toml"
#: A cell is counted as bed when its solid volume fraction is at least this share of close packing.
BED_SHARE = 0.95
KG_TO_LB = 1.0 / 0.45359237


def story(results_path: Path) -> dict:
    """What the summary table does not show, read back from the results file at the last proppant snapshot:
    parcels and proppant mass per class, bed cells (solid volume fraction >= BED_SHARE x theta_cp), cells
    flagged for bridging risk, and the share of the injected proppant held back at the inlet (screen-out)."""
    r = open_results(results_path)
    snap = r.proppant_snapshots[-1]
    classes = [c.name for c in r.scene.proppant.classes]
    p = snap.parcels
    class_id = np.asarray(p["class_id"])
    mass = np.asarray(p["particles"]) * np.pi / 6.0 * (2.0 * np.asarray(p["radius"]))**3 * np.asarray(p["density"])
    balance = {k: float(v[-1]) for k, v in r.proppant_balance.items()}
    theta = np.asarray(snap.grid["volume_fraction"])
    return dict(
        time=snap.time,
        parcels={name: int(np.sum(class_id == c)) for c, name in enumerate(classes)},
        mass={name: float(np.sum(mass[class_id == c])) for c, name in enumerate(classes)},
        bed_cells=int(np.sum(theta >= BED_SHARE * r.scene.proppant.params.theta_cp)),
        bridging_cells=int(np.count_nonzero(snap.grid.get("bridging_risk", 0))),
        held_back_share=balance["screened_out"] / balance["injected"] if balance["injected"] > 0.0 else 0.0)


def print_story(s: dict) -> None:
    print(f"proppant at t = {s['time']:.0f} s, by class and where it lies")
    for name, n in s["parcels"].items():
        print(f"  {name:<32}  {format_number(n)} parcels, {format_number(s['mass'][name] * KG_TO_LB)} lb")
    print(f"  {'bed cells':<32}  {s['bed_cells']} (solid fraction >= {BED_SHARE:g} x close packing)")
    print(f"  {'bridging-risk cells':<32}  {s['bridging_cells']} (width < bridging_factor x grain diameter)")
    print(f"  {'held back at the inlet':<32}  {100 * s['held_back_share']:.1f} % of the injected proppant")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", help=f"scene file (default: the embedded {DEFAULT_SCENE})")
    parser.add_argument("--out", default="demo_output", help="output folder (default: demo_output)")
    parser.add_argument("--view", action="store_true", help="stream to a live Rerun viewer as well")
    args = parser.parse_args()

    text = (Path(args.scene).read_text() if args.scene
            else resources.files("hfgpu").joinpath("scenes", DEFAULT_SCENE).read_text())
    scene = hfgpu.load_scene(text)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results, recording = out / "main.h5", out / "main.rrd"
    hfgpu.run(scene, results, rrd=recording, view=args.view)
    if scene.has("proppant") and scene.has("fracture"):
        print_story(story(results))
    figures = plot_results(results, out / "figures")
    print(f"\nresults:   {results}\nrecording: {recording}   (replay: rerun {recording})")
    print("figures:   " + "\n           ".join(str(f) for f in figures))


if __name__ == "__main__":
    main()
