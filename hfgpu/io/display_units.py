"""Units of the ``hfgpu plot`` figures: the results' ``[output] units`` ("SI" or "field", see
:func:`hfgpu.io.export.output_units`). SI figures keep their units (x and depth in m, widths in mm, pressures in
MPa, areas in m^2, volumes in m^3, speeds in m/s, grain radii in um); field figures draw lengths and depths in ft,
widths and grain radii in in, pressures in psi, areas in ft^2, fluid volumes in bbl, solid volumes in ft^3 and
speeds in ft/s. Times stay in s and dimensionless numbers unchanged in both. The units are those of the summary
and ``check`` (:data:`hfgpu.units.DISPLAY_UNITS`), converted by pint; the results file stays SI."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..units import DISPLAY_UNITS, SYSTEMS, convert, display_unit, stored_unit


@functools.lru_cache(maxsize=None)
def _scale(kind: str, system: str) -> tuple[str, float]:
    """("*" or "/", number): how an SI value of ``kind`` becomes its ``system`` display value
    (:data:`hfgpu.units.DISPLAY_UNITS`). A factor below one is applied as a division by its (exact) inverse, so SI
    figures draw the very numbers they did (Pa / 1e6)."""
    stored = stored_unit(kind)
    target = DISPLAY_UNITS[kind][SYSTEMS.index(system)]
    if target == stored:
        return "*", 1.0
    factor = convert(1.0, stored, target)
    return ("*", factor) if factor >= 1.0 else ("/", convert(1.0, target, stored))


@dataclass(frozen=True)
class FigureUnits:
    """The figure units of one unit system: ``units("width", values)`` converts SI values, ``units.label("width")``
    names the unit ("mm", "in", "ft^2")."""

    system: str = "SI"

    def __post_init__(self):
        if self.system not in SYSTEMS:
            raise ValueError(f"unit system {self.system!r}: allowed {', '.join(SYSTEMS)}")

    def __call__(self, kind: str, values):
        """SI ``values`` of ``kind`` in this system's figure unit (a float for a scalar, else an array)."""
        op, number = _scale(kind, self.system)
        array = np.asarray(values, dtype=np.float64)
        scaled = array if number == 1.0 else array * number if op == "*" else array / number
        return float(scaled) if scaled.ndim == 0 else scaled

    def label(self, kind: str) -> str:
        """The figure unit of ``kind`` as text ("m**2" written "m^2")."""
        return display_unit(kind, self.system)

    @property
    def field(self) -> bool:
        return self.system == "field"


SI = FigureUnits("SI")
