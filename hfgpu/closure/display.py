"""Units of the closure quantities in plots, exports and the summary table: SI as stored, or field units
(``[output] units = "field"`` or ``hfgpu export --units field``): lengths in ft, widths in in, conductivity in
md ft, permeability in md, stress in psi, area in ft^2 (conversions by pint, :func:`hfgpu.units.convert`)."""

from __future__ import annotations

import numpy as np

from ..units import SYSTEMS, convert

#: quantity kind: (SI unit, field unit), as pint spells them.
KINDS = {"length": ("m", "ft"), "width": ("m", "in"), "conductivity": ("m**3", "md*ft"),
         "permeability": ("m**2", "md"), "stress": ("Pa", "psi"), "area": ("m**2", "ft**2"), "time": ("s", "s"),
         "dimensionless": ("", "")}
#: The kind of each closure field and scalar.
QUANTITIES = {"propped_width": "width", "conductivity": "conductivity", "closure_stress": "stress",
              "permeability": "permeability", "sauter_diameter": "width", "propped_area": "area",
              "propped_half_length": "length", "propped_height": "length", "mean_conductivity": "conductivity",
              "formation_permeability": "permeability", "time": "time", "fcd": "dimensionless",
              "pack_solid_fraction": "dimensionless", "x": "length", "depth": "length", "pressure": "stress"}


def unit_label(name: str, system: str) -> str:
    """The unit of quantity ``name`` in ``system`` as text ("md*ft" written "md ft", "m**3" as "m^3")."""
    unit = KINDS[QUANTITIES[name]][SYSTEMS.index(system)]
    return unit.replace("**", "^").replace("*", " ")


def in_units(name: str, values, system: str):
    """SI ``values`` of quantity ``name`` in ``system`` (a float for a scalar, else an array)."""
    si, target = KINDS[QUANTITIES[name]][0], KINDS[QUANTITIES[name]][SYSTEMS.index(system)]
    factor = 1.0 if si == target else convert(1.0, si, target)
    scaled = np.asarray(values, dtype=np.float64) * factor
    return float(scaled) if scaled.ndim == 0 else scaled

