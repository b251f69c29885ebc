"""``hfgpu export --format stimplan-xml``: the closure map as a StimPlan fracture-template XML file, laid out as
ResInsight's reader (OPM ResInsight, ApplicationLibCode/FileInterface/RifStimPlanXmlReader.cpp) reads it::

    <contours>
      <grid xCount="NX" yCount="NZ" uom="m|ft" cs="tvd" frac="1">
        <xs>[x_0 ... x_NX-1]</xs>            (x - x_injection, the well at 0 (without an injection point in
                                             the scene: x - the grid's middle); cell centres)
        <ys>[z_NZ-1 ... z_0]</ys>            (true vertical depth, deepest first)
      </grid>
      <perf uom="m|ft" frac="1"><topTVD>..</topTVD><bottomTVD>..</bottomTVD></perf>   (the injection depth,
                                                                   else the grid's middle)
      <properties>
        <property name="WIDTH" uom="cm|in"><time value="T">      (T: the closure time in minutes)
            <depth>z_0</depth>
            <data>[v_0 ... v_NX-1]</data>      (one row per depth, shallowest first)
            ...
        </time></property>
        <property name="CONDUCTIVITY" uom="md-m|md-ft"> ... </property>
        <property name="PERMEABILITY" uom="md"> ... </property>
      </properties>
    </contours>

The reader takes a property's rows in file order against its ys list reversed and negated, so the rows run
from the shallowest depth down while ``ys`` runs from the deepest up; a ``<depth>`` and its ``<data>`` are
separated by a line break (the reader steps over exactly one token between them). Lengths are in the grid's
unit (``uom`` "m" or "ft"), WIDTH is the propped width, CONDUCTIVITY the closure conductivity. With every x >= 0
(the injection at the grid's left edge) ResInsight mirrors the xs about 0 (one wing given).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..units import convert
from .export_common import injection_point, round_off, status_note

#: unit system: (length, width, conductivity as StimPlan spells them, and as pint does).
UNITS = {"SI": ("m", "cm", "md-m", "md*m"), "field": ("ft", "in", "md-ft", "md*ft")}


def _row(values: np.ndarray) -> str:
    return "[" + " ".join(f"{v:.8g}" for v in round_off(values)) + "]"


def write_stimplan(results: Any, closure: Any, out: Path, system: str) -> list[Path]:
    """Write the StimPlan XML of ``closure`` (a :class:`hfgpu.closure.conductivity.ClosureMap`) to ``out``."""
    length, width_unit, conductivity_unit, conductivity_pint = UNITS[system]
    to_length = convert(1.0, "m", length)
    fields = closure.fields
    nz, nx = fields["propped_width"].shape
    x, z = closure.frame.centres(nz, nx)
    point = injection_point(results)
    x_well, z_perf = point if point is not None else (float(x.mean()), float(z.mean()))
    properties = (("WIDTH", width_unit, fields["propped_width"] * convert(1.0, "m", width_unit)),
                  ("CONDUCTIVITY", conductivity_unit, fields["conductivity"] * convert(1.0, "m**3", conductivity_pint)),
                  ("PERMEABILITY", "md", fields["permeability"] * convert(1.0, "m**2", "md")))
    minutes = closure.scalars["time"] / 60.0
    note = status_note(results)
    lines = ['<?xml version="1.0" ?>', *([f"<!-- {note} -->"] if note else []), "<contours>",
             f'    <grid xCount="{nx}" yCount="{nz}" uom="{length}" cs="tvd" frac="1">',
             f"        <xs>{_row((x - x_well) * to_length)}</xs>",
             f"        <ys>{_row(z[::-1] * to_length)}</ys>",
             "    </grid>",
             f'    <perf uom="{length}" frac="1">',
             f"        <topTVD>{z_perf * to_length:.8g}</topTVD>",
             f"        <bottomTVD>{z_perf * to_length:.8g}</bottomTVD>",
             "    </perf>",
             "    <properties>"]
    for name, unit, values in properties:
        lines += [f'        <property name="{name}" uom="{unit}">', f'            <time value="{minutes:.8g}">']
        for depth, row in zip(z, values):
            lines += [f"                <depth>{depth * to_length:.8g}</depth>",
                      f"                <data>{_row(row)}</data>"]
        lines += ["            </time>", "        </property>"]
    lines += ["    </properties>", "</contours>", ""]
    out.write_text("\n".join(lines))
    return [out]
