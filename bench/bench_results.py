"""What writing a results file costs: seconds per fracture snapshot (with its balance rows) as the file grows,
for the results writer (hfgpu/io/results.py: every write on a spare copy kept one write behind the file)
and, for comparison, a copy of the whole file at every write (``--with-copy``, the simple crash-safe way).

    python bench/bench_results.py [--cells 61,301] [--snapshots 400] [--with-copy]

Each snapshot holds the four fracture fields on cells x cells (gzip-compressed above 4096 values), 18 scalar
extras (as the fracture engine writes) and 50 balance rows. Prints total seconds, milliseconds per snapshot
over the first and the last tenth of the run (flat: linear in the snapshot count) and the file's size;
asserts nothing.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
import types
from pathlib import Path

import numpy as np

import hfgpu.io.results as results
from hfgpu.io.results import ResultsWriter
from hfgpu.records import BalanceRecord, FractureSnapshot, GridFrame

SCALARS = ("front_radius", "front_radius_min", "front_radius_max", "front_up", "front_down", "front_left",
           "front_right", "area", "area_radius", "length", "height", "injected_volume", "stored_volume",
           "leaked_volume", "inlet_width", "net_pressure", "efficiency", "injection_pressure")


def snapshot(t: float, cells: int) -> FractureSnapshot:
    """A radial opening of radius t [m] on cells x cells of 1 m."""
    frame = GridFrame(dx=1.0, dz=1.0, x0=-(cells - 1) / 2, z0=-(cells - 1) / 2)
    x, z = frame.centres(cells, cells)
    r = np.hypot(*np.meshgrid(x, z))
    inside = r < t
    width = np.where(inside, 1e-3 * np.sqrt(np.clip(1 - (r / t) ** 2, 0, None)), 0.0)
    return FractureSnapshot(time=t, frame=frame, width=width, pressure=np.where(inside, 61e6 - 1e5 * r, 0.0),
                            leakoff_rate=np.where(inside, 1e-6, 0.0), opening_time=np.where(inside, r, np.nan),
                            extras={name: np.array(t) for name in SCALARS})


def write(path: Path, cells: int, count: int) -> np.ndarray:
    """Seconds of each snapshot write (with its 50 balance rows) into a new results file at ``path``."""
    snap = snapshot(0.4 * cells, cells)
    writer = ResultsWriter(path, types.SimpleNamespace(source="# bench\n"))
    seconds = np.zeros(count)
    for k in range(count):
        for j in range(50):
            t = k + j / 50
            writer.fracture_balance(BalanceRecord(time=t, injected=t, stored=t, leaked=0.0))
        start = time.perf_counter()
        writer.fracture_snapshot(FractureSnapshot(**{**snap.__dict__, "time": float(k + 1)}))
        seconds[k] = time.perf_counter() - start
    writer.close()
    return seconds


class _CopyEveryWrite:
    """The writer's file with no spare: each write on a fresh copy of the whole file (the comparison row)."""

    def __init__(self, path: Path):
        self.path = path

    def apply(self, write, catch_up=None) -> None:
        with results._edit(self.path) as f:
            write(f)

    def finish(self) -> None:
        pass


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cells", default="61,301", help="snapshot sizes (cells across)")
    parser.add_argument("--snapshots", type=int, default=400)
    parser.add_argument("--with-copy", action="store_true", help="also time a copy of the file at every write")
    args = parser.parse_args()
    ways = [("spare", results._TwinFile)] + ([("copy", _CopyEveryWrite)] if args.with_copy else [])
    folder = Path(tempfile.mkdtemp(prefix="bench_results_"))
    print(f"{'writer':>7} {'cells':>6} {'snapshots':>9} {'total s':>8} {'first ms':>9} {'last ms':>8} {'file MB':>8}")
    try:
        for name, store in ways:
            results._TwinFile, real = store, results._TwinFile
            try:
                for cells in (int(c) for c in args.cells.split(",")):
                    path = folder / f"{name}_{cells}.h5"
                    seconds = write(path, cells, args.snapshots)
                    tenth = max(args.snapshots // 10, 1)
                    print(f"{name:>7} {cells:6d} {args.snapshots:9d} {seconds.sum():8.2f} "
                          f"{1e3 * seconds[:tenth].mean():9.1f} {1e3 * seconds[-tenth:].mean():8.1f} "
                          f"{path.stat().st_size / 1e6:8.1f}")
            finally:
                results._TwinFile = real
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
