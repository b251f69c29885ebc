"""The corpus of realistic treatments (bench/scenes/corpus_*.toml, written as engineers write them, numerical
knobs left out) run as a user runs them: each scene with its defaults and with every preset, each run
``hfgpu run SCENE --out OUT/<scene>-<preset>.h5`` in a fresh process. Prints a markdown table, one row per run:
outcome (completed, failed and the error's first line, timeout), wall seconds, fracture and proppant steps,
created area (the fracture's, ``/summary`` ``fracture_area``), propped area (``closure_propped_area``), the
fluid balance error (``balance_error``), the solid balance error |injected - in_domain - outflow - screened_out|
/ injected (``/proppant/balance``'s last row) and where the time went (``time_fracture``, ``time_fluid``,
``time_parcels``, ``time_io``); then the median wall time and the runs completed. Asserts nothing.

    python bench/bench_corpus.py [--scenes NAME ...] [--presets default fast balanced accurate] [--jobs 1]
                                 [--timeout 1800] [--out out/corpus] [--units field|SI] [--threads N]
                                 [--pumping-scale F ...]

NAME is a scene's file name without ``corpus_`` and ``.toml`` (``permian_slickwater_stage``). ``default`` runs
the file as written; a preset runs it with ``[run] preset`` set (``hfgpu.edit_scene``; the edited scene is
written beside the results as ``<scene>-<preset>.toml``). A run past ``--timeout`` seconds gets SIGTERM (its
file closes "interrupted", the steps reached are shown), SIGKILL 30 s later. ``--jobs N`` runs N at once (each
process single-threaded BLAS; ``--threads``: Taichi CPU threads, HFGPU_THREADS). Issue 30's targets on 2
cores: every run completes; the 80 bbl/min stage (``permian_slickwater_stage``) within 3 minutes with the
defaults and 1 minute with ``fast``; the median within 2 minutes.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import signal
import statistics
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

from hfgpu import edit_scene, load_scene, open_results

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "bench" / "scenes"
PREFIX = "corpus_"
PRESETS = ("default", "fast", "balanced", "accurate")
PHASES = ("fracture", "fluid", "parcels", "io")
#: Seconds between SIGTERM and SIGKILL of a run past its timeout.
GRACE = 30.0
#: m^2 per ft^2.
FT2 = 0.3048 ** 2


@dataclass(frozen=True)
class Outcome:
    """One run: its scene and preset, how it ended ("completed", "failed: <first line>", "timeout"), its wall
    seconds and the results file's /summary (empty where no file was written) and last solid balance row."""
    scene: str
    preset: str
    outcome: str
    wall: float
    summary: dict
    solid: dict


def corpus() -> dict[str, Path]:
    """The corpus scenes by short name (file name without ``corpus_`` and ``.toml``), sorted."""
    return {p.stem[len(PREFIX):]: p for p in sorted(SCENES.glob(f"{PREFIX}*.toml"))}


def scene_file(path: Path, preset: str, out: Path) -> Path:
    """The scene to run: the file itself for "default", else its text with ``[run] preset`` set, written to
    ``out``."""
    if preset == "default":
        return path
    out.write_text(edit_scene(load_scene(path.read_text()), {"run.preset": preset}).source)
    return out


def scaled(path: Path, factor: float, out: Path) -> Path:
    """The scene with its end time and every stage's ``duration`` (written in minutes) times ``factor``, written
    to ``out``: the same treatment pumped longer or shorter (``--pumping-scale``)."""
    def times(match: re.Match) -> str:
        return f'{match.group(1)} = "{float(match.group(2)) * factor:g} min"'

    text, count = re.subn(r'\b(duration|end_time) = "([0-9.]+) min"', times, path.read_text())
    stages = len(load_scene(path.read_text()).injection.schedule.stages)
    if count != stages + 1:
        raise SystemExit(f"--pumping-scale: {path.name} must give end_time and each stage's duration in min")
    out.write_text(text)
    return out


def run_one(name: str, path: Path, preset: str, out_dir: Path, timeout: float, threads: int | None) -> Outcome:
    """``hfgpu run`` of one scene and preset in a fresh process, stopped after ``timeout`` seconds."""
    stem = f"{name}-{preset}"
    out = out_dir / f"{stem}.h5"
    scene = scene_file(path, preset, out_dir / f"{stem}.toml")
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    if threads:
        env["HFGPU_THREADS"] = str(threads)
    command = [sys.executable, "-c", "import sys; from hfgpu.cli import main; sys.exit(main())", "run",
               str(scene), "--out", str(out), "--no-progress"]
    started = time.perf_counter()
    proc = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        _, stderr = proc.communicate(timeout=timeout)
        timed_out = False
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGTERM)
        try:
            _, stderr = proc.communicate(timeout=GRACE)
        except subprocess.TimeoutExpired:
            proc.kill()
            _, stderr = proc.communicate()
        timed_out = True
    wall = time.perf_counter() - started
    summary, solid, status = read_results(out)
    if timed_out:
        outcome = f"timeout ({timeout:g} s)"
    elif proc.returncode == 0 and status == "complete":
        outcome = "completed"
    else:
        outcome = "failed: " + first_error(status, stderr, proc.returncode)
    return Outcome(name, preset, outcome, wall, summary, solid)


def read_results(out: Path) -> tuple[dict, dict, str]:
    """The results file's /summary, last /proppant/balance row and status ({}, {}, "" where it is missing or
    unreadable)."""
    if not out.exists():
        return {}, {}, ""
    try:
        r = open_results(out)
        balance = {k: float(v[-1]) for k, v in r.proppant_balance.items() if len(v)}
        return dict(r.summary or {}), balance, r.status
    except Exception:  # a file killed mid-write may not open; the outcome then comes from stderr
        return {}, {}, ""


def first_error(status: str, stderr: str, code: int) -> str:
    """The first line of what went wrong: the file's "failed: ..." status, else the CLI's "error:" line, else
    stderr's last line, else the exit code."""
    if status.startswith("failed:"):
        return status[len("failed:"):].strip().splitlines()[0]
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    errors = [line.split("error:", 1)[1].strip() for line in lines if "error:" in line]
    return (errors or lines[-1:] or [f"exit {code}"])[0]


def solid_error(solid: dict) -> float:
    """|injected - in_domain - outflow - screened_out| / injected (NaN without proppant)."""
    injected = solid.get("injected", 0.0)
    if injected <= 0.0:
        return math.nan
    lost = injected - solid["in_domain"] - solid.get("outflow", 0.0) - solid.get("screened_out", 0.0)
    return abs(lost) / injected


def cells(row: Outcome, area_unit: float) -> list[str]:
    """The table's cells of one run."""
    s = row.summary

    def number(key: str, fmt: str, scale: float = 1.0) -> str:
        value = s.get(key)
        return "-" if value is None or not math.isfinite(float(value)) else format(float(value) / scale, fmt)

    solid = solid_error(row.solid)
    return [row.scene, row.preset, row.outcome.replace("|", "/"), f"{row.wall:.1f}",
            number("fracture_steps", ".0f"), number("proppant_steps", ".0f"),
            number("fracture_area", ",.0f", area_unit), number("closure_propped_area", ",.0f", area_unit),
            number("balance_error", ".1e"), "-" if math.isnan(solid) else f"{solid:.1e}",
            *(number(f"time_{phase}", ".1f") for phase in PHASES)]


def table(rows: list[Outcome], units: str) -> str:
    """The markdown table and the closing line (median wall time, runs completed)."""
    area = "ft^2" if units == "field" else "m^2"
    head = ["scene", "preset", "outcome", "wall s", "fracture steps", "proppant steps", f"created area {area}",
            f"propped area {area}", "fluid balance", "solid balance", *(f"{p} s" for p in PHASES)]
    unit = FT2 if units == "field" else 1.0
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(cells(row, unit)) + " |" for row in rows]
    done = sum(row.outcome == "completed" for row in rows)
    median = statistics.median(row.wall for row in rows) if rows else math.nan
    lines.append(f"\nmedian wall time {median:.1f} s over {len(rows)} runs (a run stopped at its timeout counts "
                 f"with the time it ran); {done} of {len(rows)} completed")
    return "\n".join(lines)


def main() -> None:
    scenes = corpus()
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", nargs="+", default=list(scenes), metavar="NAME",
                    help=f"scenes to run (default all): {', '.join(scenes)}")
    ap.add_argument("--presets", nargs="+", default=list(PRESETS), choices=PRESETS)
    ap.add_argument("--jobs", type=int, default=1, help="runs at once (default 1)")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per run (default 1800)")
    ap.add_argument("--out", type=Path, default=Path("out/corpus"), help="folder of the results files")
    ap.add_argument("--units", choices=("field", "SI"), default="field", help="of the areas (default field)")
    ap.add_argument("--threads", type=int, default=None, help="Taichi CPU threads per run (HFGPU_THREADS)")
    ap.add_argument("--pumping-scale", type=float, nargs="+", default=None, metavar="F",
                    help="run each scene with its end time and stage durations x F (e.g. 0.5 1 2: is wall time "
                         "linear in the pumped time?)")
    args = ap.parse_args()
    unknown = [name for name in args.scenes if name not in scenes]
    if unknown:
        ap.error(f"--scenes: no corpus scene {', '.join(unknown)}; the corpus: {', '.join(scenes)}")
    if args.jobs < 1 or args.timeout <= 0:
        ap.error(f"--jobs must be >= 1 (got {args.jobs}) and --timeout > 0 (got {args.timeout:g})")
    args.out.mkdir(parents=True, exist_ok=True)
    if args.pumping_scale:
        scenes = {f"{name}x{f:g}": scaled(scenes[name], f, args.out / f"{name}x{f:g}.toml")
                  for name in args.scenes for f in args.pumping_scale}
        args.scenes = list(scenes)
    runs = [(name, preset) for name in args.scenes for preset in args.presets]
    done: dict[tuple[str, str], Outcome] = {}
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:  # started preset by preset, in --presets' order
        futures = {pool.submit(run_one, name, scenes[name], preset, args.out, args.timeout, args.threads):
                   (name, preset) for preset in args.presets for name in args.scenes}
        for future in as_completed(futures):
            row = future.result()
            done[futures[future]] = row
            print(f"[{len(done)}/{len(runs)}] {row.scene} {row.preset}: {row.outcome}, {row.wall:.1f} s",
                  file=sys.stderr, flush=True)
    print(table([done[key] for key in runs], args.units))


if __name__ == "__main__":
    main()
