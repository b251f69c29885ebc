"""The sweep file: its keys, read and checked into a :class:`Sweep` (docs/ensembles.md).

A sweep file is TOML: ``scene`` (the base scene, relative to the sweep file), ``members`` (sampled designs),
``design`` ("latin-hypercube", "grid" or "random"), ``seed``, one ``[[vary]]`` table per varied scene key and an
optional ``[metrics] names``. These key names are a contract for outside tools: extend them, never rename them.

Each ``[[vary]]`` has ``key`` (a scene key path, ``rock.leakoff_coefficient``, ``rock.layers[0].min_stress``), or
``keys`` (several key paths that take the same kind of value, each set to the member's one value) with an optional
``name`` (the summary's column; default the keys joined by "+"), and
either ``values = [...]`` or ``distribution`` with its parameters: ``uniform`` and ``log-uniform`` (``low``,
``high``), ``normal`` (``mean``, ``std``), ``triangular`` (``low``, ``mode``, ``high``). Each value is a plain
number (SI) or a string with units, as in a scene; it is checked against the key's kind by putting it into the
base scene (into each of ``keys``) and parsing that, so a wrong unit gets the scene's own message, under the sweep's
key path (``vary[0].low``). Numbers are then held in SI (pint's base units, which are SI for every scene kind) and
written into member scenes with the SI unit of the key's kind ("65000000.0 Pa") when they were given with
units, as plain numbers otherwise. A key that takes text (``proppant[0].size = "40/70"``) can vary over
``values`` of text, kept as written. Each [[vary]] knows the kind of its values (:data:`hfgpu.units.SI_UNITS`):
that of the first value given with units, else the kind its keys take (found by parsing; "dimensionless" for a
plain ratio or count), "" for text.

Errors are :class:`SweepError`: one line naming the sweep key, the value found and what is allowed.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import MISSING, SceneError
from ..scene import parse_scene
from ..scene_reader import Table
from ..scene_text import split_key, with_value
from ..units import SI_UNITS, registry

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

DESIGNS = ("latin-hypercube", "grid", "random")
#: The parameters each distribution needs, in the order its transform takes them (hfgpu.ensemble.design).
DISTRIBUTIONS = {"uniform": ("low", "high"), "log-uniform": ("low", "high"), "normal": ("mean", "std"),
                 "triangular": ("low", "mode", "high")}
#: Metrics a sweep can ask for (hfgpu.ensemble.metrics says how each is computed); the default set is all.
METRIC_NAMES = ("propped_area", "propped_area_in_place", "created_area", "propped_fraction", "fracture_height",
                "fracture_length", "net_pressure_end", "efficiency", "screened_out", "cluster_area_uniformity",
                "cluster_propped_uniformity")


class SweepError(SceneError):
    """A sweep file value is missing, malformed or out of range: like a :class:`SceneError`, but the message
    says ``sweep key 'vary[0].low': got ...; allowed ...``."""

    def __str__(self) -> str:
        return "sweep" + super().__str__()[len("scene"):]


Steps = tuple[tuple[str, int | None], ...]   # a key path split: ("rock", None), ("layers", 0), ...


@dataclass(frozen=True)
class Vary:
    """One ``[[vary]]``: its summary column ``key`` (the key path; for ``keys``, ``name``), the scene keys it sets
    to the member's one value (``targets``: (key path, steps) each), ``values`` (SI numbers; integers and text as
    written) or a ``distribution`` with its ``params`` in SI (the order of DISTRIBUTIONS)."""

    key: str
    targets: tuple[tuple[str, Steps], ...]
    unit: str = ""                               # the SI unit member values are written with ("" : bare)
    kind: str = ""                               # the kind of the values (hfgpu.units.SI_UNITS); "" for text
    distribution: str | None = None
    params: tuple[float, ...] = ()
    values: tuple[float | int | str, ...] = ()


@dataclass(frozen=True)
class Sweep:
    """A checked sweep file: the base scene's parsed TOML, the design and what varies."""

    path: Path
    source: str                      # the sweep file's text
    scene_path: Path
    scene_data: dict[str, Any]       # the base scene's TOML, parsed (never modified)
    design: str
    members: int                     # for a grid: the number of combinations
    seed: int
    vary: tuple[Vary, ...]
    metrics: tuple[str, ...]


def load_sweep(path: str | Path) -> Sweep:
    """Read and check a sweep file; raises :class:`SweepError` (a :class:`SceneError`) naming the key."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SweepError("(file)", str(path), f"cannot read the sweep file: {exc.strerror}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SweepError("(file)", str(path)[:80], f"not valid TOML: {exc}") from None
    return parse_sweep(data, path, text)


def parse_sweep(data: dict, path: Path, source: str = "") -> Sweep:
    """Check a parsed sweep file found at ``path`` (the base scene is relative to its folder)."""
    try:
        return _parse(Table(data, ""), path, source)
    except SweepError:
        raise
    except SceneError as exc:  # the reader's own messages, said of the sweep file
        raise SweepError(exc.path, exc.value, exc.allowed) from None


def _parse(top: Table, path: Path, source: str) -> Sweep:
    scene_path = path.parent / top.string("scene")
    try:
        scene_text = scene_path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SweepError("scene", top.data["scene"], f"cannot read the scene file {scene_path}: "
                         f"{exc.strerror}") from None
    try:
        scene_data = tomllib.loads(scene_text)
    except tomllib.TOMLDecodeError as exc:
        raise SweepError("scene", top.data["scene"], f"the scene is not valid TOML: {exc}") from None
    try:
        parse_scene(copy.deepcopy(scene_data), scene_text)
    except SceneError as exc:
        raise SweepError("scene", top.data["scene"], f"the base scene is not valid: {exc}") from None
    design = top.choice("design", DESIGNS, "latin-hypercube")
    seed = top.integer("seed", 0, minimum=0)
    vary = tuple(_parse_vary(t, scene_data) for t in top.tables("vary"))
    if not vary:
        raise SweepError("vary", top.data.get("vary", MISSING), "at least one [[vary]] table is required")
    _check_once(vary)
    if design == "grid":
        for i, v in enumerate(vary):
            if not v.values:
                raise SweepError(f"vary[{i}].distribution", v.distribution, 'a "grid" design needs values = [...]')
        if top.has("members"):
            raise SweepError("members", top.raw("members"), 'allowed only for sampled designs; a "grid" has one '
                             "member per combination of the values")
        members = math.prod(len(v.values) for v in vary)
    else:
        members = top.integer("members", minimum=1)
    metrics_table = top.table("metrics", {})
    names = metrics_table.raw("names", list(METRIC_NAMES))
    if not isinstance(names, list) or not names:
        raise SweepError("metrics.names", names, "expected a non-empty list of metric names")
    for i, name in enumerate(names):
        if name not in METRIC_NAMES:
            raise SweepError(f"metrics.names[{i}]", name, f"allowed: {', '.join(map(repr, METRIC_NAMES))}")
    metrics_table.finish()
    top.finish()
    return Sweep(path=path, source=source, scene_path=scene_path, scene_data=scene_data, design=design,
                 members=members, seed=seed, vary=vary, metrics=tuple(dict.fromkeys(names)))


def _check_once(vary: tuple[Vary, ...]) -> None:
    """Each scene key varied by one [[vary]] only, and each summary column named once."""
    seen: dict[str, int] = {}
    for i, v in enumerate(vary):
        for j, (key, _) in enumerate(v.targets):
            where = f"vary[{i}].key" if len(v.targets) == 1 and v.key == key else f"vary[{i}].keys[{j}]"
            if key in seen:
                raise SweepError(where, key, f"each key may be varied once (also vary[{seen[key]}])")
            seen[key] = i
    names = [v.key for v in vary]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise SweepError(f"vary[{i}].name", name, f"each column name once (also vary[{names.index(name)}])")


def _parse_vary(t: Table, scene_data: dict) -> Vary:
    column, targets = _targets(t, scene_data)
    if t.has("values"):
        if t.has("distribution"):
            raise SweepError(t.key_path("distribution"), t.raw("distribution"), "give either values or a "
                             "distribution, not both")
        raw = t.raw("values")
        if not isinstance(raw, list) or not raw:
            raise SweepError(t.key_path("values"), raw, "expected a non-empty list of values")
        values = tuple(_value(t, f"values[{i}]", item, targets, scene_data) for i, item in enumerate(raw))
        t.finish()
        kind, unit = _kind(t, raw, values, targets, scene_data)
        return Vary(key=column, targets=targets, unit=unit, kind=kind, values=values)
    distribution = t.choice("distribution", tuple(DISTRIBUTIONS))
    names = DISTRIBUTIONS[distribution]
    params = []
    for name in names:
        raw = t.raw(name)
        if name == "std":
            params.append(_std(t, raw, t.raw("mean")))
        else:
            params.append(_value(t, name, raw, targets, scene_data))
            if isinstance(params[-1], str):
                raise SweepError(t.key_path(name), raw, "a distribution needs numbers; list text values as "
                                 "values = [...]")
    t.finish()
    _check_params(t, distribution, dict(zip(names, params)))
    kind, unit = _kind(t, [t.data[n] for n in names], params, targets, scene_data)
    return Vary(key=column, targets=targets, unit=unit, kind=kind, distribution=distribution,
                params=tuple(float(p) for p in params))


def _targets(t: Table, scene_data: dict) -> tuple[str, tuple[tuple[str, Steps], ...]]:
    """(summary column, ((key path, steps), ...)) of a [[vary]]: its ``key``, or its ``keys`` and ``name``."""
    if not t.has("keys"):
        key = t.string("key")
        return key, ((key, split_key(key, t.key_path("key"), scene_data, SweepError, "base scene")),)
    keys = t.raw("keys")
    if t.has("key"):
        raise SweepError(t.key_path("key"), t.raw("key"), "give either key or keys, not both")
    if not isinstance(keys, list) or not keys or not all(isinstance(k, str) for k in keys):
        raise SweepError(t.key_path("keys"), keys, 'expected a non-empty list of scene key paths, e.g. '
                         '["injection.schedule[0].rate", "injection.schedule[1].rate"]')
    for i, key in enumerate(keys):
        if key in keys[:i]:
            raise SweepError(t.key_path(f"keys[{i}]"), key, f"listed twice (also keys[{keys.index(key)}])")
    targets = tuple((key, split_key(key, t.key_path(f"keys[{i}]"), scene_data, SweepError, "base scene"))
                    for i, key in enumerate(keys))
    return t.string("name", "+".join(keys)), targets


def _check_params(t: Table, distribution: str, p: dict[str, float]) -> None:
    if distribution in ("uniform", "log-uniform", "triangular") and not p["low"] < p["high"]:
        raise SweepError(t.key_path("high"), t.data["high"], f"allowed: > low ({p['low']:g} in SI)")
    if distribution == "log-uniform" and p["low"] <= 0.0:
        raise SweepError(t.key_path("low"), t.data["low"], "allowed: > 0 (a log-uniform range is positive)")
    if distribution == "triangular" and not p["low"] <= p["mode"] <= p["high"]:
        raise SweepError(t.key_path("mode"), t.data["mode"], f"allowed: between low and high "
                         f"({p['low']:g} and {p['high']:g} in SI)")


def si_number(raw: Any) -> float:
    """A plain number as it is (SI), a string with units in pint's base units (SI)."""
    if isinstance(raw, (int, float)) and not isinstance(raw, bool):
        return float(raw)
    return float(registry().Quantity(raw.strip()).to_base_units().magnitude)


def _value(t: Table, name: str, raw: Any, targets, scene_data: dict) -> float | int | str:
    """``raw`` checked as a value of each target key (parsed in the base scene) and returned in SI; text that the
    keys take as text (a sieve class, "40/70") is returned as it is."""
    where = t.key_path(name)
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise SweepError(where, raw, "expected a number (SI) or a string with units, e.g. \"65 MPa\"")
    for i, (key, steps) in enumerate(targets):
        key_where = t.key_path("key" if t.has("key") else f"keys[{i}]")
        _check_value(where, raw, key, steps, scene_data, key_where, len(targets) > 1)
    if not isinstance(raw, str):
        return raw if type(raw) is int else float(raw)
    try:
        number, unit = si_number(raw), SI_UNITS[_dimension_kind(raw)]
    except Exception:  # not a quantity (pint raises several types): the text is the value
        return raw
    written = f"{number!r} {unit}" if unit else number   # as members.py writes it
    return number if _accepts(scene_data, tuple(steps for _, steps in targets), written) else raw


def _check_value(where: str, raw: Any, key: str, steps: Steps, scene_data: dict, key_where: str,
                 several: bool) -> None:
    """The scene's message for ``raw`` at the scene key ``key``, raised as a :class:`SweepError` at ``where`` (at
    ``key_where`` when the key itself is unknown); with ``several`` keys, the message names the key."""
    try:
        parse_scene(with_value(scene_data, steps, raw))
    except SceneError as exc:
        if exc.path == key and exc.allowed.startswith("unknown key"):  # the key itself is wrong, not the value
            raise SweepError(key_where, key, exc.allowed) from None
        why = exc.allowed if exc.path == key else str(exc)
        raise SweepError(where, raw, f"for key '{key}': {why}" if several else why) from None


def _kind(t: Table, raw: list[Any], values, targets, scene_data: dict) -> tuple[str, str]:
    """(kind, unit) of a [[vary]]'s values: the kind (hfgpu.units.SI_UNITS) of the first value given with units
    and its SI unit, the unit member values are written with; for plain numbers, the kind every key takes (a
    :class:`SweepError` when the keys differ) and "" (written bare); ("", "") for text."""
    for text, value in zip(raw, values):
        if isinstance(text, str) and not isinstance(value, str):
            kind = _dimension_kind(text)
            return kind, SI_UNITS[kind]
    numbers = [v for v in values if not isinstance(v, str)]
    if not numbers:
        return "", ""
    kinds = [_key_kind(steps, numbers[0], scene_data) for _, steps in targets]
    for (key, _), kind in zip(targets[1:], kinds[1:]):
        if kind != kinds[0]:
            raise SweepError(t.key_path("keys"), key, f"takes {_kind_text(kind)} where '{targets[0][0]}' takes "
                             f"{_kind_text(kinds[0])}: the keys of one [[vary]] get one value, so they must take the "
                             "same kind")
    return kinds[0], ""


def _kind_text(kind: str) -> str:
    """"a pressure (Pa)", "a plain number" for a dimensionless kind."""
    return f"a {kind.replace('_', ' ')} ({SI_UNITS[kind]})" if SI_UNITS[kind] else "a plain number"


def _dimension_kind(text: str) -> str:
    """The first kind of hfgpu.units.SI_UNITS whose unit has the dimension of the quantity ``text``."""
    ureg = registry()
    dimension = ureg.Quantity(text.strip()).dimensionality
    return next((kind for kind, unit in SI_UNITS.items() if ureg.Quantity(1.0, unit).dimensionality == dimension),
                "dimensionless")


def _key_kind(steps: Steps, number: float | int, scene_data: dict) -> str:
    """The kind a scene key takes: the first kind of hfgpu.units.SI_UNITS whose SI unit the base scene accepts
    after ``number`` at the key ("dimensionless" when none is)."""
    for kind, unit in SI_UNITS.items():
        if unit and _accepts(scene_data, (steps,), f"{number!r} {unit}"):
            return kind
    return "dimensionless"


def _accepts(scene_data: dict, paths: tuple[Steps, ...], value: Any) -> bool:
    """Whether the base scene with ``value`` at every key path of ``paths`` parses."""
    for steps in paths:
        scene_data = with_value(scene_data, steps, value)
    try:
        parse_scene(scene_data)
    except SceneError:
        return False
    return True


def _std(t: Table, raw: Any, mean: Any) -> float:
    """A standard deviation: positive, in the units of ``mean`` (pint dimension checked)."""
    where = t.key_path("std")
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise SweepError(where, raw, "expected a number (SI) or a string with units, e.g. \"1 MPa\"")
    try:
        number = si_number(raw)
        if isinstance(raw, str) and isinstance(mean, str):
            ureg = registry()
            if ureg.Quantity(raw.strip()).dimensionality != ureg.Quantity(mean.strip()).dimensionality:
                raise ValueError(f"'{raw}' is not of the dimension of mean '{mean}'")
    except Exception as exc:  # pint raises several unrelated types on bad text
        raise SweepError(where, raw, f"expected a quantity in the units of mean ({exc})") from None
    if not number > 0.0 or not math.isfinite(number):
        raise SweepError(where, raw, "allowed: > 0 and finite")
    return number
