"""Figures (matplotlib, no pyplot state) from a results file alone; ``hfgpu plot`` writes them as PNGs.

Depth z is drawn downward; maps use each snapshot's own grid frame (cell centres x0 + i dx, z0 + j dz).
Fracture: width maps at a few times with the cross-section at x = x_injection, footprint outlines over
time, area and efficiency vs time, volume balance. Proppant (last snapshot): volume fraction map, map of
the mean parcel speed per cell, parcels coloured by radius, solid balance. Coupled runs (both physics) add
the paper's Figs. 13-18: volume fraction and speed maps over time, fluid streamlines, |u_p| probability
plots at 1260 / 1800 / 3600 s (nearest snapshots), fracture and propped area vs time.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..errors import HfgpuError
from ..records import GridFrame, ProppantSnapshot
from .results import Results, open_results


def _extent(frame: GridFrame, shape: tuple[int, int]) -> tuple[float, float, float, float]:
    """imshow extent (left, right, bottom, top) of a (nz, nx) grid with depth increasing downward."""
    nz, nx = shape
    return (frame.x0 - frame.dx / 2, frame.x0 + (nx - 0.5) * frame.dx,
            frame.z0 + (nz - 0.5) * frame.dz, frame.z0 - frame.dz / 2)


def _aspect(frame: GridFrame, shape: tuple[int, int]) -> str:
    """True proportions unless the domain is more than 4 times taller than wide or wider than tall."""
    left, right, bottom, top = _extent(frame, shape)
    return "equal" if 0.25 <= (bottom - top) / (right - left) <= 4 else "auto"


def _map(fig: Figure, ax, frame: GridFrame, values: np.ndarray, label: str, title: str) -> None:
    image = ax.imshow(values, extent=_extent(frame, values.shape), origin="upper", interpolation="nearest")
    fig.colorbar(image, ax=ax, label=label)
    ax.set(xlabel="x [m]", ylabel="depth z [m]", title=title, aspect=_aspect(frame, values.shape))


def _domain_figure(frame: GridFrame, shape: tuple[int, int]) -> Figure:
    """A figure shaped for a domain: landscape when it is wider than tall, portrait otherwise."""
    nz, nx = shape
    return Figure(figsize=(8, 4) if nx * frame.dx >= nz * frame.dz else (5, 7), layout="constrained")


def _picks(n: int, count: int) -> list[int]:
    """Up to ``count`` indices spread evenly over range(n), always including the last."""
    return sorted(set(np.linspace(0, n - 1, min(n, count)).round().astype(int).tolist()))


def injection_x(results: Results) -> float:
    """x [m] of the injection point from the stored scene (0 when the scene names none)."""
    try:
        injection = results.scene.injection
    except (HfgpuError, ImportError):
        return 0.0
    return injection.x if injection is not None else 0.0


def width_maps(results: Results, count: int = 4) -> Figure:
    """Width maps [mm] at up to ``count`` times, each above its cross-section w(z) at x = x_injection."""
    snaps = [results.fracture_snapshots[i] for i in _picks(len(results.fracture_snapshots), count)]
    fig = Figure(figsize=(4 * len(snaps), 7), layout="constrained")
    axes = fig.subplots(2, len(snaps), squeeze=False)
    x_inj = injection_x(results)
    for top, bottom, snap in zip(axes[0], axes[1], snaps):
        _map(fig, top, snap.frame, snap.width * 1e3, "width [mm]", f"t = {snap.time:.4g} s")
        top.axvline(x_inj, color="w", lw=0.8, ls="--")
        x, z = snap.frame.centres(*snap.width.shape)
        column = int(np.argmin(np.abs(x - x_inj)))
        bottom.plot(snap.width[:, column] * 1e3, z, "o-", ms=3)
        bottom.invert_yaxis()
        bottom.set(xlabel=f"width at x = {x[column]:.3g} m [mm]", ylabel="depth z [m]")
    return fig


def footprints(results: Results) -> Figure:
    """Outline of the open region (width > 0) at every snapshot, coloured by time."""
    fig = Figure(figsize=(6, 5), layout="constrained")
    ax = fig.subplots()
    snaps = list(results.fracture_snapshots)
    colours = _viridis(len(snaps))
    for snap, colour in zip(snaps, colours):
        x, z = snap.frame.centres(*snap.width.shape)
        if min(snap.width.shape) >= 2 and (snap.width > 0).any():
            ax.contour(x, z, (snap.width > 0).astype(float), levels=[0.5], colors=[colour])
    ax.invert_yaxis()
    ax.set(xlabel="x [m]", ylabel="depth z [m]", title="footprint over time", aspect="equal")
    _time_colourbar(fig, ax, results.fracture_snapshots.times)
    return fig


def area_efficiency(results: Results) -> Figure:
    """Open area [m^2] at the snapshots and fluid efficiency stored / injected from the balance."""
    fig = Figure(figsize=(10, 4), layout="constrained")
    left, right = fig.subplots(1, 2)
    areas = [np.count_nonzero(s.width > 0) * s.frame.dx * s.frame.dz for s in results.fracture_snapshots]
    left.plot(results.fracture_snapshots.times, areas, "o-")
    left.set(xlabel="time [s]", ylabel="fracture area [m^2]", title="area")
    b = results.fracture_balance
    if b:
        pumped = b["injected"] > 0
        right.plot(b["time"][pumped], b["stored"][pumped] / b["injected"][pumped])
    right.set(xlabel="time [s]", ylabel="efficiency stored/injected [-]", title="fluid efficiency",
              ylim=(0, 1.05))
    return fig


def volume_balance(results: Results) -> Figure:
    """Injected, stored and leaked volume [m^3] vs time; stored + leaked dotted (it should cover injected)."""
    return _balance(results.fracture_balance, ("injected", "stored", "leaked"), "fluid volume balance")


def proppant_balance(results: Results) -> Figure:
    """Injected, in-domain and outflow solid volume [m^3] vs time."""
    return _balance(results.proppant_balance, ("injected", "in_domain", "outflow"), "proppant volume balance")


def _balance(b: dict[str, np.ndarray], names: tuple[str, str, str], title: str) -> Figure:
    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax = fig.subplots()
    for name in names:
        ax.plot(b["time"], b[name], label=name)
    ax.plot(b["time"], b[names[1]] + b[names[2]], "k:", label=f"{names[1]} + {names[2]}")
    ax.set(xlabel="time [s]", ylabel="volume [m^3]", title=title)
    ax.legend()
    return fig


def volume_fraction_map(snap: ProppantSnapshot) -> Figure:
    """Proppant volume fraction on the grid."""
    fig = _domain_figure(snap.frame, snap.grid["volume_fraction"].shape)
    _map(fig, fig.subplots(), snap.frame, snap.grid["volume_fraction"], "volume fraction [-]",
         f"proppant volume fraction, t = {snap.time:.4g} s")
    return fig


def _mean_speed(snap: ProppantSnapshot) -> np.ndarray:
    """Mean parcel speed [m/s] per grid cell (NaN where the cell holds no parcel)."""
    nz, nx = snap.grid["volume_fraction"].shape
    f, p = snap.frame, snap.parcels
    edges = (f.z0 + f.dz * (np.arange(nz + 1) - 0.5), f.x0 + f.dx * (np.arange(nx + 1) - 0.5))
    speed = np.hypot(p["u"], p["v"])
    total, _, _ = np.histogram2d(p["z"], p["x"], bins=edges, weights=speed)
    count, _, _ = np.histogram2d(p["z"], p["x"], bins=edges)
    return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def parcel_speed_map(snap: ProppantSnapshot) -> Figure:
    """Mean parcel speed [m/s] per grid cell (cells without parcels left blank)."""
    mean = _mean_speed(snap)
    fig = _domain_figure(snap.frame, mean.shape)
    _map(fig, fig.subplots(), snap.frame, mean, "mean parcel speed [m/s]", f"parcel speed, t = {snap.time:.4g} s")
    return fig


def proppant_maps(results: Results, count: int = 4) -> Figure:
    """Volume fraction (top row) and mean parcel speed (bottom row) at up to ``count`` times (the paper's
    Fig. 14); cells flagged ``bridging_risk`` are outlined in red where the file has that field."""
    snaps = [results.proppant_snapshots[i] for i in _picks(len(results.proppant_snapshots), count)]
    fig = Figure(figsize=(4.5 * len(snaps), 6), layout="constrained")
    axes = fig.subplots(2, len(snaps), squeeze=False)
    for top, bottom, snap in zip(axes[0], axes[1], snaps):
        _map(fig, top, snap.frame, snap.grid["volume_fraction"], "volume fraction [-]", f"t = {snap.time:.4g} s")
        if "bridging_risk" in snap.grid and snap.grid["bridging_risk"].any() and min(snap.grid["width"].shape) > 1:
            x, z = snap.frame.centres(*snap.grid["width"].shape)
            top.contour(x, z, snap.grid["bridging_risk"].astype(float), levels=[0.5], colors=["r"], linewidths=0.8)
        _map(fig, bottom, snap.frame, _mean_speed(snap), "mean parcel speed [m/s]", "")
    return fig


def streamlines(snap: ProppantSnapshot) -> Figure:
    """Streamlines of the fluid velocity (face values averaged to the cell centres, zero in closed cells)
    over the width map [mm], coloured by speed (the paper's Fig. 13c, 15j-l)."""
    g, f = snap.grid, snap.frame
    width = np.asarray(g["width"])
    u = 0.5 * (g["fluid_u"][:, :-1] + g["fluid_u"][:, 1:])
    v = 0.5 * (g["fluid_v"][:-1, :] + g["fluid_v"][1:, :])
    u, v = np.where(width > 0, u, 0.0), np.where(width > 0, v, 0.0)
    fig = _domain_figure(f, width.shape)
    ax = fig.subplots()
    _map(fig, ax, f, np.where(width > 0, width * 1e3, np.nan), "width [mm]", f"fluid streamlines, t = {snap.time:.4g} s")
    x, z = f.centres(*width.shape)
    if min(width.shape) >= 2 and np.any(u) | np.any(v):
        lines = ax.streamplot(x, z, u, v, color=np.hypot(u, v), cmap="magma", density=1.2, linewidth=0.7)
        fig.colorbar(lines.lines, ax=ax, label="fluid speed [m/s]")
    ax.set(xlim=(x[0] - f.dx / 2, x[-1] + f.dx / 2), ylim=(z[-1] + f.dz / 2, z[0] - f.dz / 2))
    return fig


def speed_probability(results: Results, times: tuple[float, ...] | None = None) -> Figure:
    """Cumulative probability of the parcel speed |u_p| at the snapshots nearest ``times`` (the paper's
    Fig. 16; default 1260 / 1800 / 3600 s, or the same fractions of a shorter slurry period,
    :func:`hfgpu.propped.results_times`), with the packed-parcel threshold of :mod:`hfgpu.propped` dotted."""
    from ..propped import PACKED_SPEED, packed_fraction, results_times

    times = results_times(results) if times is None else times
    fig = Figure(figsize=(4.5 * len(times), 4), layout="constrained")
    for ax, t in zip(fig.subplots(1, len(times), squeeze=False)[0], times):
        snap = results.proppant_snapshots.at(t)
        speed = np.sort(np.hypot(snap.parcels["u"], snap.parcels["v"]))
        if speed.size:
            ax.plot(speed, (np.arange(speed.size) + 0.5) / speed.size, ".", ms=2)
        ax.axvline(PACKED_SPEED, color="k", ls=":", lw=0.8)
        ax.set(xlabel="|u_p| [m/s]", ylabel="cumulative probability [-]", ylim=(0, 1),
               title=f"t = {snap.time:.4g} s, packed {packed_fraction(snap.parcels):.2f}")
    return fig


def propped_area(results: Results) -> Figure:
    """Fracture area (fracture snapshots), created and propped area (proppant grid) vs time (Fig. 18)."""
    from ..propped import area_history, fracture_area_history

    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax = fig.subplots()
    frac = fracture_area_history(results)
    ax.plot(frac["time"], frac["area"], label="fracture area")
    areas = area_history(results)
    ax.plot(areas["time"], areas["created"], "--", label="open area (proppant grid)")
    ax.plot(areas["time"], areas["propped"], "o-", ms=3, label="propped area")
    ax.set(xlabel="time [s]", ylabel="area [m^2]", title="created and propped area")
    ax.legend()
    return fig


def parcels_by_radius(snap: ProppantSnapshot) -> Figure:
    """Parcel positions coloured by particle radius [um]."""
    shape = snap.grid["volume_fraction"].shape
    fig = _domain_figure(snap.frame, shape)
    ax = fig.subplots()
    x = snap.parcels["x"]
    points = ax.scatter(x, snap.parcels["z"], c=snap.parcels["radius"] * 1e6, s=min(4.0, 2e4 / max(x.size, 1)),
                        linewidths=0)
    fig.colorbar(points, ax=ax, label="radius [um]")
    left, right, bottom, top = _extent(snap.frame, shape)
    ax.set(xlim=(left, right), ylim=(bottom, top), xlabel="x [m]", ylabel="depth z [m]",
           aspect=_aspect(snap.frame, shape),
           title=f"parcels by radius, t = {snap.time:.4g} s")
    return fig


def _viridis(n: int) -> list:
    from matplotlib import colormaps

    return [colormaps["viridis"](v) for v in np.linspace(0, 1, max(n, 1))]


def _time_colourbar(fig: Figure, ax, times: np.ndarray) -> None:
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    top = float(times.max()) if times.size else 1.0
    fig.colorbar(ScalarMappable(Normalize(float(times.min()) if times.size else 0.0, top), "viridis"),
                 ax=ax, label="time [s]")


def figures(results: Results) -> dict[str, Figure]:
    """Every figure the results support, by file stem."""
    out: dict[str, Figure] = {}
    if len(results.fracture_snapshots):
        out.update(fracture_width=width_maps(results), fracture_footprints=footprints(results),
                   fracture_area_efficiency=area_efficiency(results))
    if results.fracture_balance:
        out["fracture_volume_balance"] = volume_balance(results)
    if len(results.proppant_snapshots):
        last = results.proppant_snapshots[-1]
        out.update(proppant_volume_fraction=volume_fraction_map(last), proppant_speed=parcel_speed_map(last),
                   proppant_radius=parcels_by_radius(last))
    if results.proppant_balance:
        out["proppant_volume_balance"] = proppant_balance(results)
    if len(results.fracture_snapshots) and len(results.proppant_snapshots):  # a coupled run
        out.update(proppant_maps=proppant_maps(results), proppant_streamlines=streamlines(results.proppant_snapshots[-1]),
                   proppant_speed_probability=speed_probability(results), propped_area=propped_area(results))
    return out


def plot_results(path: str | Path, folder: str | Path, dpi: int = 120) -> list[Path]:
    """Write every figure of the results file ``path`` as ``<folder>/<name>.png``; return the paths."""
    results = open_results(path)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name, fig in figures(results).items():
        target = folder / f"{name}.png"
        fig.savefig(target, dpi=dpi)
        written.append(target)
    if not written:
        raise HfgpuError(f"'{path}' holds no snapshots or balance records to plot")
    return written
