"""Figures of a sweep folder (matplotlib, no pyplot state), from its ``ensemble.h5`` alone; ``hfgpu plot DIR``.

* ``distribution_<metric>.png``: histogram of each metric over the complete members, P10 / P50 / P90 marked;
* ``tornado.png``: per metric, Spearman's rank correlation rho of the metric with each varied input (bars sorted
  by |rho|; an input or metric that does not vary gives no bar, nor do fewer than 3 members; text inputs are
  left out);
* ``propped_maps.png`` (members with proppant only): the P10 / P50 / P90 maps of hfgpu.ensemble.summary (cells
  propped in at least 90 / 50 / 10 % of the members) over the fraction of members in which each cell is propped.

Values, ranges and axes are in the base scene's display units (``ensemble.h5``'s ``units``,
hfgpu.ensemble.table_units: ft, ft^2, psi, bbl/min in a field scene), each named on its axis or label.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ..errors import HfgpuError
from ..io.display_units import FigureUnits
from ..units import format_number
from .summary import LEVELS, MAP_THRESHOLDS, read_ensemble
from .table_units import ColumnUnits


def _values(rows: list[dict], name: str) -> np.ndarray:
    return np.array([r[name] for r in rows if r["status"] == "complete"], dtype=float)


def _named(name: str, units: ColumnUnits) -> str:
    """"name [unit]" ("name [-]" for a ratio)."""
    return f"{name} [{units.label(name)}]"


def distribution(rows: list[dict], metric: str, levels: np.ndarray, units: ColumnUnits) -> Figure:
    values = units(metric, _values(rows, metric))
    values, levels = values[np.isfinite(values)], units(metric, levels)
    fig = Figure(figsize=(6, 4), layout="constrained")
    ax = fig.subplots()
    ax.hist(values, bins=max(5, min(30, values.size // 2)), color="0.7", edgecolor="0.3")
    for level, value, colour in zip(LEVELS, levels, ("tab:red", "tab:green", "tab:blue")):
        ax.axvline(value, color=colour, label=f"P{level} = {format_number(value)} {units.label(metric)}")
    ax.set(xlabel=_named(metric, units), ylabel="members", title=f"{metric}: {values.size} members")
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))   # whole members
    ax.legend()
    return fig


def rank_correlations(rows: list[dict], inputs: list[str], metric: str) -> dict[str, float]:
    """Spearman's rho of ``metric`` with each input over the complete members with a finite metric (NaN when
    either does not vary)."""
    from scipy.stats import spearmanr

    y = _values(rows, metric)
    keep = np.isfinite(y)
    out = {}
    for name in inputs:
        x = _values(rows, name)[keep]
        varies = keep.sum() > 2 and np.ptp(x) > 0 and np.ptp(y[keep]) > 0
        out[name] = float(spearmanr(x, y[keep]).statistic) if varies else float("nan")
    return out


def _input_label(rows: list[dict], name: str, units: ColumnUnits) -> str:
    """An input's name and the range it took over the complete members, in its unit: "rate (30 to 50 bbl/min)"."""
    values, unit = units(name, _values(rows, name)), units.label(name)
    suffix = f" {unit}" if unit not in ("", "-") else ""
    return f"{name} ({format_number(values.min())} to {format_number(values.max())}{suffix})"


def tornado(rows: list[dict], inputs: list[str], metrics: list[str], units: ColumnUnits) -> Figure:
    labels = {k: _input_label(rows, k, units) for k in inputs}
    width = 4.5 + 0.075 * max((len(text) for text in labels.values()), default=0)   # the labels beside the axes
    fig = Figure(figsize=(width, 1.2 + 0.35 * len(inputs) * len(metrics) + 0.6 * len(metrics)), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(metrics), 1, sharex=True))
    for ax, metric in zip(axes, metrics):
        rho = rank_correlations(rows, inputs, metric)
        order = sorted((k for k in inputs if np.isfinite(rho[k])), key=lambda k: abs(rho[k]))
        ax.barh(range(len(order)), [rho[k] for k in order],
                color=["tab:blue" if rho[k] >= 0 else "tab:red" for k in order])
        ax.set_yticks(range(len(order)), [labels[k] for k in order])
        ax.axvline(0.0, color="0.3", lw=0.8)
        ax.set(xlim=(-1, 1), xticks=[-1, -0.5, 0, 0.5, 1], title=metric)
        if not order:
            count = int(np.isfinite(_values(rows, metric)).sum())
            why = f"{count} members, 3 needed" if count < 3 else "no input or the metric does not vary"
            ax.text(0.5, 0.5, why, transform=ax.transAxes, ha="center", va="center", color="0.4")
    axes[-1].set_xlabel("Spearman rank correlation with the input")
    return fig


def propped_maps(propped: dict, units: FigureUnits) -> Figure:
    frame, fraction = propped["frame"], propped["fraction"]
    nz, nx = fraction.shape
    extent = (units("length", frame.x0 - frame.dx / 2), units("length", frame.x0 + (nx - 0.5) * frame.dx),
              units("depth", frame.z0 + (nz - 0.5) * frame.dz), units("depth", frame.z0 - frame.dz / 2))
    fig = Figure(figsize=(12, 4), layout="constrained")
    axes = fig.subplots(1, len(LEVELS), sharey=True)
    for ax, level in zip(axes, LEVELS):
        threshold = MAP_THRESHOLDS[level]
        image = ax.imshow(np.where(fraction >= threshold, fraction, np.nan), extent=extent, origin="upper",
                          interpolation="nearest", vmin=0.0, vmax=1.0)
        ax.set(xlabel=f"x [{units.label('length')}]",
               title=f"P{level}: propped in >= {threshold:.0%} of {propped['members']} members")
    axes[0].set_ylabel(f"depth z [{units.label('depth')}]")
    fig.colorbar(image, ax=list(axes), label="fraction of members propped")
    return fig


def plot_ensemble(folder: str | Path, out: str | Path, dpi: int = 120) -> list[Path]:
    """Write the figures of the sweep folder ``folder`` (its ensemble.h5) into ``out``; return their paths."""
    path = Path(folder) / "ensemble.h5"
    if not path.is_file():
        raise HfgpuError(f"'{folder}' is not a sweep folder: it has no ensemble.h5 (written by 'hfgpu sweep')")
    data = read_ensemble(path)
    units = data["units"]
    figures = {f"distribution_{m}": distribution(data["rows"], m, data["percentiles"][m], units)
               for m in data["metrics"] if np.isfinite(data["percentiles"][m]).all()}
    numeric = [name for name in data["inputs"] if not any(isinstance(r[name], str) for r in data["rows"])]
    figures["tornado"] = tornado(data["rows"], numeric, data["metrics"], units)
    if data["propped"] is not None:
        figures["propped_maps"] = propped_maps(data["propped"], FigureUnits(units.system))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, fig in figures.items():
        paths.append(out / f"{name}.png")
        fig.savefig(paths[-1], dpi=dpi)
    return paths
