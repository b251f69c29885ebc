"""A settled bed over random seeds: the box of tests/proppant/test_bed.py (a 1 cm x 3 cm x 1 cm box of 0.3 mm
sand at theta_p 0.2 in water, NumPy backend) with its parcels placed at random in their cells
(``initial_placement = "stratified"``), one run per seed. For each time it prints how many seeds have a parcel
faster than 1e-6 m/s, the fastest over the seeds, the same for the bed below its surface rows (the parcels
deeper than two cells under the bed height theta_0 H / theta_cp, as the test takes them), and at the end the
largest theta_p / theta_cp. Asserts nothing; about 5 s a seed.

    python bench/settled_bed.py --seeds 30
    python bench/settled_bed.py --seeds 30 --set 'damping_scheme="implicit"' --set 'grain_pressure="last"'
"""

from __future__ import annotations

import argparse

import numpy as np

from hfgpu import load_scene
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

#: The box tests/proppant/test_bed.py settles (seed 3, the quiet start).
BOX = """
[run]
end_time = "16 s"
physics = ["proppant"]
seed = 3
[fluid]
viscosity = "1 cP"
[mesh]
cell_size = "2.5 mm"
[output]
every = "1 s"
[geometry]
kind = "box"
length = "1 cm"
height = "3 cm"
width = "1 cm"
[[proppant]]
name = "sand"
density = "2550 kg/m**3"
diameter = "0.3 mm"
initial_volume_fraction = 0.2
[mppic]
backend = "numpy"
parcels_per_cell = 12
"""
HEIGHT, THETA_0 = 0.03, 0.2


def speeds(seed: int, times: list[float], extra: list[str]) -> tuple[list[tuple[float, float]], float]:
    """(fastest parcel, fastest in the deep bed) at each time, and the largest theta_p / theta_cp at the end."""
    text = BOX.replace("seed = 3", f"seed = {seed}") + 'initial_placement = "stratified"\n' + "".join(
        f"{line}\n" for line in extra)
    sim = ProppantSimulation(proppant_engine_setup(load_scene(text)))
    bed = HEIGHT * THETA_0 / sim.params.theta_cp
    out = []
    for t in times:
        while sim.time < t - 1e-9:
            sim.step(limit=t - sim.time)
        speed = np.hypot(sim.parcels.u, sim.parcels.v)
        deep = sim.parcels.z > HEIGHT - bed + 2 * sim.grid.frame.dz
        out.append((float(speed.max()), float(speed[deep].max())))
    return out, float(sim.engine.moments().volume_fraction.max() / sim.params.theta_cp)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=30, help="seeds 0 .. N-1")
    parser.add_argument("--times", type=float, nargs="+", default=[4.0, 6.0, 10.0, 16.0])
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="an [mppic] key")
    args = parser.parse_args()
    runs = [speeds(seed, args.times, args.set) for seed in range(args.seeds)]
    print(f"{args.seeds} seeds, random placement; speeds [m/s]")
    print(f"{'t [s]':>6} | seeds > 1e-6 | fastest  | deep bed > 1e-6 | deep fastest")
    for j, t in enumerate(args.times):
        top = np.array([r[0][j][0] for r in runs])
        deep = np.array([r[0][j][1] for r in runs])
        print(f"{t:6.1f} | {int((top > 1e-6).sum()):12d} | {top.max():8.2g} | {int((deep > 1e-6).sum()):15d} | "
              f"{deep.max():.2g}")
    print(f"largest theta_p / theta_cp at the end: {max(r[1] for r in runs):.4f}")


if __name__ == "__main__":
    main()
