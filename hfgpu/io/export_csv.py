"""``hfgpu export --format csv``: the export map and the pressure history as plain CSV tables.

``FILE`` (the map, :mod:`hfgpu.io.export_map`): one row per cell of its grid, columns ``x``, ``depth`` (cell
centre), then with proppant ``propped`` (0/1), ``propped_width``, ``conductivity``, ``permeability``,
``closure_stress``, ``sauter_diameter`` (0 where the proppant grid does not reach), then with a fracture ``width``
(created width) and ``pressure`` (fluid pressure; both 0 in closed cells); ``<stem>_pressure.csv`` beside it: one
row per snapshot (the fracture's, or the proppant grid's for a proppant-only run), columns ``time``,
``pressure_injection`` (the cell nearest the injection point, NaN when the scene names none), ``pressure_mean``
and ``pressure_max`` (over the open cells), and for a run with a shut-in (at least 2 step records after the pumps
stop, hfgpu.io.summary.falloff_of) ``G`` (Nolte's G-function of the snapshot's time, hfgpu.fracture.falloff; NaN
while pumping) and ``G_dP/dG`` (the superposition derivative of the step history's BHTP, linear in G between
its records; NaN where the history has none). Each header names the unit, e.g. ``conductivity [md ft]``, in SI or
field units; a run that did not complete adds a first line ``# hfgpu: the run is not complete (status "...")``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..closure.display import in_units, unit_label
from .export_common import injection_point, round_off, status_note

PROPPANT_COLUMNS = ("propped", "propped_width", "conductivity", "permeability", "closure_stress", "sauter_diameter")
FRACTURE_COLUMNS = ("width", "pressure")
#: The closure quantity whose unit each fracture column takes (hfgpu.closure.display: widths m or in, Pa or psi).
_QUANTITY = {"width": "propped_width"}


def _header(names: list[str], system: str) -> str:
    return ",".join(name if name == "propped" else f"{name} [{unit_label(_QUANTITY.get(name, name), system)}]"
                    for name in names)


def map_columns(grid: Any) -> list[str]:
    """The map's columns for ``grid`` (an :class:`hfgpu.io.export_map.ExportMap`), in order."""
    return ["x", "depth", *(n for n in PROPPANT_COLUMNS + FRACTURE_COLUMNS if n in grid.fields)]


def write_csv(results: Any, grid: Any, out: Path, system: str) -> list[Path]:
    """Write the map of ``grid`` (an :class:`hfgpu.io.export_map.ExportMap`) to ``out`` and the pressure
    history to ``<stem>_pressure.csv``; return both paths."""
    nz, nx = grid.shape
    x, z = grid.frame.centres(nz, nx)
    grid_x, grid_z = np.meshgrid(x, z)
    columns = {"x": round_off(grid_x, float(np.max(np.abs(grid_z), initial=1.0))), "depth": grid_z, **grid.fields}
    names = map_columns(grid)
    table = np.column_stack([np.ravel(columns[n]) if n == "propped"
                             else np.ravel(in_units(_QUANTITY.get(n, n), columns[n], system)) for n in names])
    note = status_note(results)
    first = f"# {note}\n" if note else ""   # a comment line (pandas: comment="#") only for a run that did not complete
    np.savetxt(out, table, delimiter=",", header=first + _header(names, system), comments="", fmt="%.10g")
    pressure = out.with_name(out.stem + "_pressure.csv")
    history = pressure_history(results)
    unit = unit_label("pressure", system)
    columns = [history[0]] + [in_units("pressure", column, system) for column in history[1:]]
    header = ["time [s]"] + [f"pressure_{n} [{unit}]" for n in ("injection", "mean", "max")]
    shut_in = falloff_columns(results, history[0])
    if shut_in is not None:
        columns += [shut_in[0], in_units("pressure", shut_in[1], system)]
        header += ["G [-]", f"G_dP/dG [{unit}]"]
    table = np.column_stack(columns).reshape(-1, len(header))
    np.savetxt(pressure, table, delimiter=",", header=first + ",".join(header), comments="", fmt="%.10g")
    return [out, pressure]


def falloff_columns(results: Any, times: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(G, G dP/dG [Pa]) at ``times`` [s] for a run with a shut-in (hfgpu.io.summary.falloff_of), NaN while
    pumping and, for G dP/dG, outside the step records after the stop; None without a shut-in."""
    from ..errors import HfgpuError
    from ..fracture.falloff import G_function
    from .summary import falloff_of, pump_end

    try:
        stop = pump_end(results.scene)
    except (HfgpuError, ImportError):
        return None
    analysis = falloff_of(results.fracture_balance, stop)
    if analysis is None:
        return None
    times = np.asarray(times, dtype=np.float64)
    after = times > stop
    g = np.full(times.shape, np.nan)
    g[after] = G_function((times[after] - stop) / stop, analysis.alpha)
    derivative = np.full(times.shape, np.nan)
    derivative[after] = np.interp(g[after], analysis.G, analysis.derivative, left=np.nan, right=np.nan)
    return g, derivative


def pressure_history(results: Any) -> tuple[np.ndarray, ...]:
    """(time [s], pressure at the injection cell, mean and max pressure over the open cells [Pa]) per snapshot
    of the fracture (or, without any, of the proppant grid)."""
    snaps = results.fracture_snapshots if len(results.fracture_snapshots) else results.proppant_snapshots
    point = injection_point(results)
    rows = []
    for snap in snaps:
        pressure, width = (snap.pressure, snap.width) if hasattr(snap, "width") else (snap.grid["pressure"],
                                                                                         snap.grid["width"])
        open_cells = np.asarray(width) > 0.0
        at_injection = np.nan
        if point is not None:
            f = snap.frame
            i = int(np.clip(np.floor((point[0] - f.x0) / f.dx + 0.5), 0, pressure.shape[1] - 1))
            k = int(np.clip(np.floor((point[1] - f.z0) / f.dz + 0.5), 0, pressure.shape[0] - 1))
            at_injection = float(pressure[k, i])
        values = pressure[open_cells]
        rows.append((snap.time, at_injection, values.mean() if values.size else np.nan,
                     values.max() if values.size else np.nan))
    return tuple(np.array(rows, dtype=np.float64).reshape(-1, 4).T)
