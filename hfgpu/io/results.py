"""Results files: an HDF5 sink that survives a killed run, and a reader.

Layout (docs/results-format.md is the full contract; extend, never rename)::

    /                       attrs format="hfgpu-results", format_version, hfgpu_version, status
    /scene                  the scene's TOML text (UTF-8 string)
    /fracture/snapshots/000000 ...   attrs time, dx, dz, x0, z0; width, pressure, leakoff_rate, opening_time, extras
    /fracture/balance       time, injected, stored, leaked, ..., surface_pressure with [wellbore] (1-D, appended)
    /proppant/snapshots/000000 ...   attrs time, dx, dz, x0, z0, n_parcels; per-parcel and grid datasets
    /proppant/balance       time, injected, in_domain, outflow, screened_out (1-D, appended)
    /stage/balance          time, wellbore_pressure (1-D); rate, injection_pressure, ... (rows x clusters), a stage
    /stage/cluster_<i>/snapshots/000000 ...   each cluster's fracture snapshots, as /fracture/snapshots
    /summary                attrs status, message, and the simulator's scalar summary values
    /closure                attrs dx, dz, x0, z0, time and the closure scalars; propped_width, conductivity, ...
    /checkpoint             attrs time and record counts; state/...: the simulator's state (removed when complete)

Integrity: the file is open only while a snapshot is written, and every change is made on another copy
that is renamed over the file when complete (HDF5 is not crash-safe on its own): a spare copy one write
behind the file, which takes the write it lacks and the new one, so a write costs the write twice, not a copy
of the file (``_TwinFile``). A snapshot is built under a temporary name (``_incomplete``) and moved to its
final zero-padded name once complete; balance records are buffered and written with each snapshot (and at
close). A run killed at any moment therefore leaves every completed snapshot readable; a leftover
``_incomplete`` group is ignored by the reader. ``status`` is "running" until :meth:`ResultsWriter.close` writes "complete",
"interrupted" or "failed: <message>"; a file still saying "running" after its run ended was killed.

Checkpoints (:meth:`ResultsWriter.write_checkpoint`, :mod:`hfgpu.io.checkpoint`) are built under
``_checkpoint_new``, marked complete, flushed, and only then swapped for ``/checkpoint``; a kill between the
removal of the old one and the move leaves the complete new one, which :meth:`ResultsWriter.reopen` takes.
The file keeps its free space across openings (HDF5 persistent free-space manager), so replacing a checkpoint
reuses the old one's space instead of growing the file.

One writer at a time: a writer holds ``<file>.lock`` (its process id) from its creation or :meth:`ResultsWriter.reopen`
to :meth:`ResultsWriter.close`; another process's writer to that file is refused before it touches it
(:func:`acquire_lock`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import copy
import functools
import os
import shutil
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import h5py
import numpy as np

try:
    import fcntl
except ImportError:  # not POSIX
    fcntl = None  # type: ignore[assignment]

from ..errors import HfgpuError
from .checkpoint import read_tree, write_tree
from ..records import (BalanceRecord, FractureSnapshot, GridFrame, ProppantSnapshot,
                       SolidBalanceRecord, StageRecord, StageSnapshot)

FORMAT = "hfgpu-results"
FORMAT_VERSION = 1
INCOMPLETE = "_incomplete"
CHECKPOINT = "checkpoint"
NEW_CHECKPOINT = "_checkpoint_new"

#: Units of every dataset name the writer knows (SI; "1" is dimensionless, "" is text or a label).
UNITS = {
    "time": "s", "injected": "m^3", "stored": "m^3", "leaked": "m^3", "in_domain": "m^3", "outflow": "m^3",
    "screened_out": "m^3", "injection_pressure": "Pa", "surface_pressure": "Pa", "efficiency": "1",
    "width": "m", "pressure": "Pa", "leakoff_rate": "m/s", "opening_time": "s",
    "net_pressure": "Pa", "min_stress": "Pa", "toughness": "Pa m^0.5", "leakoff_coefficient": "m/s^0.5",
    "x": "m", "z": "m", "u": "m/s", "v": "m/s", "radius": "m", "density": "kg/m^3", "particles": "1",
    "state": "1", "class_id": "1", "volume_fraction": "1", "fluid_u": "m/s", "fluid_v": "m/s",
    "bridging_risk": "1", "wellbore_pressure": "Pa", "rate": "m^3/s",
    "scene": "",
    # the fracture engine's scalar snapshot extras (docs/results-format.md)
    **{f"front_{k}": "m" for k in ("radius", "radius_min", "radius_max", "up", "down", "left", "right")},
    "area": "m^2", "area_radius": "m", "inlet_width": "m", "length": "m", "height": "m",
    "injected_volume": "m^3", "stored_volume": "m^3", "leaked_volume": "m^3", "closed_at": "s",
    # /closure (hfgpu.closure.conductivity.ClosureMap.fields)
    "propped_width": "m", "conductivity": "m^3", "closure_stress": "Pa", "permeability": "m^2",
    "solid_volume": "m^3", "sauter_diameter": "m", "propped": "1",
}
UNKNOWN_UNITS = "unspecified"

FRACTURE_FIELDS = ("width", "pressure", "leakoff_rate", "opening_time")
FRACTURE_BALANCE = ("time", "injected", "stored", "leaked", "injection_pressure", "net_pressure", "efficiency",
                    "area", "length", "height", "inlet_width")
#: The fracture balance column a scene with ``[wellbore]`` adds after FRACTURE_BALANCE: the STP of each row.
SURFACE_PRESSURE = "surface_pressure"
PROPPANT_BALANCE = ("time", "injected", "in_domain", "outflow", "screened_out")
#: The per-cluster columns of ``/stage/balance`` (a stage of several clusters, hfgpu.fracture.stage): each a
#: (rows, clusters) dataset, after the 1-D ``time`` and ``wellbore_pressure``.
STAGE_CLUSTER_COLUMNS = ("rate", "injection_pressure", "net_pressure", "injected", "stored", "leaked", "area",
                         "length", "height", "inlet_width")
_BALANCE_FLUSH_ROWS = 4096
_COMPRESS_ABOVE = 4096  # elements; smaller arrays are stored plainly


@contextlib.contextmanager
def _edit(path: Path, create: bool = False) -> Iterator[h5py.File]:
    """The results file open for writing, copy-on-write: the change is made on a copy (``<name>.writing``),
    which is flushed to disk and then renamed over the file (atomic on POSIX). HDF5 itself is not crash-safe
    (a kill while the library flushes its metadata can leave an unreadable file: measured once in 40 random
    SIGKILLs), so the file at ``path`` is at every moment either the previous complete version or the new one."""
    work = path.with_name(path.name + ".writing")
    if not create:
        shutil.copyfile(path, work)
    try:
        with _open(work, "w" if create else "a") as f:
            yield f
        with open(work, "rb+") as raw:
            os.fsync(raw.fileno())
    except BaseException:
        work.unlink(missing_ok=True)
        raise
    os.replace(work, path)


def _open(path: Path, mode: str) -> h5py.File:
    """h5py file without HDF5 file locking, so a reader can look at a file while a run writes it; a new file
    tracks its free space persistently (a replaced checkpoint's space is reused in later openings)."""
    if mode == "w":
        return h5py.File(path, mode, locking=False, fs_strategy="fsm", fs_persist=True, fs_threshold=1)
    return h5py.File(path, mode, locking=False)


SPARE = ".writing"       # suffix of the spare copy beside the results file
PREVIOUS = ".previous"   # suffix of the replaced version while it becomes the spare


class _TwinFile:
    """The results file and a spare copy kept one write behind it (``<name>.writing``).

    ``apply(write)``: ``write`` (a function of the open h5py.File) is applied to the spare after the write the
    spare lacks, the spare is flushed to disk and renamed over the file, and the version it replaces, kept by
    a hard link, becomes the next spare. The file at ``path`` is thus at every moment a complete version, and
    a write costs the write twice instead of a copy of the whole file (copies would make a run's output time
    grow with the square of its snapshot count). The spare is copied afresh from the file when there
    is none, when hard links fail, or when a reader may still hold the replaced version open: on Linux a write
    lease on it is refused then; elsewhere it is always copied. So a reader's open file never changes under
    it. Writes are replayed, so they hold copies of their data, never the caller's arrays; a write may give a
    cheaper ``catch_up`` for the spare (a snapshot copies its group from the file, HDF5's object copy, instead
    of building it again)."""

    def __init__(self, path: Path):
        self.path = path
        self.spare = path.with_name(path.name + SPARE)
        self._behind: Callable[[h5py.File], None] | None = None   # the write the spare lacks

    def apply(self, write: Callable[[h5py.File], None], catch_up: Callable[[h5py.File], None] | None = None) -> None:
        writes = [self._behind, write] if self._behind is not None and _unshared(self.spare) else None
        self._behind = None
        if writes is None:   # a new file: the old spare may be a reader's open version
            self.spare.unlink(missing_ok=True)
            shutil.copyfile(self.path, self.spare)
            writes = [write]
        try:
            with _open(self.spare, "a") as f:
                for change in writes:
                    change(f)
            with open(self.spare, "rb+") as raw:
                os.fsync(raw.fileno())
        except BaseException:
            self.spare.unlink(missing_ok=True)
            raise
        previous = self.path.with_name(self.path.name + PREVIOUS)
        kept = _hard_link(self.path, previous)
        os.replace(self.spare, self.path)
        if kept:
            os.replace(previous, self.spare)
            self._behind = catch_up or write

    def apply_last(self, write: Callable[[h5py.File], None]) -> None:
        """``apply(write)`` as the file's last write, then ``finish`` (also when the write fails)."""
        try:
            self.apply(write)
        finally:
            self.finish()

    def finish(self) -> None:
        """Remove the spare (the run's last write is done)."""
        self._behind = None
        for path in (self.spare, self.path.with_name(self.path.name + PREVIOUS)):
            path.unlink(missing_ok=True)


def _hard_link(path: Path, link: Path) -> bool:
    """Whether ``link`` is now a second name of ``path`` (False where the file system has no hard links)."""
    try:
        link.unlink(missing_ok=True)
        os.link(path, link)
    except OSError:
        return False
    return True


def _unshared(path: Path) -> bool:
    """Whether no open file refers to ``path`` (Linux: a write lease can be taken only then); False where this
    cannot be told."""
    setlease = getattr(fcntl, "F_SETLEASE", None)
    if setlease is None:
        return False
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.fcntl(fd, setlease, fcntl.F_WRLCK)
        fcntl.fcntl(fd, setlease, fcntl.F_UNLCK)
        return True
    except OSError:
        return False
    finally:
        os.close(fd)


LOCK = ".lock"


def acquire_lock(path: Path) -> Path:
    """Take the advisory lock of the results file ``path``: the file ``<path>.lock`` holding this process's id,
    created exclusively. A lock whose process is dead (or is this one) is stale and taken over; one held by a
    live process is an :class:`HfgpuError` raised before any work, so two runs never mix one file."""
    lock = path.with_name(path.name + LOCK)
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            holder = _lock_holder(lock)
            if holder is not None:
                raise HfgpuError(f"'{path}' is being written by another run (process {holder}, lock file "
                                 f"'{lock}'); wait for it to end or choose another results file") from None
            with contextlib.suppress(FileNotFoundError):
                os.unlink(lock)
            continue
        except OSError:  # a folder where no lock can be created: the results file itself will say why
            return lock
        with os.fdopen(fd, "w") as f:
            f.write(str(os.getpid()))
        return lock
    raise HfgpuError(f"'{path}' is being written by another run (lock file '{lock}')")


def release_lock(path: Path) -> None:
    """Remove the lock of ``path`` when this process holds it."""
    lock = path.with_name(path.name + LOCK)
    with contextlib.suppress(OSError, ValueError):
        if int(lock.read_text()) == os.getpid():
            lock.unlink()


def _lock_holder(lock: Path) -> int | None:
    """The live process (not this one) holding ``lock``; None when the lock is stale."""
    try:
        text = lock.read_text().strip()
    except FileNotFoundError:
        return None
    if not text.isdigit():  # being written by its creator now, or garbage left by a crash long ago
        return -1 if _age(lock) < 5.0 else None
    pid = int(text)
    if pid == os.getpid():
        return None
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return None
    except PermissionError:  # alive, another user's
        return pid
    return pid


def _age(path: Path) -> float:
    import time

    try:
        return time.time() - path.stat().st_mtime
    except FileNotFoundError:
        return 0.0


class ResultsWriter:
    """Output sink writing an HDF5 results file (an hfgpu.io.sink.ResultsSink: the records of hfgpu/records.py).

    The file at ``path`` is created (replaced if it exists) with the scene text and status "running".
    Use as a context manager, or call :meth:`close` with the final status. :meth:`reopen` continues a file
    from its checkpoint instead.
    """

    def __init__(self, path: str | Path, scene: Any):
        from ..version import __version__

        acquire_lock(Path(path))
        self._start(Path(path), {"fracture": 0, "proppant": 0}, 0.0, scene)
        try:
            with _edit(self.path, create=True) as f:
                f.attrs.update(format=FORMAT, format_version=FORMAT_VERSION, hfgpu_version=__version__,
                               status="running")
                _dataset(f, "scene", np.array(getattr(scene, "source", "") or "", dtype=h5py.string_dtype()))
        except OSError as exc:
            release_lock(self.path)
            raise HfgpuError(f"cannot create the results file '{self.path}': {exc}") from None

    def _start(self, path: Path, counts: dict[str, int], last_time: float, scene: Any) -> None:
        from ..wellbore import surface_pressure_of

        self.path = path
        self._surface = surface_pressure_of(scene)   # None without [wellbore]
        self._counts = counts
        self._pending: dict[str, list[tuple[float, ...]]] = {"fracture": [], "proppant": [], "stage": []}
        self._last_time = last_time
        self._closed = False
        self._file = _TwinFile(path)

    @classmethod
    def reopen(cls, path: str | Path, scene: Any = None) -> tuple["ResultsWriter", float, dict]:
        """(writer, time, state): continue the results file ``path`` of ``scene`` from its checkpoint. Snapshots
        and balance rows written after the checkpoint are dropped, ``/summary`` removed and the status set back
        to "running"; ``state`` is the tree the simulator saved at simulated time ``time`` [s]. Raises
        :class:`HfgpuError` for a file that is not a results file or holds no checkpoint."""
        path = Path(path)
        acquire_lock(path)
        try:
            time, state, counts = cls._rewind(path)
        except BaseException:
            release_lock(path)
            raise
        writer = cls.__new__(cls)
        writer._start(path, counts, time, scene)
        return writer, time, state

    @staticmethod
    def _rewind(path: Path) -> tuple[float, dict, dict[str, int]]:
        """The checkpoint's (time, state, snapshot counts) of ``path``, the file cut back to it (see :meth:`reopen`)."""
        with contextlib.ExitStack() as stack:
            try:
                f = stack.enter_context(_edit(path))
            except OSError as exc:
                raise HfgpuError(f"cannot open the results file '{path}' to resume: {exc}") from None
            if f.attrs.get("format") != FORMAT:
                raise HfgpuError(f"'{path}' is not an hfgpu results file (no format=\"{FORMAT}\" attribute)")
            group = _checkpoint(f, finish_swap=True)
            if group is None:
                raise HfgpuError(f"'{path}' holds no checkpoint to resume from (status "
                                 f"\"{f.attrs.get('status', 'running')}\"); run the scene again without --resume")
            a = group.attrs
            counts = {key[:-len("_snapshots")]: int(a[key]) for key in a if key.endswith("_snapshots")}
            for physics in counts:   # fracture, proppant and a stage's stage/cluster_<i>
                parent = f.get(f"{physics}/snapshots")
                for name in list(parent) if parent is not None else []:
                    if not name.isdigit() or int(name) >= counts[physics]:
                        del parent[name]
            for physics in ("fracture", "proppant", "stage"):
                balance = f.get(f"{physics}/balance")
                rows = int(a.get(f"{physics}_balance_rows", 0))
                for ds in balance.values() if balance is not None else []:
                    ds.resize((rows,) + ds.shape[1:])
            f.pop("summary", None)
            f.attrs["status"] = "running"
            time, state = float(a["time"]), read_tree(group["state"])
            f.flush()
        return time, state, counts

    # sink methods ------------------------------------------------------------------------------

    def fracture_snapshot(self, snap: FractureSnapshot) -> None:
        """Write one fracture snapshot (and the buffered balance records)."""
        self._fracture_snapshot("fracture", snap)

    def stage_snapshot(self, record: StageSnapshot) -> None:
        """Write one cluster's fracture snapshot of a stage, as ``/stage/cluster_<i>/snapshots/<k>``."""
        group = f"stage/cluster_{record.cluster}"
        self._counts.setdefault(group, 0)
        self._fracture_snapshot(group, record.snapshot)

    def _fracture_snapshot(self, group: str, snap: FractureSnapshot) -> None:
        fields = {name: getattr(snap, name) for name in FRACTURE_FIELDS}
        clash = set(snap.extras) & set(fields)
        if clash:
            raise HfgpuError(f"fracture snapshot extras {sorted(clash)} clash with the standard fields")
        fields.update(snap.extras)
        self._snapshot(group, snap.time, snap.frame, {k: (v, "grid") for k, v in fields.items()}, {})

    def proppant_snapshot(self, snap: ProppantSnapshot) -> None:
        """Write one proppant snapshot: per-parcel datasets (kind "parcel") and grid datasets (kind "grid")."""
        clash = set(snap.parcels) & set(snap.grid)
        if clash:
            raise HfgpuError(f"proppant snapshot names {sorted(clash)} are both parcel and grid fields")
        data = {k: (v, "parcel") for k, v in snap.parcels.items()}
        data.update({k: (v, "grid") for k, v in snap.grid.items()})
        n = len(next(iter(snap.parcels.values()))) if snap.parcels else 0
        self._snapshot("proppant", snap.time, snap.frame, data, {"n_parcels": n})

    def fracture_balance(self, record: BalanceRecord) -> None:
        """Buffer one fluid balance row; rows are written with the next snapshot or at close."""
        self._balance("fracture", tuple(float(getattr(record, k)) for k in FRACTURE_BALANCE))

    def proppant_balance(self, record: SolidBalanceRecord) -> None:
        """Buffer one solid balance row; rows are written with the next snapshot or at close."""
        self._balance("proppant", tuple(float(getattr(record, k)) for k in PROPPANT_BALANCE))

    def stage_record(self, record: StageRecord) -> None:
        """Buffer one stage row (time, wellbore pressure, then each of STAGE_CLUSTER_COLUMNS for every cluster);
        rows are written with the fracture rows."""
        per_cluster = [record.rates] + [[getattr(c, name) for c in record.clusters]
                                        for name in STAGE_CLUSTER_COLUMNS[1:]]
        self._balance("stage", (float(record.time), float(record.wellbore_pressure),
                                *(float(v) for column in per_cluster for v in column)))

    def write_checkpoint(self, time: float, state: dict) -> None:
        """Replace ``/checkpoint`` with the simulator's ``state`` at simulated time ``time`` [s], after writing the
        buffered balance rows; records the snapshot and balance-row counts it belongs to (see the module
        docstring for the atomic swap)."""
        rows, state = self._take_rows(), copy.deepcopy(state)
        counts = {f"{physics}_snapshots": n for physics, n in self._counts.items()}

        def write(f: h5py.File) -> None:
            _append_rows(f, rows)
            f.pop(NEW_CHECKPOINT, None)
            group = f.create_group(NEW_CHECKPOINT)
            write_tree(group.create_group("state"), state)
            rows_now = {}
            for physics in ("fracture", "proppant", "stage"):
                column = f.get(f"{physics}/balance/time")
                rows_now[f"{physics}_balance_rows"] = column.shape[0] if column is not None else 0
            group.attrs.update(time=float(time), **counts, **rows_now)
            group.attrs["complete"] = True
            f.flush()
            f.pop(CHECKPOINT, None)
            f.move(NEW_CHECKPOINT, CHECKPOINT)
            f.flush()

        self._file.apply(write)

    # ending -----------------------------------------------------------------------------------

    def close(self, status: str = "complete", summary: dict[str, Any] | None = None) -> None:
        """Write buffered rows, ``/summary`` (status, snapshot counts, scalar ``summary`` values), close; a
        complete run's checkpoint is removed (a failed run keeps it, to resume from)."""
        if self._closed:
            return
        self._closed = True
        rows = self._take_rows()
        values = {k: v for k, v in (summary or {}).items() if _is_scalar(v)}
        values.update(status=status, sim_time=self._last_time, fracture_snapshots=self._counts["fracture"],
                      proppant_snapshots=self._counts["proppant"])

        def write(f: h5py.File) -> None:
            _append_rows(f, rows)
            for physics in self._counts:
                f.pop(f"{physics}/snapshots/{INCOMPLETE}", None)
            if status == "complete":
                f.pop(CHECKPOINT, None)
                f.pop(NEW_CHECKPOINT, None)
            f.require_group("summary").attrs.update(values)
            f.attrs["status"] = status

        try:
            self._file.apply_last(write)
        finally:
            release_lock(self.path)

    def write_closure(self, frame: GridFrame, fields: dict[str, np.ndarray], attrs: dict[str, Any]) -> None:
        """Replace ``/closure`` (grid ``fields`` on ``frame``, scalar ``attrs``) and add ``attrs`` prefixed
        ``closure_`` to ``/summary``, in one atomic edit (after :meth:`close`)."""
        arrays = {name: _array(array) for name, array in fields.items()}

        def write(f: h5py.File) -> None:
            f.pop("closure", None)
            group = f.create_group("closure")
            group.attrs.update(dx=float(frame.dx), dz=float(frame.dz), x0=float(frame.x0), z0=float(frame.z0),
                               **attrs)
            for name, array in arrays.items():
                _dataset(group, name, array).attrs["kind"] = "grid"
            f.require_group("summary").attrs.update({f"closure_{k}": v for k, v in attrs.items()})

        acquire_lock(self.path)
        try:
            self._file.apply_last(write)
        finally:
            release_lock(self.path)

    def add_summary(self, values: dict[str, Any]) -> None:
        """Add scalar ``values`` to ``/summary`` in one atomic edit (after :meth:`close`: post-processing of the
        complete run, such as its fall-off)."""
        def write(f: h5py.File) -> None:
            f.require_group("summary").attrs.update(values)

        acquire_lock(self.path)
        try:
            self._file.apply_last(write)
        finally:
            release_lock(self.path)

    def fail(self, message: str, summary: dict[str, Any] | None = None) -> None:
        """Close with status "failed: <message>"."""
        self.close(f"failed: {message}", summary)

    def __enter__(self) -> "ResultsWriter":
        return self

    def __exit__(self, kind, exc, tb) -> None:
        if exc is None:
            self.close()
        else:
            self.fail(str(exc) or kind.__name__)

    # internals --------------------------------------------------------------------------------

    def _snapshot(self, physics: str, time: float, frame: GridFrame,
                  data: dict[str, tuple[np.ndarray, str]], attrs: dict[str, Any]) -> None:
        self._last_time = max(self._last_time, float(time))
        rows, name = self._take_rows(), f"{self._counts[physics]:06d}"
        arrays = {key: (_array(array), kind) for key, (array, kind) in data.items()}

        def write(f: h5py.File) -> None:
            _append_rows(f, rows)
            parent = f.require_group(f"{physics}/snapshots")
            parent.pop(INCOMPLETE, None)
            group = parent.create_group(INCOMPLETE)
            group.attrs.update(time=float(time), dx=float(frame.dx), dz=float(frame.dz),
                               x0=float(frame.x0), z0=float(frame.z0), **attrs)
            for key, (array, kind) in arrays.items():
                _dataset(group, key, array).attrs["kind"] = kind
            parent.move(INCOMPLETE, name)
            f.flush()

        def catch_up(f: h5py.File) -> None:
            _append_rows(f, rows)
            with _open(self.path, "r") as done:   # the file that holds this snapshot
                done.copy(done[f"{physics}/snapshots/{name}"], f.require_group(f"{physics}/snapshots"), name)

        self._file.apply(write, catch_up)
        self._counts[physics] += 1

    def _balance(self, physics: str, row: tuple[float, ...]) -> None:
        self._last_time = max(self._last_time, row[0])
        pending = self._pending[physics]
        pending.append(row)
        if len(pending) >= _BALANCE_FLUSH_ROWS:
            rows = self._take_rows()
            self._file.apply(lambda f: _append_rows(f, rows))

    def _take_rows(self) -> dict[str, np.ndarray]:
        """The buffered balance rows of each physics as (rows, columns) arrays, the buffers emptied; with
        ``[wellbore]`` the fracture rows get their STP (:func:`hfgpu.wellbore.surface_pressure`) as a last column."""
        rows = {physics: np.array(pending, dtype=np.float64) for physics, pending in self._pending.items() if pending}
        for pending in self._pending.values():
            pending.clear()
        fracture = rows.get("fracture")
        if fracture is not None and self._surface is not None:
            bhtp = fracture[:, FRACTURE_BALANCE.index("injection_pressure")]
            rows["fracture"] = np.column_stack([fracture, self._surface(fracture[:, 0], bhtp)])
        return rows


def _append_rows(f: h5py.File, rows: dict[str, np.ndarray]) -> None:
    """Append balance rows ({physics: (rows, columns) array}) to ``/<physics>/balance``, one dataset per column
    (fracture rows without the STP column leave ``surface_pressure`` out: zip stops at the last column); a stage's
    rows to ``/stage/balance`` (:func:`_append_stage`)."""
    if "stage" in rows:
        _append_stage(f, rows["stage"])
    for physics, names in (("fracture", FRACTURE_BALANCE + (SURFACE_PRESSURE,)), ("proppant", PROPPANT_BALANCE)):
        if physics not in rows:
            continue
        group = f.require_group(f"{physics}/balance")
        for name, column in zip(names, rows[physics].T):
            if name not in group:
                _dataset(group, name, np.zeros(0), maxshape=(None,), chunks=(1024,))
            ds = group[name]
            ds.resize((ds.shape[0] + column.size,))
            ds[-column.size:] = column


def _append_stage(f: h5py.File, rows: np.ndarray) -> None:
    """Stage rows (:meth:`ResultsWriter.stage_record`) as ``/stage/balance``: ``time`` and ``wellbore_pressure``
    1-D, each of STAGE_CLUSTER_COLUMNS (rows, clusters)."""
    clusters = (rows.shape[1] - 2) // len(STAGE_CLUSTER_COLUMNS)
    group = f.require_group("stage/balance")
    columns = {"time": rows[:, 0], "wellbore_pressure": rows[:, 1]}
    for k, name in enumerate(STAGE_CLUSTER_COLUMNS):
        columns[name] = rows[:, 2 + k * clusters:2 + (k + 1) * clusters]
    for name, column in columns.items():
        if name not in group:
            _dataset(group, name, np.zeros((0,) + column.shape[1:]), maxshape=(None,) + column.shape[1:],
                     chunks=(1024,) + column.shape[1:])
        ds = group[name]
        ds.resize((ds.shape[0] + column.shape[0],) + column.shape[1:])
        ds[-column.shape[0]:] = column


def _array(value: Any) -> np.ndarray:
    """A copy: float64 for real data; integer labels (state, class_id) keep their type."""
    array = np.asarray(value)
    return array.astype(np.float64) if array.dtype.kind == "f" else array.copy()


def _dataset(group: h5py.Group, name: str, data: np.ndarray, **options: Any) -> h5py.Dataset:
    """Create dataset ``name`` with its ``units`` attribute (gzip-compressed when large)."""
    if data.size > _COMPRESS_ABOVE and data.dtype.kind in "fiu" and "maxshape" not in options:
        options.update(compression="gzip", compression_opts=1, shuffle=True)
    ds = group.create_dataset(name, data=data, **options)
    ds.attrs["units"] = UNITS.get(name, UNKNOWN_UNITS)
    return ds


def _is_scalar(value: Any) -> bool:
    return isinstance(value, (bool, int, float, str, np.integer, np.floating))


def _checkpoint(f: h5py.File, finish_swap: bool = False) -> h5py.Group | None:
    """The file's checkpoint group: ``/checkpoint``, else a complete ``_checkpoint_new`` left by a run killed
    in the middle of the swap (moved into place when ``finish_swap``); None when there is none."""
    if CHECKPOINT in f:
        return f[CHECKPOINT]
    new = f.get(NEW_CHECKPOINT)
    if new is None or not new.attrs.get("complete", False):
        return None
    if finish_swap:
        f.move(NEW_CHECKPOINT, CHECKPOINT)
        return f[CHECKPOINT]
    return new


# ----------------------------------------------------------------------------------------------
# reading


class Snapshots(Sequence):
    """The snapshots of one physics, in time order, read from the file on access (``len``, ``[i]``,
    iteration, ``times``, :meth:`at`)."""

    def __init__(self, path: Path, group: str, names: list[str], times: np.ndarray,
                 build: Callable[[h5py.Group], Any]):
        self._path, self._group, self._names, self._build = path, group, names, build
        self.times = times

    def __len__(self) -> int:
        return len(self._names)

    def __getitem__(self, index):  # type: ignore[override]
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        name = self._names[index]
        with _open(self._path, "r") as f:
            return self._build(f[f"{self._group}/{name}"])

    def at(self, time: float):
        """The snapshot whose time is nearest to ``time`` [s]."""
        if not len(self):
            raise HfgpuError(f"{self._path}: no {self._group.split('/')[0]} snapshots")
        return self[int(np.argmin(np.abs(self.times - time)))]


@dataclass(frozen=True)
class Results:
    """A results file, read back. Arrays come from the file when asked for.

    status: "complete", "interrupted" (Ctrl-C, SIGTERM, SIGHUP), "failed: <message>", or "running" (still
    being written, or killed).
    summary: the ``/summary`` attributes (empty until the run closed the file).
    fracture_balance / proppant_balance: dicts of 1-D arrays (empty dict when absent).
    checkpoint_time: simulated time [s] of the checkpoint the file holds (None when it holds none).
    stage_balance: ``/stage/balance`` of a stage of several clusters (1-D ``time``, ``wellbore_pressure``; the
    per-cluster columns (rows, clusters)); empty dict otherwise.
    stage_snapshots: each cluster's fracture snapshots of a stage (``/stage/cluster_<i>/snapshots``); empty
    otherwise.
    """

    path: Path
    status: str
    format_version: int
    scene_text: str
    summary: dict[str, Any]
    fracture_snapshots: Snapshots
    proppant_snapshots: Snapshots
    fracture_balance: dict[str, np.ndarray] = field(repr=False)
    proppant_balance: dict[str, np.ndarray] = field(repr=False)
    checkpoint_time: float | None = None
    stage_balance: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    stage_snapshots: list[Snapshots] = field(default_factory=list, repr=False)

    @functools.cached_property
    def closure(self) -> dict[str, Any] | None:
        """The ``/closure`` group: {"frame": GridFrame, "fields": {name: array}, "attrs": {name: value}}; None
        when the file has none (:func:`hfgpu.closure.conductivity.closure_of` computes it then)."""
        with _open(self.path, "r") as f:
            group = f.get("closure")
            if group is None:
                return None
            return dict(frame=_frame(group), fields={name: ds[()] for name, ds in group.items()},
                        attrs={k: _plain(v) for k, v in group.attrs.items()})

    def cluster(self, i: int) -> Results:
        """Cluster ``i`` of a stage read as one fracture's file: its snapshots (``/stage/cluster_<i>/snapshots``) as
        ``fracture_snapshots``, the rest (balances, proppant, closure: the stage's) as they are."""
        return dataclasses.replace(self, fracture_snapshots=self.stage_snapshots[i])

    @functools.cached_property
    def scene(self):
        """The stored scene, parsed again with :func:`hfgpu.load_scene`."""
        from ..scene import load_scene

        return load_scene(self.scene_text)


def open_results(path: str | Path) -> Results:
    """Open an hfgpu results file; raises :class:`HfgpuError` when it is missing or not one."""
    path = Path(path)
    try:
        f = _open(path, "r")
    except (OSError, FileNotFoundError) as exc:
        raise HfgpuError(f"cannot open results file '{path}': {exc}") from None
    with f:
        if f.attrs.get("format") != FORMAT:
            raise HfgpuError(f"'{path}' is not an hfgpu results file (no format=\"{FORMAT}\" attribute)")
        scene = f["scene"][()] if "scene" in f else b""
        return Results(
            path=path,
            status=str(f.attrs.get("status", "running")),
            format_version=int(f.attrs["format_version"]),
            scene_text=scene.decode("utf-8") if isinstance(scene, bytes) else str(scene),
            summary={k: _plain(v) for k, v in f["summary"].attrs.items()} if "summary" in f else {},
            fracture_snapshots=_snapshots(f, path, "fracture", _fracture_snapshot),
            proppant_snapshots=_snapshots(f, path, "proppant", _proppant_snapshot),
            fracture_balance=_balance(f, "fracture"),
            proppant_balance=_balance(f, "proppant"),
            checkpoint_time=_checkpoint_time(f),
            stage_balance=_balance(f, "stage"),
            stage_snapshots=[_snapshots(f, path, f"stage/cluster_{i}", _fracture_snapshot)
                             for i in range(_stage_clusters(f))],
        )


def _stage_clusters(f: h5py.File) -> int:
    """The clusters with snapshots under ``/stage`` (``cluster_0``, ``cluster_1``, ...)."""
    group = f.get("stage")
    n = 0
    while group is not None and f"cluster_{n}" in group:
        n += 1
    return n


def _checkpoint_time(f: h5py.File) -> float | None:
    group = _checkpoint(f)
    return float(group.attrs["time"]) if group is not None else None


def _snapshots(f: h5py.File, path: Path, physics: str, build: Callable) -> Snapshots:
    group = f.get(f"{physics}/snapshots")
    names = sorted(n for n in group if n.isdigit()) if group is not None else []
    times = np.array([group[n].attrs["time"] for n in names], dtype=np.float64)
    return Snapshots(path, f"{physics}/snapshots", names, times, build)


def _frame(group: h5py.Group) -> GridFrame:
    return GridFrame.of(group.attrs)


def _fracture_snapshot(group: h5py.Group) -> FractureSnapshot:
    arrays = {name: group[name][()] for name in group}
    return FractureSnapshot(time=float(group.attrs["time"]), frame=_frame(group),
                            **{name: arrays.pop(name) for name in FRACTURE_FIELDS}, extras=arrays)


def _proppant_snapshot(group: h5py.Group) -> ProppantSnapshot:
    parts: dict[str, dict[str, np.ndarray]] = {"parcel": {}, "grid": {}}
    for name, ds in group.items():
        parts[ds.attrs["kind"]][name] = ds[()]
    return ProppantSnapshot(time=float(group.attrs["time"]), frame=_frame(group), parcels=parts["parcel"],
                            grid=parts["grid"])


def _balance(f: h5py.File, physics: str) -> dict[str, np.ndarray]:
    group = f.get(f"{physics}/balance")
    return {name: ds[()] for name, ds in group.items()} if group is not None else {}


def _plain(value: Any) -> Any:
    if isinstance(value, bytes):
        return value.decode("utf-8")
    return value.item() if isinstance(value, np.generic) else value
