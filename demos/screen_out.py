"""A designed tip screen-out (hfgpu/scenes/frac_pack_tso.toml), two-way coupled, beside the same scene one-way.

    python demos/screen_out.py [--out screen_out_output] [--one-way]

Prints the screen-out (time, net-pressure rise, packed length), the net pressure, length and width at the
perforation every 30 s, and writes the figures of the two-way run (``<out>/figures``: the pressure history
shows the rise, the maps the packed tip). ``--one-way`` runs the scene one-way too: the same treatment without
the proppant's feedback has no screen-out.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import hfgpu
from hfgpu.io.plots import plot_results
from hfgpu.scene_text import edit_scene
from hfgpu.units import in_display_units

SCENE = "frac_pack_tso.toml"


def history(path: Path, every: float = 30.0) -> None:
    """Net pressure [psi], length [ft] and width at the perforation [in] every ``every`` seconds."""
    b = hfgpu.open_results(path).fracture_balance
    print(f"{'t [s]':>6} {'net p [psi]':>12} {'length [ft]':>12} {'w0 [in]':>8}")
    for t in np.arange(every, b["time"][-1] + 1e-9, every):
        i = min(int(np.searchsorted(b["time"], t)), b["time"].size - 1)
        print(f"{b['time'][i]:6.0f} {in_display_units(b['net_pressure'][i], 'pressure', 'field'):12.0f} "
              f"{in_display_units(b['length'][i], 'length', 'field'):12.0f} "
              f"{in_display_units(b['inlet_width'][i], 'width', 'field'):8.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("screen_out_output"))
    parser.add_argument("--one-way", action="store_true", help="also run the scene one-way")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    scene = hfgpu.load_scene(hfgpu.scene_path(SCENE))
    modes = ("two-way", "one-way") if args.one_way else ("two-way",)
    for mode in modes:
        path = args.out / f"{mode}.h5"
        s = hfgpu.run(edit_scene(scene, {"coupling.mode": mode}), path, progress=False)
        print(f"\n{mode}: created area {in_display_units(s['fracture_area'], 'area', 'field'):.0f} ft^2, "
              f"length {in_display_units(s['fracture_length'], 'length', 'field'):.0f} ft")
        if mode == "two-way":
            print(f"tip screen-out at {s['tip_screen_out_time']:.0f} s; net pressure rise after it "
                  f"{in_display_units(s['net_pressure_rise'], 'pressure', 'field'):.0f} psi; packed length "
                  f"{in_display_units(s['packed_length'], 'length', 'field'):.0f} ft")
        history(path)
    for figure in plot_results(args.out / "two-way.h5", args.out / "figures"):
        print(figure)


if __name__ == "__main__":
    main()
