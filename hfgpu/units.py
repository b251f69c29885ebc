"""Physical quantities in scene files, parsed with pint.

Every value is either a plain number, taken as SI, or a string with units ("40 GPa", "20 bbl/min",
"2 MPa*m**0.5"). Oilfield units are defined here once: ``bbl`` is the 42-gallon oil barrel (pint's own
``bbl`` is the 31.5-gallon fluid barrel), ``gpm`` is US gallons per minute, ``ppa``/``ppg`` are pounds of
proppant added per US gallon of clean fluid.
"""

from __future__ import annotations

import functools
import re
import warnings

import pint

from .errors import SceneError

#: The SI unit each kind of quantity is converted to.
SI_UNITS = {
    "length": "m",
    "time": "s",
    "pressure": "Pa",
    "toughness": "Pa*m**0.5",
    "leakoff": "m/s**0.5",
    "viscosity": "Pa*s",
    "density": "kg/m**3",
    "rate": "m**3/s",
    "volume": "m**3",
    "concentration": "kg/m**3",
    "velocity": "m/s",
    "acceleration": "m/s**2",
    "dimensionless": "",
}

_EXAMPLES = {
    "length": '"2 m", "5 mm", "198 um"',
    "time": '"370 s", "20 min", "1 h"',
    "pressure": '"60 MPa", "9000 psi"',
    "toughness": '"1 MPa*m**0.5"',
    "leakoff": '"2e-7 m/s**0.5"',
    "viscosity": '"0.08 Pa*s", "1 cP"',
    "density": '"2650 kg/m**3"',
    "rate": '"0.053 m**3/s", "20 bbl/min", "6 gpm"',
    "volume": '"100 m**3", "500 bbl"',
    "concentration": '"2 ppa", "240 kg/m**3"',
    "velocity": '"0.1 m/s"',
    "acceleration": '"9.81 m/s**2"',
    "dimensionless": "a plain number",
}


@functools.lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The one unit registry of hfgpu, with oilfield units added."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ureg = pint.UnitRegistry(on_redefinition="warn")
        ureg.define("bbl = 42 * gallon = oilfield_barrel")
        ureg.define("gpm = gallon / minute")
        ureg.define("ppa = pound / gallon")
        ureg.define("ppg = pound / gallon")
    return ureg


def to_si(value: object, kind: str, path: str = "value") -> float:
    """Convert a scene value of the given kind to its SI number.

    Raises :class:`SceneError` naming ``path`` when the value is not a number or a string with units of
    the right dimension.
    """
    unit = SI_UNITS[kind]
    allowed = f"expected a {kind} in {unit or 'no unit'}, e.g. {_EXAMPLES[kind]}"
    if isinstance(value, bool):
        raise SceneError(path, value, allowed)
    if isinstance(value, (int, float)):
        number = float(value)
    elif isinstance(value, str):
        _check_quantity_text(value, path, allowed)
        ureg = registry()
        try:
            quantity = ureg.Quantity(value.strip())
        except Exception as exc:  # pint raises several unrelated types on bad text
            raise SceneError(path, value, f"{allowed} ({exc})") from None
        try:
            number = float(quantity.to(unit).magnitude) if unit else float(quantity.to("").magnitude)
        except pint.DimensionalityError:
            raise SceneError(path, value, f"{allowed}; '{value}' has dimension "
                             f"{quantity.dimensionality}") from None
        except Exception as exc:
            raise SceneError(path, value, f"{allowed} ({exc})") from None
    else:
        raise SceneError(path, value, allowed)
    if number != number or number in (float("inf"), float("-inf")):
        raise SceneError(path, value, f"{allowed}; the value must be finite")
    return number


_LEADING_NUMBER = re.compile(r"\s*[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")


def _check_quantity_text(value: str, path: str, allowed: str) -> None:
    """One number, then units: pint would read "0 3 m" (or "0\\n3 m") as 0 * 3 m, and "MPa" as 1 MPa."""
    match = _LEADING_NUMBER.match(value)
    rest = value[match.end():].lstrip(" ") if match else ""
    if match is None or any(c in value for c in "\r\n\t\f\v") or rest[:1].isdigit() or rest[:1] == ".":
        raise SceneError(path, value, f"{allowed}; write one number followed by its units")


def convert(value: float, from_unit: str, to_unit: str) -> float:
    """Convert a number between units (for reports and field-unit display)."""
    return float(registry().Quantity(value, from_unit).to(to_unit).magnitude)
