"""Convergence of the field case's proppant result with the proppant grid (issue 18): the base case
``five_layer.toml`` with ``[coupling] cell_size`` 5, 2.5 and 1.25 m, parcels per cell held (so 4x the parcels
per halving), the fracture as in the scene (5 m cells) and the inlet ring at the scene's 7.5 m radius
(``[coupling] inlet_radius``; left to its default, 1.5 proppant cells, it would shrink with the cells and change
the injection, not only its discretisation).

    python demos/grid_study.py [--out grid_output] [--cells 5 2.5 1.25] [--end 3600] [--size 40/70]
                               [--times 1800 3600] [--reuse]

Prints, for each grid at each of ``--times``: created and propped area, propped fraction, packed share, where
the parcels are (hfgpu.propped.parcel_groups: suspended, moving bed, bed at rest, bridged), the dense height of
the column at x = 0 (rows with theta_p >= friction_volume_fraction) and the screen-out cells; then, from the
last three grids, the observed order of the propped area and the coarsest grid within 5 % of the finest. Writes
``<out>/cells_<c>.h5`` per grid (``--reuse`` keeps a complete one) and ``<out>/grid_study.png`` (theta_p over
depth at x = 0, and the propped area against time).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from field_case import load, propped_area_panel, save  # noqa: E402  (demos/ is on sys.path as a script)

from hfgpu import edit_scene, open_results, run  # noqa: E402
from hfgpu.presets import BALANCED  # noqa: E402
from hfgpu.propped import GROUPS, created_area, packed_fraction, parcel_groups, propped_cells  # noqa: E402

#: "Converged" here: the propped area within this share of the finest grid's.
TOLERANCE = 0.05
#: Parcels per cell on every grid (the balanced preset's; so 4x the parcels per halving of the cells).
PARCELS_PER_CELL = BALANCED.parcels_per_cell


def scene_for(cells: float, end: float, size: str | None):
    """The base case with proppant cells of ``cells`` m, run to ``end`` s, at 16 parcels per cell (the preset's
    default: a grid study holds the parcels per cell, not the parcel budget a scene without it gets)."""
    return edit_scene(load(False, None, size), {"coupling.cell_size": f"{cells:g} m", "run.end_time": f"{end:g} s",
                                                "mppic.parcels_per_cell": PARCELS_PER_CELL})


def run_grid(cells: float, out: Path, end: float, size: str | None, reuse: bool) -> Path:
    """Results file of one grid (run unless ``reuse`` finds a complete one)."""
    path = out / f"cells_{cells:g}.h5"
    if not (reuse and path.exists() and open_results(path).status == "complete"):
        run(scene_for(cells, end, size), path, progress=True)
    return path


def measure(path: Path, time: float) -> dict:
    """The study's quantities at the proppant snapshot nearest to ``time``."""
    results = open_results(path)
    scene, snap = results.scene, results.proppant_snapshots.at(time)
    params, f = scene.proppant.params, snap.frame
    created = created_area(snap)
    propped = float(propped_cells(snap, params.theta_cp).sum()) * f.dx * f.dz
    column = int(round((scene.injection.x - f.x0) / f.dx))
    theta = np.asarray(snap.grid["volume_fraction"])[:, column]
    depth = f.z0 + f.dz * np.arange(theta.size)
    groups = parcel_groups(snap, scene.proppant, scene.fluid.density, scene.fluid.viscosity)
    risk = snap.grid.get("bridging_risk")
    return dict(time=snap.time, cells=f.dx, parcels=len(snap.parcels["x"]), created=created, propped=propped,
                fraction=propped / created if created > 0.0 else math.nan, packed=packed_fraction(snap.parcels),
                groups=groups, dense_height=float(np.sum(theta >= params.friction_volume_fraction)) * f.dz,
                profile=(depth, theta), screen_out=int(np.count_nonzero(risk)) if risk is not None else 0)


def observed_order(coarse: float, medium: float, fine: float, ratio: float = 2.0) -> float:
    """p = log(|f_c - f_m| / |f_m - f_f|) / log(ratio) of three grids refined by ``ratio`` (NaN when the
    differences vanish or change sign: no asymptotic range)."""
    a, b = coarse - medium, medium - fine
    if a == 0.0 or b == 0.0 or a * b < 0.0:
        return math.nan
    return math.log(abs(a) / abs(b)) / math.log(ratio)


def table(rows: list[dict]) -> str:
    head = (f"{'t s':>6} {'cells m':>7} {'parcels':>8} {'created m^2':>11} {'propped m^2':>11} {'propped %':>9} "
            f"{'packed':>6} " + " ".join(f"{g:>11}" for g in GROUPS) + f" {'dense h m':>9} {'screen-out cells (m^2)':>22}")
    lines = [head]
    for r in rows:
        shares = [sum(g[name]["count"] for g in r["groups"].values()) / max(r["parcels"], 1) for name in GROUPS]
        lines.append(f"{r['time']:6.0f} {r['cells']:7.3g} {r['parcels']:8d} {r['created']:11.0f} "
                     f"{r['propped']:11.0f} {100 * r['fraction']:9.1f} {r['packed']:6.3f} "
                     + " ".join(f"{s:11.3f}" for s in shares) + f" {r['dense_height']:9.2f} {r['screen_out']:>11d} ({r['screen_out'] * r['cells']**2:7.0f})")
    return "\n".join(lines)


def convergence(rows: list[dict]) -> list[str]:
    """Observed order and the coarsest grid within TOLERANCE of the finest, per time."""
    lines = []
    for t in sorted({r["time"] for r in rows}):
        at = sorted((r for r in rows if r["time"] == t), key=lambda r: -r["cells"])
        finest = at[-1]
        close = [r["cells"] for r in at if abs(r["propped"] / finest["propped"] - 1.0) <= TOLERANCE] \
            if finest["propped"] > 0.0 else []
        order = observed_order(*(r["propped"] for r in at[-3:])) if len(at) >= 3 else math.nan
        changes = ", ".join(f"{r['cells']:g} m {100 * (r['propped'] / finest['propped'] - 1):+.1f} %"
                            for r in at[:-1]) if finest["propped"] > 0.0 else "-"
        lines.append(f"t = {t:.0f} s: propped area vs the {finest['cells']:g} m grid: {changes}; observed order "
                     f"{order:.2f}; within {100 * TOLERANCE:.0f} % from {max(close) if close else '-'} m cells")
    return lines


def figure(paths: dict[float, Path], rows: list[dict], out: Path) -> Path:
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    for r in rows:
        depth, theta = r["profile"]
        left.plot(theta, depth, marker=".", label=f"{r['cells']:g} m, {r['time']:.0f} s",
                  linestyle="-" if r["time"] == max(x["time"] for x in rows) else "--")
    left.invert_yaxis()
    left.set(xlabel="theta_p at x = 0", ylabel="depth [m]", title="proppant volume fraction at the well")
    left.legend(fontsize=8)
    propped_area_panel(right, {f"propped, {cells:g} m": path for cells, path in paths.items()})
    return save(fig, out / "grid_study.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("grid_output"))
    parser.add_argument("--cells", type=float, nargs="+", default=[5.0, 2.5, 1.25])
    parser.add_argument("--end", type=float, default=3600.0, help="end time [s] of every run")
    parser.add_argument("--size", default=None, help="sieve class (default: the scene's 40/70)")
    parser.add_argument("--times", type=float, nargs="+", default=[1800.0, 3600.0])
    parser.add_argument("--reuse", action="store_true", help="keep a complete results file of a grid")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    paths = {c: run_grid(c, args.out, args.end, args.size, args.reuse) for c in args.cells}
    rows = [measure(path, t) for path in paths.values() for t in args.times if t <= args.end]
    print(table(sorted(rows, key=lambda r: (r["time"], -r["cells"]))))
    print("\n".join(convergence(rows)))
    print(figure(paths, rows, args.out))


if __name__ == "__main__":
    main()
