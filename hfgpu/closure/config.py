"""Scene keys of the closure model (docs/closure.md): ``[closure]`` and the conductivity keys of ``[[proppant]]``.

``[closure]`` (optional; only with "proppant" in ``run.physics``): ``settling`` ("bed", default, or "in_place"),
``pack_solid_fraction`` (default the scene's ``[mppic] theta_cp``), ``layers`` (one-layer criterion, default 1),
``embedment`` (width lost per face, default 0), ``closure_stress`` (a uniform closure stress; required for a
conductivity table in a scene without ``[rock]``), ``formation_permeability`` (for F_CD), ``time`` (the proppant
snapshot nearest to it is closed; default the last one).

``[[proppant]]``: ``conductivity = [{ stress = "2000 psi", value = "4000 md*ft" }, ...]`` (value a conductivity,
or a permeability such as "180 darcy"), ``conductivity_loading`` (areal concentration of the lab pack the table
was measured at, default 2 lb/ft^2, the API RP 19D / ISO 13503-5 loading), ``conductivity_factor`` (a multiplier
on the class's permeability in (0, 1], default 1).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..errors import MISSING, SceneError
from ..scene_reader import Table
from ..units import to_si

SETTLING_RULES = ("bed", "in_place")
#: API RP 19D / ISO 13503-5 long-term conductivity tests load the cell with 2 lb/ft^2 of proppant [kg/m^2].
LAB_LOADING = 2.0 * 0.45359237 / 0.3048**2


@dataclass(frozen=True)
class ConductivityTable:
    """A vendor table of one class: closure stresses [Pa] (increasing) and values, either conductivities
    [m^3] (``is_permeability`` False) or permeabilities [m^2]."""

    stress: tuple[float, ...]
    value: tuple[float, ...]
    is_permeability: bool = False


@dataclass(frozen=True)
class ClassClosure:
    """The closure keys of one ``[[proppant]]`` class: ``table`` (None: Kozeny-Carman), ``loading`` [kg/m^2] of
    the table's lab pack and ``factor`` on the class's permeability."""

    table: ConductivityTable | None = None
    loading: float = LAB_LOADING
    factor: float = 1.0


@dataclass(frozen=True)
class ClosureConfig:
    """``[closure]``: settling rule, pack solid fraction, one-layer criterion ``layers``, ``embedment`` [m per
    face], uniform ``closure_stress`` [Pa] (None: the rock's layers), ``formation_permeability`` [m^2] (None: no
    F_CD) and ``time`` [s] (None: the last proppant snapshot)."""

    settling: str = "bed"
    pack_solid_fraction: float = 0.6
    layers: float = 1.0
    embedment: float = 0.0
    closure_stress: float | None = None
    formation_permeability: float | None = None
    time: float | None = None


def parse_class_closure(t: Table) -> ClassClosure:
    """The closure keys of one ``[[proppant]]`` table."""
    raw = t.raw("conductivity", None)
    table = _parse_table(raw, t.key_path("conductivity")) if raw is not None else None
    loading = t.quantity("conductivity_loading", "areal_density", LAB_LOADING, minimum=0.0, exclusive_minimum=True)
    factor = t.number("conductivity_factor", 1.0, minimum=0.0, maximum=1.0, exclusive_minimum=True)
    return ClassClosure(table=table, loading=loading, factor=factor)


def _parse_table(raw: Any, path: str) -> ConductivityTable:
    example = 'e.g. [{ stress = "2000 psi", value = "4000 md*ft" }, { stress = "4000 psi", value = "3000 md*ft" }]'
    if not isinstance(raw, list) or not raw:
        raise SceneError(path, raw, f"expected a non-empty list of {{ stress, value }} tables, {example}")
    stresses, values, kinds = [], [], set()
    for i, item in enumerate(raw):
        row = Table(item, f"{path}[{i}]")
        stresses.append(row.quantity("stress", "pressure", minimum=0.0))
        value, is_permeability = _conductivity_or_permeability(row.raw("value"), row.key_path("value"))
        values.append(value)
        kinds.add(is_permeability)
        row.finish()
    if len(kinds) > 1:
        raise SceneError(path, raw, "give every value of one table as a conductivity (md*ft) or every one as a "
                         "permeability (darcy), not a mix")
    if any(b <= a for a, b in zip(stresses, stresses[1:])):
        raise SceneError(path, raw, "the stresses must increase from one row to the next")
    return ConductivityTable(stress=tuple(stresses), value=tuple(values), is_permeability=kinds.pop())


def _conductivity_or_permeability(value: Any, path: str) -> tuple[float, bool]:
    """(SI number, is a permeability): a conductivity [m^3] ("4000 md*ft") or a permeability [m^2]
    ("180 darcy"), > 0."""
    try:
        number, is_permeability = to_si(value, "conductivity", path), False
    except SceneError:
        try:
            number, is_permeability = to_si(value, "permeability", path), True
        except SceneError:
            raise SceneError(path, value, 'expected a conductivity, e.g. "4000 md*ft", or a permeability, e.g. '
                             '"180 darcy"') from None
    if number <= 0.0:
        raise SceneError(path, value, "allowed: > 0")
    return number, is_permeability


def parse_closure(t: Table, proppant: Any, rock: Any) -> ClosureConfig:
    """``[closure]`` of a scene with proppant (``proppant``: its ProppantSetup; ``rock``: its Rock or None)."""
    config = ClosureConfig(
        settling=t.choice("settling", SETTLING_RULES, "bed"),
        pack_solid_fraction=t.number("pack_solid_fraction", proppant.params.theta_cp, minimum=0.0, maximum=1.0,
                                     exclusive_minimum=True, exclusive_maximum=True),
        layers=t.number("layers", 1.0, minimum=0.0, exclusive_minimum=True),
        embedment=t.quantity("embedment", "length", 0.0, minimum=0.0),
        closure_stress=t.quantity("closure_stress", "pressure", None),
        formation_permeability=t.quantity("formation_permeability", "permeability", None, minimum=0.0,
                                          exclusive_minimum=True),
        time=t.quantity("time", "time", None, minimum=0.0),
    )
    tables = [c.name for c in proppant.classes if c.closure.table is not None]
    if tables and rock is None and config.closure_stress is None:
        raise SceneError(t.key_path("closure_stress"), MISSING, f"required: class {tables[0]!r} has a "
                         "conductivity table and the scene has no [rock] to take the closure stress from")
    t.finish()
    return config
