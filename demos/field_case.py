"""The paper's field case (section 6, Table 4): a one-way coupled fracture + proppant run of the five-layer
reservoir, its results file, the figures of Figs. 12-18 and the propped-area table.

    python demos/field_case.py [--scaled] [--out field_output] [--rrd run.rrd] [--backend numpy|taichi]

``--scaled`` runs ``hfgpu/scenes/five_layer_demo.toml`` (the quick variant, see its header) instead of the full
base case ``five_layer.toml``. Writes ``<out>/field.h5``, ``<out>/figures/*.png`` and prints the summary.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from hfgpu import load_scene, run  # noqa: E402
from hfgpu.io.plots import plot_results  # noqa: E402
from hfgpu.propped import packed_history, propped_summary  # noqa: E402

SCENES = Path(__file__).resolve().parents[1] / "hfgpu" / "scenes"


def load(scaled: bool, backend: str | None = None, size: str | None = None):
    """The base (or scaled) five-layer scene; ``backend`` overrides [mppic] backend, ``size`` the sieve class
    (the proppant class keeps its name, so the schedule still refers to it)."""
    scene = load_scene(SCENES / ("five_layer_demo.toml" if scaled else "five_layer.toml"))
    setup = scene.proppant
    if backend is not None:
        setup = dataclasses.replace(setup, numerics=dataclasses.replace(setup.numerics, backend=backend))
    if size is not None:
        setup = setup.with_sieve(size)
    return scene.replace(proppant=setup)


def report(path: Path) -> dict:
    """Propped-area summary and packed fractions at 1260 / 1800 / 3600 s (nearest snapshots) of a results file."""
    summary = propped_summary(path)
    summary["packed"] = packed_history(path)
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scaled", action="store_true", help="the quick variant (five_layer_demo.toml)")
    parser.add_argument("--out", type=Path, default=Path("field_output"))
    parser.add_argument("--rrd", type=Path, default=None, help="also save a Rerun recording")
    parser.add_argument("--backend", choices=("taichi", "numpy"), default=None)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    results = args.out / "field.h5"
    summary = run(load(args.scaled, args.backend), results, progress=True, rrd=args.rrd)
    for figure in plot_results(results, args.out / "figures"):
        print(figure)
    r = report(results)
    print(f"\ncreated area {r['created_area']:.0f} m^2, propped area {r['propped_area']:.0f} m^2 "
          f"({100 * r['propped_fraction']:.1f} %), screen-out cells {r['screen_out_cells']}")
    print("packed parcel fraction (the paper's Fig. 16 times, scaled to the slurry period): " + ", ".join(f"{f:.2f} at {t:.0f} s" for t, f in r["packed"]))
    supplied, injected = summary["proppant_fluid_supplied"], summary["proppant_fluid_injected"]
    print(f"fluid supplied for the fracture width history's mismatch: {supplied:.3g} m^3 "
          f"({100 * supplied / injected:+.1f} % of the injected fluid)")
    print("wall time [s]: " + ", ".join(f"{k[5:]} {summary[k]:.1f}" for k in summary if k.startswith("time_")))


if __name__ == "__main__":
    main()
