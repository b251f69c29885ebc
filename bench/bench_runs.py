"""Whole runs end to end, process start included: the Chun slot (30 s), the Davis column (600 s), the scaled
field demo and a 16 000-parcel, 1 000 s settling column, each as ``hfgpu run SCENE`` in a fresh process.

    python bench/bench_runs.py [--cases slot davis demo column] [--checkout PATH] [--threads 2]

``--checkout PATH`` runs another checkout of hfgpu instead (its ``hfgpu`` package and ``kernels`` folder
arranged under a folder on PYTHONPATH, e.g. an older commit for a comparison in one sitting; the scene files
are this checkout's). ``--threads``: Taichi CPU threads (HFGPU_THREADS). Prints the wall seconds, the
parcels at the end and the proppant steps per case; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py

ROOT = Path(__file__).resolve().parents[1]
CASES = {"slot": ROOT / "hfgpu/scenes/chun2020_slot.toml", "davis": ROOT / "hfgpu/scenes/davis1982.toml",
         "demo": ROOT / "hfgpu/scenes/five_layer_demo.toml", "column": ROOT / "bench/scenes/settling_column.toml"}


def run_case(scene: Path, checkout: str | None, threads: int | None) -> tuple[float, dict]:
    """Wall seconds of ``hfgpu run`` on ``scene`` in a fresh process, and the results' summary."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    if checkout:
        env["PYTHONPATH"] = checkout
    if threads:
        env["HFGPU_THREADS"] = str(threads)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run.h5"
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import sys; from hfgpu.cli import main; sys.exit(main())", "run",
                        str(scene), "--out", str(out), "--no-progress"], env=env, check=True, capture_output=True)
        wall = time.perf_counter() - t
        with h5py.File(out) as f:
            summary = dict(f["summary"].attrs)
    return wall, summary


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--checkout", default=None)
    ap.add_argument("--threads", type=int, default=None)
    args = ap.parse_args()
    print(f"hfgpu from {args.checkout or ROOT}")
    print(f"{'case':<6} | {'wall s':>8} | {'parcels':>8} | {'steps':>6}")
    for name in args.cases:
        wall, summary = run_case(CASES[name], args.checkout, args.threads)
        parcels = summary.get("parcels", summary.get("proppant_parcels", "-"))
        steps = summary.get("proppant_steps", summary.get("steps", "-"))
        print(f"{name:<6} | {wall:8.1f} | {parcels!s:>8} | {steps!s:>6}", flush=True)


if __name__ == "__main__":
    main()
