"""Units of the ``hfgpu plot`` figures: the results' ``[output] units`` ("SI" or "field", see
:func:`hfgpu.io.export.output_units`). SI figures keep their units (x and depth in m, widths in mm, pressures in
MPa, areas in m^2, volumes in m^3, speeds in m/s, grain radii in um); field figures draw lengths and depths in ft,
widths and grain radii in in, pressures in psi, areas in ft^2, fluid volumes in bbl, solid volumes in ft^3 and
speeds in ft/s. Times stay in s and dimensionless numbers unchanged in both. Conversions by pint
(:func:`hfgpu.units.convert`); the results file stays SI."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..units import SYSTEMS, convert

#: kind: (unit stored in the results file, figure unit in SI, figure unit in field units), as pint spells them.
FIGURE_UNITS = {
    "length": ("m", "m", "ft"), "width": ("m", "mm", "in"), "radius": ("m", "um", "in"),
    "pressure": ("Pa", "MPa", "psi"), "area": ("m**2", "m**2", "ft**2"), "volume": ("m**3", "m**3", "bbl"),
    "solid_volume": ("m**3", "m**3", "ft**3"), "speed": ("m/s", "m/s", "ft/s"), "time": ("s", "s", "s"),
}


@functools.lru_cache(maxsize=None)
def _scale(kind: str, system: str) -> tuple[str, float]:
    """("*" or "/", number): how an SI value of ``kind`` becomes its ``system`` figure value. A factor below one is
    applied as a division by its (exact) inverse, so SI figures draw the very numbers they did (Pa / 1e6)."""
    stored, *shown = FIGURE_UNITS[kind]
    target = shown[SYSTEMS.index(system)]
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
        return FIGURE_UNITS[kind][1 + SYSTEMS.index(self.system)].replace("**", "^").replace("*", " ")

    @property
    def field(self) -> bool:
        return self.system == "field"


SI = FigureUnits("SI")
