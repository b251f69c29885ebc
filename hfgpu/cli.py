"""The ``hfgpu`` command: run a scene, plot or export a results file, check a scene, run an
ensemble of scenes (docs/cli.md).

Exit codes: 0 success; 2 bad input or a failed run (an :class:`HfgpuError`, one line on stderr, no
traceback; argparse usage errors too); 128 + the signal's number when interrupted: 130 Ctrl-C (SIGINT), 143
SIGTERM, 129 SIGHUP (the results file then says "interrupted" and resumes with --resume).
"""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from . import __version__
from .errors import HfgpuError
from .interrupts import signal_number


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="hfgpu", description="Hydraulic fracture and proppant transport "
                                     "simulator (planar 3-D fracture, MP-PIC proppant).")
    parser.add_argument("--version", action="version", version=f"hfgpu {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = commands.add_parser("run", help="run a scene and write a results file")
    run.add_argument("scene", type=Path, help="scene file (TOML)")
    run.add_argument("--out", type=Path, required=True, help="results file to write (HDF5, replaced)")
    run.add_argument("--resume", action="store_true", help="continue the killed run in --out from its last "
                     "checkpoint (the scene must be the same); a complete file is left alone")
    run.add_argument("--rrd", type=Path, help="also save a Rerun recording to this .rrd file")
    run.add_argument("--view", action="store_true", help="stream to a Rerun viewer (spawned)")
    run.add_argument("--connect", metavar="URL", help="stream to a Rerun viewer or gRPC proxy already running "
                     "at URL, e.g. rerun+http://127.0.0.1:9876/proxy")
    run.add_argument("--viewer-required", action="store_true", help="stop before any work when the viewer of "
                     "--view or --connect cannot be reached (default: run without it, saying so in one line)")
    run.add_argument("--no-progress", action="store_true", help="no progress bar and no summary table")

    plot = commands.add_parser("plot", help="write PNG figures from a results file")
    plot.add_argument("results", type=Path, help="results file (HDF5) written by 'hfgpu run', or a sweep "
                      "folder written by 'hfgpu sweep'")
    plot.add_argument("--out", type=Path, help="folder for the figures (default: <results>_plots; a sweep "
                      "folder: <folder>/plots)")

    check = commands.add_parser("check", help="validate a scene file and describe it")
    check.add_argument("scene", type=Path, help="scene file (TOML)")

    sweep = commands.add_parser("sweep", help="run an ensemble (a sweep file) on Dask (docs/ensembles.md)")
    sweep.add_argument("sweep", type=Path, help="sweep file (TOML)")
    sweep.add_argument("--out", type=Path, required=True, help="folder for members/, summary.csv, ensemble.h5")
    sweep.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask cluster's scheduler address or "
                       "scheduler file (default: a local cluster, one single-threaded worker per core)")
    sweep.add_argument("--workers", type=int, metavar="N", help="worker processes of the local cluster")
    sweep.add_argument("--resume", action="store_true", help="keep the complete members in --out, run the others")
    sweep.add_argument("--no-progress", action="store_true", help="no progress bar")

    export = commands.add_parser("export", help="export a results file for other tools (StimPlan XML for "
                                 "ResInsight, VTK for ParaView, CSV)")
    export.add_argument("results", type=Path, help="results file (HDF5) written by 'hfgpu run'")
    export.add_argument("--format", required=True, choices=("stimplan-xml", "vtk", "csv"), help="file format")
    export.add_argument("--out", type=Path, required=True, help="file to write (vtk: the stem of the .pvd "
                        "series; csv: the map, with <stem>_pressure.csv beside it)")
    export.add_argument("--units", choices=("SI", "field"), help="units of the stimplan-xml and csv files "
                        "(default: the scene's [output] units)")
    return parser


def _run(args: argparse.Namespace) -> None:
    from .runner import run
    from .scene_checks import print_warnings, validate

    scene = validate(args.scene)  # what check reports: errors, then the same warnings
    print_warnings(scene)
    run(scene, args.out, progress=not args.no_progress, rrd=args.rrd, view=args.view,
        connect=args.connect, resume=args.resume, viewer_required=args.viewer_required)


def _plot(args: argparse.Namespace) -> None:
    from .io.plots import plot_results

    if args.results.is_dir():  # a sweep folder
        from .ensemble.plots import plot_ensemble

        for path in plot_ensemble(args.results, args.out or args.results / "plots"):
            print(path)
        return
    folder = args.out or args.results.with_name(args.results.stem + "_plots")
    for path in plot_results(args.results, folder):
        print(path)


def _export(args: argparse.Namespace) -> None:
    from .io.export import export

    for path in export(args.results, args.format, args.out, args.units):
        print(path)


def _sweep(args: argparse.Namespace) -> None:
    from .ensemble import sweep

    rows = sweep(args.sweep, args.out, workers=args.workers, scheduler=args.scheduler, resume=args.resume,
                 progress=not args.no_progress)
    complete = sum(row["status"] == "complete" for row in rows)
    print(f"{args.out}: {complete} of {len(rows)} members complete; summary.csv, ensemble.h5, members/ "
          f"(figures: hfgpu plot {args.out})")


def _check(args: argparse.Namespace) -> None:
    """Validate as ``run`` does (:func:`hfgpu.scene_checks.validate`): warnings on stderr, then the description
    (cells in use, knobs, pump schedule) in the scene's output units on stdout."""
    from .scene_checks import describe, print_warnings, validate

    scene = validate(args.scene)
    print_warnings(scene)
    print(describe(scene, str(args.scene)), flush=True)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        {"run": _run, "plot": _plot, "check": _check, "export": _export, "sweep": _sweep}[args.command](args)
    except HfgpuError as exc:  # one line per error (a scene's errors come together), even where a value holds breaks
        for error in getattr(exc, "errors", None) or [exc]:
            print(f"hfgpu {args.command}: error: {' '.join(str(error).splitlines())}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        number = signal_number(exc)
        print(f"hfgpu {args.command}: interrupted ({signal.Signals(number).name})", file=sys.stderr)
        return 128 + number
    return 0


if __name__ == "__main__":
    sys.exit(main())
