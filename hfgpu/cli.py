"""The ``hfgpu`` command: run a scene, plot a results file, check a scene (docs/cli.md).

Exit codes: 0 success; 2 bad input or a failed run (an :class:`HfgpuError`, one line on stderr, no
traceback; argparse usage errors too); 128 + the signal's number when interrupted: 130 Ctrl-C (SIGINT), 143
SIGTERM, 129 SIGHUP (the results file then says "interrupted" and resumes with --resume).
"""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from .errors import HfgpuError
from .interrupts import signal_number


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="hfgpu", description="Hydraulic fracture and proppant transport "
                                     "simulator (planar 3-D fracture, MP-PIC proppant).")
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
    plot.add_argument("results", type=Path, help="results file (HDF5) written by 'hfgpu run'")
    plot.add_argument("--out", type=Path, help="folder for the figures (default: <results>_plots)")

    check = commands.add_parser("check", help="validate a scene file and describe it")
    check.add_argument("scene", type=Path, help="scene file (TOML)")
    return parser


def _run(args: argparse.Namespace) -> None:
    from .runner import run

    run(args.scene, args.out, progress=not args.no_progress, rrd=args.rrd, view=args.view,
        connect=args.connect, resume=args.resume, viewer_required=args.viewer_required)


def _plot(args: argparse.Namespace) -> None:
    from .io.plots import plot_results

    folder = args.out or args.results.with_name(args.results.stem + "_plots")
    for path in plot_results(args.results, folder):
        print(path)


def _check(args: argparse.Namespace) -> None:
    from .presets import knob_report
    from .runner import check_supported
    from .scene import load_scene

    scene = load_scene(args.scene)
    check_supported(scene)
    print(f"{args.scene}: ok; physics {', '.join(scene.run.physics)}, end time {scene.run.end_time:g} s, "
          f"cells {scene.mesh.dx:g} x {scene.mesh.dz:g} m, output every {scene.output.every:g} s")
    print(knob_report(scene))


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        {"run": _run, "plot": _plot, "check": _check}[args.command](args)
    except HfgpuError as exc:  # one line, even where a scene value holds line breaks
        print(f"hfgpu {args.command}: error: {' '.join(str(exc).splitlines())}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        number = signal_number(exc)
        print(f"hfgpu {args.command}: interrupted ({signal.Signals(number).name})", file=sys.stderr)
        return 128 + number
    return 0


if __name__ == "__main__":
    sys.exit(main())
