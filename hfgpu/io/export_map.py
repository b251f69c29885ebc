"""The map ``hfgpu export --format stimplan-xml|csv`` writes: one grid holding the created fracture and, where the
run has proppant, its closure map.

- fracture-only run: the fracture grid of the last fracture snapshot, fields ``width`` (created width) and
  ``pressure`` (fluid pressure), both 0 in closed cells;
- proppant-only run: the closure map's grid and fields (:class:`hfgpu.closure.conductivity.ClosureMap`);
- coupled run: the closure map's grid (the proppant grid's cells) extended by whole cells until it covers the
  box of the fracture snapshot nearest the closure time; the closure fields are 0 in the added cells, and
  ``width`` and ``pressure`` are those of the fracture cell holding each cell's centre (0 outside the fracture's
  box).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..closure.conductivity import ClosureMap, closure_of
from ..errors import HfgpuError
from ..records import GridFrame
from ..stage_blocks import block_columns

#: The fracture's fields on the export map (created width [m], fluid pressure [Pa]).
FRACTURE_FIELDS = ("width", "pressure")


@dataclass(frozen=True)
class ExportMap:
    """``fields``: (nz, nx) arrays on ``frame`` (SI); ``time`` [s]: the snapshot time they describe;
    ``proppant``: whether the closure fields are among them."""

    frame: GridFrame
    fields: dict[str, np.ndarray]
    time: float
    proppant: bool

    @property
    def shape(self) -> tuple[int, int]:
        return next(iter(self.fields.values())).shape


def cluster_closure(closure: ClosureMap, labels: np.ndarray, cluster: int) -> ClosureMap:
    """Cluster ``cluster``'s columns of a stage's closure map (its clusters side by side; ``labels``: the grid
    field ``cluster`` of the proppant snapshot it was computed from, hfgpu.stage_blocks)."""
    cut = slice(*block_columns(labels, cluster))
    return dataclasses.replace(closure, fields={name: values[:, cut] for name, values in closure.fields.items()},
                               clusters=())


def export_map(results, cluster: int | None = None) -> ExportMap:
    """The :class:`ExportMap` of a results file (module docstring); of cluster ``cluster`` of a stage with
    proppant (``results`` then the cluster's view, :meth:`hfgpu.io.results.Results.cluster`: its fracture
    snapshots; the closure map cut to its block). :class:`HfgpuError` when it holds no snapshot."""
    closure = closure_of(results) if len(results.proppant_snapshots) else None
    if closure is not None and cluster is not None:
        labels = results.proppant_snapshots.at(closure.scalars["time"]).grid["cluster"]
        closure = cluster_closure(closure, labels, cluster)
    fractures = results.fracture_snapshots
    if not len(fractures):
        if closure is None:
            raise HfgpuError(f"'{results.path}' holds no snapshot to export")
        return ExportMap(closure.frame, dict(closure.fields), closure.scalars["time"], True)
    if closure is None:
        snap = fractures[-1]
        return ExportMap(snap.frame, {"width": snap.width, "pressure": snap.pressure}, snap.time, False)
    snap = fractures.at(closure.scalars["time"])
    shape = closure.fields["propped_width"].shape
    frame, pad = covering(closure.frame, shape, snap.frame, snap.width.shape)
    fields = {name: np.pad(values, pad) for name, values in closure.fields.items()}
    nz, nx = fields["propped_width"].shape
    fields.update({name: sample(getattr(snap, name), snap.frame, frame, (nz, nx)) for name in FRACTURE_FIELDS})
    return ExportMap(frame, fields, closure.scalars["time"], True)


def _cells_to_add(inner_edge: float, outer_edge: float, size: float) -> int:
    """Whole cells of ``size`` to add beyond ``inner_edge`` to reach ``outer_edge`` (0 when already there)."""
    return max(0, math.ceil((outer_edge - inner_edge) / size - 1e-9))


def covering(frame: GridFrame, shape: tuple[int, int], other: GridFrame,
             other_shape: tuple[int, int]) -> tuple[GridFrame, tuple[tuple[int, int], tuple[int, int]]]:
    """(frame, ((rows above, rows below), (columns left, columns right))): ``frame`` (cells of ``shape``)
    extended by whole cells of its own size so that it covers the box of ``other`` (cells of ``other_shape``)."""
    (nz, nx), (mz, mx) = shape, other_shape
    left = _cells_to_add(-(frame.x0 - frame.dx / 2), -(other.x0 - other.dx / 2), frame.dx)
    right = _cells_to_add(frame.x0 + (nx - 0.5) * frame.dx, other.x0 + (mx - 0.5) * other.dx, frame.dx)
    top = _cells_to_add(-(frame.z0 - frame.dz / 2), -(other.z0 - other.dz / 2), frame.dz)
    bottom = _cells_to_add(frame.z0 + (nz - 0.5) * frame.dz, other.z0 + (mz - 0.5) * other.dz, frame.dz)
    extended = GridFrame(dx=frame.dx, dz=frame.dz, x0=frame.x0 - left * frame.dx, z0=frame.z0 - top * frame.dz)
    return extended, ((top, bottom), (left, right))


def sample(values: np.ndarray, frame: GridFrame, target: GridFrame, shape: tuple[int, int]) -> np.ndarray:
    """``values`` (cells on ``frame``) at the cell centres of ``target`` (cells of ``shape``): the value of the
    cell holding each centre, 0 outside ``frame``'s box."""
    values = np.asarray(values, dtype=np.float64)
    x, z = target.centres(*shape)
    i = np.floor((x - (frame.x0 - frame.dx / 2)) / frame.dx).astype(int)
    k = np.floor((z - (frame.z0 - frame.dz / 2)) / frame.dz).astype(int)
    inside = (k[:, None] >= 0) & (k[:, None] < values.shape[0]) & (i[None, :] >= 0) & (i[None, :] < values.shape[1])
    rows = np.clip(k, 0, values.shape[0] - 1)[:, None]
    columns = np.clip(i, 0, values.shape[1] - 1)[None, :]
    return np.where(inside, values[rows, columns], 0.0)
