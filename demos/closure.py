"""The main demo's fracture through closure: the same 9 minutes of pumping, then 12 hours shut in instead of 5 minutes.

    python demos/closure.py          # output in ./demo_output/closure.h5 and demo_output/closure_figures/

The main demo's scene (hfgpu/scenes/slickwater_demo.toml) pumps 40 bbl/min for 9 min, then shuts in for 5 min
while its proppant settles. This runs its fracture alone (the proppant does not act on the fracture: one-way
coupling) with the shut-in stretched to 12 h, so that leak-off drains it and it closes; then it reads the fall-off
(``hfgpu falloff``) and draws the figures. docs/field-case.md ("Through closure") says why the main demo stops
before closure and what this run shows. About a minute and a half on 2 cores.
"""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path

import hfgpu
from hfgpu.io.plots import plot_results
from hfgpu.io.summary import falloff_report
from hfgpu.scene_text import toml_text

SHUT_IN_UNTIL = "12 h"


def scene() -> hfgpu.Scene:
    """The main demo's scene, fracture only, pumping its 9 min of slurry as fluid and shut in until 12 h."""
    text = (resources.files("hfgpu") / "scenes" / "slickwater_demo.toml").read_text()
    pumping = hfgpu.load_scene(text).injection.schedule.pump_end
    data = tomllib.loads(text)
    for section in ("proppant", "coupling", "mppic"):
        del data[section]
    data["run"].update(physics=["fracture"], end_time=SHUT_IN_UNTIL)
    data["output"]["every"] = "1 h"
    data["injection"]["schedule"] = [{"until": f"{pumping:g} s", "rate": "40 bbl/min"},
                                     {"until": SHUT_IN_UNTIL, "rate": "0 bbl/min"}]
    return hfgpu.load_scene(toml_text(data))


def main() -> None:
    out = Path("demo_output")
    out.mkdir(exist_ok=True)
    hfgpu.run(scene(), out / "closure.h5")
    print(falloff_report(out / "closure.h5"))
    for path in plot_results(out / "closure.h5", out / "closure_figures"):
        print(path)


if __name__ == "__main__":
    main()
