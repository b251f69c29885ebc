"""R(t) and w(0, t) of the four radial cases of the paper's Table 2 against Dontsov's (2016) universal solution.

Usage: python demos/radial_regimes.py OUT.png [--cases I,II,III,IV] [--front cells|subgrid]
(each case with its scene's front tracking unless --front is given; IV's scene uses the sub-grid front and
takes ~3 CPU minutes, II with --front subgrid as long)
"""

from __future__ import annotations

import argparse
import dataclasses
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
    """Keeps the sub-grid mean front radius and the injection cell's width of every snapshot."""

    def __init__(self, z_injection: float):
        self.z_injection = z_injection
        self.t, self.r, self.w0 = [], [], []

    def fracture_balance(self, record):
        pass

    def fracture_snapshot(self, snap):
        f = snap.frame
        self.t.append(snap.time)
        self.r.append(float(snap.extras["front_radius"]))
        self.w0.append(float(snap.width[round((self.z_injection - f.z0) / f.dz), round(-f.x0 / f.dx)]))


def run(name: str, front: str | None):
    sc = load_scene(SCENES / f"radial_{name}.toml")
    sc = sc.replace(output=Output(every=sc.run.end_time / 20))
    if front is not None:
        sc = sc.replace(fracture=dataclasses.replace(sc.fracture, front_tracking=front))
    sink = FrontSink(sc.injection.depth)
    out = simulate(sc, sink)
    rock = sc.rock
    ref = dontsov_radial(rock.plane_strain_modulus, math.sqrt(32 / math.pi) * rock.toughness,
                         12 * sc.fluid.viscosity, 2 * rock.leakoff_coefficient,
                         sc.injection.schedule.stages[0].rate, np.geomspace(out["t0"], sc.run.end_time, 60))
    return sink, ref, out, sc.fracture.front_tracking


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="figure file (png, pdf, ...)")
    parser.add_argument("--cases", default="I,II,III", help="comma-separated cases from I, II, III, IV")
    parser.add_argument("--front", choices=("cells", "subgrid"), help="front tracking (default: the scene's)")
    args = parser.parse_args()
    cases = args.cases.split(",")
    fig, axes = plt.subplots(2, len(cases), figsize=(4 * len(cases), 6.4), squeeze=False)
    for col, name in enumerate(cases):
        sink, ref, out, front = run(name, args.front)
        err_r, err_w = out["radius"] / ref.R[-1] - 1, out["w_inlet"] / ref.w0[-1] - 1
        top, bottom = axes[0, col], axes[1, col]
        top.plot(ref.t, ref.R, "k-", label="Dontsov (2016)")
        top.plot(sink.t, sink.r, "o", ms=4, label=f"hfgpu ({front})")
        top.set_title(f"case {name}: R error {err_r:+.1%}")
        top.set_ylabel("R [m]")
        top.legend()
        bottom.plot(ref.t, 1e3 * ref.w0, "k-")
        bottom.plot(sink.t, 1e3 * np.array(sink.w0), "o", ms=4)
        bottom.set_title(f"w(0) error {err_w:+.1%}")
        bottom.set_xlabel("t [s]")
        bottom.set_ylabel("w(0) [mm]")
        print(f"case {name} ({front}): R {out['radius']:.4g} m (ref {ref.R[-1]:.4g}, {err_r:+.2%}), "
              f"w(0) {out['w_inlet']:.4g} m (ref {ref.w0[-1]:.4g}, {err_w:+.2%})")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
