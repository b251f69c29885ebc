"""The member scenes of a sweep: the base scene with each member's inputs put in, as TOML text, all validated.

A member's scene text is the base scene's TOML written back (comments dropped, values as parsed) with the
varied keys set to the member's values in SI (a [[vary]] with ``keys`` puts its one value into each of them):
with the key's SI unit when the sweep gave units ("6.5e7 Pa"), else as plain numbers (SI in a scene); under a
comment naming the member and its inputs. It is what the member's results file stores under ``/scene``.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import HfgpuError
from ..scene_text import toml_text, with_value
from .design import member_inputs
from .sweep_file import Sweep


class MemberError(HfgpuError, ValueError):
    """A member scene of a sweep is not valid: the member, its inputs and the scene's own message."""


@dataclass(frozen=True)
class Member:
    """One member: ``id`` (zero-padded index, the name of its results file), inputs {column: SI value} (a [[vary]]'s
    column: its key, or its name), scene text."""

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
    from ..simulators import check_supported
    from ..scene import load_scene

    out = []
    for mid, inputs in zip(member_ids(sweep.members), member_inputs(sweep)):
        data = sweep.scene_data
        for vary in sweep.vary:
            value = inputs[vary.key]
            for _, steps in vary.targets:
                data = with_value(data, steps, f"{value!r} {vary.unit}" if vary.unit else value)
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
