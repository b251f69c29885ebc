"""Chun et al. (2020) slot demo (the paper's Fig. 9-10): proppant volume fraction snapshots, bed profiles at 5, 15
and 20 s, and the bank length and area vs time against the experiment (when the GEOS-digitised data are given).

    python demos/slot.py [--scene hfgpu/scenes/chun2020_slot.toml] [--end 30] [--out demo_output] [--data BANK.txt]

BANK.txt: the experiment's bank length and area against time as digitised for GEOS (columns t [s], length / slot
length, area / slot area); reference data that a clone of hfgpu does not hold (without them: the model only).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hfgpu import load_scene  # noqa: E402
from hfgpu.proppant.analysis import bank, bed_height  # noqa: E402
from hfgpu.proppant.engine_setup import proppant_engine_setup  # noqa: E402
from hfgpu.proppant.simulator import ProppantSimulation  # noqa: E402
from hfgpu.records import MemorySink  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "hfgpu" / "scenes" / "chun2020_slot.toml"
DATA = ROOT.parent / "shared" / "validation-data" / "chun_2020_bank_length_area_geos.txt"



def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(SCENE))
    parser.add_argument("--end", type=float, default=None)
    parser.add_argument("--out", default="demo_output")
    parser.add_argument("--data", default=str(DATA))
    args = parser.parse_args()
    scene = load_scene(args.scene)
    if args.end is not None:
        scene = scene.replace(run=type(scene.run)(args.end, scene.run.physics, scene.run.seed))
    sim = ProppantSimulation(proppant_engine_setup(scene))
    sink = MemorySink()
    summary = sim.run(sink, progress=lambda t: None)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    threshold = 0.5 * sim.params.theta_cp
    g = scene.proppant.geometry

    shown = [s for s in sink.proppant_snapshots if any(abs(s.time - t) < 1e-6 for t in (5.0, 15.0, 20.0, 30.0))]
    fig, axes = plt.subplots(len(shown), 1, figsize=(8, 2.2 * len(shown)), squeeze=False)
    for ax, snap in zip(axes[:, 0], shown):
        im = ax.imshow(snap.grid["volume_fraction"], extent=(0, g.length, g.height, 0), vmin=0,
                       vmax=sim.params.theta_cp, cmap="YlOrBr", aspect="equal")
        ax.set_title(f"t = {snap.time:.0f} s", fontsize=9)
        ax.set_ylabel("depth [m]")
        fig.colorbar(im, ax=ax, label=r"$\theta_p$ (one scale, 0 to close packing)")
    axes[-1, 0].set_xlabel("x [m]")
    fig.tight_layout()
    fig.savefig(out / "slot_snapshots.png", dpi=150)

    fig, ax = plt.subplots(figsize=(7, 3))
    for snap in shown:
        x = snap.frame.x0 + snap.frame.dx * np.arange(snap.grid["width"].shape[1])
        ax.step(x, bed_height(snap.grid["volume_fraction"], snap.grid["width"], snap.frame, threshold), where="mid",
                label=f"{snap.time:.0f} s")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("bed height [m]")
    ax.set_ylim(0, g.height)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "slot_bed_profiles.png", dpi=150)

    t = np.array([s.time for s in sink.proppant_snapshots])
    banks = [bank(s.grid["volume_fraction"], s.grid["width"], s.frame, threshold) for s in sink.proppant_snapshots]
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot(t, [b.normalised_length for b in banks], "b-o", ms=3, label="bank length (MP-PIC)")
    ax.plot(t, [b.normalised_area for b in banks], "r-o", ms=3, label="bank area (MP-PIC)")
    if Path(args.data).is_file():
        data = np.loadtxt(args.data)
        ax.plot(data[:, 0], data[:, 1], "bs", mfc="none", label="length, Chun et al. (2020)")
        ax.plot(data[:, 0], data[:, 2], "rs", mfc="none", label="area, Chun et al. (2020)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("bank length / slot length,\nbank area / slot area [-]")
    ax.set_title(f"bank: cells with theta_p >= {threshold:.2g} (half of close packing)", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "slot_bank.png", dpi=150)
    for s, b in zip(sink.proppant_snapshots, banks):
        print(f"t = {s.time:5.1f} s  bank length {b.normalised_length:.3f}  area {b.normalised_area:.3f}")
    if Path(args.data).is_file():
        by_time = {round(s.time, 6): b for s, b in zip(sink.proppant_snapshots, banks)}
        print("against the experiment (Chun et al. 2020, digitised by GEOS): model / measured - 1")
        for t_data, length, area in np.loadtxt(args.data):
            b = by_time.get(round(t_data, 6))
            if b is not None:
                print(f"t = {t_data:5.1f} s  length {b.normalised_length:.3f} vs {length:.3f} "
                      f"({100 * (b.normalised_length / length - 1):+.1f} %)  area {b.normalised_area:.3f} vs "
                      f"{area:.3f} ({100 * (b.normalised_area / area - 1):+.1f} %)")
    fractions = (0.3, 0.4, 0.5, 0.6, 0.7)
    print("bank length against the bank threshold (theta_p >= fraction x theta_cp; the validation uses 0.5):")
    print("    t [s] | " + " | ".join(f"{f:5.1f}" for f in fractions))
    for s in sink.proppant_snapshots:
        if any(abs(s.time - t) < 1e-6 for t in (10.0, 12.5, 15.0, 20.0, 30.0)):
            lengths = [bank(s.grid["volume_fraction"], s.grid["width"], s.frame, f * sim.params.theta_cp)
                       for f in fractions]
            print(f"    {s.time:5.1f} | " + " | ".join(f"{b.normalised_length:5.3f}" for b in lengths))
    print(f"{summary['steps']} steps, {summary['parcels']} parcels, outflow {summary['outflow']:.3e} m^3; "
          f"figures in {out}/")


if __name__ == "__main__":
    main()
