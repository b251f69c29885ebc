"""Scene keys changed as TOML text, so that what a results file stores under ``/scene`` is what ran.

    edit_scene(scene, {"coupling.cell_size": "2.5 m", "proppant[0].size": "30/50"}) -> Scene
    edit_scene(scene, {"proppant[0].size": None, "proppant[0].diameter": "300 um"})   # None removes a key

A key is a dotted path with ``[i]`` for an entry of an array of tables (``rock.layers[0].min_stress``), as a
sweep's ``key``; it holds one value or an array of values (``run.physics``, ``mesh.cell_size``), never a table
or an array of tables. A value is what the scene file would hold there ("2.5 m", 0.2, true,
["fracture", "proppant"]); None removes the key, so that the scene's default applies (TOML has no null: None
inside an array is an error), and removing a key the scene does not hold is an error. The scene's TOML text (``Scene.source``) is parsed, the
keys set or removed in order, written back (:func:`toml_text`: comments dropped, values as parsed) and read
again with :func:`hfgpu.load_scene`, so errors name the key as for a scene file.
``Scene.replace`` changes parsed values only: the text it keeps no longer describes the scene
(:func:`hfgpu.runner.run` warns when it is asked to run such a scene).

Public API: ``edit_scene``, ``assignment``, ``toml_text``, ``split_key``, ``with_value``.
"""

from __future__ import annotations

import copy
import datetime
import json
import math
import re
from typing import Any

from .errors import MISSING, SceneError

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib  # type: ignore[no-redef]

_STEP = re.compile(r"([A-Za-z_][A-Za-z0-9_-]*)(?:\[(\d+)\])?$")
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+$")


def edit_scene(scene: Any, changes: dict[str, Any]) -> Any:
    """The scene with each key of ``changes`` set to its value, or removed where the value is None (module
    docstring); its ``source`` is the new text, headed by a comment listing the changes. A bad key, or the
    removal of a key the scene does not hold, raises :class:`SceneError` naming the key."""
    from .scene import load_scene

    data = tomllib.loads(scene.source)
    for key, value in changes.items():
        if value is not None and _holds_none(value):
            raise SceneError(key, value, "None inside a value: TOML has no null; None as the whole value "
                             "removes the key")
        steps = split_key(key, key, data, arrays=True)
        data = _without(data, steps, key) if value is None else with_value(data, steps, value)
    said = ", ".join(f"{k} removed" if v is None else f"{k} = {_value(v)}" for k, v in changes.items())
    return load_scene(f"# edited: {said}\n" + toml_text(data))


def assignment(text: str) -> tuple[str, Any]:
    """``KEY=VALUE`` (a command line's scene change) as (key, value): VALUE read as a TOML value (2, true,
    "2.5 m"), else taken as text (2.5 m)."""
    key, _, value = text.partition("=")
    try:
        return key.strip(), tomllib.loads(f"v = {value}")["v"]
    except tomllib.TOMLDecodeError:
        return key.strip(), value.strip()


def split_key(key: str, where: str, scene_data: dict, error: type[SceneError] = SceneError,
              scene_name: str = "scene", arrays: bool = False) -> tuple[tuple[str, int | None], ...]:
    """``rock.layers[0].min_stress`` as ((rock, None), (layers, 0), (min_stress, None)), checked against the
    scene: every table on the way must exist there (the last name may be new: a scene default), and the key
    must hold one value, or with ``arrays`` also an array of values (not a table or an array of tables). A bad
    key raises ``error(where, key, why)``, ``why`` calling the scene ``scene_name``."""
    steps = []
    node: Any = scene_data
    parts = key.split(".")
    for depth, part in enumerate(parts):
        match = _STEP.match(part)
        if match is None:
            raise error(where, key, "expected a scene key path such as 'rock.leakoff_coefficient' or "
                        "'rock.layers[0].min_stress'")
        name, index = match.group(1), match.group(2)
        steps.append((name, None if index is None else int(index)))
        last = depth == len(parts) - 1
        if not isinstance(node, dict) or (name not in node and not (last and index is None)):
            raise error(where, key, f"the {scene_name} has no '{'.'.join(parts[:depth + 1])}'")
        node = node.get(name)
        if index is not None:
            if not isinstance(node, list) or int(index) >= len(node):
                size = len(node) if isinstance(node, list) else 0
                raise error(where, key, f"index {index} is past the end of '{name}' in the {scene_name} "
                            f"({size} {'entry' if size == 1 else 'entries'}, the first is [0])")
            node = node[int(index)]
    kind = _kind(node)
    if kind and not (arrays and kind == "an array"):
        allowed = "one value or an array of values" if arrays else "one value"
        raise error(where, key, f"expected a key holding {allowed}, not {kind}")
    return tuple(steps)


def _holds_none(value: Any) -> bool:
    """Whether None is anywhere in a value (an entry of an array, a value of a table)."""
    if value is None:
        return True
    if isinstance(value, dict):
        return any(_holds_none(v) for v in value.values())
    if isinstance(value, (list, tuple)):
        return any(_holds_none(v) for v in value)
    return False


def _kind(node: Any) -> str:
    """What a parsed TOML value holding more than one value is: "a table", "an array of tables" (an array
    with a table in it), "an array"; "" for one value."""
    if isinstance(node, dict):
        return "a table"
    if isinstance(node, list):
        return "an array of tables" if any(isinstance(v, dict) for v in node) else "an array"
    return ""


def with_value(scene_data: dict, steps: tuple[tuple[str, int | None], ...], value: Any) -> dict:
    """A copy of the parsed scene with the value at the key path ``steps`` replaced (or added)."""
    data = copy.deepcopy(scene_data)
    node = _parent(data, steps)
    name, index = steps[-1]
    if index is None:
        node[name] = value
    else:
        node[name][index] = value
    return data


def _without(scene_data: dict, steps: tuple[tuple[str, int | None], ...], key: str) -> dict:
    """A copy of the parsed scene without the key at the path ``steps`` (an entry of an array, for a last step
    with an index); a SceneError naming ``key`` when the scene does not hold it."""
    data = copy.deepcopy(scene_data)
    node = _parent(data, steps)
    name, index = steps[-1]
    if name not in node:
        raise SceneError(key, MISSING, "the scene does not hold this key, so it cannot be removed")
    if index is None:
        del node[name]
    else:
        del node[name][index]
    return data


def _parent(data: dict, steps: tuple[tuple[str, int | None], ...]) -> dict:
    """The table of the parsed scene ``data`` that holds the last name of the key path ``steps``."""
    node = data
    for name, index in steps[:-1]:
        node = node[name] if index is None else node[name][index]
    return node


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
