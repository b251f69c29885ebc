"""One-way coupling, fracture -> proppant (the paper, section 4.3 and Fig. 4): the fracture history that the
MP-PIC model reads.

The fracture engine runs first and emits :class:`~hfgpu.records.FractureSnapshot` s, each on its own frame (the
bounding box of the open cells plus a margin; the cell size grows 3x when the grid is coarsened, blocks aligned
on the injection cell). The proppant model runs on one fixed grid and needs, at any time t, the width and the
leak-off fields on that grid (the moving walls w of Eq. 7-8 and the sink s_l of Eq. 7). This module

* resamples a snapshot onto a target grid conservatively: each target cell takes the area-overlap-weighted
  mean of the source cells, w_t = sum_s w_s |A_t n A_s| / |A_t|, so the fluid volume sum w dA and the leak-off
  rate sum q dA are unchanged wherever the target grid covers the source (refined, coarsened or shifted);
* interpolates linearly in time between the two snapshots that bracket t (zero before the first snapshot,
  the last one after it); a cell is open when its interpolated width is > 0;
* builds the fixed proppant grid (:func:`proppant_frame`) and flags cells where proppant would bridge
  (:func:`bridging_risk`, :func:`screen_out_cells`: reported by a one-way run, fed back to the fracture by a
  two-way run, hfgpu.slurry_feedback).

Public API: ``FractureHistory(snapshots)``, ``FractureHistory.from_results(path)``, ``history.times``,
``history.fields_at(t, frame, shape, min_width=0)``, ``history.width_field(frame, shape, min_width=0)``,
``history.opening_time_on(frame, shape)``, ``history.injection_point()``,
``proppant_frame(history, cell_size=None, margin=1, source=None)``, ``bridging_risk(width, diameter, factor)``,
``cell_indices(frame, shape, x, z)``, ``screen_out_cells(snapshot, factor)``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from .records import FractureSnapshot, GridFrame, ProppantSnapshot

Shape = tuple[int, int]

#: Overlaps shorter than this fraction of the smaller cell are round-off slivers of coinciding edges.
_SLIVER = 1e-9
_CACHE = 4  # resampled snapshots kept (the proppant loop asks for increasing t: two are in use at a time)


def overlap_lengths(src_centre0: float, src_h: float, src_n: int,
                    dst_centre0: float, dst_h: float, dst_n: int) -> np.ndarray:
    """(dst_n, src_n) lengths of overlap of 1-D cells [c - h/2, c + h/2] (first centres given).

    Round-off slivers where edges coincide are removed and each source column is rescaled to its exact
    covered length, so column sums (the source length inside the target grid) are kept to round-off.
    """
    se = src_centre0 + src_h * (np.arange(src_n + 1) - 0.5)
    de = dst_centre0 + dst_h * (np.arange(dst_n + 1) - 0.5)
    raw = np.clip(np.minimum(de[1:, None], se[None, 1:]) - np.maximum(de[:-1, None], se[None, :-1]), 0.0, None)
    covered = raw.sum(axis=0)
    clean = np.where(raw > _SLIVER * min(src_h, dst_h), raw, 0.0)
    kept = clean.sum(axis=0)
    return clean * np.divide(covered, kept, out=np.zeros_like(kept), where=kept > 0.0)


def _overlaps(src: GridFrame, src_shape: Shape, dst: GridFrame, dst_shape: Shape) -> tuple[np.ndarray, np.ndarray]:
    """1-D overlap matrices (z, x) between two frames; a rectangle's overlap area is their product."""
    az = overlap_lengths(src.z0, src.dz, src_shape[0], dst.z0, dst.dz, dst_shape[0])
    ax = overlap_lengths(src.x0, src.dx, src_shape[1], dst.x0, dst.dx, dst_shape[1])
    return az, ax


def resample_mean(values: np.ndarray, src: GridFrame, dst: GridFrame, dst_shape: Shape) -> np.ndarray:
    """Area-overlap-weighted mean of a per-area field (width, leak-off rate) on the target grid.

    v_t = sum_s v_s |A_t n A_s| / |A_t| (first-order conservative remapping of a piecewise-constant field,
    Jones 1999, Mon. Weather Rev. 127:2204); sum v dA is kept where the target covers the source.
    """
    values = np.asarray(values, dtype=np.float64)
    az, ax = _overlaps(src, values.shape, dst, dst_shape)
    return az @ values @ ax.T / (dst.dx * dst.dz)


def resample_earliest(times: np.ndarray, src: GridFrame, dst: GridFrame, dst_shape: Shape) -> np.ndarray:
    """Earliest opening time of the source cells overlapping each target cell (NaN where none is open);
    the rule of :meth:`hfgpu.fracture.coarsen.Coarsening.earliest` for overlapping rather than nested cells."""
    times = np.asarray(times, dtype=np.float64)
    az, ax = _overlaps(src, times.shape, dst, dst_shape)
    along_z = np.array([np.fmin.reduce(times[row > 0.0], axis=0, initial=np.nan) for row in az])
    return np.array([np.fmin.reduce(along_z[:, col > 0.0], axis=1, initial=np.nan) for col in ax]).T


class FractureHistory:
    """Fracture snapshots in time order, read by the proppant model on its own grid.

    ``snapshots``: any sequence of :class:`FractureSnapshot` (a list, or the lazy
    ``open_results(path).fracture_snapshots``, whose ``times`` attribute avoids reading every snapshot).
    Times must not decrease; of snapshots with equal times the last one is kept (a run's final snapshot may
    repeat the last output time).
    """

    def __init__(self, snapshots: Sequence[FractureSnapshot]):
        if len(snapshots) == 0:
            raise ValueError("FractureHistory: got no fracture snapshots; needs at least one")
        times = np.asarray(snapshots.times if hasattr(snapshots, "times") else [s.time for s in snapshots],
                           dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(times) | (np.diff(times, prepend=-np.inf) < 0.0))
        if bad.size:
            k = int(bad[0])
            raise ValueError(f"FractureHistory: snapshot {k} has time {float(times[k])}; snapshot times must be "
                             "finite and non-decreasing")
        self._snapshots = snapshots
        self._index = np.flatnonzero(np.append(np.diff(times) > 0.0, True))  # last of equal times
        self.times = times[self._index]
        self._cache: dict[tuple[int, GridFrame, Shape], tuple[np.ndarray, np.ndarray]] = {}

    @classmethod
    def from_results(cls, path: str | Path) -> "FractureHistory":
        """The history stored in a results file (``/fracture/snapshots/<k>``, docs/results-format.md)."""
        from .io.results import open_results

        return cls(open_results(path).fracture_snapshots)

    def __len__(self) -> int:
        return self.times.size

    def snapshot(self, k: int) -> FractureSnapshot:
        """The k-th kept snapshot (in time order), checked: 2-D fields of one shape, positive cell sizes."""
        snap = self._snapshots[int(self._index[k])]
        shape = np.shape(snap.width)
        for name in ("width", "leakoff_rate", "opening_time"):
            if len(shape) != 2 or np.shape(getattr(snap, name)) != shape:
                raise ValueError(f"FractureHistory: snapshot at t = {snap.time} has {name} of shape "
                                 f"{np.shape(getattr(snap, name))}; every field must be 2-D of shape {shape}")
        if not (snap.frame.dx > 0.0 and snap.frame.dz > 0.0):
            raise ValueError(f"FractureHistory: snapshot at t = {snap.time} has cell size dx = {snap.frame.dx}, "
                             f"dz = {snap.frame.dz}; both must be > 0")
        return snap

    def snapshots(self):
        """The kept snapshots, in time order (read one at a time)."""
        return (self.snapshot(k) for k in range(len(self)))

    def _on(self, k: int, frame: GridFrame, shape: Shape) -> tuple[np.ndarray, np.ndarray]:
        """Snapshot k's (width, leakoff_rate) resampled onto the grid (frame, shape); a few are cached."""
        key = (k, frame, shape)
        if key not in self._cache:
            snap = self.snapshot(k)
            self._cache[key] = (resample_mean(snap.width, snap.frame, frame, shape),
                                resample_mean(snap.leakoff_rate, snap.frame, frame, shape))
            while len(self._cache) > _CACHE:
                del self._cache[next(iter(self._cache))]
        return self._cache[key]

    def fields_at(self, t: float, frame: GridFrame, shape: Shape,
                  min_width: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(width [m], leakoff_rate [m/s], open_mask) on the grid (frame, shape) at time t [s].

        Linear in time between the snapshots bracketing t, f = (1 - a) f_k + a f_(k+1),
        a = (t - t_k) / (t_(k+1) - t_k); zero before the first snapshot, the last snapshot after it.
        open_mask: width > ``min_width`` (default 0); other cells get width 0 (closed): a negative width (a cell
        drained by leak-off to round-off below 0; the engine holds contact), and, with ``min_width`` > 0, the
        nanometre widths that a cell passes through while it opens between two snapshots. Leak-off is kept >= 0
        and 0 in closed cells.
        """
        shape = (int(shape[0]), int(shape[1]))
        k = int(np.searchsorted(self.times, t, side="right")) - 1
        if k < 0:
            zero = np.zeros(shape)
            return zero, zero.copy(), np.zeros(shape, dtype=bool)
        if k >= len(self) - 1:
            width, leak = (f.copy() for f in self._on(len(self) - 1, frame, shape))
        else:
            a = (t - self.times[k]) / (self.times[k + 1] - self.times[k])
            (w0, q0), (w1, q1) = self._on(k, frame, shape), self._on(k + 1, frame, shape)
            width, leak = (1.0 - a) * w0 + a * w1, (1.0 - a) * q0 + a * q1
        is_open = width > max(min_width, 0.0)
        return np.where(is_open, width, 0.0), np.where(is_open, np.maximum(leak, 0.0), 0.0), is_open

    def width_field(self, frame: GridFrame, shape: Shape,
                    min_width: float = 0.0) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
        """``t -> (width, leakoff_rate)`` on the grid: the ``width_field`` the proppant simulator takes."""
        return lambda t: self.fields_at(t, frame, shape, min_width)[:2]

    def opening_time_on(self, frame: GridFrame, shape: Shape) -> np.ndarray:
        """Opening time [s] on the grid: earliest over the snapshots of the earliest overlapping open source
        cell (NaN where no snapshot has an open cell overlapping)."""
        shape = (int(shape[0]), int(shape[1]))
        out = np.full(shape, np.nan)
        for snap in self.snapshots():
            out = np.fmin(out, resample_earliest(snap.opening_time, snap.frame, frame, shape))
        return out

    def injection_point(self) -> tuple[float, float]:
        """(x, z) of the injection cell's centre, estimated from the first snapshot: the centroid of the
        cells that opened first (the injection cell, or the seed disc centred on it), moved to the nearest
        cell centre of that snapshot (the fracture grid's injection cell holds the injection point, its
        centre up to half a cell from it: hfgpu.fracture.mesh)."""
        snap = self.snapshot(0)
        opened = np.asarray(snap.opening_time, dtype=np.float64)
        if not np.isfinite(opened).any():
            raise ValueError(f"FractureHistory: the first snapshot (t = {snap.time}) has no open cell; "
                             "pass the injection point explicitly")
        rows, cols = np.nonzero(opened == np.nanmin(opened))
        f = snap.frame
        return f.x0 + f.dx * float(np.round(cols.mean())), f.z0 + f.dz * float(np.round(rows.mean()))


def _cell_size(cell_size: float | tuple[float, float] | None, history: FractureHistory) -> tuple[float, float]:
    """(dx, dz) of the proppant grid: the given size(s), or the finest snapshot's cells."""
    if cell_size is None:
        finest = min((s.frame for s in history.snapshots()), key=lambda f: f.dx * f.dz)
        return finest.dx, finest.dz
    sizes = (cell_size, cell_size) if np.isscalar(cell_size) else tuple(cell_size)
    if len(sizes) != 2 or not all(np.isfinite(h) and h > 0.0 for h in sizes):
        raise ValueError(f"proppant_frame: cell_size = {cell_size!r}; must be a positive length [m] or a "
                         "pair (dx, dz) of them")
    return float(sizes[0]), float(sizes[1])


def proppant_frame(history: FractureHistory, cell_size: float | tuple[float, float] | None = None,
                   margin: int = 1, source: tuple[float, float] | None = None) -> tuple[GridFrame, Shape]:
    """The fixed proppant grid (frame, (nz, nx)): cells of ``cell_size`` [m] (default: the finest fracture
    cells) covering the largest footprint (union over the snapshots of the open cells' bounding boxes) plus
    ``margin`` cells on each side, placed so that ``source`` is a cell centre: the fracture's injection cell's
    centre (default :meth:`FractureHistory.injection_point`; exact: hfgpu.fracture.mesh.injection_cell_centre),
    so that proppant cells of the fracture's size coincide with its cells and the layer boundaries on their
    faces stay on faces."""
    if not (isinstance(margin, (int, np.integer)) and margin >= 0):
        raise ValueError(f"proppant_frame: margin = {margin!r}; must be an integer >= 0 (cells)")
    dx, dz = _cell_size(cell_size, history)
    sx, sz = history.injection_point() if source is None else (float(source[0]), float(source[1]))
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for snap in history.snapshots():
        rows, cols = np.nonzero(np.asarray(snap.width) > 0.0)
        if rows.size:
            f = snap.frame
            lo = np.minimum(lo, (f.x0 + f.dx * (cols.min() - 0.5), f.z0 + f.dz * (rows.min() - 0.5)))
            hi = np.maximum(hi, (f.x0 + f.dx * (cols.max() + 0.5), f.z0 + f.dz * (rows.max() + 0.5)))
    if not np.isfinite(lo).all():
        raise ValueError("proppant_frame: no snapshot has an open cell (width > 0); nothing to cover")
    h, s = np.array([dx, dz]), np.array([sx, sz])
    # cell k covers s + (k -+ 1/2) h; the tolerance keeps coinciding edges from adding a cell
    first = np.floor((lo - s) / h + 0.5 + _SLIVER).astype(int) - margin
    last = np.ceil((hi - s) / h - 0.5 - _SLIVER).astype(int) + margin
    x0, z0 = s + first * h
    return GridFrame(dx=dx, dz=dz, x0=float(x0), z0=float(z0)), (int(last[1] - first[1] + 1),
                                                                 int(last[0] - first[0] + 1))


def bridging_risk(width: np.ndarray, diameter: float | np.ndarray, factor: float) -> np.ndarray:
    """Open cells (width > 0) whose width is below factor x diameter: where packed proppant would bridge
    (the criterion of the parcels' push, hfgpu.proppant.params ``bridging_factor``). ``diameter``: one grain size, or one per cell (same shape as width)."""
    for name, value in (("diameter", diameter), ("factor", factor)):
        value = np.asarray(value, dtype=np.float64)
        if not np.all(np.isfinite(value) & (value > 0.0)):
            raise ValueError(f"bridging_risk: {name} = {value}; must be positive finite number(s)")
    width = np.asarray(width, dtype=np.float64)
    return (width > 0.0) & (width < factor * np.asarray(diameter, dtype=np.float64))


def cell_indices(frame: GridFrame, shape: tuple[int, int], x: np.ndarray, z: np.ndarray) -> tuple:
    """(k, i) of the cells holding points (x, z), clipped to the grid."""
    nz, nx = shape
    i = np.clip(np.floor((np.asarray(x) - frame.x0) / frame.dx + 0.5).astype(int), 0, nx - 1)
    k = np.clip(np.floor((np.asarray(z) - frame.z0) / frame.dz + 0.5).astype(int), 0, nz - 1)
    return k, i


def screen_out_cells(snap: ProppantSnapshot, factor: float) -> np.ndarray:
    """Cells holding parcels whose width is below ``factor`` x the largest parcel diameter in the cell
    (:func:`hfgpu.coupling.bridging_risk` with each cell's own largest grain)."""
    width = np.asarray(snap.grid["width"], dtype=np.float64)
    diameter = np.zeros(width.shape)
    p = snap.parcels
    if len(p["x"]):
        k, i = cell_indices(snap.frame, width.shape, p["x"], p["z"])
        np.maximum.at(diameter, (k, i), 2.0 * np.asarray(p["radius"]))
    held = diameter > 0.0
    out = np.zeros(width.shape, dtype=bool)
    if held.any():
        out[held] = bridging_risk(width[held], diameter[held], factor)
    return out
