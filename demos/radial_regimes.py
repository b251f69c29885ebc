"""R(t) of the four radial cases of the paper's Table 2 against Dontsov's (2016) universal solution.

Usage: python demos/radial_regimes.py OUT.png [--cases I,III]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hfgpu.fracture.simulator import simulate  # noqa: E402
from hfgpu.reference.radial import dontsov_radial  # noqa: E402
from hfgpu.scene import Output, load_scene  # noqa: E402

SCENES = Path(__file__).resolve().parents[1] / "hfgpu" / "scenes"


class FrontSink:
    """Keeps the sub-grid mean front radius of every snapshot."""

    def __init__(self):
        self.t, self.r = [], []

    def fracture_balance(self, record):
        pass

    def fracture_snapshot(self, snap):
        self.t.append(snap.time)
        self.r.append(float(snap.extras["front_radius"]))


def run(name: str):
    sc = load_scene(SCENES / f"radial_{name}.toml")
    sc = sc.replace(output=Output(every=sc.run.end_time / 20))
    sink = FrontSink()
    out = simulate(sc, sink)
    rock = sc.rock
    ref = dontsov_radial(rock.plane_strain_modulus, math.sqrt(32 / math.pi) * rock.toughness,
                         12 * sc.fluid.viscosity, 2 * rock.leakoff_coefficient,
                         sc.injection.schedule.stages[0].rate, np.geomspace(out["t0"], sc.run.end_time, 60))
    return sink, ref, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="figure file (png, pdf, ...)")
    parser.add_argument("--cases", default="I,II,III", help="comma-separated cases from I, II, III, IV")
    args = parser.parse_args()
    cases = args.cases.split(",")
    fig, axes = plt.subplots(1, len(cases), figsize=(4 * len(cases), 3.6), squeeze=False)
    for ax, name in zip(axes[0], cases):
        sink, ref, out = run(name)
        ax.plot(ref.t, ref.R, "k-", label="Dontsov (2016)")
        ax.plot(sink.t, sink.r, "o", ms=4, label="hfgpu")
        err = out["radius"] / ref.R[-1] - 1
        ax.set_title(f"case {name}: R error {err:+.1%}")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("R [m]")
        ax.legend()
        print(f"case {name}: R {out['radius']:.4g} m (ref {ref.R[-1]:.4g}, {err:+.2%}), "
              f"w(0) {out['w_inlet']:.4g} m (ref {ref.w0[-1]:.4g}, {out['w_inlet'] / ref.w0[-1] - 1:+.2%})")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
