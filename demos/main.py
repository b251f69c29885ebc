"""The main demo: run an embedded scene on the CPU, write results, a Rerun recording and figures.

    python demos/main.py                      # the default scene below, output in ./demo_output/
    python demos/main.py --scene SCENE.toml   # any scene file
    python demos/main.py --view               # also stream live to a spawned Rerun viewer (needs a display)

Afterwards: ``rerun demo_output/main.rrd`` replays the run, ``demo_output/figures/*.png`` are the figures
(``hfgpu plot demo_output/main.h5`` redraws them from the results file alone).
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

import hfgpu
from hfgpu.io.plots import plot_results

DEFAULT_SCENE = "five_layer_demo.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", help=f"scene file (default: the embedded {DEFAULT_SCENE})")
    parser.add_argument("--out", default="demo_output", help="output folder (default: demo_output)")
    parser.add_argument("--view", action="store_true", help="stream to a live Rerun viewer as well")
    args = parser.parse_args()

    text = (Path(args.scene).read_text() if args.scene
            else resources.files("hfgpu").joinpath("scenes", DEFAULT_SCENE).read_text())
    scene = hfgpu.load_scene(text)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results, recording = out / "main.h5", out / "main.rrd"
    hfgpu.run(scene, results, rrd=recording, view=args.view)
    figures = plot_results(results, out / "figures")
    print(f"\nresults:   {results}\nrecording: {recording}   (replay: rerun {recording})")
    print("figures:   " + "\n           ".join(str(f) for f in figures))


if __name__ == "__main__":
    main()
