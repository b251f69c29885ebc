"""The units of a sweep's columns (inputs, metrics, ``wall_seconds``) in the base scene's unit system.

Each column has a kind of :mod:`hfgpu.units`: an input that of its ``[[vary]]`` (``Vary.kind``), a metric that of
its SI unit in :data:`hfgpu.ensemble.metrics.UNITS` (m^2 an area, m a length, Pa a pressure), ``wall_seconds`` a
time; ``id``, ``status``, text inputs and ratios have none. A column of kind k is shown in:

* the display unit of k (:class:`hfgpu.io.display_units.FigureUnits`: ft, ft^2, psi, bbl/min, cP, lb/gal, ...
  in a field scene; m, m^2, MPa, m^3/min, mPa s in an SI one) where :data:`hfgpu.units.DISPLAY_UNITS` has k;
* else the unit a scene of that system writes k in: :data:`hfgpu.units.FIELD_UNITS` (ft/min^0.5, psi in^0.5,
  psi/ft, md) or the SI unit of :data:`hfgpu.units.SI_UNITS`;
* with ``stored``, an SI scene's columns stay in their stored SI units (Pa, m^3/s, Pa s): summary.csv of an SI
  scene holds the numbers it always held.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..io.display_units import FigureUnits
from ..units import DISPLAY_UNITS, FIELD_UNITS, SI_UNITS, SYSTEMS, convert, stored_unit
from .metrics import UNITS

#: The kind (hfgpu.units) of each SI unit of hfgpu.ensemble.metrics.UNITS.
METRIC_KINDS = {"m^2": "area", "m": "length", "Pa": "pressure", "-": "dimensionless"}


def metric_kind(name: str) -> str:
    """The kind of a metric's values."""
    return METRIC_KINDS[UNITS[name]]


def column_kinds(inputs: dict[str, str], metrics: list[str]) -> dict[str, str]:
    """{column: kind} of a summary: ``inputs`` {column: kind} (""for text), the metrics, ``wall_seconds``."""
    return {"id": "", "status": "", **inputs, **{m: metric_kind(m) for m in metrics}, "wall_seconds": "time"}


@dataclass(frozen=True)
class ColumnUnits:
    """The units of a summary's columns in ``system`` ("SI" or "field"): ``units.label(column)`` names the unit
    ("psi", "ft^2"; "-" for a ratio, "" for text), ``units(column, value)`` converts a stored (SI) value."""

    kinds: dict[str, str]
    system: str = "SI"
    stored: bool = False
    _figure: FigureUnits = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "_figure", FigureUnits(self.system))

    def unit(self, column: str) -> str:
        """The unit of ``column`` as pint writes it ("" for text and ratios)."""
        kind = self.kinds.get(column, "")
        if kind in ("", "dimensionless"):
            return ""
        if self.stored and self.system == "SI":
            return stored_unit(kind)
        if kind in DISPLAY_UNITS:
            return DISPLAY_UNITS[kind][SYSTEMS.index(self.system)]
        return FIELD_UNITS.get(kind, SI_UNITS[kind]) if self.system == "field" else SI_UNITS[kind]

    def label(self, column: str) -> str:
        """The unit of ``column`` as text ("ft^2", "Pa s"); "-" for a ratio or a flag, "" for text."""
        if self.kinds.get(column, "") == "":
            return ""
        return self.unit(column).replace("**", "^").replace("*", " ") or "-"

    def __call__(self, column: str, values: Any) -> Any:
        """Stored (SI) ``values`` of ``column`` in its unit (text as it is; converted numbers to 12 significant
        digits, so that 5600 ft^2 reads 5600.0, not 5599.999999999583)."""
        if isinstance(values, str):
            return values
        kind, unit = self.kinds.get(column, ""), self.unit(column)
        if not unit or unit == stored_unit(kind):
            return values
        shown = self._figure(kind, values) if kind in DISPLAY_UNITS else values * convert(1.0, stored_unit(kind), unit)
        return _significant(shown)


def _significant(values: Any, digits: int = 12) -> Any:
    """``values`` (a number or an array) rounded to ``digits`` significant digits."""
    array = np.asarray(values, dtype=np.float64)
    rounded = np.vectorize(lambda v: float(f"{v:.{digits}g}"), otypes=[np.float64])(array)
    return float(rounded) if rounded.ndim == 0 else rounded
