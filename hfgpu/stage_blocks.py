"""The proppant of a stage on one grid: the clusters' planes side by side, and each cluster's view of it.

A stage of N clusters (hfgpu.fracture.stage) has N fracture planes on one in-plane grid. Their proppant runs in
one MP-PIC engine, so N planes cost one engine's kernel launches per pass: the proppant grid holds N blocks of
one plane's grid (nz, nx) side by side along x,

    block i = columns [i (nx + 1), i (nx + 1) + nx),    one closed column (zero width) between two blocks,

so that no fluid or grain passes from one cluster to another (a closed cell's faces are walls). Block i's width
and leak-off are cluster i's; its inlet is the perforation's annulus moved by i (nx + 1) dx along x; the slurry
rate splits among the inlets as the wellbore node split the fluid (:class:`ClusterSplit`): the proppant split
follows the fluid split. Every proppant snapshot of a stage carries the grid field ``cluster`` (int8: each
cell's block, -1 on the closed columns), from which :func:`cluster_view` cuts one cluster's snapshot on the
plane's own frame (x as on the fracture plane).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .records import GridFrame, ProppantSnapshot


@dataclass(frozen=True)
class Blocks:
    """N blocks of one plane's grid (``frame``, ``shape`` = (nz, nx)) side by side (module docstring)."""

    frame: GridFrame
    shape: tuple[int, int]
    clusters: int

    @property
    def stride(self) -> int:
        """Columns from one block's first column to the next's (nx + 1)."""
        return self.shape[1] + 1

    @property
    def tiled_shape(self) -> tuple[int, int]:
        """(nz, N (nx + 1) - 1): the shape of the stage's proppant grid."""
        return self.shape[0], self.clusters * self.stride - 1

    def shift(self, i: int) -> float:
        """How far block i lies along x from the plane's frame [m]: i (nx + 1) dx."""
        return i * self.stride * self.frame.dx

    def tile(self, fields: list[np.ndarray]) -> np.ndarray:
        """One (nz, nx) cell field per cluster as the stage grid's (zero on the closed columns)."""
        nz, nx = self.shape
        out = np.zeros(self.tiled_shape)
        for i, values in enumerate(fields):
            out[:, i * self.stride:i * self.stride + nx] = values
        return out

    def labels(self) -> np.ndarray:
        """The grid field ``cluster`` (module docstring)."""
        nz, nx = self.shape
        out = np.full(self.tiled_shape, -1, dtype=np.int8)
        for i in range(self.clusters):
            out[:, i * self.stride:i * self.stride + nx] = i
        return out


class ClusterSplit:
    """Each cluster's share of the pump rate over (t0, t1]: the increments of the clusters' injected volumes over
    the interval (linear between the stage's records), divided by their sum; equal shares where nothing is
    injected. ``times`` (n,) and ``injected`` (n, N), the cumulative volume of each cluster at each time, from the
    stage's records (hfgpu.records.StageRecord); the stage starts with equal volumes in every cluster."""

    def __init__(self, times: np.ndarray, injected: np.ndarray):
        self.times = np.concatenate([[0.0], np.asarray(times, dtype=np.float64)])
        self.injected = np.vstack([np.zeros((1, injected.shape[1])), np.asarray(injected, dtype=np.float64)])

    def volumes(self, t: float) -> np.ndarray:
        """The volume each cluster has taken by t [m^3]."""
        return np.array([np.interp(t, self.times, column) for column in self.injected.T])

    def __call__(self, t0: float, t1: float) -> np.ndarray:
        taken = self.volumes(t1) - self.volumes(t0)
        total = float(taken.sum())
        n = self.injected.shape[1]
        return taken / total if total > 0.0 else np.full(n, 1.0 / n)


def block_columns(labels: np.ndarray, cluster: int) -> tuple[int, int]:
    """(first, stop) columns of a cluster's block, from the grid field ``cluster`` (``labels``) of a stage's
    proppant grid (its snapshots, or a map on the same grid such as the closure map)."""
    labels = np.asarray(labels)
    columns = np.flatnonzero(np.any(labels == cluster, axis=0))
    if not columns.size:
        raise ValueError(f"cluster_view: no cluster {cluster} in the snapshot (clusters 0-{int(labels.max())})")
    return int(columns[0]), int(columns[-1]) + 1


def clusters_of(snap: ProppantSnapshot) -> int:
    """The number of clusters of a stage's proppant snapshot (0 for one fracture's)."""
    labels = snap.grid.get("cluster")
    return 0 if labels is None else int(np.max(labels)) + 1


def cluster_view(snap: ProppantSnapshot, cluster: int) -> ProppantSnapshot:
    """Cluster ``cluster``'s part of a stage's proppant snapshot: its block's cell fields (nz, nx), x-face fields
    (nz, nx + 1) and z-face fields (nz + 1, nx), and the parcels in it with x moved back by the block's shift, on
    the plane's frame."""
    if "cluster" not in snap.grid:
        raise ValueError("cluster_view: the snapshot has no grid field 'cluster' (not a stage's proppant)")
    first, stop = block_columns(snap.grid["cluster"], cluster)
    nz, n_total = np.asarray(snap.grid["cluster"]).shape
    grid = {}
    for name, values in snap.grid.items():
        values = np.asarray(values)
        wide = values.ndim == 2 and values.shape[1] == n_total + 1
        grid[name] = values[:, first:stop + 1] if wide else values[:, first:stop]
    f = snap.frame
    x = np.asarray(snap.parcels["x"])
    lo, hi = f.x0 + (first - 0.5) * f.dx, f.x0 + (stop - 0.5) * f.dx
    inside = (x >= lo) & (x < hi)
    parcels = {name: np.asarray(values)[inside] for name, values in snap.parcels.items()}
    parcels["x"] = parcels["x"] - first * f.dx
    return dataclasses.replace(snap, parcels=parcels, grid=grid)
