"""``hfgpu check`` and ``hfgpu run`` read a scene once: one TOML parse, one validation, one set of physics checks
(the fracture engine's start checks among them) and one estimate per command, in both coupling modes (issue 35,
item 4): the engines take typed setups and check nothing again."""

from __future__ import annotations

import collections
import tomllib
from pathlib import Path

import pytest

import hfgpu.estimate
import hfgpu.fracture.simulator
import hfgpu.limits
import hfgpu.runner
import hfgpu.scene
import hfgpu.scene_checks
from hfgpu.cli import main

TINY = Path(__file__).resolve().parent / "scenes" / "tiny_coupled.toml"
#: (module, function) of each step counted; a module that imported the function by name counts there too.
COUNTED = ((tomllib, "loads"), (hfgpu.scene, "parse_scene"), (hfgpu.scene_checks, "validate"),
           (hfgpu.runner, "validate"), (hfgpu.limits, "check_limits"), (hfgpu.limits, "check_engine_start"),
           (hfgpu.estimate, "estimate"), (hfgpu.scene_checks, "estimate"), (hfgpu.fracture.simulator, "check_scene"))


@pytest.fixture
def calls(monkeypatch) -> collections.Counter:
    """Calls of each counted function, by name."""
    counter: collections.Counter = collections.Counter()
    for module, name in COUNTED:
        function = getattr(module, name)

        def counted(*args, _function=function, _name=name, **kwargs):
            counter[_name] += 1
            return _function(*args, **kwargs)

        monkeypatch.setattr(module, name, counted)
    return counter


ONCE = {"loads": 1, "parse_scene": 1, "validate": 1, "check_limits": 1, "check_engine_start": 1, "estimate": 1,
        "check_scene": 1}


def test_check_reads_and_checks_the_scene_once(calls, capsys):
    assert main(["check", str(TINY)]) == 0
    assert "expected" in capsys.readouterr().out
    assert dict(calls) == ONCE


@pytest.mark.parametrize("mode", ["one-way", "two-way"])
def test_run_reads_and_checks_the_scene_once(calls, tmp_path, mode):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY.read_text().replace('fracture_every = "5 s"', f'fracture_every = "5 s"\nmode = "{mode}"'))
    calls.clear()
    assert main(["run", str(path), "--out", str(tmp_path / "r.h5"), "--no-progress"]) == 0
    assert dict(calls) == ONCE

