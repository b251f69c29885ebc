"""Reading one TOML table of a scene with key paths in every error.

:class:`Table` wraps a parsed TOML table and hands out checked values; each physics folder parses its
own section with it, so the error format is the same everywhere. Keys a table does not know are an
error too (a typo must not be silently ignored), with the closest allowed key ("did you mean"); a required key
that is missing names a close unknown key of the same table as the likely typo.

Bare numbers: a plain number for a key that takes a unit is read as SI; unless it is 0 it adds a warning (one
line). In a scene whose unit system is field (``[output] units``, else the majority of its values,
:func:`hfgpu.units.majority_system`) such a number is an error instead, unless its kind is time (seconds in both
systems). Warnings are collected, the did-you-mean hints given and the scene's system known while
:func:`collecting_warnings` is active (as in :func:`hfgpu.scene.parse_scene`; other files read with :class:`Table`,
such as sweep files, keep the plain messages and the SI rule).
"""

from __future__ import annotations

import contextlib
import contextvars
import difflib
from typing import Any, Iterable, Iterator

from .errors import MISSING, SceneError
from .units import FIELD_UNITS, SI_UNITS, has_dimension_of, to_si

#: Characters of the allowed-key list an unknown-key error shows (:func:`key_list`).
KEY_LIST_CHARS = 200

_WARNINGS: contextvars.ContextVar[list[str] | None] = contextvars.ContextVar("scene_warnings", default=None)
_SYSTEM: contextvars.ContextVar[str] = contextvars.ContextVar("scene_system", default="SI")


class SceneErrors(SceneError):
    """Several :class:`SceneError` of one scene, reported together (``errors``, in the order found); the message
    has one line per error. ``path``, ``value`` and ``allowed`` are the first error's."""

    def __init__(self, errors: list[SceneError]):
        self.errors = list(errors)
        first = self.errors[0]
        self.path, self.value, self.allowed = first.path, first.value, first.allowed
        Exception.__init__(self, "\n".join(str(e) for e in self.errors))


def raise_all(errors: list[SceneError]) -> None:
    """Raise nothing, the one error, or a :class:`SceneErrors` of them all."""
    flat = [e for error in errors for e in (error.errors if isinstance(error, SceneErrors) else [error])]
    if len(flat) == 1:
        raise flat[0]
    if flat:
        raise SceneErrors(flat)


@contextlib.contextmanager
def collecting_warnings(system: str = "SI") -> Iterator[list[str]]:
    """Collect the warnings of the tables read inside the block into the list it yields, give did-you-mean
    hints in the errors, and judge bare numbers as the scene's unit ``system`` ("SI" or "field") asks."""
    found: list[str] = []
    token, system_token = _WARNINGS.set(found), _SYSTEM.set(system)
    try:
        yield found
    finally:
        _WARNINGS.reset(token)
        _SYSTEM.reset(system_token)


def scene_system() -> str:
    """The unit system of the scene being read ("SI" outside :func:`collecting_warnings`)."""
    return _SYSTEM.get()


def warn(message: str) -> None:
    """Add a warning line to the active collection (dropped when none is active)."""
    found = _WARNINGS.get()
    if found is not None and message not in found:
        found.append(message)


def closest(key: str, allowed: Iterable[str]) -> str | None:
    """The allowed key closest to ``key`` (difflib, similarity >= 0.6), or None (always None outside
    :func:`collecting_warnings`)."""
    if _WARNINGS.get() is None:
        return None
    match = difflib.get_close_matches(str(key), [str(a) for a in allowed], n=1, cutoff=0.6)
    return match[0] if match else None


class Table:
    """A TOML table at key path ``path``; track which keys were read to reject unknown ones."""

    def __init__(self, data: Any, path: str):
        if not isinstance(data, dict):
            raise SceneError(path, data, "expected a table")
        self.data = data
        self.path = path
        self._read: set[str] = set()

    def key_path(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default: Any = MISSING) -> Any:
        self._read.add(key)
        if key not in self.data:
            if default is MISSING:
                typo = closest(key, [k for k in self.data if k not in self._read])
                hint = f"; found '{typo}': did you mean '{key}'?" if typo is not None else ""
                raise SceneError(self.key_path(key), MISSING, "this key is required" + hint)
            return default
        return self.data[key]

    def quantity(self, key: str, kind: str, default: Any = MISSING, *, minimum: float | None = None,
                 maximum: float | None = None, exclusive_minimum: bool = False,
                 exclusive_maximum: bool = False) -> float:
        """A physical value in SI, checked against bounds (``default`` may be None: then None is returned)."""
        value = self.raw(key, default)
        if value is None:
            return None  # type: ignore[return-value]
        number = to_si(value, kind, self.key_path(key))
        if kind != "dimensionless" and number != 0.0 and key in self.data and not isinstance(value, str):
            _bare_number(self.key_path(key), value, kind)
        check_bounds(self.key_path(key), value, number, kind, minimum, maximum,
                     exclusive_minimum, exclusive_maximum)
        return number

    def stress(self, key: str, default: Any = MISSING) -> tuple[float | None, float]:
        """(sigma_c [Pa], gradient [Pa/m]) of a stress that is either a pressure ("6000 psi": (sigma, 0)) or a
        gradient in depth ("0.75 psi/ft": (0, gradient >= 0)), so that sigma(z) = sigma_c + gradient z."""
        value = self.raw(key, default)
        if has_dimension_of(value, "stress_gradient"):
            return 0.0, self.quantity(key, "stress_gradient", minimum=0.0)
        try:
            return self.quantity(key, "pressure", default), 0.0
        except SceneError as exc:
            if exc.path != self.key_path(key) or not exc.allowed.startswith("expected"):
                raise
            raise SceneError(exc.path, exc.value, exc.allowed.replace(
                "expected a pressure", 'expected a stress gradient (e.g. "0.75 psi/ft") or a pressure', 1)) from None

    def number(self, key: str, default: Any = MISSING, **bounds: Any) -> float:
        return self.quantity(key, "dimensionless", default, **bounds)

    def integer(self, key: str, default: Any = MISSING, *, minimum: int | None = None,
                maximum: int | None = None) -> int:
        value = self.raw(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise SceneError(self.key_path(key), value, "expected an integer")
        check_bounds(self.key_path(key), value, value, "dimensionless", minimum, maximum, False, False)
        return value

    def boolean(self, key: str, default: Any = MISSING) -> bool:
        value = self.raw(key, default)
        if not isinstance(value, bool):
            raise SceneError(self.key_path(key), value, "expected true or false")
        return value

    def choice(self, key: str, choices: Iterable[str], default: Any = MISSING) -> str:
        choices = tuple(choices)
        value = self.raw(key, default)
        if value not in choices:
            raise SceneError(self.key_path(key), value, f"allowed: {', '.join(map(repr, choices))}")
        return value

    def string(self, key: str, default: Any = MISSING) -> str:
        value = self.raw(key, default)
        if not isinstance(value, str) or not value.strip():
            raise SceneError(self.key_path(key), value, "expected a non-empty string")
        return value

    def table(self, key: str, default: Any = MISSING) -> "Table | None":
        value = self.raw(key, default)
        if value is None:
            return None
        return Table(value, self.key_path(key))

    def tables(self, key: str) -> list["Table"]:
        """An array of tables (``[[key]]`` or an inline list of tables); missing means empty."""
        value = self.raw(key, [])
        if not isinstance(value, list):
            raise SceneError(self.key_path(key), value, "expected an array of tables ([[...]])")
        return [Table(item, f"{self.key_path(key)}[{i}]") for i, item in enumerate(value)]

    def finish(self) -> None:
        """Raise on keys that were never read: they are typos or unsupported."""
        unknown = sorted(set(self.data) - self._read)
        known = key_list(sorted(self._read))
        errors = []
        for key in unknown:
            near = closest(key, self._read)
            hint = f"did you mean '{near}'? " if near is not None else ""
            errors.append(SceneError(self.key_path(key), self.data[key], f"unknown key; {hint}keys allowed here: "
                                     f"{known}"))
        raise_all(errors)


def key_list(names: list[str], budget: int = KEY_LIST_CHARS) -> str:
    """``names`` joined by commas; a list longer than ``budget`` characters is cut after the last name that fits
    and says how many there are in all (an unknown-key error stays one readable line; docs/scene.md lists
    every key)."""
    text = ", ".join(names) or "(none)"
    if len(text) <= budget:
        return text
    shown = text[:budget].rsplit(", ", 1)[0]
    return f"{shown}, ... ({len(names)} keys; docs/scene.md)"


def _bare_number(path: str, value: float, kind: str) -> None:
    """A plain non-zero number for a key of ``kind`` (not dimensionless): an error in a field scene (except a
    time), else a warning; both name the unit to write."""
    unit = SI_UNITS[kind]
    field_unit = FIELD_UNITS.get(kind)
    if scene_system() == "field" and field_unit is not None:
        raise SceneError(path, value, f"a bare number is not read in a scene written in field units: write its "
                                      f"unit, e.g. \"{value} {field_unit}\" (or \"{value} {unit}\" if SI is meant)")
    warn(f"scene key '{path}': bare number {value!r} read as {value!r} {unit} (SI); write the unit, e.g. "
         f"\"{value} {unit}\"")


def check_bounds(path: str, raw: Any, number: float, kind: str, minimum: float | None,
                 maximum: float | None, exclusive_minimum: bool, exclusive_maximum: bool) -> None:
    """Raise a SceneError when ``number`` lies outside [minimum, maximum] (SI)."""
    unit = SI_UNITS.get(kind, "")
    low_bad = minimum is not None and (number <= minimum if exclusive_minimum else number < minimum)
    high_bad = maximum is not None and (number >= maximum if exclusive_maximum else number > maximum)
    if low_bad or high_bad:
        parts = []
        if minimum is not None:
            parts.append(f"{'>' if exclusive_minimum else '>='} {minimum:g} {unit}".rstrip())
        if maximum is not None:
            parts.append(f"{'<' if exclusive_maximum else '<='} {maximum:g} {unit}".rstrip())
        raise SceneError(path, raw, "allowed: " + " and ".join(parts))
