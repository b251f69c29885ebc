"""Figures (matplotlib, no pyplot state) from a results file alone; ``hfgpu plot`` writes them as PNGs.

Depth z is drawn downward; maps use each snapshot's own grid frame (cell centres x0 + i dx, z0 + j dz). The
time panels of one map share one colour scale; every map of a layered scene draws the layer boundaries
(``[[rock.layers]]``, depth positive down); outlines and markers have legends.
Fracture: width maps at a few times with the cross-section at x = x_injection, footprint outlines over time, area
and efficiency vs time, volume balance, and after a shut-in the fall-off on Nolte's G-function
(hfgpu.fracture.falloff). Proppant (last snapshot): volume fraction map, map of the mean parcel speed per cell,
parcels coloured by radius, solid balance. Coupled runs (both physics) add the paper's Figs. 13-18: volume
fraction and speed maps over time, fluid streamlines, |u_p| probability plots at 1260 / 1800 / 3600 s (nearest
snapshots), fracture and propped area vs time. Runs with proppant add the propped width and conductivity after
closure (hfgpu.closure). A proppant-only column (at most MAX_COLUMN_CELLS columns, taller than wide) adds its
interface heights against time. A stage of several clusters adds the split of the rate and the fluid among its
clusters, their areas and pressures, and one width map per cluster at the last snapshot.
Every figure draws in the results' ``[output] units`` (:mod:`hfgpu.io.display_units`: SI as stored, widths in
mm, pressures in MPa; or field: ft, in, psi, bbl, ft^3, ft^2, ft/s); times stay in s. Functions that take a results
file read its units (``units=`` overrides them); those that take a snapshot draw SI unless given ``units``.
"""

from __future__ import annotations

import math
import re
import textwrap
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..errors import HfgpuError
from ..proppant.injection import batch_solid_volume
from ..records import GridFrame, ProppantSnapshot
from ..stage_blocks import cluster_view, clusters_of
from .display_units import SI, FigureUnits
from .results import Results, open_results


def _extent(frame: GridFrame, shape: tuple[int, int], units: FigureUnits = SI) -> tuple[float, float, float, float]:
    """imshow extent (left, right, bottom, top) of a (nz, nx) grid with depth increasing downward, in the length
    unit of ``units``."""
    nz, nx = shape
    edges = (frame.x0 - frame.dx / 2, frame.x0 + (nx - 0.5) * frame.dx,
             frame.z0 + (nz - 0.5) * frame.dz, frame.z0 - frame.dz / 2)
    return edges if not units.field else tuple(units("length", edges).tolist())


def _units(results: Results, units: FigureUnits | None = None) -> FigureUnits:
    """``units``, or the results' ``[output] units`` (SI when the stored scene does not parse)."""
    from .export import output_units

    return units if units is not None else FigureUnits(output_units(results))


def _xz_labels(units: FigureUnits) -> dict[str, str]:
    return dict(xlabel=f"x [{units.label('length')}]", ylabel=f"depth z [{units.label('length')}]")


def _aspect(frame: GridFrame, shape: tuple[int, int]) -> str:
    """True proportions unless the domain is more than 4 times taller than wide or wider than tall."""
    left, right, bottom, top = _extent(frame, shape)
    return "equal" if 0.25 <= (bottom - top) / (right - left) <= 4 else "auto"


#: A proppant-only run on at most this many columns of cells (and taller than wide) is a settling column.
MAX_COLUMN_CELLS = 4
#: Style of the layer boundaries drawn on maps.
LAYER_STYLE = dict(color="0.85", ls="--", lw=0.8)


def colour_range(*maps: np.ndarray) -> tuple[float, float]:
    """One (vmin, vmax) for all of ``maps`` (their finite values): 0 at the bottom for non-negative fields, and
    never an empty range (an all-zero map gets 0..1, not -0.1..0.1)."""
    finite = [np.asarray(m, dtype=float)[np.isfinite(m)] for m in maps]
    values = np.concatenate([f.ravel() for f in finite]) if finite else np.zeros(0)
    if values.size == 0:
        return 0.0, 1.0
    low, high = float(values.min()), float(values.max())
    low = min(low, 0.0) if low >= 0.0 else low
    if high <= low:
        high = low + (abs(low) if low else 1.0)
    return low, high


def _map(fig: Figure, ax, frame: GridFrame, values: np.ndarray, label: str, title: str,
         limits: tuple[float, float] | None = None, colourbar: bool = True, units: FigureUnits = SI) -> None:
    """``values`` (already in their figure unit) on the grid ``frame`` (SI), the axes in ``units``' length."""
    vmin, vmax = limits if limits is not None else colour_range(values)
    image = ax.imshow(values, extent=_extent(frame, values.shape, units), origin="upper", interpolation="nearest",
                      vmin=vmin, vmax=vmax)
    if colourbar:
        fig.colorbar(image, ax=ax, label=label)
    ax.set(**_xz_labels(units), title=title, aspect=_aspect(frame, values.shape))


def layer_boundaries(results: Results) -> list[float]:
    """Depths [m] of the boundaries between the layers of the stored scene (``[[rock.layers]]``; the outermost
    layers extend to +-infinity, so the table's first top and last bottom are not boundaries); none when the
    scene has no layers or does not parse."""
    try:
        rock = results.scene.rock
    except (HfgpuError, ImportError, AttributeError):
        return []
    layers = sorted(getattr(rock, "layers", ()) or (), key=lambda layer: layer.top)
    depths = {layer.bottom for layer in layers[:-1]} | {layer.top for layer in layers[1:]}
    return sorted(depths)


def draw_layers(ax, boundaries: Sequence[float], low: float, high: float, legend: bool = True) -> int:
    """Horizontal lines at the layer ``boundaries`` between depths ``low`` and ``high`` (all in the axes' unit;
    the rest would stretch the axes); a legend entry "layer boundary" unless ``legend`` is False. Returns how many
    were drawn."""
    drawn = 0
    for depth in boundaries:
        if min(low, high) <= depth <= max(low, high):
            ax.axhline(depth, **LAYER_STYLE, label="layer boundary" if drawn == 0 and legend else None)
            drawn += 1
    return drawn


def _layers_on_map(ax, frame: GridFrame, shape: tuple[int, int], boundaries: Sequence[float],
                   legend: bool = True, units: FigureUnits = SI) -> int:
    """The layer ``boundaries`` [m depth] on a map drawn in ``units``."""
    _, _, bottom, top = _extent(frame, shape, units)
    return draw_layers(ax, _lengths(boundaries, units), top, bottom, legend)


def _lengths(values: Sequence[float], units: FigureUnits) -> Sequence[float]:
    """SI lengths in ``units`` (unchanged, as given, in SI)."""
    return values if not units.field or not len(values) else units("length", values).tolist()


def _legend(ax, *extra: Line2D) -> None:
    """A legend of the labelled artists (plus ``extra`` proxies) when there is any."""
    handles, _ = ax.get_legend_handles_labels()
    if handles or extra:
        ax.legend(handles=[*handles, *extra], loc="lower right", fontsize=7, framealpha=0.7)


def _number(value: float, fmt: str = ".4g", missing: str = "n/a") -> str:
    """``value`` formatted, or ``missing`` when it is not finite (no 'nan' in a title)."""
    return format(value, fmt) if value is not None and math.isfinite(value) else missing


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


def width_maps(results: Results, count: int = 4, boundaries: Sequence[float] | None = None,
               units: FigureUnits | None = None) -> Figure:
    """Width maps [mm or in] at up to ``count`` times on one colour scale, each above its cross-section w(z) at
    x = x_injection (dashed line on the map), with the layer boundaries [m] (default: the stored scene's)."""
    boundaries = layer_boundaries(results) if boundaries is None else boundaries
    u = _units(results, units)
    length, width = u.label("length"), u.label("width")
    snaps = [results.fracture_snapshots[i] for i in _picks(len(results.fracture_snapshots), count)]
    fig = Figure(figsize=(4 * len(snaps), 7), layout="constrained")
    axes = fig.subplots(2, len(snaps), squeeze=False)
    x_inj = injection_x(results)
    limits = colour_range(*(u("width", snap.width) for snap in snaps))
    for n, (top, bottom, snap) in enumerate(zip(axes[0], axes[1], snaps)):
        _map(fig, top, snap.frame, u("width", snap.width), f"width [{width}]", f"t = {_number(snap.time)} s",
             limits, colourbar=n == len(snaps) - 1, units=u)
        top.axvline(u("length", x_inj), color="w", lw=0.8, ls="--", label="cross-section (injection x)")
        _layers_on_map(top, snap.frame, snap.width.shape, boundaries, legend=n == 0, units=u)
        if n == 0:
            _legend(top)
        x, z = snap.frame.centres(*snap.width.shape)
        column = int(np.argmin(np.abs(x - x_inj)))
        bottom.plot(u("width", snap.width[:, column]), u("length", z), "o-", ms=3, label="width")
        draw_layers(bottom, _lengths(boundaries, u), u("length", z[0] - snap.frame.dz / 2),
                    u("length", z[-1] + snap.frame.dz / 2))
        bottom.invert_yaxis()
        bottom.set(xlabel=f"width at x = {u('length', x[column]):.3g} {length} [{width}]",
                   ylabel=f"depth z [{length}]", xlim=(limits[0], limits[1] * 1.05))
    return fig


def footprints(results: Results, boundaries: Sequence[float] | None = None,
               units: FigureUnits | None = None) -> Figure:
    """Outline of the open region (width > 0) at every snapshot, coloured by time (the colour bar), with the
    layer boundaries [m] (default: the stored scene's)."""
    boundaries = layer_boundaries(results) if boundaries is None else boundaries
    u = _units(results, units)
    snaps = list(results.fracture_snapshots)
    exaggeration = vertical_exaggeration(snaps)
    fig = Figure(figsize=(6, 5) if exaggeration == 1 else (8, 4.5), layout="constrained")
    ax = fig.subplots()
    colours = _viridis(len(snaps))
    for snap, colour in zip(snaps, colours):
        x, z = snap.frame.centres(*snap.width.shape)
        if min(snap.width.shape) >= 2 and (snap.width > 0).any():
            ax.contour(u("length", x), u("length", z), (snap.width > 0).astype(float), levels=[0.5],
                       colors=[colour])
    if snaps:
        lows, highs = zip(*((s.frame.z0 - s.frame.dz / 2, s.frame.z0 + (s.width.shape[0] - 0.5) * s.frame.dz)
                            for s in snaps))
        draw_layers(ax, _lengths(boundaries, u), u("length", min(lows)), u("length", max(highs)))
    ax.invert_yaxis()
    title = "footprint (width > 0) over time" + ("" if exaggeration == 1 else
                                                 f", depth exaggerated {exaggeration:g}x")
    ax.set(**_xz_labels(u), title=title, aspect=exaggeration)
    handles, _ = ax.get_legend_handles_labels()
    fig.legend(handles=[*handles, Line2D([], [], color="k", lw=1, label="footprint outline (colour: time)")],
               loc="outside lower center", ncols=2, fontsize=7)
    _time_colourbar(fig, ax, results.fracture_snapshots.times)
    return fig


#: A footprint more than this many times longer than high is drawn with its depth exaggerated.
FOOTPRINT_ELONGATION = 4.0


def vertical_exaggeration(snaps: Sequence[Any]) -> float:
    """1 for a footprint no more than FOOTPRINT_ELONGATION times as long as it is high (drawn to scale), else the
    whole-number factor (depth exaggeration) that draws it about that elongated."""
    opened = [s for s in snaps if (s.width > 0).any()]
    if not opened:
        return 1.0
    last = opened[-1]
    rows, cols = np.nonzero(last.width > 0)
    length = (cols.max() - cols.min() + 1) * last.frame.dx
    height = (rows.max() - rows.min() + 1) * last.frame.dz
    ratio = length / height
    return 1.0 if ratio <= FOOTPRINT_ELONGATION else float(max(1, round(ratio / FOOTPRINT_ELONGATION)))


def area_efficiency(results: Results, units: FigureUnits | None = None) -> Figure:
    """Open area [m^2 or ft^2] at the snapshots and fluid efficiency stored / injected from the balance."""
    u = _units(results, units)
    fig = Figure(figsize=(10, 4), layout="constrained")
    left, right = fig.subplots(1, 2)
    areas = [np.count_nonzero(s.width > 0) * s.frame.dx * s.frame.dz for s in results.fracture_snapshots]
    left.plot(results.fracture_snapshots.times, u("area", areas), "o-")
    left.set(xlabel="time [s]", ylabel=f"fracture area [{u.label('area')}]", title="area")
    b = results.fracture_balance
    if b:
        pumped = b["injected"] > 0
        right.plot(b["time"][pumped], b["stored"][pumped] / b["injected"][pumped])
    right.set(xlabel="time [s]", ylabel="efficiency stored/injected [-]", title="fluid efficiency",
              ylim=(0, 1.05))
    return fig


def pressure_history(results: Results, units: FigureUnits | None = None) -> Figure:
    """Pressures against time from the step history (/fracture/balance), in MPa or psi: the net pressure at the
    injection cell (BHTP less the minimum stress there), linear; the bottom-hole treating pressure (BHTP, the
    fluid pressure in the perforated cell; with ``[wellbore]`` the surface treating pressure, hfgpu.wellbore) with
    the end of pumping and the ISIP (hfgpu.io.summary.treatment_pressures) marked; the net pressure log-log
    while pumping only (a Nolte-Smith plot: slope 1/4 to 1/5 for a confined PKN-like fracture, negative for a
    radial or unconfined one; the shut-in decline is not a power law of the time since the start and stays on
    the linear panels), positive values only, its ticks by :func:`_log_ticks`."""
    from .summary import pump_end, surface_history, treatment_pressures

    u = _units(results, units)
    b = results.fracture_balance
    fig = Figure(figsize=(14, 4), layout="constrained")
    left, middle, right = fig.subplots(1, 3)
    t, net = b["time"], u("pressure", b["net_pressure"])
    unit = u.label("pressure")
    label = f"net pressure at injection [{unit}]"
    left.plot(t, net)
    left.set(xlabel="time [s]", ylabel=label, title="net pressure")
    try:
        stop = pump_end(results.scene)
    except (HfgpuError, ImportError):
        stop = None
    middle.plot(t, u("pressure", b["injection_pressure"]), label="BHTP")
    try:
        stp = surface_history(b, results.scene)
    except (HfgpuError, ImportError):
        stp = None
    if stp is not None:
        middle.plot(t, u("pressure", stp), label="STP (surface, [wellbore])")
    shut_in = treatment_pressures(b, stop)
    if shut_in:
        middle.axvline(stop, color="k", ls=":", lw=1, label="pumps stop")
        middle.plot([shut_in["isip_time"]], [u("pressure", shut_in["isip"])], "rv",
                    label=f"ISIP {_number(float(u('pressure', shut_in['isip'])))} {unit}")
    middle.set(xlabel="time [s]", ylabel=f"treating pressure [{unit}]", title="bottom-hole treating pressure")
    middle.legend(fontsize="small")
    pumping = np.ones(t.shape, dtype=bool) if stop is None else t <= stop
    positive = pumping & (t > 0) & (net > 0)
    right.loglog(t[positive], net[positive])
    for axis, values in ((right.xaxis, t[positive]), (right.yaxis, net[positive])):
        _log_ticks(axis, values)
    right.set(xlabel="time [s]", ylabel=label, title="log-log while pumping (Nolte-Smith)")
    return fig


def stage_split(results: Results, units: FigureUnits | None = None) -> Figure:
    """A stage of several clusters (``/stage/balance``): each cluster's rate against time (stacked: they sum to
    the pump rate), its share of the fluid pumped so far, its created area, and the wellbore pressure with each
    cluster's inlet pressure (the difference is its perforation friction)."""
    u = _units(results, units)
    b = results.stage_balance
    t, n = b["time"], b["rate"].shape[1]
    labels = [f"cluster {i + 1}" for i in range(n)]
    fig = Figure(figsize=(12, 8), layout="constrained")
    (rates, shares), (areas, pressures) = fig.subplots(2, 2)
    rates.stackplot(t, *u("rate", b["rate"]).T, labels=labels, step="pre")
    rates.set(xlabel="time [s]", ylabel=f"cluster rate [{u.label('rate')}]", title="split of the pump rate")
    rates.legend(fontsize="small")
    total = b["injected"].sum(axis=1)
    pumped = total > 0
    for i in range(n):
        shares.plot(t[pumped], b["injected"][pumped, i] / total[pumped], label=labels[i])
        areas.plot(t, u("area", b["area"][:, i]), label=labels[i])
    shares.set(xlabel="time [s]", ylabel="share of the fluid pumped [-]", title="split of the fluid so far")
    areas.set(xlabel="time [s]", ylabel=f"created area (one face) [{u.label('area')}]", title="area per cluster")
    pressures.plot(t, u("pressure", b["wellbore_pressure"]), "k", lw=2, label="wellbore")
    for i in range(n):
        pressures.plot(t, u("pressure", b["injection_pressure"][:, i]), label=f"{labels[i]} inlet")
    pressures.set(xlabel="time [s]", ylabel=f"pressure [{u.label('pressure')}]",
                  title="wellbore and cluster inlet pressures")
    for ax in (shares, areas, pressures):
        ax.legend(fontsize="small")
    return fig


def stage_widths(results: Results, units: FigureUnits | None = None) -> Figure:
    """One panel per cluster of a stage (``/stage/cluster_<i>/snapshots``): its width map at the last snapshot,
    all on one colour scale, titled with its share of the fluid pumped and its created area."""
    u = _units(results, units)
    snaps = [clusters[-1] for clusters in results.stage_snapshots]
    fig = Figure(figsize=(3.6 * len(snaps), 4.2), layout="constrained")
    axes = fig.subplots(1, len(snaps), squeeze=False)[0]
    limits = colour_range(*(u("width", snap.width) for snap in snaps))
    total = sum(float(snap.extras["injected_volume"]) for snap in snaps)
    for n, (ax, snap) in enumerate(zip(axes, snaps)):
        share = float(snap.extras["injected_volume"]) / total if total > 0 else math.nan
        area = float(u("area", float(snap.extras["area"])))
        _map(fig, ax, snap.frame, u("width", snap.width), f"width [{u.label('width')}]",
             f"cluster {n + 1}: {_number(100 * share, '.3g')} % of the fluid\narea {_number(area)} "
             f"{u.label('area')}, t = {_number(snap.time)} s", limits, colourbar=n == len(snaps) - 1, units=u)
    return fig


def stage_proppant(results: Results, boundaries: Sequence[float] = (), units: FigureUnits | None = None) -> Figure:
    """The proppant of a stage (its clusters side by side, hfgpu.stage_blocks): one panel per cluster with its
    proppant volume fraction at the last snapshot (one colour scale), titled with its share of the proppant and
    its propped area after closure where the summary has it; below, the proppant in each cluster against time
    (stacked), and each cluster's share of the proppant beside its share of the fluid pumped since the proppant
    started (``/stage/balance``): the proppant follows the fluid split."""
    u = _units(results, units)
    snaps = results.proppant_snapshots
    last = snaps[-1]
    n = clusters_of(last)
    views = [cluster_view(last, i) for i in range(n)]
    s = results.summary
    fig = Figure(figsize=(3.6 * n, 8.4), layout="constrained")
    top, bottom = fig.subfigures(2, 1)
    axes = top.subplots(1, n, squeeze=False)[0]
    limits = colour_range(*(v.grid["volume_fraction"] for v in views))
    for i, (ax, view) in enumerate(zip(axes, views)):
        title = f"cluster {i + 1}"
        if f"cluster_{i}_solid_share" in s:
            title += f": {_number(100 * float(s[f'cluster_{i}_solid_share']), '.3g')} % of the proppant"
        if f"cluster_{i}_closure_propped_area" in s:
            title += (f"\npropped {_number(float(u('area', float(s[f'cluster_{i}_closure_propped_area']))))} "
                      f"{u.label('area')} after closure")
        _map(top, ax, view.frame, view.grid["volume_fraction"], "volume fraction [-]", title, limits,
             colourbar=i == n - 1, units=u)
        _layers_on_map(ax, view.frame, view.grid["volume_fraction"].shape, boundaries, units=u)
    sand, fluid = bottom.subplots(1, 2)
    times = np.array([snap.time for snap in snaps])
    solids = np.array([[batch_solid_volume(cluster_view(snap, i).parcels) for i in range(n)] for snap in snaps])
    labels = [f"cluster {i + 1}" for i in range(n)]
    sand.stackplot(times, *u("solid_volume", solids).T, labels=labels)
    sand.set(xlabel="time [s]", ylabel=f"proppant in the cluster [{u.label('solid_volume')}]",
             title="where the proppant went")
    sand.legend(fontsize="small")
    b = results.stage_balance
    if b:   # the fluid each cluster took since the proppant started, which carried its proppant
        start = float(s.get("proppant_start", 0.0))
        since = b["injected"] - np.array([np.interp(start, b["time"], column) for column in b["injected"].T])
        total = since.sum(axis=1)
        pumped = (b["time"] > start) & (total > 0)
        for i in range(n):
            fluid.plot(b["time"][pumped], since[pumped, i] / total[pumped], label=labels[i])
    held = solids.sum(axis=1) > 0.0
    for i in range(n):
        fluid.plot(times[held], solids[held, i] / solids[held].sum(axis=1), "o", color=f"C{i}", ms=3)
    fluid.set(xlabel="time [s]", ylabel="share [-]",
              title="share of the fluid (lines) and of the proppant (dots) since the proppant started")
    fluid.legend(fontsize="small")
    return fig


def falloff(results: Results):
    """The fall-off of the results' step history after the pumps stop (hfgpu.io.summary.falloff_of), None for a
    run without one (no shut-in record, or a scene that does not parse)."""
    from .summary import falloff_of, pump_end

    try:
        stop = pump_end(results.scene)
    except (HfgpuError, ImportError):
        return None
    return falloff_of(results.fracture_balance, stop)


def fall_off(results: Results, units: FigureUnits | None = None, analysis: Any = None) -> Figure:
    """The fall-off on Nolte's G-function (hfgpu.fracture.falloff, ``analysis`` or :func:`falloff`): BHTP and
    the minimum stress at the injection depth (left axis) and the superposition derivative G dP/dG (right axis)
    against G, in MPa or psi, with the straight line through the origin the closure pick is read on and the
    closure marked (or "no closure picked" in the title)."""
    a = falloff(results) if analysis is None else analysis
    if a is None:
        raise HfgpuError("the results hold no record after the pumps stop: no fall-off to plot")
    u = _units(results, units)
    unit = u.label("pressure")
    fig = Figure(figsize=(8, 4.5), layout="constrained")
    left = fig.subplots()
    right = left.twinx()
    left.plot(a.G, u("pressure", a.pressure), "o-", ms=2, color="C0", label="BHTP")
    if math.isfinite(a.sigma_min):
        left.axhline(u("pressure", a.sigma_min), color="0.5", ls="-.", lw=0.8,
                     label="minimum stress at injection depth")
    right.plot(a.G, u("pressure", a.derivative), "s-", ms=2, color="C1", label="G dP/dG")
    if math.isfinite(a.slope):  # a straight line through the origin was found
        right.plot([0.0, float(a.G[-1])], [0.0, float(u("pressure", a.slope * a.G[-1]))], "--", color="C1", lw=0.8,
                   label="line through the origin (open fracture)")
    title = f"fall-off, G-function (alpha = {a.alpha:g}): "
    if a.closure is not None:
        c = a.closure
        left.axvline(c.G, color="k", ls=":", lw=1)
        left.plot([c.G], [u("pressure", c.pressure)], "kD",
                  label=f"closure {_number(float(u('pressure', c.pressure)))} {unit}, "
                        f"{_number(a.closure_time)} s after shut-in")
        right.plot([c.G], [u("pressure", a.derivative[c.index])], "kD")
        title += f"closure at G = {_number(c.G, '.3g')}, efficiency {_number(a.efficiency, '.2f')}"
    else:
        title += "no closure picked"
    left.set(xlabel=f"G (alpha = {a.alpha:g}) [-]", ylabel=f"bottom-hole pressure [{unit}]", title=title)
    right.set(ylabel=f"G dP/dG [{unit}]", ylim=(0, None))
    handles = [*left.get_legend_handles_labels()[0], *right.get_legend_handles_labels()[0]]
    fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize=7)
    return fig


def _log_ticks(axis, values: np.ndarray) -> None:
    """Ticks of a log axis that do not overlap: labels at the decades and, when ``values`` span less than two
    decades (so that few decades are labelled), also at 2 and 5 times them, as plain numbers ("200", "0.5")."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    span = np.log10(values.max() / values.min()) if values.size and values.min() > 0 else 0.0
    plain = FuncFormatter(lambda v, _: f"{v:g}")
    axis.set_major_locator(LogLocator(base=10.0))
    axis.set_major_formatter(plain)
    axis.set_minor_locator(LogLocator(base=10.0, subs=(2.0, 5.0) if span < 2.0 else (2.0, 3.0, 4.0, 5.0, 6.0,
                                                                                        7.0, 8.0, 9.0)))
    axis.set_minor_formatter(plain if span < 2.0 else NullFormatter())


def volume_balance(results: Results, units: FigureUnits | None = None) -> Figure:
    """Injected, stored and leaked volume [m^3 or bbl] vs time; stored + leaked dotted (it should cover
    injected)."""
    return _balance(results.fracture_balance, ("injected", "stored", "leaked"), "fluid volume balance",
                    units=_units(results, units), kind="volume")


def proppant_balance(results: Results, units: FigureUnits | None = None) -> Figure:
    """Injected, in-domain, outflow and held-back (screened out at the inlet, when the file has it) proppant vs
    time, as the run summary gives it: a mass [kg or lb] where every class has the same grain density
    (hfgpu.io.summary.shared_density), else a solid volume [m^3 or ft^3]; their sum dotted (it should cover
    injected)."""
    from .summary import shared_density

    names = ("injected", "in_domain", "outflow") + (("screened_out",) if "screened_out" in results.proppant_balance
                                                    else ())
    try:
        density = shared_density(results.scene)
    except (HfgpuError, ImportError):
        density = None
    b = results.proppant_balance
    if density is not None:
        b = {k: v * density if k in names else v for k, v in b.items()}
    return _balance(b, names, "proppant balance" if density is not None else "proppant (solid) volume balance",
                    {"in_domain": "in the domain", "screened_out": "held back at the inlet (screened out)"},
                    units=_units(results, units), kind="mass" if density is not None else "solid_volume")


def _balance(b: dict[str, np.ndarray], names: tuple[str, ...], title: str,
             labels: dict[str, str] | None = None, units: FigureUnits = SI, kind: str = "volume") -> Figure:
    """``names[0]`` (what came in) and the others (where it went) vs time, with the others' sum dotted, as
    ``kind`` in ``units``."""
    labels = labels or {}
    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax = fig.subplots()
    for name in names:
        ax.plot(b["time"], units(kind, b[name]), label=labels.get(name, name))
    ax.plot(b["time"], units(kind, sum(b[name] for name in names[1:])), "k:",
            label=" + ".join(labels.get(name, name).split(" (")[0] for name in names[1:]))
    ax.set(xlabel="time [s]", ylabel=f"{'mass' if kind == 'mass' else 'volume'} [{units.label(kind)}]", title=title)
    ax.legend()
    return fig


def volume_fraction_map(snap: ProppantSnapshot, boundaries: Sequence[float] = (), units: FigureUnits = SI) -> Figure:
    """Proppant volume fraction on the grid, with the layer ``boundaries`` [m depth], axes in ``units``."""
    fig = _domain_figure(snap.frame, snap.grid["volume_fraction"].shape)
    ax = fig.subplots()
    _map(fig, ax, snap.frame, snap.grid["volume_fraction"], "volume fraction [-]",
         f"proppant volume fraction, t = {_number(snap.time)} s", units=units)
    _layers_on_map(ax, snap.frame, snap.grid["volume_fraction"].shape, boundaries, units=units)
    _legend(ax)
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


def parcel_speed_map(snap: ProppantSnapshot, boundaries: Sequence[float] = (), units: FigureUnits = SI) -> Figure:
    """Mean parcel speed [m/s or ft/s] per grid cell (cells without parcels left blank), with the layer
    ``boundaries`` [m depth]."""
    mean = units("speed", _mean_speed(snap))
    fig = _domain_figure(snap.frame, mean.shape)
    ax = fig.subplots()
    _map(fig, ax, snap.frame, mean, f"mean parcel speed [{units.label('speed')}]",
         f"parcel speed, t = {_number(snap.time)} s", units=units)
    _layers_on_map(ax, snap.frame, mean.shape, boundaries, units=units)
    _legend(ax)
    return fig


def proppant_maps(results: Results, count: int = 4, boundaries: Sequence[float] | None = None,
                  units: FigureUnits | None = None) -> Figure:
    """Volume fraction (top row) and mean parcel speed (bottom row) at up to ``count`` times (the paper's
    Fig. 14), each row on one colour scale; cells flagged ``bridging_risk`` are outlined in red where the file
    has that field; the layer boundaries (default: the stored scene's)."""
    boundaries = layer_boundaries(results) if boundaries is None else boundaries
    u = _units(results, units)
    snaps = [results.proppant_snapshots[i] for i in _picks(len(results.proppant_snapshots), count)]
    fig = Figure(figsize=(4.5 * len(snaps), 6), layout="constrained")
    axes = fig.subplots(2, len(snaps), squeeze=False)
    speeds = [u("speed", _mean_speed(snap)) for snap in snaps]
    fractions = colour_range(*(snap.grid["volume_fraction"] for snap in snaps))
    speed_range = colour_range(*speeds)
    outlined = [("bridging_risk" in snap.grid and snap.grid["bridging_risk"].any()
                 and min(snap.grid["width"].shape) > 1) for snap in snaps]
    bridging = Line2D([], [], color="r", lw=0.8, label="bridging risk (width < bridging_factor x grain diameter)")
    for n, (top, bottom, snap, speed) in enumerate(zip(axes[0], axes[1], snaps, speeds)):
        last = n == len(snaps) - 1
        shape = snap.grid["volume_fraction"].shape
        _map(fig, top, snap.frame, snap.grid["volume_fraction"], "volume fraction [-]",
             f"t = {_number(snap.time)} s", fractions, colourbar=last, units=u)
        if outlined[n]:
            x, z = snap.frame.centres(*snap.grid["width"].shape)
            top.contour(u("length", x), u("length", z), snap.grid["bridging_risk"].astype(float), levels=[0.5],
                        colors=["r"], linewidths=0.8)
        _map(fig, bottom, snap.frame, speed, f"mean parcel speed [{u.label('speed')}]", "", speed_range,
             colourbar=last, units=u)
        for ax in (top, bottom):
            _layers_on_map(ax, snap.frame, shape, boundaries, legend=n == 0, units=u)
    _legend(axes[0][0], *([bridging] if any(outlined) else []))  # one legend for the row
    return fig


def streamlines(snap: ProppantSnapshot, boundaries: Sequence[float] = (), units: FigureUnits = SI) -> Figure:
    """Streamlines of the fluid velocity (face values averaged to the cell centres, zero in closed cells)
    over the width map [mm or in], coloured by speed (the paper's Fig. 13c, 15j-l)."""
    g, f = snap.grid, snap.frame
    width = np.asarray(g["width"])
    u = 0.5 * (g["fluid_u"][:, :-1] + g["fluid_u"][:, 1:])
    v = 0.5 * (g["fluid_v"][:-1, :] + g["fluid_v"][1:, :])
    u, v = units("speed", np.where(width > 0, u, 0.0)), units("speed", np.where(width > 0, v, 0.0))
    fig = _domain_figure(f, width.shape)
    ax = fig.subplots()
    _map(fig, ax, f, np.where(width > 0, units("width", width), np.nan), f"width [{units.label('width')}]",
         f"fluid streamlines, t = {_number(snap.time)} s", units=units)
    _layers_on_map(ax, f, width.shape, boundaries, units=units)
    x, z = f.centres(*width.shape)
    x, z, dx, dz = units("length", x), units("length", z), units("length", f.dx), units("length", f.dz)
    if min(width.shape) >= 2 and np.any(u) | np.any(v):
        lines = ax.streamplot(x, z, u, v, color=np.hypot(u, v), cmap="magma", density=1.2, linewidth=0.7)
        fig.colorbar(lines.lines, ax=ax, label=f"fluid speed [{units.label('speed')}]")
    ax.set(xlim=(x[0] - dx / 2, x[-1] + dx / 2), ylim=(z[-1] + dz / 2, z[0] - dz / 2))
    _legend(ax)
    return fig


def speed_probability(results: Results, times: tuple[float, ...] | None = None,
                      units: FigureUnits | None = None) -> Figure:
    """Cumulative probability of the parcel speed |u_p| at the snapshots nearest ``times`` (the paper's
    Fig. 16; default 1260 / 1800 / 3600 s, or the same fractions of a shorter slurry period,
    :func:`hfgpu.propped.results_times`), with the packed-parcel threshold of :mod:`hfgpu.propped` dotted."""
    from ..propped import PACKED_SPEED, packed_fraction, results_times

    times = results_times(results) if times is None else times
    u = _units(results, units)
    speed_unit, threshold = u.label("speed"), u("speed", PACKED_SPEED)
    fig = Figure(figsize=(4.5 * len(times), 4), layout="constrained")
    for ax, t in zip(fig.subplots(1, len(times), squeeze=False)[0], times):
        snap = results.proppant_snapshots.at(t)
        speed = u("speed", np.sort(np.hypot(snap.parcels["u"], snap.parcels["v"])))
        if speed.size:
            ax.plot(speed, (np.arange(speed.size) + 0.5) / speed.size, ".", ms=2, label="parcels")
        ax.axvline(threshold, color="k", ls=":", lw=0.8,
                   label=f"packed below {threshold:{'.3g' if u.field else 'g'}} {speed_unit}")
        packed = packed_fraction(snap.parcels) if speed.size else math.nan
        ax.set(xlabel=f"|u_p| [{speed_unit}]", ylabel="cumulative probability [-]", ylim=(0, 1),
               title=f"t = {_number(snap.time)} s, " + (f"packed {packed:.2f}" if math.isfinite(packed)
                                                         else "no parcels"))
        _legend(ax)
    return fig


def propped_area(results: Results, units: FigureUnits | None = None) -> Figure:
    """Fracture area (fracture snapshots), created and propped area (proppant grid) [m^2 or ft^2] vs time
    (Fig. 18). The propped area is drawn by both definitions of :data:`hfgpu.propped.DEFINITIONS`: after closure
    (the run summary's headline, its closed snapshot marked) and one layer in place."""
    from ..propped import DEFINITIONS, area_history, closure_area_history, fracture_area_history, headline_propped

    u = _units(results, units)
    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax = fig.subplots()
    frac = fracture_area_history(results)
    ax.plot(frac["time"], u("area", frac["area"]), label="fracture area (one face)")
    areas = area_history(results)
    ax.plot(areas["time"], u("area", areas["created"]), "--", label="open area (proppant grid)")
    closed = closure_area_history(results)
    ax.plot(closed["time"], u("area", closed["propped_area"]), "o-", ms=3,
            label=f"propped area, {DEFINITIONS['propped_area']}")
    ax.plot(areas["time"], u("area", areas["propped"]), "s:", ms=3,
            label=f"propped area, {DEFINITIONS['propped_area_in_place']}")
    head = headline_propped(results)
    ax.plot([head["time"]], [u("area", head["propped_area"])], "k*", ms=10, label="run summary's propped area")
    ax.set(xlabel="time [s]", ylabel=f"area [{u.label('area')}]", title="created and propped area")
    ax.legend(fontsize="small")
    return fig


def parcels_by_radius(snap: ProppantSnapshot, boundaries: Sequence[float] = (), units: FigureUnits = SI) -> Figure:
    """Parcel positions coloured by particle radius [um or in]."""
    shape = snap.grid["volume_fraction"].shape
    fig = _domain_figure(snap.frame, shape)
    ax = fig.subplots()
    x = units("length", snap.parcels["x"])
    points = ax.scatter(x, units("length", snap.parcels["z"]), c=units("radius", snap.parcels["radius"]),
                        s=min(4.0, 2e4 / max(x.size, 1)), linewidths=0)
    fig.colorbar(points, ax=ax, label=f"radius [{units.label('radius')}]")
    left, right, bottom, top = _extent(snap.frame, shape, units)
    ax.set(xlim=(left, right), ylim=(bottom, top), **_xz_labels(units), aspect=_aspect(snap.frame, shape),
           title=f"parcels by radius, t = {_number(snap.time)} s")
    _layers_on_map(ax, snap.frame, shape, boundaries, units=units)
    _legend(ax)
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


def closure_maps(closure, system: str = "SI", boundaries: Sequence[float] = ()) -> Figure:
    """Propped width and conductivity after closure (:mod:`hfgpu.closure`), in ``system``'s units ("SI" or
    "field", the axes in m or ft; the values in :mod:`hfgpu.closure.display`'s units), with the layer
    ``boundaries`` [m depth]."""
    from ..closure.display import in_units, unit_label

    shape = closure.fields["propped_width"].shape
    wide = shape[1] * closure.frame.dx >= shape[0] * closure.frame.dz
    fig = Figure(figsize=(8, 7) if wide else (9, 6), layout="constrained")
    for ax, name, title in zip(fig.subplots(2, 1) if wide else fig.subplots(1, 2), ("propped_width", "conductivity"),
                               ("propped width after closure", "conductivity after closure")):
        values = np.where(closure.fields["propped"] > 0, in_units(name, closure.fields[name], system), np.nan)
        _map(fig, ax, closure.frame, values, f"{name.replace('_', ' ')} [{unit_label(name, system)}]",
             f"{title} (t = {_number(closure.scalars.get('time', math.nan))} s)", units=FigureUnits(system))
        _layers_on_map(ax, closure.frame, shape, boundaries, units=FigureUnits(system))
        _legend(ax)
    return fig


def is_column(results: Results) -> bool:
    """A proppant-only run on at most MAX_COLUMN_CELLS columns of cells, taller than wide (a settling column)."""
    if len(results.fracture_snapshots) or not len(results.proppant_snapshots):
        return False
    nz, nx = results.proppant_snapshots[0].grid["volume_fraction"].shape
    return nx <= MAX_COLUMN_CELLS and nz > nx


def _theta_cp(results: Results) -> float:
    """Close packing of the stored scene (0.6 when it does not parse)."""
    try:
        return float(results.scene.proppant.params.theta_cp)
    except (HfgpuError, ImportError, AttributeError):
        return 0.6


def interface_heights(results: Results) -> dict[str, np.ndarray]:
    """Heights above the column's bottom [m] against time of the top of the suspension (where the width-weighted
    row profile of theta_p first rises through half the first snapshot's suspension value, going down) and of
    the bed top (where it rises through the midpoint of that value and close packing), at every proppant
    snapshot; also the two levels used (:func:`hfgpu.proppant.analysis.interface_depth`)."""
    from ..proppant.analysis import interface_depth, row_profile

    snaps = list(results.proppant_snapshots)
    first = row_profile(snaps[0].grid["volume_fraction"], snaps[0].grid["width"])
    suspension = float(np.median(first[first > 0])) if (first > 0).any() else 0.5 * _theta_cp(results)
    top_level, bed_level = 0.5 * suspension, 0.5 * (suspension + _theta_cp(results))
    out = {"time": np.array([s.time for s in snaps]), "suspension_top": [], "bed_top": []}
    for snap in snaps:
        profile = row_profile(snap.grid["volume_fraction"], snap.grid["width"])
        bottom = snap.frame.z0 + (profile.size - 0.5) * snap.frame.dz
        out["suspension_top"].append(bottom - interface_depth(profile, snap.frame, top_level))
        out["bed_top"].append(bottom - interface_depth(profile, snap.frame, bed_level))
    return {**{k: np.asarray(v, dtype=float) for k, v in out.items()}, "suspension_level": top_level,
            "bed_level": bed_level}


def column_interfaces(results: Results, units: FigureUnits | None = None) -> Figure:
    """Top of the suspension and bed top [m or ft above the bottom] against time in a settling column
    (:func:`interface_heights`)."""
    u = _units(results, units)
    h = interface_heights(results)
    snap = results.proppant_snapshots[0]
    height = u("length", snap.grid["volume_fraction"].shape[0] * snap.frame.dz)
    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax = fig.subplots()
    ax.plot(h["time"], u("length", h["suspension_top"]), "o-", ms=3,
            label=f"top of the suspension (theta_p = {h['suspension_level']:.3g})")
    ax.plot(h["time"], u("length", h["bed_top"]), "s-", ms=3, label=f"bed top (theta_p = {h['bed_level']:.3g})")
    ax.set(xlabel="time [s]", ylabel=f"height above the bottom [{u.label('length')}]", ylim=(0, height * 1.02),
           title="settling column: interface heights")
    ax.legend()
    return fig


def _closure(results: Results):
    """The results' closure map (stored, or computed from the last proppant snapshot), None when the stored scene
    has no proppant or does not parse."""
    from ..closure.conductivity import closure_of

    try:
        return closure_of(results)
    except HfgpuError:
        return None


def status_banner(results: Results) -> str | None:
    """What a reader must know before trusting the figures of ``results``: a run that did not complete (its
    status) or unphysical states found during it (their kinds and first times, hfgpu.proppant.health); None when
    neither."""
    lines = []
    if results.status != "complete":
        lines.append(f"NOT COMPLETE: {' '.join(str(results.status).split())[:110]}")
    summary = results.summary or {}
    found = summary.get("proppant_unphysical_states") or summary.get("unphysical_states") or ""
    if found:
        kinds = re.findall(r"(?:^|; )([a-z][^;:]*? at t = [^:;]+ s):", str(found)) or [str(found)[:80]]
        lines.append("unphysical states: " + "; ".join(kinds))
    return "\n".join(textwrap.fill(line, BANNER_WIDTH) for line in lines) or None


#: Characters per line of the status banner (it must fit the narrowest figure, 6 in wide at 8 pt).
BANNER_WIDTH = 95


def figures(results: Results, units: FigureUnits | None = None) -> dict[str, Figure]:
    """Every figure the results support, by file stem, in ``units`` (default: the results' ``[output] units``);
    each carries :func:`status_banner` in red at its top left where there is one."""
    out: dict[str, Figure] = {}
    layers = layer_boundaries(results)
    u = _units(results, units)
    if len(results.fracture_snapshots):
        out.update(fracture_width=width_maps(results, boundaries=layers, units=u),
                   fracture_footprints=footprints(results, boundaries=layers, units=u),
                   fracture_area_efficiency=area_efficiency(results, units=u))
    if results.fracture_balance:
        out["fracture_volume_balance"] = volume_balance(results, units=u)
        if np.isfinite(results.fracture_balance.get("net_pressure", np.nan)).any():
            out["pressure_history"] = pressure_history(results, units=u)
        analysis = falloff(results)
        if analysis is not None:  # a run with a shut-in (records after the pumps stop)
            out["fall_off"] = fall_off(results, units=u, analysis=analysis)
    if results.stage_balance:
        out["stage_split"] = stage_split(results, units=u)
    if results.stage_snapshots:
        out["stage_widths"] = stage_widths(results, units=u)
    if len(results.proppant_snapshots):
        last = results.proppant_snapshots[-1]
        out.update(proppant_volume_fraction=volume_fraction_map(last, layers, u),
                   proppant_speed=parcel_speed_map(last, layers, u), proppant_radius=parcels_by_radius(last, layers, u))
        closure = _closure(results)
        if closure is not None:
            out["closure_maps"] = closure_maps(closure, u.system, layers)
        if clusters_of(last):
            out["stage_proppant"] = stage_proppant(results, layers, u)
    if results.proppant_balance:
        out["proppant_volume_balance"] = proppant_balance(results, units=u)
    if is_column(results):
        out["proppant_interfaces"] = column_interfaces(results, units=u)
    if len(results.fracture_snapshots) and len(results.proppant_snapshots):  # a coupled run
        out.update(proppant_maps=proppant_maps(results, boundaries=layers, units=u),
                   proppant_streamlines=streamlines(results.proppant_snapshots[-1], layers, u),
                   proppant_speed_probability=speed_probability(results, units=u),
                   propped_area=propped_area(results, units=u))
    banner = status_banner(results)
    if banner is not None:
        for fig in out.values():
            fig.text(0.005, 0.995, banner, ha="left", va="top", color="red", fontsize=8)
    return out


#: The figures only a run with a shut-in (records after the pumps stop) gets.
SHUT_IN_FIGURES = ("fall_off",)
#: The figure names (file stems) ``figures`` can produce, by the kind of results that produces them.
FIGURE_NAMES = {
    "fracture": ("fracture_width", "fracture_footprints", "fracture_area_efficiency", "fracture_volume_balance",
                 "pressure_history", "fall_off"),
    "proppant": ("proppant_volume_fraction", "proppant_speed", "proppant_radius", "closure_maps",
                 "proppant_volume_balance"),
    "column": ("proppant_interfaces",),
    "coupled": ("proppant_maps", "proppant_streamlines", "proppant_speed_probability", "propped_area"),
    "stage": ("stage_split", "stage_widths", "stage_proppant"),
}


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
