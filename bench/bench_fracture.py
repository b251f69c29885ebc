"""Fracture-engine benchmark: cells, steps, Newton iterations, wall seconds and errors per radial case.

Cases: the paper's Table 2 (I-IV, scenes hfgpu/scenes/radial_*.toml) and two long runs to 1e5 s on PyFrac's
radial example (E 33 GPa, nu 0.4, Q 1e-3 m^3/s, mu 1.1 mPa s): "long" (radial_long.toml, K_Ic 0.5 MPa m^0.5)
and "viscosity" (radial_viscosity.toml, K_Ic 0: the pure-viscosity fracture PyFrac's example computes). Both
start on 0.1 m cells and are merged 3x3 whenever the footprint spans more than --max-cells-across cells, once
per cap, tip asymptote, front, coarsening factor and linear solver listed (the speed-accuracy trade of the
coarsening cap). A case whose scene uses the sub-grid front (II, IV) also runs with whole cells opening
(front_tracking = "cells"), the faster and less accurate front. Errors are against Dontsov's (2016) universal
solution (the M vertex of Savitski & Detournay (2002) where K_Ic = C_L = 0): of the front's mean, smallest
and largest radius, of the radius from the area (sqrt(area / pi), tip cells by their filled fraction,
hfgpu/fracture/geometry.py) and of the inlet width at the end, and the largest |error| of the last two over
the run (every accepted step after 10 t0, t0 the start time, from the balance records). The runs do not depend
on ``[output] every`` (snapshots between steps are interpolated).

Usage: OMP_NUM_THREADS=1 python bench/bench_fracture.py [--cases I,II,III,IV,long,viscosity]
       [--max-cells-across 24,30,36] [--tip-asymptotes km,universal] [--fronts cells,subgrid] [--factors 3,2]
       [--solvers auto,direct] [--every 1e4,1e3]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from hfgpu.fracture.simulator import simulate
from hfgpu.records import MemorySink
from hfgpu.reference.radial import dontsov_radial, m_vertex
from hfgpu.scene import load_scene

SCENES = Path(__file__).resolve().parents[1] / "hfgpu" / "scenes"


def run(scene):
    """(summary, wall s, Dontsov's final R, w0 error at the end, largest |R from area| and |w0| errors over the
    steps after 10 t0)."""
    sink = MemorySink()
    start = time.perf_counter()
    out = simulate(scene, sink)
    wall = time.perf_counter() - start
    rock = scene.rock
    times = np.array([r.time for r in sink.fracture_balances])
    keep = np.concatenate([np.diff(times) > 0.0, [True]]) & (times > 10.0 * out["t0"])
    records = [r for r, k in zip(sink.fracture_balances, keep) if k]
    q = scene.injection.schedule.stages[0].rate
    if rock.toughness == 0.0 and rock.leakoff_coefficient == 0.0:   # pure viscosity: the M vertex itself
        ref = m_vertex(rock.plane_strain_modulus, 12 * scene.fluid.viscosity, q, times[keep])
    else:
        ref = dontsov_radial(rock.plane_strain_modulus, math.sqrt(32 / math.pi) * rock.toughness,
                             12 * scene.fluid.viscosity, 2 * rock.leakoff_coefficient, q, times[keep])
    r_area = np.sqrt(np.array([r.area for r in records]) / math.pi) / ref.R - 1
    w0 = np.array([r.inlet_width for r in records]) / ref.w0 - 1
    return out, wall, ref.R[-1], out["w_inlet"] / ref.w0[-1] - 1, np.abs(r_area).max(), np.abs(w0).max()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="I,II,III,long,viscosity",
                        help="any of I,II,III,IV,long,viscosity (II ~1, IV ~3 minutes)")
    parser.add_argument("--max-cells-across", default="24,30,36", help="footprint caps of the long runs")
    parser.add_argument("--tip-asymptotes", default="km,universal", help="tip asymptotes of the long runs")
    parser.add_argument("--fronts", default="",
                        help="front_tracking of the long runs (cells, subgrid; default: the scene's own)")
    parser.add_argument("--factors", default="",
                        help="mesh.coarsening_factor of the long runs (3, 2; default: the scene's own)")
    parser.add_argument("--solvers", default="",
                        help="linear_solver of the long runs (auto, direct, krylov; default: the scene's own)")
    parser.add_argument("--every", default="1e4", help="output spacings [s] of the long runs (same results)")
    args = parser.parse_args()
    print(f"{'case':9} {'front':>7} {'tip':>9} {'cap':>4} {'f':>2} {'solver':>6} {'every':>6} {'cell [m]':>9} {'end cell':>9} {'cells':>6} {'steps':>6} {'newton':>7} "
          f"{'factor.':>7} {'gmres':>6} {'retries':>7} {'rejected':>8} {'wall [s]':>9} {'R err':>8} {'Rmin err':>9} {'Rmax err':>9} "
          f"{'R(area)':>8} {'w0 err':>8} {'max|R(area)|':>12} {'max|w0|':>8}")
    for name in args.cases.split(","):
        base = load_scene(SCENES / f"radial_{name}.toml")
        variants = [base]
        if base.fracture.front_tracking != "cells":
            variants.append(base.replace(fracture=dataclasses.replace(base.fracture, front_tracking="cells")))
        if name in ("long", "viscosity"):
            fronts = args.fronts.split(",") if args.fronts else [base.fracture.front_tracking]
            factors = [int(f) for f in args.factors.split(",")] if args.factors else [base.mesh.coarsening_factor]
            solvers = args.solvers.split(",") if args.solvers else [base.fracture.linear_solver]
            variants = [base.replace(mesh=dataclasses.replace(base.mesh, max_cells_across=int(cap), coarsening_factor=factor),
                                     fracture=dataclasses.replace(base.fracture, tip_asymptote=tip, front_tracking=front,
                                                                  linear_solver=solver),
                                     output=dataclasses.replace(base.output, every=float(every)))
                        for front in fronts for factor in factors for solver in solvers
                        for tip in args.tip_asymptotes.split(",")
                        for cap in args.max_cells_across.split(",") for every in args.every.split(",")]
        for scene in variants:
            out, wall, ref_r, w_err, r_max, w_max = run(scene)
            print(f"{name:9} {scene.fracture.front_tracking:>7} {scene.fracture.tip_asymptote:>9} {scene.mesh.max_cells_across or '-':>4} "
                  f"{scene.mesh.coarsening_factor:2d} {scene.fracture.linear_solver:>6} "
                  f"{scene.output.every:6.3g} {scene.mesh.dx:9.3g} {out['dx']:9.3g} {out['cells']:6d} {out['steps']:6d} "
                  f"{out['newton_iterations']:7d} {out['factorisations']:7d} {out['gmres_iterations']:6d} {out['retries']:7d} {out['rejected']:8d} {wall:9.2f} "
                  f"{out['radius'] / ref_r - 1:+8.2%} {out['radius_min'] / ref_r - 1:+9.2%} "
                  f"{out['radius_max'] / ref_r - 1:+9.2%} {out['area_radius'] / ref_r - 1:+8.2%} {w_err:+8.2%} "
                  f"{r_max:12.2%} {w_max:8.2%}", flush=True)


if __name__ == "__main__":
    main()
