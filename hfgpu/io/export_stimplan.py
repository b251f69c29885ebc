"""``hfgpu export --format stimplan-xml``: the export map (:mod:`hfgpu.io.export_map`: the created fracture and,
with proppant, the closure map, on one grid covering both) as a StimPlan fracture-template XML file, laid out as
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
        <property name="WIDTH" uom="cm|in"><time value="T">      (T: the map's time in minutes: the closure
                                                                 time, else the last fracture snapshot's)
            <depth>z_0</depth>
            <data>[v_0 ... v_NX-1]</data>      (one row per depth, shallowest first)
            ...
        </time></property>
        <property name="CONDUCTIVITY" uom="md-m|md-ft"> ... </property>
        <property name="PERMEABILITY" uom="md"> ... </property>
        <property name="HYDRAULIC_WIDTH" uom="cm|in"> ... </property>
        <property name="PRESSURE" uom="MPa|psi"> ... </property>
      </properties>
    </contours>

The reader takes a property's rows in file order against its ys list reversed and negated, so the rows run
from the shallowest depth down while ``ys`` runs from the deepest up; a ``<depth>`` and its ``<data>`` are
separated by a line break (the reader steps over exactly one token between them). Lengths are in the grid's
unit (``uom`` "m" or "ft"). WIDTH, CONDUCTIVITY and PERMEABILITY (runs with proppant) are the propped width, the
closure conductivity and the pack permeability, 0 where the proppant grid does not reach; HYDRAULIC_WIDTH and
PRESSURE (runs with a fracture) are the created width and the fluid pressure, 0 in closed cells. With every
x >= 0 (the injection at the grid's left edge) ResInsight mirrors the xs about 0 (one wing given).
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


def _properties(fields: dict[str, np.ndarray], system: str) -> list[tuple[str, str, np.ndarray]]:
    """(StimPlan name, unit, values) of each property the map holds (module docstring), in ``system``'s units."""
    _, width_unit, conductivity_unit, conductivity_pint = UNITS[system]
    pressure_unit = "psi" if system == "field" else "MPa"
    known = (("WIDTH", "propped_width", width_unit, "m", width_unit),
             ("CONDUCTIVITY", "conductivity", conductivity_unit, "m**3", conductivity_pint),
             ("PERMEABILITY", "permeability", "md", "m**2", "md"),
             ("HYDRAULIC_WIDTH", "width", width_unit, "m", width_unit),
             ("PRESSURE", "pressure", pressure_unit, "Pa", pressure_unit))
    return [(name, unit, fields[key] * convert(1.0, si, pint)) for name, key, unit, si, pint in known if key in fields]


def write_stimplan(results: Any, grid: Any, out: Path, system: str) -> list[Path]:
    """Write the StimPlan XML of ``grid`` (a :class:`hfgpu.io.export_map.ExportMap`) to ``out``."""
    length = UNITS[system][0]
    to_length = convert(1.0, "m", length)
    nz, nx = grid.shape
    x, z = grid.frame.centres(nz, nx)
    point = injection_point(results)
    x_well, z_perf = point if point is not None else (float(x.mean()), float(z.mean()))
    properties = _properties(grid.fields, system)
    minutes = grid.time / 60.0
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
