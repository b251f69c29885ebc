"""Proppant size study of the paper's section 6.2 (Figs. 15-18): the field case with 30/50, 40/70 and 100 mesh
sand, from one command; prints a table of created area, propped area, propped fraction, packed fraction,
screen-out flags and the share of the scheduled solids held back at the packed perforation (screen-out), and
the closure values of each run (docs/closure.md): propped area after closure A_p (one face), effective propped
half-length x_p and height h_p, mean conductivity C (md ft) and F_CD = C / (k_f x_p) (needs the scene's
``[closure] formation_permeability``; NaN without it).

    python demos/size_study.py [--scaled] [--out size_output] [--sizes 30/50 40/70 "100 mesh"] [--backend numpy|taichi]
                               [--reuse] [--set KEY=VALUE ...]

Then, per size at the last snapshot, where the parcels are (hfgpu.propped.parcel_groups): the share suspended,
in a moving bed, in a bed at rest and bridged, with each group's median speed and, for the bed groups, the
share below the threshold of motion (Shields); and how the definitions the paper leaves open move the packed and
propped shares (speed threshold 0.1 / 1 / 10 mm/s or "in a bed"; one or half a grain layer or any proppant).

Only the sieve class changes between the runs (normal distribution over the sieve range, as the paper's
Fig. 15a-c). Each run writes ``<out>/<size>.h5`` (sizes with "/" written with "-", spaces with "_"; ``--reuse``
keeps a complete one; ``--set`` changes other scene keys, e.g. ``run.seed=2``); a run that fails is reported with its
last snapshot and the error.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from field_case import load, propped_area_panel, report, save  # demos/ is on sys.path when run as a script

from hfgpu import open_results, run
from hfgpu.kernels.stencil_numpy import owning_cell
from hfgpu.propped import (GROUPS, PACKED_SPEED, created_area, packed_fraction, packed_history, parcel_groups,
                           propped_cells, results_times)
from hfgpu.reference.settling import column_settling_velocity
from hfgpu.scene_text import assignment
from hfgpu.units import to_si

MD_FT = to_si("1 md*ft", "conductivity")  # [m^3]
PAPER = "paper (section 6.2): propped 30.9 % of the area for 30/50, 100 mesh +59.3 % over 30/50; packed " \
        "fraction at 3600 s ~0.71 (30/50) to ~0.18 (100 mesh)"


def definitions(results) -> dict:
    """How the paper's undefined criteria move the result at the last snapshot: the packed share at 0.1, 1 and
    10 mm/s, the share of parcels in a bed (parcel_groups' bed groups), and the propped share of the created area
    counted with 1 and 0.5 grain layers and with any proppant in the cell."""
    snap = results.proppant_snapshots[-1]
    scene = results.scene
    cp, f = scene.proppant.params.theta_cp, snap.frame
    groups = parcel_groups(snap, scene.proppant, scene.fluid.density, scene.fluid.viscosity)
    count = sum(g["all"]["count"] for g in groups.values())
    in_bed = sum(g[name]["count"] for g in groups.values() for name in ("moving bed", "bed at rest"))
    created = created_area(snap)
    return dict(packed=[packed_fraction(snap.parcels, v) for v in (1e-4, 1e-3, 1e-2)], bed=in_bed / max(count, 1),
                settled=settling_bound(results),
                propped=[float(propped_cells(snap, cp, layers).sum()) * f.dx * f.dz / created
                         for layers in (1.0, 0.5, 1e-9)])


def settling_bound(results) -> float:
    """Share of the solids pumped early enough to fall from the perforation to the fracture's bottom (the
    deepest open cell of the injection column at the end) by the end, at the hindered settling speed of the
    class's mean grain at the schedule's largest volume fraction (hfgpu.reference.settling, the paper's drag
    law): (t_end - fall / v - t_start) / (t_end - t_start), clipped to [0, 1], the slurry pumped at a steady
    rate over [t_start, t_end] (the proppant snapshots' span). A kinematic estimate of the share that can be at
    rest by the end, before any flow carries it down or sideways."""
    scene, snaps = results.scene, results.proppant_snapshots
    snap, f = snaps[-1], snaps[-1].frame
    cls, inj = scene.proppant.classes[0], scene.injection
    column = np.asarray(snap.grid["width"])[:, int(round((inj.x - f.x0) / f.dx))]
    fall = f.z0 + (np.flatnonzero(column > 0.0).max() + 0.5) * f.dz - inj.depth
    phi = max(max(s.volume_fraction, s.end_volume_fraction) for s in inj.schedule.stages)
    speed = float(column_settling_velocity(cls.size.mean, cls.density, scene.fluid.density, scene.fluid.viscosity,
                                           phi))
    start, end = float(snaps.times[0]), float(snaps.times[-1])
    return float(np.clip((end - fall / speed - start) / (end - start), 0.0, 1.0))


def narrowest_held(results) -> list[tuple[float, float]]:
    """(snapshot time, w / d) at the paper's Fig. 16 times (hfgpu.propped.results_times): the narrowest width of
    the cells that hold parcels over the class's mean grain diameter. A parcel bridges where w / d falls below
    ``bridging_factor`` (2): above it, no parcel stands where it could be trapped (the paper's Fig. 15)."""
    scene = results.scene
    diameter = scene.proppant.classes[0].size.mean
    out = []
    for t in results_times(results):
        snap = results.proppant_snapshots.at(t)
        width = np.asarray(snap.grid["width"])
        k, i, inside = owning_cell(snap.parcels["x"], snap.parcels["z"], snap.frame, width.shape)
        held = width[k[inside], i[inside]]
        held = held[held > 0.0]
        out.append((snap.time, float(held.min()) / diameter if held.size else float("nan")))
    return out


def result_path(out: Path, size: str) -> Path:
    """``<out>/<size>.h5``, "/" written "-" and spaces "_"."""
    return out / f"{size.replace('/', '-').replace(' ', '_')}.h5"


def figure(paths: dict[str, Path], out: Path) -> Path:
    """Propped area over time per size (the paper's Fig. 18) and the packed share at every snapshot (its
    Fig. 16 gives it at 1260, 1800 and 3600 s): ``<out>/size_study.png``."""
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    propped_area_panel(left, paths)
    for size, path in paths.items():
        results = open_results(path)
        times = results.proppant_snapshots.times
        right.plot(times, [p for _, p in packed_history(results, tuple(times))], marker=".", label=size)
    right.set(xlabel="time [s]", ylabel="packed share of the parcels", ylim=(0.0, 1.0),
              title=f"packed: |u_p| < {PACKED_SPEED * 1e3:g} mm/s or bridged")
    right.legend(fontsize=8)
    return save(fig, out / "size_study.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scaled", action="store_true")
    parser.add_argument("--out", type=Path, default=Path("size_output"))
    parser.add_argument("--sizes", nargs="+", default=["30/50", "40/70", "100 mesh"])
    parser.add_argument("--backend", choices=("taichi", "numpy"), default=None)
    parser.add_argument("--reuse", action="store_true", help="keep a complete results file of a size")
    parser.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE", type=assignment,
                        help='other scene keys, e.g. run.seed=2 "rock.layers[2].top=2987.5 m"')
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for size in args.sizes:
        path = result_path(args.out, size)
        status = "complete"
        if not (args.reuse and path.exists() and open_results(path).status == "complete"):
            try:
                run(load(args.scaled, args.backend, size, dict(args.set)), path, progress=False)
            except Exception as exc:  # noqa: BLE001 -- the file keeps every snapshot written before the failure
                status = f"failed: {type(exc).__name__}: {exc}"
        summary = open_results(path).summary
        held = summary.get("proppant_screened_out", 0.0) / max(summary.get("proppant_injected", 0.0), 1e-300)
        closed = {k: summary.get(f"closure_{k}", float("nan"))
                  for k in ("propped_area", "propped_half_length", "propped_height", "mean_conductivity", "fcd")}
        results = open_results(path)
        scene = results.scene
        groups = parcel_groups(results.proppant_snapshots[-1], scene.proppant, scene.fluid.density,
                               scene.fluid.viscosity)
        rows.append((size, {**report(path), "held_back": held, "closed": closed, "groups": next(iter(groups.values())),
                            "definitions": definitions(results), "narrowest": narrowest_held(results),
                            "bridging": scene.proppant.params.bridging_factor}, status))
    times = "/".join(f"{t:.0f}" for t, _ in rows[0][1]["packed"])
    print(f"{'size':>8} {'t end s':>8} {'created m^2':>12} {'propped m^2':>12} {'propped %':>10} "
          f"{'packed at ' + times + ' s':>24} "
          f"{'screen-out':>10} {'held back %':>11} {'A_p m^2':>8} {'x_p m':>6} {'h_p m':>6} {'C md ft':>8} "
          f"{'F_CD':>6}  status")
    for size, r, status in rows:
        c = r["closed"]
        print(f"{size:>8} {r['time']:8.1f} {r['created_area']:12.0f} {r['propped_area']:12.0f} "
              f"{100 * r['propped_fraction']:10.1f} {' / '.join(f'{p:.2f}' for _, p in r['packed']):>24} "
              f"{r['screen_out_cells']:10d} "
              f"{100 * r['held_back']:11.1f} {c['propped_area']:8.0f} {c['propped_half_length']:6.0f} "
              f"{c['propped_height']:6.1f} {c['mean_conductivity'] / MD_FT:8.0f} {c['fcd']:6.2f}  {status}")
    print("\nwhere the parcels are at the last snapshot: share (median speed m/s; bed groups: share below the "
          "threshold of motion)")
    print(f"{'size':>8} " + " ".join(f"{name:>26}" for name in GROUPS))
    for size, r, _ in rows:
        cells = []
        for name in GROUPS:
            g = r["groups"][name]
            below = "" if math.isnan(g["subcritical"]) else f"; {g['subcritical']:.2f}"
            cells.append(f"{g['share']:.3f} ({g['median_speed']:.2g}{below})")
        print(f"{size:>8} " + " ".join(f"{c:>26}" for c in cells))
    print("\nthe definitions, at the last snapshot: packed share with |u_p| below 0.1 / 1 / 10 mm/s (or bridged), "
          "share in a bed (at rest or moving), share that can have settled (settling_bound); propped % of the "
          "created area with 1 / 0.5 grain layers or any proppant in the cell")
    for size, r, _ in rows:
        d = r["definitions"]
        print(f"{size:>8} packed {' / '.join(f'{p:.2f}' for p in d['packed'])}  in a bed {d['bed']:.2f}  "
              f"can have settled {d['settled']:.2f}  "
              f"propped {' / '.join(f'{100 * p:.1f}' for p in d['propped'])} %")
    print(f"\nnarrowest width holding parcels, in mean grain diameters, at {times} s (bridging below "
          f"bridging_factor, {rows[0][1]['bridging']:g})")
    for size, r, _ in rows:
        print(f"{size:>8} " + " / ".join(f"{ratio:.1f}" for _, ratio in r["narrowest"]))
    base = rows[0][1]["propped_area"]
    for size, r, _ in rows[1:]:
        if base > 0:
            print(f"propped area {size} vs {rows[0][0]}: {100 * (r['propped_area'] / base - 1):+.1f} %")
    print(PAPER)
    print(figure({size: result_path(args.out, size) for size, _, _ in rows}, args.out))


if __name__ == "__main__":
    main()
