"""What a shut-in costs: a radial fracture pumped 20 s (0.01 m^3, Carter C_L 2e-6 m/s^0.5, 0.4 m cells: the case of
issue 33) run to the end of pumping, and the same run followed by 5e4 s of shut-in, during which it drains and
closes. Each run is timed inside one process (the fracture engine only: no process start, no results file), the
two kinds interleaved, ``--repeats`` times each; the table gives the median wall seconds, the steps (before and
after shut-in), when the fracture closed, and the ratio of the shut-in run to the injection alone (target: 2).

    python bench/bench_shut_in.py [--repeats 3] [--fronts cells,subgrid] [--step-growth 1.05,1.1,1.2,1.5]

``--step-growth`` also prints, per ``[fracture] max_step_growth``, when the whole-cell front's fracture closed
and the steps it took (the closure time's convergence with the time step). Asserts nothing.
"""

from __future__ import annotations

import argparse
import statistics
import time

#: The case's scene (tests/fracture/test_closure.py runs it too): ``end`` and ``schedule`` as the run needs,
#: ``c_l`` the Carter coefficient [m/s^0.5], ``fracture`` the lines of ``[fracture]``.
SCENE = """
[run]
end_time = "{end}"
physics = ["fracture"]

[rock]
youngs_modulus = "10 GPa"
poisson_ratio = 0.25
toughness = "0.5 MPa*m**0.5"
leakoff_coefficient = "{c_l} m/s**0.5"
min_stress = "6 MPa"

[fluid]
viscosity = "1e-3 Pa*s"

[injection]
depth = "1000 m"
schedule = [{schedule}]

[fracture]
{fracture}

[mesh]
cell_size = "0.4 m"

[output]
every = "{end}"
"""
C_L = 2e-6   # Carter coefficient [m/s^0.5]
PUMP = '{ until = "20 s", rate = "5e-4 m**3/s" }'   # 0.01 m^3
SHUT_IN = 5e4


def run(front: str, shut_in: bool, growth: float = 1.5) -> tuple[float, dict, int]:
    """(wall s, summary, steps after the pumps stop) of one run (``growth``: max_step_growth, the default's)."""
    from hfgpu.fracture.simulator import simulate
    from hfgpu.records import MemorySink
    from hfgpu.scene import load_scene

    end = f"{20.0 + SHUT_IN:g} s" if shut_in else "20 s"
    schedule = PUMP + (f', {{ until = "{end}", rate = "0 m**3/s" }}' if shut_in else "")
    scene = load_scene(SCENE.format(end=end, schedule=schedule, c_l=C_L,
                                    fracture=f'front_tracking = "{front}"\nmax_step_growth = {growth}'))
    sink = MemorySink()
    start = time.perf_counter()
    out = simulate(scene, sink)
    wall = time.perf_counter() - start
    return wall, out, sum(r.time > 20.0 for r in sink.fracture_balances)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--fronts", default="cells,subgrid", help="any of cells,subgrid")
    parser.add_argument("--step-growth", default="", help="max_step_growth values for the closure-time table")
    args = parser.parse_args()
    run("cells", False)   # imports and first-call caches out of the timings
    print(f"{'front':8} {'pumped s':>9} {'shut-in s':>10} {'ratio':>6} {'steps':>6} {'after':>6} {'closed at s':>12} "
          f"{'balance':>8}")
    for front in args.fronts.split(","):
        walls: dict[bool, list[float]] = {False: [], True: []}
        for _ in range(args.repeats):
            for shut_in in (False, True):
                wall, out, after = run(front, shut_in)
                walls[shut_in].append(wall)
                if shut_in:
                    summary, steps_after = out, after
        pumped, total = statistics.median(walls[False]), statistics.median(walls[True])
        print(f"{front:8} {pumped:9.2f} {total:10.2f} {total / pumped:6.2f} {summary['steps']:6d} {steps_after:6d} "
              f"{summary['closed_at']:12.0f} {summary['max_balance_error']:8.1e}")
    if args.step_growth:
        print(f"\n{'max_step_growth':>15} {'closed at s':>12} {'steps':>6}")
        for growth in (float(g) for g in args.step_growth.split(",")):
            _, out, _ = run("cells", True, growth)
            print(f"{growth:15g} {out['closed_at']:12.0f} {out['steps']:6d}")


if __name__ == "__main__":
    main()
