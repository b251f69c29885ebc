"""The sweep's tables: one row per member, ``summary.csv``, percentiles, propped-cell probability maps, and
``ensemble.h5`` holding them all (docs/ensembles.md has the layout).

Row: ``id``, ``status`` ("complete" or "failed: <reason>"), every varied input (SI; text inputs as text), every
metric (NaN where the member has none or failed), ``wall_seconds``.

``summary.csv``: a first header row of the column names (the contract: key paths and metric names), a second one
of their units (``hfgpu.ensemble.table_units``: the scene's display units in a field scene, SI in an SI scene;
"-" for ratios, empty for id, status and text), then one row per member in those units. ``ensemble.h5`` holds
the same table in SI, with the unit system and each column's kind.

Percentiles: P10, P50, P90 of a metric = ``numpy.percentile(v, [10, 50, 90])`` over the complete members'
finite values v (linear interpolation; P10 is the low case).

Probability map: the members that have proppant are put on a common grid (the smallest cell sizes of the
members, spanning all their frames; each common cell takes the propped state of the member cell holding its
centre, False outside the member's frame). ``fraction`` = the share of those members in which a cell is
propped. The P10 / P50 / P90 maps are the cells with fraction >= 0.9 / 0.5 / 0.1: the P10 map is the low case
(cells propped in at least 90 % of members), the P90 map the high case, as for the metrics.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..records import GridFrame
from .table_units import ColumnUnits, column_kinds

LEVELS = (10, 50, 90)
#: The fraction of members a cell must be propped in to be in the P10 / P50 / P90 map.
MAP_THRESHOLDS = {10: 0.9, 50: 0.5, 90: 0.1}


def columns(keys: list[str], metrics: list[str]) -> list[str]:
    """The summary's columns in order."""
    return ["id", "status", *keys, *metrics, "wall_seconds"]


def row(member_id: str, status: str, inputs: dict[str, Any], metrics: dict[str, float], names: list[str],
        wall: float) -> dict[str, Any]:
    """One summary row; metrics not asked for are left out, those missing are NaN."""
    return {"id": member_id, "status": status, **inputs, **{n: float(metrics.get(n, math.nan)) for n in names},
            "wall_seconds": float(wall)}


class CsvWriter:
    """``summary.csv`` written a row at a time in ``units`` (flushed: a killed sweep keeps the rows it had): the
    column names, their units, the rows."""

    def __init__(self, path: Path, header: list[str], units: ColumnUnits):
        self.header, self.units = header, units
        self._file = open(path, "w", newline="", encoding="utf-8")
        self._csv = csv.writer(self._file)
        self._csv.writerows([header, [units.label(name) for name in header]])
        self._file.flush()

    def write(self, values: dict[str, Any]) -> None:
        self._csv.writerow([_cell(self.units(name, values[name])) for name in self.header])
        self._file.flush()

    def close(self) -> None:
        self._file.close()


def _cell(value: Any) -> str:
    return repr(float(value)) if isinstance(value, (float, np.floating)) else str(value)


def write_csv(path: Path, header: list[str], rows: list[dict[str, Any]], units: ColumnUnits) -> None:
    """The whole table at once (the final, id-ordered ``summary.csv``)."""
    writer = CsvWriter(path, header, units)
    for values in rows:
        writer.write(values)
    writer.close()


def read_csv(path: str | Path) -> list[dict[str, Any]]:
    """``summary.csv`` read back, in the units it is written in (:func:`read_units`): id, status and text inputs as
    text, every other column a float."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    return [{k: v if k in ("id", "status") else _number(v) for k, v in r.items()} for r in rows if r["id"]]


def read_units(path: str | Path) -> dict[str, str]:
    """{column: unit} of ``summary.csv`` (its second header row; a file without one, of an earlier version, is SI
    and gives {})."""
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        header, units = next(reader), next(reader, [])
    return dict(zip(header, units)) if units and units[0] == "" else {}


def _number(text: str) -> float | str:
    try:
        return float(text)
    except ValueError:  # a text input (a sieve class)
        return text


def percentiles(rows: list[dict[str, Any]], metric: str) -> np.ndarray:
    """[P10, P50, P90] of a metric over the complete members' finite values (NaN when there are none)."""
    values = np.array([r[metric] for r in rows if r["status"] == "complete"], dtype=float)
    values = values[np.isfinite(values)]
    return np.percentile(values, LEVELS) if values.size else np.full(len(LEVELS), np.nan)


def common_fraction(maps: list[tuple[GridFrame, np.ndarray]]) -> tuple[GridFrame, np.ndarray]:
    """(frame, fraction of the maps in which each cell is propped) on the common grid of the module docstring."""
    dx = min(f.dx for f, _ in maps)
    dz = min(f.dz for f, _ in maps)
    left = min(f.x0 - f.dx / 2 for f, _ in maps)
    top = min(f.z0 - f.dz / 2 for f, _ in maps)
    right = max(f.x0 + (m.shape[1] - 0.5) * f.dx for f, m in maps)
    bottom = max(f.z0 + (m.shape[0] - 0.5) * f.dz for f, m in maps)
    nx, nz = max(1, round((right - left) / dx)), max(1, round((bottom - top) / dz))
    frame = GridFrame(dx=dx, dz=dz, x0=left + dx / 2, z0=top + dz / 2)
    x, z = frame.centres(nz, nx)
    total = np.zeros((nz, nx))
    for f, propped in maps:
        i = np.floor((x - (f.x0 - f.dx / 2)) / f.dx).astype(int)
        k = np.floor((z - (f.z0 - f.dz / 2)) / f.dz).astype(int)
        inside = (k[:, None] >= 0) & (k[:, None] < propped.shape[0]) & (i >= 0) & (i < propped.shape[1])
        kk = np.clip(k, 0, propped.shape[0] - 1)
        ii = np.clip(i, 0, propped.shape[1] - 1)
        total += inside & propped[kk[:, None], ii[None, :]]
    return frame, total / len(maps)


def write_ensemble(path: Path, sweep_source: str, header: list[str], rows: list[dict[str, Any]],
                   metrics: list[str], propped: tuple[GridFrame, np.ndarray, int] | None, units: ColumnUnits) -> None:
    """``ensemble.h5``: the summary as columns (SI; each dataset's ``unit``), the percentiles, the probability maps
    when there are any; the scene's unit system (``units``) and each column's kind, for the figures."""
    import h5py

    with h5py.File(path, "w") as f:
        f.attrs["format"] = "hfgpu-ensemble"
        f.attrs["format_version"] = 1
        f.attrs["sweep"] = sweep_source
        f.attrs["units"] = units.system
        table = f.create_group("summary")
        si = ColumnUnits(units.kinds, "SI", stored=True)
        for name in header:
            values = [r[name] for r in rows]
            if any(isinstance(v, str) for v in values):   # id, status, text inputs
                table.create_dataset(name, data=np.array(values, dtype=object), dtype=h5py.string_dtype())
            else:
                table.create_dataset(name, data=np.array(values, dtype=float))
            table[name].attrs["unit"] = si.label(name)
        table.attrs["columns"] = header
        table.attrs["kinds"] = [units.kinds.get(name, "") for name in header]
        table.attrs["metrics"] = metrics
        group = f.create_group("percentiles")
        group.attrs["levels"] = LEVELS
        for name in metrics:
            group.create_dataset(name, data=percentiles(rows, name))
        if propped is not None:
            frame, fraction, count = propped
            maps = f.create_group("propped")
            maps.attrs.update(dx=frame.dx, dz=frame.dz, x0=frame.x0, z0=frame.z0, members=count)
            maps.create_dataset("fraction", data=fraction)
            for level, threshold in MAP_THRESHOLDS.items():
                maps.create_dataset(f"p{level}", data=(fraction >= threshold).astype(np.uint8))


def read_ensemble(path: str | Path) -> dict[str, Any]:
    """``ensemble.h5`` read back: {"rows", "columns", "metrics", "inputs", "percentiles", "propped" (None or
    {"frame", "fraction", "members"}), "units" (a :class:`ColumnUnits` in the scene's display units; a file of an
    earlier version: SI, metrics only)}."""
    import h5py

    with h5py.File(path, "r") as f:
        table = f["summary"]
        header = [str(c) for c in table.attrs["columns"]]
        metrics = [str(m) for m in table.attrs["metrics"]]
        data = {name: table[name].asstr()[()] if table[name].dtype.kind == "O" else table[name][()] for name in header}
        rows = [{name: data[name][i] for name in header} for i in range(len(data["id"]))]
        kinds = dict(zip(header, (str(k) for k in table.attrs["kinds"]))) if "kinds" in table.attrs else \
            column_kinds({}, metrics)
        units = ColumnUnits(kinds, str(f.attrs.get("units", "SI")))
        propped = None
        if "propped" in f:
            g = f["propped"]
            frame = GridFrame.of(g.attrs)
            propped = dict(frame=frame, fraction=g["fraction"][()], members=int(g.attrs["members"]))
        return dict(rows=rows, columns=header, metrics=metrics, inputs=header[2:len(header) - len(metrics) - 1],
                    percentiles={m: f["percentiles"][m][()] for m in metrics}, propped=propped, units=units)
