"""Bad scenes through the command line (property-based): the real scenes of hfgpu/scenes, broken by dropping keys,
wrong types, bad units, negative / zero / NaN / infinite / huge values, unknown keys, bad physics sets, a bad
preset or malformed TOML text, given to ``hfgpu check`` and ``hfgpu run`` in-process. Each answer is exit code 2
and one short line on stderr that names the broken key; never a traceback, and ``run`` stops before any work.

(tests/test_scene.py fuzzes ``parse_scene`` on one scene's values; this file fuzzes the whole path from the
file on disk to the exit code, on every stored scene.)
"""

from __future__ import annotations

import copy
import json
import math
import re
import tempfile
import tomllib
from importlib.resources import files
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hfgpu.runner
from hfgpu.cli import main
from hfgpu.presets import PRESETS

SCENES = {p.name: p.read_text() for p in (files("hfgpu") / "scenes").iterdir() if p.name.endswith(".toml")}
DATA = {name: tomllib.loads(text) for name, text in SCENES.items()}
NAMES = sorted(SCENES)
MAX_MESSAGE = 400  # characters of the one error line
UNKNOWN = "zz_unknown_key"
# a number followed by a unit: the values that take units (not names, kinds or sieve labels like "40/70")
WITH_UNIT = re.compile(r"^\s*[-+]?[\d.]+(e[-+]?\d+)?\s+[A-Za-z]")


def toml(value, top: bool = False) -> str:
    """TOML text of a parsed document (inline tables and arrays; NaN and infinities as TOML writes them)."""
    if top:
        return "".join(f"{json.dumps(k)} = {toml(v)}\n" for k, v in value.items())
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, list):
        return "[" + ", ".join(map(toml, value)) + "]"
    return "{" + ", ".join(f"{json.dumps(k)} = {toml(v)}" for k, v in value.items()) + "}"


def walk(data, path=()):
    """(path, value) of every table (dict) and leaf below ``data``; arrays of tables are entered."""
    if isinstance(data, dict):
        yield path, data
        for key, value in data.items():
            yield from walk(value, path + (key,))
    elif isinstance(data, list) and data and all(isinstance(v, dict) for v in data):
        for i, value in enumerate(data):
            yield from walk(value, path + (i,))
    else:
        yield path, data


def key_path(path) -> str:
    """The key path as SceneError writes it: ``injection.schedule[0].rate``."""
    return "".join(f"[{p}]" if isinstance(p, int) else (f".{p}" if i else p) for i, p in enumerate(path))


def parent(data, path):
    for key in path[:-1]:
        data = data[key]
    return data


LEAVES = {n: [p for p, v in walk(d) if p and not isinstance(v, dict)] for n, d in DATA.items()}
TABLES = {n: [p for p, v in walk(d) if isinstance(v, dict)] for n, d in DATA.items()}
UNIT_LEAVES = {n: [p for p in LEAVES[n] if isinstance(v := parent(DATA[n], p)[p[-1]], str) and WITH_UNIT.match(v)
                   and p[-1] != "name"] for n in NAMES}
BROKEN_LINES = ["key = ", "[run", "= 3", 'a = "unterminated', "[[", "x = 1 2", "]]"]
BAD_PHYSICS = [[], ["magma"], ["fracture", "fracture"], "proppant ", [1], {"fracture": True}, "", [["fracture"]]]
NONFINITE = [math.nan, math.inf, -math.inf]


@st.composite
def invalid_scenes(draw):
    """(TOML text, key path the error must name): one change that makes a stored scene invalid."""
    name = draw(st.sampled_from(NAMES))
    data = copy.deepcopy(DATA[name])
    kind = draw(st.sampled_from(["nonfinite", "table", "unit", "unknown", "preset", "physics", "toml"]))
    if kind == "toml":
        lines = SCENES[name].splitlines()
        at = draw(st.integers(0, len(lines)))
        return "\n".join(lines[:at] + [draw(st.sampled_from(BROKEN_LINES))] + lines[at:]), "(file)"
    if kind == "unknown":
        path = draw(st.sampled_from(TABLES[name]))
        parent(data, path + (UNKNOWN,))[UNKNOWN] = draw(st.one_of(st.integers(), st.text(max_size=8)))
        return toml(data, top=True), key_path(path + (UNKNOWN,))
    if kind == "preset":
        data["run"]["preset"] = draw(st.one_of(st.text(max_size=10).filter(lambda s: s not in PRESETS),
                                               st.integers(), st.sampled_from(NONFINITE), st.lists(st.booleans())))
        return toml(data, top=True), "run.preset"
    if kind == "physics":
        data["run"]["physics"] = draw(st.sampled_from(BAD_PHYSICS))
        return toml(data, top=True), "run.physics"
    path = draw(st.sampled_from(UNIT_LEAVES[name] if kind == "unit" else LEAVES[name]))
    value = {"nonfinite": st.sampled_from(NONFINITE),
             "table": st.dictionaries(st.sampled_from("abc"), st.integers(), min_size=1, max_size=2),
             "unit": st.sampled_from(["3 qwerty", "3 kg*s", "2 m/s**3", "1 s**0.7", "--", "3 m m", "0\r\n3 m"])}[kind]
    parent(data, path)[path[-1]] = draw(value)
    return toml(data, top=True), key_path(path)


ANY_VALUE = st.one_of(st.sampled_from([0, -1, 0.0, -1e-9, 1e300, -1e300, 10**18, True, False, "", "0 m", "-3 s",
                                       "1e308 Pa", "5e-324 m", "0\r", "2\nm"]),
                      st.floats(), st.integers(-10**6, 10**6), st.text(max_size=10),
                      st.lists(st.integers(0, 3), max_size=3))


@st.composite
def suspect_scenes(draw):
    """Up to three drops or changes of any kind (the scene may stay valid): TOML text."""
    name = draw(st.sampled_from(NAMES))
    data = copy.deepcopy(DATA[name])
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from([p for p, _ in walk(data) if p]))
        holder = parent(data, path)
        if draw(st.booleans()):
            del holder[path[-1]]
        else:
            holder[path[-1]] = draw(ANY_VALUE)
    return toml(data, top=True)


def one_error_line(capsys, command: str) -> str:
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    assert out == "", out
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"hfgpu {command}: error: "), err
    assert len(lines[0]) <= MAX_MESSAGE, lines[0]
    return lines[0]


def error_lines(capsys, command: str) -> list[str]:
    """The error lines of a scene with one or more errors: nothing on stdout, each line short and one error."""
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err and out == "", out + err
    lines = err.strip().splitlines()
    assert lines and all(line.startswith(f"hfgpu {command}: error: ") and len(line) <= MAX_MESSAGE
                         for line in lines), err
    assert len(set(lines)) == len(lines), err   # one mistake is reported once
    return lines


def no_work(*args, **kwargs):
    raise AssertionError("hfgpu run went past validation of an invalid scene")


def test_serialiser_round_trips_every_stored_scene():
    for name, data in DATA.items():
        assert tomllib.loads(toml(data, top=True)) == data, name


FUZZ = settings(deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


@settings(FUZZ, max_examples=120)
@given(invalid_scenes())
def test_invalid_scene_check_and_run_one_line_naming_the_key(capsys, monkeypatch, case):
    text, path = case
    monkeypatch.setattr(hfgpu.runner, "simulator_for", no_work)
    capsys.readouterr()
    with tempfile.TemporaryDirectory() as folder:
        scene, out = Path(folder) / "scene.toml", Path(folder) / "r.h5"
        scene.write_text(text, encoding="utf-8")
        for command, extra in (("check", []), ("run", ["--out", str(out), "--no-progress"])):
            assert main([command, str(scene), *extra]) == 2
            line = one_error_line(capsys, command)
            assert f"scene key '{path}'" in line, (path, line)
        assert not out.exists()


@settings(FUZZ, max_examples=80)
@given(suspect_scenes())
def test_any_broken_scene_check_ok_or_one_line(capsys, text):
    capsys.readouterr()
    with tempfile.TemporaryDirectory() as folder:
        scene = Path(folder) / "scene.toml"
        scene.write_text(text, encoding="utf-8")
        code = main(["check", str(scene)])
    if code == 0:
        out, err = capsys.readouterr()
        assert "ok; physics" in out and "Traceback" not in out + err
    else:  # every error of the scene, one line each (several changes may make several errors)
        assert code == 2
        for line in error_lines(capsys, "check"):
            assert re.search(r"error: (scene key '[^']+'|run\.physics)", line), line


@pytest.mark.parametrize("args", [["check", "/no/such/scene.toml"], ["run", "/no/such/scene.toml", "--out", "x.h5"]])
def test_missing_scene_file(capsys, args):
    assert main(args) == 2
    assert "cannot read the scene file" in one_error_line(capsys, args[0])
