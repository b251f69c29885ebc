"""The main demo's fracture through closure: the same 9 minutes of pumping, then shut in until 14 h, not for 5 min.

    python demos/closure.py                         # output in ./demo_output/closure.h5, closure_figures/
    python demos/closure.py --max-step-growth 1.1   # finer steps: closure 15 % sooner (docs/field-case.md)

The main demo's scene (hfgpu/scenes/slickwater_demo.toml) pumps 40 bbl/min for 9 min, then shuts in for 5 min
while its proppant settles. This runs its fracture alone (the proppant does not act on the fracture: one-way
coupling) with the shut-in stretched to 14 h, so that leak-off drains it and it closes; then it reads the fall-off
(``hfgpu falloff``) and draws the figures. docs/field-case.md ("Through closure") says why the main demo stops
before closure and what this run shows. About a minute and a half on 2 cores.
"""

from __future__ import annotations

import argparse
import tomllib
from importlib import resources
from pathlib import Path

import hfgpu
from hfgpu.io.plots import plot_results
from hfgpu.io.summary import falloff_report
from hfgpu.scene_text import toml_text

SHUT_IN_UNTIL = "14 h"


def scene(max_step_growth: float | None = None) -> hfgpu.Scene:
    """The main demo's scene, fracture only, pumping its 9 min of slurry as fluid and shut in until 14 h
    (``max_step_growth``: [fracture]'s, default the scene's)."""
    text = (resources.files("hfgpu") / "scenes" / "slickwater_demo.toml").read_text()
    pumping = hfgpu.load_scene(text).injection.schedule.pump_end
    data = tomllib.loads(text)
    for section in ("proppant", "coupling", "mppic"):
        del data[section]
    data["run"].update(physics=["fracture"], end_time=SHUT_IN_UNTIL)
    data["output"]["every"] = "1 h"
    if max_step_growth is not None:
        data.setdefault("fracture", {})["max_step_growth"] = max_step_growth
    data["injection"]["schedule"] = [{"until": f"{pumping:g} s", "rate": "40 bbl/min"},
                                     {"until": SHUT_IN_UNTIL, "rate": "0 bbl/min"}]
    return hfgpu.load_scene(toml_text(data))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-step-growth", type=float, help="[fracture] max_step_growth (default 1.5)")
    args = parser.parse_args()
    out = Path("demo_output")
    out.mkdir(exist_ok=True)
    hfgpu.run(scene(args.max_step_growth), out / "closure.h5")
    print(falloff_report(out / "closure.h5"))
    for path in plot_results(out / "closure.h5", out / "closure_figures"):
        print(path)


if __name__ == "__main__":
    main()
