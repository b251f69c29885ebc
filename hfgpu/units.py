"""Physical quantities in scene files, parsed with pint.

Every value is either a plain number, taken as SI, or a string with units ("40 GPa", "20 bbl/min",
"2 MPa*m**0.5"). Oilfield units are defined here once: ``bbl`` is the 42-gallon oil barrel (pint's own
``bbl`` is the 31.5-gallon fluid barrel), ``bpm`` is bbl per minute, ``gpm`` is US gallons per minute, ``cp`` is
the centipoise (as ``cP``; pint's own ``cp`` is the cup), ``ppa``/``ppg`` are pounds of proppant added per US
gallon of clean fluid, ``md`` is the millidarcy (conductivities in "md*ft").
"""

from __future__ import annotations

import functools
import pickle
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
    "permeability": "m**2",
    "conductivity": "m**3",
    "areal_density": "kg/m**2",
    "stress_gradient": "Pa/m",
    "dimensionless": "",
}

_EXAMPLES = {
    "length": '"2 m", "5 mm", "198 um"',
    "time": '"370 s", "20 min", "1 h"',
    "pressure": '"60 MPa", "9000 psi"',
    "toughness": '"1 MPa*m**0.5"',
    "leakoff": '"2e-7 m/s**0.5"',
    "viscosity": '"0.08 Pa*s", "20 cP"',
    "density": '"2650 kg/m**3"',
    "rate": '"0.053 m**3/s", "20 bbl/min", "5 bpm", "6 gpm"',
    "volume": '"100 m**3", "500 bbl"',
    "concentration": '"2 ppa", "240 kg/m**3"',
    "velocity": '"0.1 m/s"',
    "acceleration": '"9.81 m/s**2"',
    "permeability": '"0.1 md", "180 darcy"',
    "conductivity": '"4000 md*ft", "1.2 darcy*m"',
    "areal_density": '"2 lb/ft**2", "9.76 kg/m**2"',
    "stress_gradient": '"0.75 psi/ft", "17 kPa/m"',
    "dimensionless": "a plain number",
}

#: The field unit a bare number of each kind would most likely have been meant in (the unit a field-units scene is
#: told to write, hfgpu.scene_reader); time is missing: seconds are read the same in both systems.
FIELD_UNITS = {
    "length": "ft", "pressure": "psi", "toughness": "psi*in**0.5", "leakoff": "ft/min**0.5", "viscosity": "cP",
    "density": "lb/gal", "rate": "bbl/min", "volume": "bbl", "concentration": "ppa", "velocity": "ft/s",
    "acceleration": "ft/s**2", "permeability": "md", "conductivity": "md*ft", "areal_density": "lb/ft**2",
    "stress_gradient": "psi/ft",
}


@functools.lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The one unit registry of hfgpu, with oilfield units added. Pint's parsed definitions are cached on disk
    (``cache_folder=":auto:"``, the user cache folder): a process then builds the registry in ~0.04 s instead of
    ~0.25 s. Where that folder cannot be written, or a cache file cannot be read (16 processes started at once on a
    fresh machine read each other's half-written files: EOFError, UnicodeDecodeError in flexcache's unpickling),
    the registry is built without it."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            ureg = pint.UnitRegistry(on_redefinition="warn", cache_folder=":auto:")
        except (OSError, EOFError, ValueError, pickle.UnpicklingError):
            ureg = pint.UnitRegistry(on_redefinition="warn")
        ureg.define("bbl = 42 * gallon = oilfield_barrel")
        ureg.define("bpm = bbl / minute")
        ureg.define("gpm = gallon / minute")
        ureg.define("cp = centipoise")  # pint would read "cp" as the cup, a volume
        ureg.define("ppa = pound / gallon")
        ureg.define("ppg = pound / gallon")
        ureg.define("md = millidarcy")  # pint would read "md" as a milli-day
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


def has_dimension_of(value: object, kind: str) -> bool:
    """Whether ``value`` is a quantity text ("0.75 psi/ft") whose dimension is that of ``kind``'s SI unit."""
    if not isinstance(value, str):
        return False
    ureg = registry()
    try:
        return ureg.Quantity(value.strip()).dimensionality == ureg.Quantity(1.0, SI_UNITS[kind]).dimensionality
    except Exception:  # pint raises several unrelated types on bad text: to_si reports it
        return False


def convert(value: float, from_unit: str, to_unit: str) -> float:
    """Convert a number between units (for reports and field-unit display)."""
    return float(registry().Quantity(value, from_unit).to(to_unit).magnitude)


# ----------------------------------------------------------------------------------------------
# unit systems: which one a scene is written in, and numbers shown in it

SYSTEMS = ("SI", "field")
#: Unit words that mark a value as written in field (oilfield) units; any other length, pressure, volume, mass or
#: viscosity unit (m, mm, Pa, MPa, kg, L, Pa*s, mPa*s, ...) marks it SI; time units (s, min, h), darcy and md
#: mark neither.
FIELD_WORDS = frozenset({"ft", "foot", "feet", "in", "inch", "inches", "yd", "mi", "mile", "psi", "kpsi", "bbl",
                         "gal", "gallon", "gallons", "gpm", "bpm", "ppa", "ppg", "lb", "lbs", "pound", "pounds", "cp",
                         "centipoise", "degF", "lbf", "ton"})
NEUTRAL_WORDS = frozenset({"s", "sec", "second", "seconds", "min", "minute", "minutes", "h", "hr", "hour", "hours",
                           "day", "days", "md", "darcy", "millidarcy", "percent"})
_WORD = re.compile(r"[A-Za-z_]+")


def system_of(text: str) -> str | None:
    """"field", "SI" or None (no unit, or time units only) for the unit part of a quantity text such as
    "9000 psi", "2 MPa*m**0.5", "20 bbl/min", "370 s"."""
    match = _LEADING_NUMBER.match(text)
    if match is None:
        return None
    words = [w for w in _WORD.findall(text[match.end():]) if w not in ("e", "E")]
    if not words:
        return None
    if any(w in FIELD_WORDS or w.lower() in ("cp", "psi", "bbl", "bpm", "ppa", "ppg") for w in words):
        return "field"
    if all(w in NEUTRAL_WORDS for w in words):
        return None
    return "SI"


def count_systems(data: object) -> dict[str, int]:
    """{"SI": n, "field": m}: the unit-bearing string values of a parsed scene document by unit system (names and
    labels without a leading number, bare numbers and time-only values are not counted)."""
    counts = {"SI": 0, "field": 0}
    stack = [data]
    while stack:
        item = stack.pop()
        if isinstance(item, dict):
            stack.extend(item.values())
        elif isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, str):
            system = system_of(item)
            if system is not None:
                counts[system] += 1
    return counts


def majority_system(data: object) -> str:
    """The unit system most unit-bearing values of ``data`` are written in: "field" when field values outnumber SI
    ones, else "SI" (a tie and a scene without units give SI)."""
    counts = count_systems(data)
    return "field" if counts["field"] > counts["SI"] else "SI"


#: kind: (SI display unit, field display unit), as pint spells them: the units of the summary, ``check``, the
#: pump-schedule table and the figures (the results file stays SI).
DISPLAY_UNITS = {
    "length": ("m", "ft"), "depth": ("m", "ft"), "width": ("mm", "in"), "area": ("m**2", "ft**2"),
    "pressure": ("MPa", "psi"), "volume": ("m**3", "bbl"), "solid_volume": ("m**3", "ft**3"),
    "mass": ("kg", "lb"), "rate": ("m**3/min", "bbl/min"), "concentration": ("kg/m**3", "ppa"),
    "viscosity": ("mPa*s", "cP"), "time": ("s", "s"), "density": ("kg/m**3", "lb/gal"),
    "radius": ("um", "in"), "speed": ("m/s", "ft/s"), "leakoff": ("m/s**0.5", "ft/min**0.5"),
}


def display_unit(kind: str, system: str) -> str:
    """The unit ``kind`` is shown in, in ``system``, as text ("m**3/min" written "m^3/min")."""
    return DISPLAY_UNITS[kind][SYSTEMS.index(system)].replace("**", "^").replace("*", " ")


def in_display_units(value: float, kind: str, system: str) -> float:
    """An SI ``value`` of ``kind`` in the display unit of ``system``."""
    return convert(value, stored_unit(kind), DISPLAY_UNITS[kind][SYSTEMS.index(system)])


def stored_unit(kind: str) -> str:
    """The SI unit a value of display ``kind`` is stored in (scenes and results files)."""
    return SI_UNITS.get(kind, _DISPLAY_SI.get(kind, ""))


_DISPLAY_SI = {"depth": "m", "width": "m", "area": "m**2", "solid_volume": "m**3", "mass": "kg", "radius": "m",
               "speed": "m/s"}


def display_text(value: float, kind: str, system: str, digits: int = 4) -> str:
    """An SI ``value`` of display ``kind`` as text in ``system``'s display unit: "8 025 ft", "2 446 m"."""
    return f"{format_number(in_display_units(value, kind, system), digits)} {display_unit(kind, system)}"


def format_number(value: float, digits: int = 4) -> str:
    """``value`` to ``digits`` significant figures, without an exponent between 1e-3 and 1e9 (thousands grouped
    by a thin space: "123 500")."""
    if value != value:
        return "n/a"
    if value == 0 or not 1e-3 <= abs(value) < 1e9:
        return f"{value:.{digits}g}" if value else "0"
    exponent = int(f"{abs(value):e}".split("e")[1])
    places = digits - 1 - exponent
    text = f"{round(value, places):,.{max(places, 0)}f}".replace(",", " ")
    return text.rstrip("0").rstrip(".") if "." in text else text
