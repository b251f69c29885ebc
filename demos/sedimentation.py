"""Davis et al. (1982) bimodal sedimentation demo (the paper's Fig. 8): interface heights vs time against Kynch /
Masliyah-Lockett-Bassoon theory, and the parcels' density, radius and speed at 300 s.

    python demos/sedimentation.py [--scene hfgpu/scenes/davis1982.toml] [--end 600] [--out demo_output]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hfgpu import load_scene  # noqa: E402
from hfgpu.proppant.analysis import class_volume_fraction, fitted_speed, interface_depth, row_profile  # noqa: E402
from hfgpu.proppant.engine_setup import proppant_engine_setup  # noqa: E402
from hfgpu.proppant.simulator import ProppantSimulation  # noqa: E402
from hfgpu.reference.settling import bidisperse_batch, bidisperse_interface_heights  # noqa: E402
from hfgpu.records import MemorySink  # noqa: E402

SCENE = Path(__file__).resolve().parents[1] / "hfgpu" / "scenes" / "davis1982.toml"



def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(SCENE))
    parser.add_argument("--end", type=float, default=None, help="end time [s] (default: the scene's)")
    parser.add_argument("--out", default="demo_output")
    args = parser.parse_args()
    scene = load_scene(args.scene)
    if args.end is not None:
        scene = scene.replace(run=type(scene.run)(args.end, scene.run.physics, scene.run.seed))
    heavy, light = scene.proppant.classes
    theory = bidisperse_batch((heavy.size.mean / 2, heavy.density, heavy.initial_volume_fraction),
                              (light.size.mean / 2, light.density, light.initial_volume_fraction),
                              scene.fluid.density, scene.fluid.viscosity)
    sim = ProppantSimulation(proppant_engine_setup(scene))
    height = scene.proppant.geometry.height
    history = []

    def record(info):
        frame, width, parcels = sim.grid.frame, sim.grid.width, sim.parcels
        th = class_volume_fraction(parcels, frame, width, 0)
        tl = class_volume_fraction(parcels, frame, width, 1)
        history.append((sim.time,
                        height - interface_depth(row_profile(tl, width), frame, 0.5 * theory.phi_light_only),
                        height - interface_depth(row_profile(th, width), frame, 0.5 * heavy.initial_volume_fraction)))

    sink = MemorySink()
    summary = sim.run(sink, on_step=record)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    t, upper, lower = np.array(history).T
    tt = np.linspace(0.0, t[-1], 200)
    h_up, h_low, h_bed = bidisperse_interface_heights(tt, height, theory, heavy.initial_volume_fraction,
                                                      light.initial_volume_fraction, scene.proppant.params.theta_cp)
    fig, ax = plt.subplots(figsize=(5, 4))
    every = max(1, t.size // 40)
    ax.plot(t[::every], 100 * upper[::every], "bo", ms=3, mfc="none", label="upper interface (MP-PIC)")
    ax.plot(t[::every], 100 * lower[::every], "ro", ms=3, mfc="none", label="lower interface (MP-PIC)")
    ax.plot(tt, 100 * h_up, "b-", lw=1, label="upper interface (Kynch + MLB theory)")
    ax.plot(tt, 100 * h_low, "r-", lw=1, label="lower interface (Kynch + MLB theory)")
    ax.plot(tt, 100 * h_bed, "k--", lw=1, label=f"sediment (packing {scene.proppant.params.theta_cp})")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("height [cm]")
    ax.set_title("Davis et al. (1982) bimodal sedimentation")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "davis_interfaces.png", dpi=150)

    snap = min(sink.proppant_snapshots, key=lambda s: abs(s.time - 300.0))
    p = snap.parcels
    fig, axes = plt.subplots(1, 3, figsize=(9, 5), sharey=True)
    for ax, values, label in zip(axes, (p["density"], 1e6 * p["radius"], 100 * np.hypot(p["u"], p["v"])),
                                 ("density [kg/m$^3$]", r"radius [$\mu$m]", "speed [cm/s]")):
        sc = ax.scatter(100 * p["x"], 100 * (height - p["z"]), c=values, s=2, cmap="viridis")
        fig.colorbar(sc, ax=ax, label=label)
        ax.set_xlabel("x [cm]")
    axes[0].set_ylabel("height [cm]")
    fig.suptitle(f"parcels at t = {snap.time:.0f} s")
    fig.tight_layout()
    fig.savefig(out / "davis_parcels_300s.png", dpi=150)
    speeds = []
    for h in (upper, lower):  # fitted where the interface is 0.02-0.4 m below the top (tests/proppant/test_davis.py)
        use = (height - h > 0.02) & (height - h < 0.4)
        speeds.append(fitted_speed(t[use], height - h[use]) if use.sum() > 1 else float("nan"))
    print(f"{summary['steps']} steps, {summary['parcels']} parcels; upper/lower interface speed "
          f"{speeds[0]:.4e}/{speeds[1]:.4e} m/s, theory {theory.upper_speed:.4e}/{theory.lower_speed:.4e} m/s "
          f"({100 * (speeds[0] / theory.upper_speed - 1):+.2f} % / {100 * (speeds[1] / theory.lower_speed - 1):+.2f} %); "
          f"figures in {out}/")


if __name__ == "__main__":
    main()
