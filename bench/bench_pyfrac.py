"""hfgpu beside PyFrac: wall and CPU seconds, steps, cells and errors against closed forms on PyFrac's examples.

PyFrac (https://github.com/GeoEnergyLab-EPFL/PyFrac) is the open-source planar-3D code users compare with. Its
examples run UNMODIFIED, each in a fresh working directory holding ``batch_run.txt`` (which makes the example skip
its closing plots; the plots PyFrac draws while it runs, every ``plotTSJump`` steps, stay, with MPLBACKEND=Agg),
with PYTHONPATH=<checkout>/src and the interpreter --pyfrac-python (numpy < 1.24: PyFrac uses ``np.int``).
hfgpu runs the matching scene. Each run is its own subprocess, timed around it: wall seconds, and CPU seconds
(user + system of the child, ``resource.getrusage(RUSAGE_CHILDREN)``), so both include the interpreter's start
and imports. Threads: "default" removes OMP/OPENBLAS/MKL_NUM_THREADS and HFGPU_BLAS_THREADS from the
environment; "one" sets all four to 1.

Cases:

* radial: ``examples/radial_viscosity_explicit.py`` (41 x 41 cells on 0.6 m, remeshed by compressing the domain,
  R 0.1 m to 1e5 s, explicit front, M tip asymptote: the example's K_Ic = 0.5 MPa m^0.5 does not enter, so the
  fracture it computes is the pure-viscosity one) against ``hfgpu/scenes/radial_viscosity.toml`` (the same
  injection with K_Ic = 0; whole cells opening, 3x3 merges at 36 cells across) and
  ``radial_viscosity_subgrid.toml`` (PyFrac's kind of front and remeshing: the sub-grid front, the grid
  coarsened by 2 at 40 cells across). Closed form: the M vertex (Savitski & Detournay 2002, mu' = 12 mu). Errors of the
  radius from the footprint's area, R_A = sqrt(A / pi), and of the inlet width w(0).
* height: ``examples/Ex2_height_contained_CPC.py`` (6 m layer at 1 MPa between 7.5 MPa barriers, K_Ic 0, 125 x 35
  cells on [-20, 20] x [-2.3, 2.3] m, compressed (domain and cells doubled) when the front reaches its edge, to
  145 s) against
  ``hfgpu/scenes/pyfrac_height_contained.toml``. Closed form: PKN (hfgpu.reference.plane.pkn, h = 6 m, the
  layer; PyFrac's example plots h = 7 m). Errors of the half-length (the longest row's wetted length / 2, tip
  cells by their filled fraction) and of the inlet width.

* pulse: ``examples/radial_viscosity_pulse.py`` (0.5 m^3 in 0.01 s, K_Ic 0, no leak-off, to 5e6 s) against
  ``hfgpu/scenes/pyfrac_pulse.toml``. Closed form: the viscous pulse R = 0.8364 (E' V^3 t / mu')^(1/9)
  (PyFrac's Mp_vertex_solution); errors of R_A from 100x the shut-in time.
* arrest: ``examples/radial_pulse_leakoff_arrest.py`` (0.05 m^3 in 0.01 s, K_Ic 0, C_L 5e-9 m/s^0.5, to 1e6 s)
  against ``hfgpu/scenes/pyfrac_pulse_leakoff.toml``. Closed form: the leak-off arrest radius R_a (PyFrac's
  LeakOff_arrest); errors of the largest R_A so far (hfgpu's wetted footprint recedes as it drains; PyFrac's
  does not), from 2e5 s.

"end" is the error at the end time; "max" the largest |error| (with its sign) over the run's late times: radial,
every step (hfgpu) or saved step (PyFrac saves every 5th) at t >= 10x the latest first time of the runs in the
table (the same times for every row; hfgpu starts from a larger fracture than PyFrac's 0.1 m); height, t >= 60 s
(the half-length is then > 3 layer heights). The footprint and widths of PyFrac come from its saved fractures
(``visualization.load_fractures``): area = (channel cells + sum of the tip cells' filling fractions) x cell area,
w(0) in the cell holding the injection point (PyFrac's ``plot_fracture_list_at_point`` default [0, 0]); steps
from its log ("number of time steps"), cells = cells of the final footprint (channel + tip), and the final mesh.

With --pyfrac-results DIR each PyFrac run's results go to DIR/<case>-<threads>.json (its working directory,
log and saved fractures under DIR/<case>-<threads>/) and are read from there on the next call instead of
rerunning PyFrac (--rerun-pyfrac forces a run); without --pyfrac the PyFrac rows come from DIR alone. hfgpu
always runs, once per scene of the case (the "scene" column); its log and record (with the series) go to
DIR/hfgpu-<scene>-<threads>.log/.json. The PyFrac/hfgpu wall ratio is against the case's first scene.

Usage: python bench/bench_pyfrac.py [--pyfrac /path/to/PyFrac] [--pyfrac-python /path/to/python]
       [--pyfrac-results DIR] [--rerun-pyfrac | --pyfrac-no-run] [--cases radial,height,pulse,arrest]
       [--threads default,one]
       [--no-hfgpu]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "hfgpu" / "scenes"
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "HFGPU_BLAS_THREADS")

# The physical inputs of PyFrac's examples (for the closed forms).
YOUNGS, POISSON, RATE, VISCOSITY = 3.3e10, 0.4, 1e-3, 1.1e-3
E_PRIME = YOUNGS / (1.0 - POISSON**2)
LAYER_HEIGHT = 6.0
PKN_FROM = 60.0          # [s] height case: errors over the run from here on (half-length > 3 heights)
RADIAL_FROM_FACTOR = 10.0  # radial case: errors over the run from 10x the run's first time
# The pulse examples: 50 (pulse) or 5 (arrest) m^3/s for 0.01 s, viscosity 1e-3 Pa s, C_L 5e-9 m/s^0.5 (arrest)
PULSE_SHUT_IN, PULSE_VISCOSITY = 0.01, 1e-3
PULSE_VOLUME = {"pulse": 50.0 * PULSE_SHUT_IN, "arrest": 5.0 * PULSE_SHUT_IN}
ARREST_CARTER = 5e-9
PULSE_FROM_FACTOR = 100.0   # pulse case: errors from 100x the shut-in time (the target: 2 % from there)
ARREST_FROM = 2e5           # [s] arrest case: the largest radius from here on (past the arrest)


@dataclass(frozen=True)
class Case:
    example: str        # PyFrac's examples/<example>
    data: str           # its output folder, relative to the working directory
    scenes: tuple       # hfgpu's scenes in hfgpu/scenes (the first: the wall ratio's)
    size: str           # the size the errors are of


CASES = {
    "radial": Case("radial_viscosity_explicit.py", "Data/M_radial_explicit",
                   ("radial_viscosity.toml", "radial_viscosity_subgrid.toml"), "R_A"),
    "height": Case("Ex2_height_contained_CPC.py", "Data/height_contained", ("pyfrac_height_contained.toml",), "l"),
    "pulse": Case("radial_viscosity_pulse.py", "Data/Pulse", ("pyfrac_pulse.toml",), "R_A"),
    "arrest": Case("radial_pulse_leakoff_arrest.py", "Data/Pulse", ("pyfrac_pulse_leakoff.toml",), "Rmax"),
}


# ---------------------------------------------------------------------------------------------- closed forms

def radial_reference(times):
    """(R, w0) of the M-vertex radial fracture (Savitski & Detournay 2002) at ``times`` [s]."""
    from hfgpu.reference.radial import m_vertex

    ref = m_vertex(E_PRIME, 12.0 * VISCOSITY, RATE, np.asarray(times, dtype=np.float64))
    return ref.R, ref.w0


def height_reference(times):
    """(half-length, w0) of the PKN fracture of the 6 m layer at ``times`` [s]."""
    from hfgpu.reference.plane import pkn

    ref = pkn(E_PRIME, VISCOSITY, RATE, LAYER_HEIGHT, np.asarray(times, dtype=np.float64))
    return ref.length, ref.w0


def pulse_reference(times):
    """(R, no w0 reference) of the viscous pulse (PyFrac's Mp_vertex_solution) of the pulse case at ``times``."""
    from hfgpu.reference.radial import mp_pulse_radius

    t = np.asarray(times, dtype=np.float64)
    return mp_pulse_radius(E_PRIME, 12.0 * PULSE_VISCOSITY, PULSE_VOLUME["pulse"], t), np.full(t.shape, np.nan)


def arrest_reference(times):
    """(R_a at every time, no w0 reference): the leak-off arrest radius of the arrest case (PyFrac's
    LeakOff_arrest, C' = 2 C_L)."""
    from hfgpu.reference.radial import leakoff_arrest_radius

    t = np.asarray(times, dtype=np.float64)
    r_a = leakoff_arrest_radius(E_PRIME, 2.0 * ARREST_CARTER, PULSE_VOLUME["arrest"], 12.0 * PULSE_VISCOSITY)
    return np.full(t.shape, r_a), np.full(t.shape, np.nan)


def run_errors(times, values, reference, t_from):
    """(error at the last time, the largest-|error| relative error at times >= t_from, with its sign) of
    ``values`` against ``reference`` (same length, same times). Non-finite values are skipped; NaN where no
    time qualifies."""
    t = np.asarray(times, dtype=np.float64)
    err = np.asarray(values, dtype=np.float64) / np.asarray(reference, dtype=np.float64) - 1.0
    end = float(err[-1]) if err.size else math.nan
    late = err[(t >= t_from) & np.isfinite(err)]
    return end, (float(late[np.argmax(np.abs(late))]) if late.size else math.nan)


def case_errors(case: str, series: dict, t_from: float | None = None) -> dict:
    """Errors of a run's series {time, size, w0} (size: R_A for radial, the half-length for height):
    {size_end, size_max, w0_end, w0_max, from} (``from``: the first time the max is taken over; by default
    10x the run's first time (radial) or PKN_FROM (height))."""
    t = np.asarray(series["time"], dtype=np.float64)
    keep = t > 0.0
    t = t[keep]
    size = np.asarray(series["size"], dtype=np.float64)[keep]
    w0 = np.asarray(series["w0"], dtype=np.float64)[keep]
    if case == "radial":
        ref_size, ref_w0 = radial_reference(t)
        default_from = RADIAL_FROM_FACTOR * float(t.min())
    elif case == "pulse":
        ref_size, ref_w0 = pulse_reference(t)
        default_from = PULSE_FROM_FACTOR * PULSE_SHUT_IN
    elif case == "arrest":
        ref_size, ref_w0 = arrest_reference(t)
        default_from = ARREST_FROM
    else:
        ref_size, ref_w0 = height_reference(t)
        default_from = PKN_FROM
    t_from = default_from if t_from is None else t_from
    size_end, size_max = run_errors(t, size, ref_size, t_from)
    w0_end, w0_max = run_errors(t, w0, ref_w0, t_from)
    return {"size_end": size_end, "size_max": size_max, "w0_end": w0_end, "w0_max": w0_max, "from": t_from}


# ---------------------------------------------------------------------------------------------- subprocesses

def thread_env(threads: str) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in THREAD_VARS}
    if threads == "one":
        env.update({k: "1" for k in THREAD_VARS})
    elif threads != "default":
        raise SystemExit(f"--threads: got {threads!r}; allowed: default, one")
    return env


def timed(cmd, cwd, env, log_path) -> tuple[float, float, int]:
    """(wall s, CPU s of the child and its children, return code) of ``cmd``, its output to ``log_path``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    with open(log_path, "w") as log:
        rc = subprocess.call(cmd, cwd=cwd, env=env, stdout=log, stderr=subprocess.STDOUT)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), rc


# Run in PyFrac's interpreter (PYTHONPATH=<checkout>/src): the saved fractures of a run as JSON.
PYFRAC_EXTRACT = r'''
import json, sys
import numpy as np
from visualization import load_fractures

frs, _ = load_fractures(address=sys.argv[1], load_all=True)
out = {"time": [], "area": [], "w0": [], "half_length": [], "height": [], "d_mean": [], "d_max": []}
for fr in frs:
    m = fr.mesh
    frac = np.zeros(m.NumberOfElts)
    frac[fr.EltChannel] = 1.0
    frac[fr.EltTip] = fr.FillF
    col = np.rint((m.CenterCoor[:, 0] - m.CenterCoor[:, 0].min()) / m.hx).astype(int)
    row = np.rint((m.CenterCoor[:, 1] - m.CenterCoor[:, 1].min()) / m.hy).astype(int)
    rows = np.zeros(row.max() + 1); np.add.at(rows, row, frac)
    cols = np.zeros(col.max() + 1); np.add.at(cols, col, frac)
    inlet = int(np.argmin(np.hypot(m.CenterCoor[:, 0], m.CenterCoor[:, 1])))
    src = m.CenterCoor[fr.source[0]] if len(fr.source) else np.zeros(2)
    d = np.hypot(fr.Ffront[:, [0, 2]].ravel() - src[0], fr.Ffront[:, [1, 3]].ravel() - src[1])
    out["time"].append(float(fr.time))
    out["area"].append(float(frac.sum() * m.EltArea))
    out["w0"].append(float(fr.w[inlet]))
    out["half_length"].append(float(rows.max() * m.hx / 2))
    out["height"].append(float(cols.max() * m.hy))
    out["d_mean"].append(float(d.mean()))
    out["d_max"].append(float(d.max()))
m, fr = frs[-1].mesh, frs[-1]
out["saved"] = len(frs)
out["cells"] = int(len(fr.EltCrack))
out["mesh"] = {"nx": int(m.nx), "ny": int(m.ny), "hx": float(m.hx), "hy": float(m.hy),
               "x": [float(m.domainLimits[2]), float(m.domainLimits[3])],
               "y": [float(m.domainLimits[0]), float(m.domainLimits[1])]}
out["first_mesh"] = {"nx": int(frs[0].mesh.nx), "ny": int(frs[0].mesh.ny), "hx": float(frs[0].mesh.hx),
                     "hy": float(frs[0].mesh.hy)}
print("JSON" + json.dumps(out))
'''


def _log_int(text: str, label: str) -> int | None:
    found = re.findall(re.escape(label) + r"\s*=\s*(\d+)", text)
    return int(found[-1]) if found else None


def pyfrac_extract(case: str, work: Path, checkout: Path, python: str) -> dict:
    """PyFrac's run in ``work`` (timing.json, log.txt, its saved fractures) as the results record."""
    env = dict(os.environ, PYTHONPATH=str(checkout / "src"), MPLBACKEND="Agg")
    proc = subprocess.run([python, "-c", PYFRAC_EXTRACT, str(work / CASES[case].data)], cwd=work, env=env,
                          capture_output=True, text=True)
    line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("JSON")), None)
    if line is None:
        raise SystemExit(f"PyFrac's results in {work} could not be read:\n{proc.stderr[-3000:]}")
    fr = json.loads(line[4:])
    timing = json.loads((work / "timing.json").read_text())
    log = (work / "log.txt").read_text(errors="replace")
    steps = _log_int(log, "number of time steps")
    return {"code": "PyFrac", "case": case, "threads": timing["threads"], "wall_s": timing["wall_s"],
            "cpu_s": timing["cpu_s"], "returncode": timing["returncode"],
            "steps": steps if steps is not None else log.count("Time step successful"),
            "failed_steps": _log_int(log, "failed time steps"), "remeshings": _log_int(log, "number of remeshings"),
            "remesh_log": sorted(set(re.findall(r"Remeshing[^\n]*", log))),
            "cells": fr["cells"], "mesh": fr["mesh"], "first_mesh": fr["first_mesh"], "saved": fr["saved"],
            "series": {"time": fr["time"], "area": fr["area"], "w0": fr["w0"], "half_length": fr["half_length"],
                       "height": fr["height"], "d_mean": fr["d_mean"], "d_max": fr["d_max"]}}


def run_pyfrac(case: str, threads: str, checkout: Path, python: str, results: Path, rerun: bool,
               may_run: bool = True) -> dict | None:
    """PyFrac's record of (case, threads): from results/<case>-<threads>.json where there, else by running
    the example in results/<case>-<threads>/ (or only reading it, where that run finished but was not read;
    None where it has not and ``may_run`` is false)."""
    saved = results / f"{case}-{threads}.json"
    if saved.exists() and not rerun:
        return json.loads(saved.read_text())
    if checkout is None:
        return None
    work = results / f"{case}-{threads}"
    timing = work / "timing.json"
    log = work / "log.txt"
    if rerun or not timing.exists() or json.loads(timing.read_text()).get("returncode") != 0:
        if not may_run:
            print(f"no finished PyFrac run in {work}: its row is left out", file=sys.stderr)
            return None
        if not rerun and not timing.exists() and log.exists() and time.time() - log.stat().st_mtime < 600:
            raise SystemExit(f"PyFrac's run in {work} looks in progress (no timing.json, log written in the last "
                             "10 minutes); wait for it, or --rerun-pyfrac to start it again")
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True)
        shutil.copy(checkout / "examples" / CASES[case].example, work)
        (work / "batch_run.txt").touch()
        env = thread_env(threads)
        env.update(PYTHONPATH=str(checkout / "src"), MPLBACKEND="Agg")
        print(f"running PyFrac's {CASES[case].example} ({threads} threads) in {work} ...", file=sys.stderr, flush=True)
        wall, cpu, rc = timed([python, CASES[case].example], work, env, work / "log.txt")
        timing.write_text(json.dumps({"wall_s": wall, "cpu_s": cpu, "returncode": rc,
                                      "example": CASES[case].example, "threads": threads}, indent=1))
        if rc != 0:
            raise SystemExit(f"PyFrac's {CASES[case].example} failed (exit {rc}); see {work / 'log.txt'}")
    record = pyfrac_extract(case, work, checkout, python)
    saved.write_text(json.dumps(record))
    return record


def hfgpu_worker(scene: str) -> None:
    """In the timed subprocess: run hfgpu's ``scene`` (in hfgpu/scenes), print its record as JSON."""
    from hfgpu.fracture.simulator import simulate
    from hfgpu.records import MemorySink
    from hfgpu.scene import load_scene

    sink = MemorySink()
    start = time.perf_counter()
    out = simulate(load_scene(SCENES / scene), sink)
    wall = time.perf_counter() - start
    keep = ("steps", "newton_iterations", "retries", "rejected", "coarsenings", "cells", "dx", "dz", "area",
            "area_radius", "length", "height", "w_inlet", "time")
    rec = sink.fracture_balances
    print("JSON" + json.dumps({
        "summary": {k: out[k] for k in keep if k in out}, "simulate_wall_s": wall,
        "series": {"time": [r.time for r in rec], "area": [r.area for r in rec],
                   "half_length": [r.length / 2 for r in rec], "height": [r.height for r in rec],
                   "w0": [r.inlet_width for r in rec]}}))


def run_hfgpu(case: str, scene: str, threads: str, logs: Path) -> dict:
    log = logs / f"hfgpu-{Path(scene).stem}-{threads}.log"
    env = thread_env(threads)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p)
    wall, cpu, rc = timed([sys.executable, str(Path(__file__).resolve()), "--hfgpu-worker", scene], ROOT, env, log)
    text = log.read_text(errors="replace")
    line = next((ln for ln in text.splitlines() if ln.startswith("JSON")), None)
    if rc != 0 or line is None:
        raise SystemExit(f"hfgpu's {scene} run failed (exit {rc}):\n{text[-3000:]}")
    data = json.loads(line[4:])
    s = data["summary"]
    record = {"code": "hfgpu", "case": case, "scene": Path(scene).stem, "threads": threads, "wall_s": wall, "cpu_s": cpu,
              "steps": s["steps"], "newton_iterations": s.get("newton_iterations"), "cells": s["cells"],
              "mesh": {"dx": s.get("dx"), "dz": s.get("dz")}, "summary": s, "series": data["series"]}
    log.with_suffix(".json").write_text(json.dumps(record))   # for a look at the series; never read back
    return record


# ---------------------------------------------------------------------------------------------- the table

def size_series(case: str, record: dict) -> dict:
    """{time, size, w0} of a record: size = R_A = sqrt(area / pi) (radial, pulse), its largest so far (arrest: the
    wetted footprint recedes as it drains) or the half-length (height)."""
    s = record["series"]
    size = s["half_length"] if case == "height" else np.sqrt(np.asarray(s["area"], dtype=np.float64) / math.pi)
    if case == "arrest":
        size = np.maximum.accumulate(size)
    return {"time": s["time"], "size": size, "w0": s["w0"]}


HEADER = (f"{'case':7} {'code':7} {'threads':8} {'wall s':>8} {'CPU s':>8} {'steps':>6} {'cells':>6} {'size':>4} "
          f"{'end err':>8} {'max err':>8} {'w0 end':>8} {'w0 max':>8} {'from s':>7} {'PyFrac/hfgpu wall':>17}  scene")


def common_from(case: str, records: list[dict]) -> float | None:
    """The radial case's common start of the late times: 10x the latest first time of the runs shown (hfgpu
    starts from a larger fracture than PyFrac's R = 0.1 m), so every row's max is over the same times."""
    if case != "radial" or not records:
        return None
    return RADIAL_FROM_FACTOR * max(min(t for t in r["series"]["time"] if t > 0.0) for r in records)


def row(case: str, record: dict, hfgpu_wall: float | None, t_from: float | None = None) -> str:
    e = case_errors(case, size_series(case, record), t_from)
    ratio = (f"{record['wall_s'] / hfgpu_wall:17.2f}" if record["code"] == "PyFrac" and hfgpu_wall
             else f"{'':17}")
    return (f"{case:7} {record['code']:7} {record['threads']:8} {record['wall_s']:8.1f} {record['cpu_s']:8.1f} "
            f"{record['steps']:6d} {record['cells']:6d} {CASES[case].size:>4} {e['size_end']:+8.2%} "
            f"{e['size_max']:+8.2%} {e['w0_end']:+8.2%} {e['w0_max']:+8.2%} {e['from']:7.3g} {ratio}  "
            f"{record.get('scene', '')}")


def mesh_note(case: str, record: dict) -> str:
    if record["code"] == "PyFrac":
        m, f = record["mesh"], record["first_mesh"]
        return (f"{case} PyFrac {record['threads']}: mesh {f['nx']}x{f['ny']} cells of {f['hx']:.4g} x {f['hy']:.4g} m "
                f"-> {m['nx']}x{m['ny']} of {m['hx']:.4g} x {m['hy']:.4g} m on x {m['x'][0]:.4g}..{m['x'][1]:.4g}, "
                f"y {m['y'][0]:.4g}..{m['y'][1]:.4g} m; {record['remeshings']} remeshings, "
                f"{record['failed_steps']} failed steps, {record['saved']} saved fractures")
    m = record["mesh"]
    return (f"{case} hfgpu {record['scene']} {record['threads']}: final cells {m['dx']:.4g} x {m['dz']:.4g} m, "
            f"{record['newton_iterations']} Newton iterations")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pyfrac", type=Path, help="PyFrac checkout (src/, examples/); without it, PyFrac's "
                        "rows only from --pyfrac-results")
    parser.add_argument("--pyfrac-python", default=sys.executable,
                        help="interpreter with numpy < 1.24, scipy, matplotlib, dill for PyFrac")
    parser.add_argument("--pyfrac-results", type=Path, help="folder of PyFrac's results, read and written")
    parser.add_argument("--rerun-pyfrac", action="store_true", help="run PyFrac even where results are saved")
    parser.add_argument("--cases", default="radial,height,pulse,arrest", help="any of radial,height,pulse,arrest")
    parser.add_argument("--threads", default="default,one", help="any of default,one")
    parser.add_argument("--no-hfgpu", action="store_true", help="PyFrac's rows only")
    parser.add_argument("--pyfrac-no-run", action="store_true",
                        help="never run PyFrac: only read its saved or finished runs in --pyfrac-results")
    parser.add_argument("--hfgpu-worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.hfgpu_worker:
        hfgpu_worker(args.hfgpu_worker)
        return
    cases = args.cases.split(",")
    threads_list = args.threads.split(",")
    for name in cases:
        if name not in CASES:
            parser.error(f"--cases: got {name!r}; allowed: {', '.join(CASES)}")
    for threads in threads_list:
        thread_env(threads)
    results = args.pyfrac_results or (Path(tempfile.mkdtemp(prefix="bench_pyfrac_")) if args.pyfrac else None)
    if results is not None:
        results.mkdir(parents=True, exist_ok=True)
    logs = results if results is not None else Path(tempfile.mkdtemp(prefix="bench_pyfrac_"))
    rows, notes = [], []
    for case in cases:
        pairs = []
        for threads in threads_list:
            ours = [] if args.no_hfgpu else [run_hfgpu(case, scene, threads, logs) for scene in CASES[case].scenes]
            theirs = (run_pyfrac(case, threads, args.pyfrac, args.pyfrac_python, results, args.rerun_pyfrac,
                                 not args.pyfrac_no_run) if results is not None else None)
            pairs.append((ours, theirs))
            for record in [*ours, theirs]:
                if record is not None:
                    print(row(case, record, None), file=sys.stderr, flush=True)
        t_from = common_from(case, [r for ours, theirs in pairs for r in [*ours, theirs] if r is not None])
        for ours, theirs in pairs:
            for record in [*ours, theirs]:
                if record is not None:
                    rows.append(row(case, record, ours[0]["wall_s"] if ours else None, t_from))
                    notes.append(mesh_note(case, record))
    print(HEADER)
    print("\n".join(rows))
    print("size: R_A = sqrt(area / pi) (radial, against the M vertex; pulse, against the viscous pulse), its largest "
          "so far (Rmax: arrest, against the leak-off arrest radius) or the half-length (height, against PKN, "
          "h = 6 m); max err: the largest |error| at t >= 'from s' (radial: 10x the latest first time of the runs "
          "shown; pulse: 100x the shut-in; PyFrac's series holds its saved steps, every 5th (radial) or every step). "
          "cells: the final footprint's cells. w0: no closed form for the pulses (nan).")
    print("\n".join(notes))


if __name__ == "__main__":
    main()
