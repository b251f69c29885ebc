"""docs/tutorial.md works as written: its code blocks run in order in an empty folder (``toml`` blocks whose
first line is ``# file: NAME`` are saved as NAME, each line of a ``bash`` block is run), every figure it
names is written, and the ``text`` block is what ``hfgpu falloff`` prints."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TUTORIAL = ROOT / "docs" / "tutorial.md"
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.S | re.M)


def blocks(text: str) -> list[tuple[str, str]]:
    """(language, body) of each fenced code block, in order."""
    return [(m.group(1), m.group(2)) for m in BLOCK.finditer(text)]


def _command(line: str) -> list[str]:
    """A command line of the tutorial as argv, ``hfgpu`` run by this interpreter's console script."""
    argv = shlex.split(line, comments=True)
    script = Path(sys.executable).with_name("hfgpu")
    if argv and argv[0] == "hfgpu":
        argv = ([str(script)] if script.exists() else [sys.executable, "-m", "hfgpu.cli"]) + argv[1:]
    return argv


def test_tutorial_blocks_are_files_and_commands():
    found = blocks(TUTORIAL.read_text())
    assert {language for language, _ in found} == {"toml", "bash", "text"}   # text: what a command prints
    assert all(body.startswith("# file: ") for language, body in found if language == "toml")
    assert sum(language == "bash" for language, _ in found) >= 4


def test_tutorial_runs(tmp_path):
    text = TUTORIAL.read_text()
    env = dict(os.environ, OMP_NUM_THREADS="1")
    ran = []
    for language, body in blocks(text):
        if language == "toml":
            name = body.splitlines()[0].removeprefix("# file: ").strip()
            (tmp_path / name).write_text(body)
            continue
        if language != "bash":
            continue
        for line in body.splitlines():
            argv = _command(line)
            if not argv:
                continue
            done = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True, env=env, timeout=300)
            assert done.returncode == 0, f"{line}\n{done.stdout}\n{done.stderr}"
            assert "Traceback" not in done.stderr, done.stderr
            ran.append((line, done))
    assert len(ran) >= 7
    runs = [done for line, done in ran if "slurry.h5" in line and line.startswith("hfgpu run")]
    assert "proppant" in runs[-1].stderr and "fracture" in runs[-1].stderr  # one bar per phase
    written = {p.name for p in tmp_path.rglob("*.png")}
    named = set(re.findall(r"`(\w+\.png)`", text))
    assert named and named <= written, named - written
    assert (tmp_path / "slurry.csv").is_file() and (tmp_path / "slurry.xml").is_file()
    falloff = next(done for line, done in ran if line.startswith("hfgpu falloff"))
    shown = next(body for language, body in blocks(text) if language == "text")
    assert falloff.stdout.strip() == shown.strip()   # the tutorial shows what the command prints
