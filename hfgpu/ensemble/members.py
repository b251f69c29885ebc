"""The member scenes of a sweep: the base scene with each member's inputs put in, as TOML text, all validated.

A member's scene text is the base scene's TOML written back (comments dropped, values as parsed) with the
varied keys set to the member's values in SI: with the key's SI unit when the sweep gave units ("6.5e7 Pa"),
else as plain numbers (SI in a scene); under a comment naming the member and its inputs. It is what the
member's results file stores under ``/scene``.
"""

from __future__ import annotations

import datetime
import json
import math
import re
from dataclasses import dataclass
from typing import Any

from ..errors import HfgpuError
from .design import member_inputs
from .sweep_file import Sweep, with_value

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+$")


class MemberError(HfgpuError, ValueError):
    """A member scene of a sweep is not valid: the member, its inputs and the scene's own message."""


@dataclass(frozen=True)
class Member:
    """One member: ``id`` (zero-padded index, the name of its results file), inputs {key: SI value}, scene text."""

    id: str
    inputs: dict[str, float | int | str]
    scene_text: str


def member_ids(count: int) -> list[str]:
    """Zero-padded indices, at least four digits: "0000", "0001", ..."""
    width = max(4, len(str(count - 1)))
    return [f"{i:0{width}d}" for i in range(count)]


def members(sweep: Sweep) -> list[Member]:
    """Every member of the sweep, each scene parsed and checked as ``hfgpu run`` would before any work
    (:class:`MemberError` names the first bad one)."""
    from ..limits import check_limits
    from ..runner import check_supported
    from ..scene import load_scene

    out = []
    for mid, inputs in zip(member_ids(sweep.members), member_inputs(sweep)):
        data = sweep.scene_data
        for vary in sweep.vary:
            value = inputs[vary.key]
            data = with_value(data, vary.steps, f"{value!r} {vary.unit}" if vary.unit else value)
        said = ", ".join(f"{k} = {v!r}" for k, v in inputs.items())
        text = f"# hfgpu sweep member {mid}: {said}\n"
        text += toml_text(data)
        try:
            check_limits(scene := load_scene(text))
            check_supported(scene)
        except HfgpuError as exc:  # SceneError, NotSupportedError
            raise MemberError(f"sweep member {mid} ({said}): {exc}") from None
        out.append(Member(id=mid, inputs=inputs, scene_text=text))
    return out


def toml_text(data: dict[str, Any]) -> str:
    """TOML text of a parsed TOML document (``tomllib.loads(toml_text(d)) == d``)."""
    lines: list[str] = []
    _table(lines, (), data, header=False)
    return "\n".join(lines).lstrip("\n") + "\n"


def _table(lines: list[str], prefix: tuple[str, ...], table: dict[str, Any], header: bool,
           array: bool = False) -> None:
    if header:
        name = ".".join(_key(k) for k in prefix)
        lines.extend(["", f"[[{name}]]" if array else f"[{name}]"])
    nested = []
    for key, value in table.items():
        if isinstance(value, dict) or (isinstance(value, list) and value and all(isinstance(v, dict) for v in value)):
            nested.append((key, value))
        else:
            lines.append(f"{_key(key)} = {_value(value)}")
    for key, value in nested:
        if isinstance(value, dict):
            _table(lines, prefix + (key,), value, header=True)
        else:
            for item in value:
                _table(lines, prefix + (key,), item, header=True, array=True)


def _key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key, ensure_ascii=False)


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return ("-inf" if value < 0 else "inf") if math.isinf(value) else "nan" if value != value else repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (datetime.date, datetime.time)):
        return value.isoformat()
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return "{ " + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + " }"
