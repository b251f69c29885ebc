"""Wu et al. (2008) layered-stress experiment: simulated footprints over the digitised fronts.

Usage: python demos/wu2008.py OUT.png [--data FRONTS.csv]

FRONTS.csv: the measured fronts digitised by PyFrac (column pairs x, z [mm] at 665, 376, 144, 60 and 22 s); they
are reference data that a clone of hfgpu does not hold: without them the figure shows the simulated fronts only.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hfgpu.fracture.simulator import simulate  # noqa: E402
from hfgpu.scene import load_scene  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TIMES = (665.0, 376.0, 144.0, 60.0, 22.0)   # column pairs of the csv


class SnapSink:
    def __init__(self):
        self.snaps = {}

    def fracture_balance(self, record):
        pass

    def fracture_snapshot(self, snap):
        self.snaps[round(snap.time)] = snap


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="figure file")
    parser.add_argument("--data", type=Path,
                        default=ROOT.parent / "shared" / "validation-data" / "wu_et_al_2008_fronts_pyfrac.csv")
    args = parser.parse_args()
    scene = load_scene(ROOT / "hfgpu" / "scenes" / "wu2008.toml")
    sink = SnapSink()
    simulate(scene, sink)
    data = np.genfromtxt(args.data, delimiter=",") if args.data.is_file() else None
    fig, ax = plt.subplots(figsize=(6, 7))
    colours = plt.cm.viridis(np.linspace(0, 1, len(TIMES)))
    for k, (t, c) in enumerate(zip(TIMES, colours)):
        snap = sink.snaps[round(t)]
        nz, nx = snap.width.shape
        x, z = snap.frame.centres(nz, nx)
        ax.contour(1000 * x, 1000 * (z - scene.injection.depth), np.isfinite(snap.opening_time).astype(float),
                   levels=[0.5], colors=[c])
        down = 1000 * float(snap.extras["front_down"])  # the time written at each simulated front's bottom
        ax.text(0.0, down, f"{t:g} s", color=c, fontsize=7, ha="center", va="center",
                bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8))
        ax.plot([], [], "-", color=c, label=f"{t:g} s, simulated")
        if data is not None:
            ax.plot(data[:, 2 * k], data[:, 2 * k + 1], "--", color=c, label=f"{t:g} s, measured")
        e = snap.extras
        print(f"t = {t:5g} s: up {1000 * float(e['front_up']):6.1f}  down {1000 * float(e['front_down']):6.1f}  "
              f"left {1000 * float(e['front_left']):6.1f}  right {1000 * float(e['front_right']):6.1f} mm")
    for n, y in enumerate((-25, 25)):
        ax.axhline(y, color="grey", lw=0.5, label="stress layer boundary" if n == 0 else None)
    ax.set_aspect("equal")
    ax.invert_yaxis()
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("depth below injection [mm] (5 MPa layer below +25 mm)")
    ax.set_title("Wu et al. (2008): fronts, simulated (solid)" + (" and measured (dashed)" if data is not None
                                                                  else "; measured data not given"), fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
