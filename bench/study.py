"""Speed-accuracy study: error against CPU time across mesh size, time step, tolerances and parcel count.

Cases (bench/_study_cases.py): radial I and III against Dontsov (2016), Wu et al. (2008) against the digitised
fronts, Davis et al. (1982) against Kynch + MLB theory, and the scaled five-layer field case against its most
accurate run. Prints a table (case, setting, cells, parcels, steps, CPU s, wall s, error), and writes
``<out>/speed-accuracy.md`` (tables, Pareto fronts, convergence orders, parcel-count study, recommended preset
per use) with ``<out>/figures/pareto.png`` and ``<out>/figures/convergence.png``.

    python bench/study.py [--quick] [--cases radial_I,radial_III,wu2008,davis1982,field] [--out docs/]
                          [--backend numpy|taichi] [--save runs.pkl] [--report-from a.pkl,b.pkl]

Runs are single-threaded (OMP/BLAS/Taichi threads at 1) and timed with time.process_time(): on a shared, loaded
machine CPU seconds are the honest measure; wall seconds are printed beside them. The runs are deterministic
(fixed scenes and seeds), so a re-run reproduces the errors; the times move with the machine.
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS",
              "TI_CPU_MAX_NUM_THREADS"):
    os.environ[_name] = "1"

import argparse  # noqa: E402
import pickle  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _study_cases import CASES, PRESETS  # noqa: E402
from _study_plan import format_table, run_study, score_relative, table_rows  # noqa: E402
from _study_report import write_report  # noqa: E402


def _merge(a: dict | None, b: dict) -> dict:
    """Run metadata of studies run in parts: CPU and wall seconds add up, the first start and load are kept."""
    if a is None:
        return dict(b)
    return {**a, "cpu_total": a["cpu_total"] + b["cpu_total"], "wall_total": a["wall_total"] + b["wall_total"],
            "load": (a["load"][0], b["load"][1]), "quick": a["quick"] and b["quick"],
            "backend": a["backend"] if a["backend"] == b["backend"] else f"{a['backend']} / {b['backend']}"}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer settings (< 10 min on one core)")
    parser.add_argument("--cases", default=",".join(CASES), help=f"comma-separated from {','.join(CASES)}")
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "docs")
    parser.add_argument("--backend", choices=("numpy", "taichi"), default="numpy",
                        help="MP-PIC particle kernels (default numpy: the single-threaded, deterministic reference)")
    parser.add_argument("--save", type=Path, default=None, help="also keep the runs in this pickle file")
    parser.add_argument("--report-from", type=Path, default=None,
                        help="write the report from runs saved with --save (pickle files, comma-separated) "
                             "instead of running")
    args = parser.parse_args(argv)
    if args.report_from is not None:
        runs, meta = [], None
        for path in str(args.report_from).split(","):
            with open(path, "rb") as f:
                saved = pickle.load(f)
            runs += saved["runs"]
            meta = _merge(meta, saved["meta"])
        score_relative(runs)
        print(format_table(table_rows(runs)))
        print("\n".join(f"wrote {p}" for p in write_report(runs, meta, args.out)))
        return
    names = args.cases.split(",")
    unknown = [n for n in names if n not in CASES]
    if unknown:
        parser.error(f"--cases: unknown {unknown}; allowed {list(CASES)}")
    backend = args.backend
    started = time.time()
    cpu0 = time.process_time()
    load0 = os.getloadavg()
    print(format_table([]))
    runs = run_study(names, args.quick, backend)
    rows = table_rows(runs)
    print("\n" + format_table(rows))
    meta = dict(quick=args.quick, backend=args.backend, started=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(started)),
                cpu_total=time.process_time() - cpu0, wall_total=time.time() - started, load=(load0, os.getloadavg()),
                cores=os.cpu_count(), presets=PRESETS)
    if args.save is not None:
        with open(args.save, "wb") as f:
            pickle.dump(dict(runs=runs, meta=meta), f)
    paths = write_report(runs, meta, args.out)
    print("\n".join(f"wrote {p}" for p in paths))


if __name__ == "__main__":
    main()
