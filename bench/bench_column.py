"""A settling box several columns wide, as a user writes it: noise control measured (docs/proppant-closures.md,
"Noise in a settling box").

A closed box (default 4 cm wide, 40 cm tall, a 4 cm gap, 4 mm cells) holds a uniform suspension of 6 % 120 um
glass beads (2500 kg/m^3) in a 0.04 Pa s fluid (1000 kg/m^3); only the proppant is simulated. The table gives,
for each initial placement and averaging asked for: when the fluid first moves faster than 10 times the
suspension's backflow (the onset of a convection the real suspension does not have), the fluid speed at the
end, the top interface's depth and mean speed against Richardson & Zaki (1954, exponent 4.65), the excess of
theta_p under the interface over theta_0 in the box's middle column at the end and its peak over the run (sampled
each second: the pile-up the averaging controls) and the wall time.

    python bench/bench_column.py                                  # the defaults, to 100 s
    python bench/bench_column.py --placement lattice stratified --averaging dual moment --end 100
    python bench/bench_column.py --columns 1 --averaging dual moment basic --end 100   # one column
    python bench/bench_column.py --gap 4mm --end 970               # a 10-column slot to half its settling time
    python bench/bench_column.py --columns 20 --cell 2 --averaging moment   # the 4 cm box in 2 mm cells
    python bench/bench_column.py --set 'damping_scheme="implicit"'   # an [mppic] key
"""

from __future__ import annotations

import argparse
import itertools
import time

import numpy as np

from hfgpu import load_scene
from hfgpu.proppant.analysis import interface_depth, row_profile
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation
from hfgpu.reference import settling

SCENE = """
[run]
end_time = "{end} s"
physics = ["proppant"]
seed = 1
[fluid]
viscosity = "0.04 Pa*s"
density = "1000 kg/m**3"
[mesh]
cell_size = "{cell} mm"
refinement = 1
[output]
every = "{end} s"
[geometry]
kind = "box"
length = "{length} mm"
height = "40 cm"
width = "{gap}"
[[proppant]]
name = "beads"
density = "2500 kg/m**3"
diameter = "120 um"
initial_volume_fraction = 0.06
[mppic]
parcels_per_cell = 16
initial_placement = "{placement}"
averaging = "{averaging}"
"""
THETA0 = 0.06


def run(columns: int, gap: str, placement: str, averaging: str, end: float, extra: tuple[str, ...] = (),
        cell: float = 4.0) -> dict:
    """One box of ``columns`` cells ``cell`` [mm] wide to ``end`` [s], with the [mppic] lines ``extra``; the row of
    the table."""
    scene = load_scene(SCENE.format(end=end, length=cell * columns, cell=cell, gap=gap, placement=placement,
                                    averaging=averaging)
                       + "".join(f"{line}\n" for line in extra))
    sim = ProppantSimulation(proppant_engine_setup(scene))
    cls = sim.setup.classes[0]
    hindered = settling.hindered_velocity(settling.stokes_velocity(cls.size.mean, cls.density, sim.rho_f, sim.mu_f),
                                          THETA0, settling.STOKES_RZ_EXPONENT)
    backflow = THETA0 * hindered / (1.0 - THETA0)
    t0 = time.perf_counter()
    onset, steps, peak, sample = float("nan"), 0, float("nan"), 1.0
    while sim.time < end - 1e-9:
        sim.step(limit=end - sim.time)
        steps += 1
        speed = max(np.abs(sim.fluid.u).max(), np.abs(sim.fluid.v).max())
        if np.isnan(onset) and speed > 10.0 * backflow:
            onset = sim.time
        if sim.time >= sample - 1e-9:  # once a second of simulated time
            peak, sample = np.fmax(peak, pile_up(sim.engine.moments().volume_fraction)), sim.time + 1.0
    theta = sim.engine.moments().volume_fraction
    depth = interface_depth(row_profile(theta, sim.grid.width), sim.grid.frame, 0.5 * THETA0)
    return dict(onset=onset, speed=speed, depth=depth, rate=depth / end / hindered - 1.0, pile=pile_up(theta),
                peak=peak, steps=steps, wall=time.perf_counter() - t0)


def pile_up(theta: np.ndarray) -> float:
    """The excess of theta_p over theta_0 in the three cells of the middle column under the top interface (the
    first cell from the top above theta_0 / 2)."""
    middle = theta[:, theta.shape[1] // 2]
    below = np.flatnonzero(middle > 0.5 * THETA0)
    return middle[below[0]:below[0] + 3].max() / THETA0 - 1.0 if below.size else float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--columns", type=int, default=10)
    parser.add_argument("--gap", default="4 cm")
    parser.add_argument("--placement", nargs="+", default=["lattice"])
    parser.add_argument("--averaging", nargs="+", default=["dual"])
    parser.add_argument("--end", type=float, default=100.0)
    parser.add_argument("--cell", type=float, default=4.0, help="cell size [mm]; the box is --columns cells wide")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="an [mppic] key, e.g. --set 'damping_scheme=\"implicit\"'")
    args = parser.parse_args()
    print(f"{args.columns} column(s) of {args.cell:g} mm, gap {args.gap}, 6 % 120 um beads, to {args.end:g} s")
    print("| placement | averaging | onset [s] | end |u_f| [m/s] | interface depth [mm] | speed vs RZ | "
          "pile-up under it | its peak | steps | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for placement, name in itertools.product(args.placement, args.averaging):
        r = run(args.columns, args.gap, placement, name, args.end, tuple(args.set), args.cell)
        onset = "none" if np.isnan(r["onset"]) else f"{r['onset']:.1f}"
        print(f"| {placement} | {name} | {onset} | {r['speed']:.2e} | {1e3 * r['depth']:.1f} | "
              f"{100 * r['rate']:+.1f} % | {100 * r['pile']:+.1f} % | {100 * r['peak']:+.1f} % | {r['steps']} | "
              f"{r['wall']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
