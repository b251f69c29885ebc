"""Running a sweep on Dask (``dask.distributed``): members submitted as tasks, results gathered, tables written.

Where it runs: a ``LocalCluster`` of one single-threaded worker process per core (``workers`` to choose),
each with OMP_NUM_THREADS, OPENBLAS_NUM_THREADS, MKL_NUM_THREADS, HFGPU_THREADS and HFGPU_BLAS_THREADS at 1 (set
before the worker process starts), and Dask's ``worker-saturation`` at 1.0 (in a sweep of more than two members
per worker, none waits on a worker behind another); or a running cluster: ``scheduler`` is its address
(``tcp://host:8786``) or its scheduler file.

Faults: a member whose run raises (bad combination, Newton failure, a SceneError the engine finds) is recorded
as "failed: <message>" and the others go on. A member whose worker is lost is run again on another worker, at
most MEMBER_RETRIES more times (the local cluster's ``allowed_failures``; a cluster of your own uses its
``distributed.scheduler.allowed-failures``), and then recorded as failed; an I/O error (OSError) raised by the
member is retried as many times (Dask's ``retries=``). Member files are written by the workers as they go, and
summary.csv a row at a time, so stopping the sweep (Ctrl-C, SIGTERM, SIGHUP: the local cluster is closed on the
way out) loses no finished member; ``resume`` skips the members
whose file is complete (root ``status == "complete"``) and holds the same scene, and reruns the others.
"""

from __future__ import annotations

import os
import time
import uuid
from pathlib import Path
from typing import Any

from ..errors import HfgpuError
from ..interrupts import stop_signals_interrupt
from ..scene import unit_system
from .members import Member, members
from .metrics import member_metrics, propped_map
from .summary import CsvWriter, columns, common_fraction, row, write_csv, write_ensemble
from .sweep_file import load_sweep
from .table_units import ColumnUnits, column_kinds

#: Further attempts of a member whose worker was lost (or that raised OSError): at most 1 + 2 runs.
MEMBER_RETRIES = 2
#: Seconds to reach a --scheduler address before giving up.
CONNECT_TIMEOUT = 30
#: Set in every local worker process before it starts: one thread for BLAS, OpenMP and Taichi.
THREAD_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "HFGPU_THREADS": "1",
              "HFGPU_BLAS_THREADS": "1"}


def run_member(scene_text: str, path: str, names: list[str]) -> tuple[str, dict[str, float], float]:
    """The task: run one member into its results file; (status, metrics, wall seconds). A failed run is
    returned as "failed: <message>"; OSError and MemoryError are raised for Dask to retry."""
    from ..runner import run

    start = time.perf_counter()
    try:
        run(scene_text, path, progress=False)  # the text: read once (a Scene would be read again, warn_edited)
    except (OSError, MemoryError):
        raise
    except Exception as exc:  # any failure of the run itself is the member's result
        return f"failed: {one_line(exc)}", {}, time.perf_counter() - start
    return "complete", metrics_of(path, names), time.perf_counter() - start


def one_line(exc: BaseException) -> str:
    return " ".join((str(exc) or type(exc).__name__).split())


def metrics_of(path: str | Path, names: list[str]) -> dict[str, float]:
    from ..io.results import open_results

    values = member_metrics(open_results(path))
    return {name: values[name] for name in names}


def sweep(sweep_file: str | Path, out: str | Path, *, workers: int | None = None, scheduler: str | None = None,
          resume: bool = False, progress: bool = True) -> list[dict[str, Any]]:
    """Run a sweep file into the folder ``out`` and return the summary, one dict per member in id order
    (docs/ensembles.md). ``workers``: local worker processes (default one per core); ``scheduler``: the
    address or scheduler file of a running Dask cluster instead; ``resume``: keep the complete members of an
    earlier run into ``out``. Every member scene is checked before any work; a bad one raises
    :class:`hfgpu.ensemble.members.MemberError` and a bad sweep file :class:`SweepError`."""
    if workers is not None and workers < 1:
        raise HfgpuError(f"workers = {workers}: allowed: a whole number >= 1")
    if workers is not None and scheduler is not None:
        raise HfgpuError("workers is for the local cluster; the cluster at the scheduler given has its own")
    spec = load_sweep(sweep_file)
    todo = members(spec)
    out = Path(out)
    folder = out.absolute() / "members"   # the workers' paths: they may run in another folder
    if not resume and folder.is_dir() and any(folder.glob("*.h5")):
        raise HfgpuError(f"'{folder}' holds member files of an earlier sweep: pass --resume (resume=True) to "
                         "continue it, or choose another --out")
    folder.mkdir(parents=True, exist_ok=True)
    names = list(spec.metrics)
    header = columns([v.key for v in spec.vary], names)
    kinds = column_kinds({v.key: v.kind for v in spec.vary}, names)
    units = ColumnUnits(kinds, unit_system(spec.scene_data), stored=True)
    rows = {}
    for m in todo:
        kept = _complete_row(m, folder / f"{m.id}.h5", names) if resume else None
        if kept is not None:
            rows[m.id] = kept
    writer = CsvWriter(out / "summary.csv", header, units)
    for values in rows.values():
        writer.write(values)
    pending = [m for m in todo if m.id not in rows]
    try:
        with stop_signals_interrupt() as stop:  # SIGTERM, SIGHUP: as Ctrl-C, the cluster closed on the way out
            if pending:
                for values in _run_members(pending, folder, names, len(todo), workers, scheduler, progress):
                    rows[values["id"]] = values
                    writer.write(values)
                    stop.check()   # a stop signal whose raise was lost (hfgpu.interrupts)
    finally:
        writer.close()
    ordered = [rows[m.id] for m in todo]
    write_csv(out / "summary.csv", header, ordered, units)
    write_ensemble(out / "ensemble.h5", spec.source, header, ordered, names, _propped(folder, ordered), units)
    return ordered


def percentile_lines(rows: list[dict[str, Any]], names: list[str], system: str) -> list[str]:
    """One line per metric, "name [unit]  P10 ...  P50 ...  P90 ..." over the complete members
    (:func:`hfgpu.ensemble.summary.percentiles`), in ``system``'s display units (the base scene's
    ``[output] units``); ratios and flags as they are."""
    from .summary import percentiles

    units, lines = ColumnUnits(column_kinds({}, names), system), []
    for name in names:
        shown, label = units(name, percentiles(rows, name)), units.label(name)
        lines.append((f"  {name + ' [' + label + ']':<32}" + "  ".join(f"P{level} {_number(v):<10}" for level, v
                                                                       in zip((10, 50, 90), shown))).rstrip())
    return lines


def _number(value: float) -> str:
    """Four significant digits, without an exponent below 1e7 (18200, not 1.82e+04)."""
    return f"{value:.0f}" if 1e4 <= abs(value) < 1e7 else f"{value:.4g}"


def _complete_row(member: Member, path: Path, names: list[str]) -> dict[str, Any] | None:
    """The row of a member whose file is complete and holds its scene; None when it must run."""
    from ..io.results import open_results

    if not path.is_file():
        return None
    try:
        results = open_results(path)
    except (HfgpuError, OSError):
        return None
    if results.status != "complete" or results.scene_text != member.scene_text:
        return None
    return row(member.id, "complete", member.inputs, metrics_of(path, names), names,
               float(results.summary.get("wall_time", float("nan"))))


def _run_members(pending: list[Member], folder: Path, names: list[str], total: int, workers: int | None,
                 scheduler: str | None, progress: bool):
    """Submit the pending members and yield their rows as they finish (a progress bar counts members)."""
    from dask.distributed import as_completed
    from tqdm import tqdm

    client, cluster = _client(workers, scheduler)
    try:
        dashboard = client.scheduler_info().get("services", {}).get("dashboard")
        if dashboard is not None and progress:
            print(f"Dask dashboard: {client.dashboard_link}", flush=True)
        tag = uuid.uuid4().hex[:8]
        futures = {client.submit(run_member, m.scene_text, str(folder / f"{m.id}.h5"), names,
                                 key=f"hfgpu-member-{m.id}-{tag}", retries=MEMBER_RETRIES, pure=False): m
                   for m in pending}
        bar = tqdm(total=total, initial=total - len(pending), unit="member", disable=not progress)
        for future in as_completed(futures):
            m = futures[future]
            try:
                status, metrics, wall = future.result()
            except Exception as exc:  # KilledWorker (worker lost too often), or OSError/MemoryError after retries
                status, metrics, wall = f"failed: {type(exc).__name__}: {one_line(exc)}", {}, float("nan")
            bar.update()
            yield row(m.id, status, m.inputs, metrics, names, wall)
        bar.close()
        if cluster is not None:   # every member done: nothing runs in the workers
            client.run(release_kernels, on_error="ignore")
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def release_kernels() -> None:
    """Run in each local worker once its members are done: finalise Taichi (``ti.reset``) where a member used it,
    which writes the kernels the worker compiled into Taichi's offline cache (kernels/runtime.py) for later
    workers and sweeps. Left to the worker's exit, that finalisation ran inside the 4 s Dask's nanny gives a
    closing worker and overran them (measured: close 4.2 s, "Worker process still alive after 4.0 seconds,
    killing"; 0.5 s with this call first), the cache written or not depending on how far it had got."""
    import sys

    taichi = sys.modules.get("taichi")
    if taichi is not None:
        taichi.reset()


def _client(workers: int | None, scheduler: str | None):
    """(client, the local cluster it made or None)."""
    import dask
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        file = Path(scheduler).is_file()
        try:
            return (Client(scheduler_file=scheduler) if file else Client(scheduler, timeout=CONNECT_TIMEOUT)), None
        except (OSError, ValueError, TypeError) as exc:  # unreachable, or not an address
            raise HfgpuError(f"cannot reach the Dask scheduler '{scheduler}': {one_line(exc)}") from None
    count = workers or (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)
    environ = {**dask.config.get("distributed.nanny.pre-spawn-environ", {}), **THREAD_ENV}
    with dask.config.set({"distributed.nanny.pre-spawn-environ": environ,
                          "distributed.scheduler.worker-saturation": 1.0}):
        cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True,
                               scheduler_kwargs={"allowed_failures": MEMBER_RETRIES})
    return Client(cluster), cluster


def _propped(folder: Path, rows: list[dict[str, Any]]):
    """(frame, fraction, members) of the complete members that have proppant; None when none has."""
    from ..io.results import open_results

    maps = []
    for values in rows:
        if values["status"] == "complete":
            found = propped_map(open_results(folder / f"{values['id']}.h5"))
            if found is not None:
                maps.append(found)
    if not maps:
        return None
    frame, fraction = common_fraction(maps)
    return frame, fraction, len(maps)
