"""The paper's field case (section 6, Table 4): a one-way coupled fracture + proppant run of the five-layer
reservoir, its results file, the figures of Figs. 12-18 and the propped-area table.

    python demos/field_case.py [--scaled] [--out field_output] [--rrd run.rrd] [--backend numpy|taichi]

``--scaled`` runs ``hfgpu/scenes/five_layer_demo.toml`` (the quick variant, see its header) instead of the full
base case ``five_layer.toml``. Writes ``<out>/field.h5``, ``<out>/figures/*.png`` and prints the summary.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

from hfgpu import edit_scene, load_scene, run  # noqa: E402
from hfgpu.io.plots import plot_results  # noqa: E402
from hfgpu.propped import area_history, packed_history, propped_summary  # noqa: E402

SCENES = Path(__file__).resolve().parents[1] / "hfgpu" / "scenes"


def load(scaled: bool, backend: str | None = None, size: str | None = None, changes: dict | None = None):
    """The base (or scaled) five-layer scene; ``backend`` sets [mppic] backend, ``size`` the sieve class of every
    proppant class (names kept, so the schedule still refers to them), ``changes`` any other keys
    ({"run.seed": 2}). Changed as text (hfgpu.edit_scene), so the results file stores the scene that ran."""
    scene = load_scene(SCENES / ("five_layer_demo.toml" if scaled else "five_layer.toml"))
    changes = dict(changes or {}) | ({} if backend is None else {"mppic.backend": backend})
    if size is not None:
        changes.update({f"proppant[{i}].size": size for i in range(len(scene.proppant.classes))})
    return edit_scene(scene, changes) if changes else scene


def propped_area_panel(ax, paths: dict[str, Path]) -> None:
    """Propped area against time of each results file (labelled by its key), and the created area of the last."""
    for label, path in paths.items():
        history = area_history(path)
        ax.plot(history["time"], history["propped"], label=label)
    ax.plot(history["time"], history["created"], color="k", linestyle=":", label="created")
    ax.set(xlabel="time [s]", ylabel="area [m^2] (one face)", title="propped area")
    ax.legend(fontsize=8)


def save(fig, target: Path) -> Path:
    """Write a study's figure (110 dpi) and close it."""
    fig.tight_layout()
    fig.savefig(target, dpi=110)
    plt.close(fig)
    return target


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
