"""The ``hfgpu`` command: run a scene, plot or export a results file, check a scene, run an
ensemble of scenes, re-print a results file's summary or read its fall-off (docs/cli.md).

Exit codes: 0 success; 2 bad input or a failed run (an :class:`HfgpuError`, one line on stderr, no
traceback; argparse usage errors and files or folders that cannot be written (OSError) too); 128 + the signal's number when interrupted: 130 Ctrl-C (SIGINT), 143
SIGTERM, 129 SIGHUP (the results file then says "interrupted" and resumes with --resume).
"""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from .version import __version__
from .errors import HfgpuError
from .interrupts import signal_number


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="hfgpu", description="Hydraulic fracture and proppant transport "
                                     "simulator (planar 3-D fracture, MP-PIC proppant).")
    parser.add_argument("--version", action="version", version=f"hfgpu {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = commands.add_parser("run", help="run a scene and write a results file")
    run.add_argument("scene", type=Path, help="scene file (TOML)")
    run.add_argument("--out", type=Path, required=True, help="results file to write (HDF5, replaced; its folder is "
                     "created; refused while another run writes it)")
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

    summary = commands.add_parser("summary", help="print the run summary of a results file again")
    summary.add_argument("results", type=Path, help="results file (HDF5) written by 'hfgpu run'")

    falloff = commands.add_parser("falloff", help="read the pressure fall-off after shut-in of a results file "
                                  "with Nolte's G-function")
    falloff.add_argument("results", type=Path, help="results file (HDF5) written by 'hfgpu run'")
    falloff.add_argument("--alpha", type=float, default=None, help="area-growth exponent of G while pumping, "
                         "0.5 to 1 (default 1; 0.5 low efficiency, 4/5 a toughness-dominated radial fracture)")

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
    from .runner import run_validated
    from .scene_checks import print_warnings, validate

    scene = validate(args.scene)  # what check reports: errors, then the same warnings
    print_warnings(scene)
    args.out.parent.mkdir(parents=True, exist_ok=True)  # as plot and export create theirs
    run_validated(scene, args.out, progress=not args.no_progress, rrd=args.rrd, view=args.view,
        connect=args.connect, resume=args.resume, viewer_required=args.viewer_required)


def _warn_unfinished(path: Path) -> None:
    """A warning line on stderr when the results file ``path`` holds a run that did not complete."""
    from .io.results import open_results

    status = open_results(path).status
    if status != "complete":
        print(f"hfgpu: warning: {path}: the run is not complete (status \"{status}\"); what follows shows it "
              "as far as it got", file=sys.stderr, flush=True)


def _plot(args: argparse.Namespace) -> None:
    from .io.plots import plot_results

    if args.results.is_dir():  # a sweep folder
        from .ensemble.plots import plot_ensemble

        for path in plot_ensemble(args.results, args.out or args.results / "plots"):
            print(path)
        return
    _warn_unfinished(args.results)
    folder = args.out or args.results.with_name(args.results.stem + "_plots")
    for path in plot_results(args.results, folder):
        print(path)


def _export(args: argparse.Namespace) -> None:
    from .io.export import export

    _warn_unfinished(args.results)
    for path in export(args.results, args.format, args.out, args.units):
        print(path)


def _sweep(args: argparse.Namespace) -> None:
    from .ensemble import sweep
    from .ensemble.execute import percentile_lines
    from .ensemble.sweep_file import load_sweep
    from .scene import unit_system

    rows = sweep(args.sweep, args.out, workers=args.workers, scheduler=args.scheduler, resume=args.resume,
                 progress=not args.no_progress)
    complete = sum(row["status"] == "complete" for row in rows)
    spec = load_sweep(args.sweep)
    system = unit_system(spec.scene_data)
    print(f"metrics over the {complete} complete members ({system} units):")
    print("\n".join(percentile_lines(rows, list(spec.metrics), system)))
    print(f"{args.out}: {complete} of {len(rows)} members complete; summary.csv, ensemble.h5, members/ "
          f"(figures: hfgpu plot {args.out})")


def _summary(args: argparse.Namespace) -> None:
    from . import summary

    print(summary(args.results), flush=True)


def _falloff(args: argparse.Namespace) -> None:
    from .io.summary import falloff_report

    if args.alpha is not None and not 0.5 <= args.alpha <= 1.0:
        raise HfgpuError(f"--alpha {args.alpha:g}: Nolte's G is defined for an area-growth exponent from 0.5 to 1")
    _warn_unfinished(args.results)
    print(falloff_report(args.results, args.alpha), flush=True)


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
        {"run": _run, "plot": _plot, "check": _check, "export": _export, "sweep": _sweep,
         "summary": _summary, "falloff": _falloff}[args.command](args)
    except HfgpuError as exc:  # one line per error (a scene's errors come together), even where a value holds breaks
        for error in getattr(exc, "errors", None) or [exc]:
            print(f"hfgpu {args.command}: error: {' '.join(str(error).splitlines())}", file=sys.stderr)
        return 2
    except OSError as exc:  # a folder or file the user cannot write or read: what and where, not a traceback
        where = f"'{exc.filename}': " if exc.filename else ""
        print(f"hfgpu {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        number = signal_number(exc)
        if args.command in ("run", "sweep"):
            print(f"hfgpu {args.command}: {_resume_hint(args)}", file=sys.stderr)
        print(f"hfgpu {args.command}: interrupted ({signal.Signals(number).name})", file=sys.stderr)
        return 128 + number
    return 0


def _resume_hint(args: argparse.Namespace) -> str:
    """How to continue an interrupted ``run`` or ``sweep``."""
    given = args.scene if args.command == "run" else args.sweep
    return f"what is done is kept; continue with: hfgpu {args.command} {given} --out {args.out} --resume"


if __name__ == "__main__":
    sys.exit(main())
