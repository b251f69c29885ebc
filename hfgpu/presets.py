"""Named speed/accuracy presets: the defaults of the numerical knobs a scene may leave out.

A scene picks one with ``[run] preset = "fast" | "balanced" | "accurate"`` (default "balanced", which is the
knobs' defaults before presets existed, so no result changes). A preset supplies only DEFAULTS: a key the scene
gives wins. The parse functions of ``[mesh]``, ``[fracture]``, ``[mppic]`` and ``[coupling]`` receive the
preset and read no other defaults; the dataclass defaults of :class:`hfgpu.fracture.config.FractureNumerics`
and :class:`hfgpu.proppant.config.MppicNumerics` are the "balanced" values of this table. What each knob buys
and costs, with measured numbers: docs/presets.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Any


@dataclass(frozen=True)
class Preset:
    """The default of each preset-controlled knob (scene key in brackets).

    refinement [mesh]: cell sizes used = cell_size / refinement (also [coupling] cell_size); the coarsening
    cap max_cells_across is multiplied by it. time_step_relaxation, newton_tolerance [fracture]: lambda of
    Eq. 35 and epsilon of Eq. 32. simple_tolerance [mppic]: Algorithm 1's stopping rule; parcels_per_cell:
    parcels filling a cell at a class's largest loading (sets particles per parcel); particle_substeps:
    particle sub-steps per fluid step (section 4.3); c_max: Courant limit of Eq. 42; dt_max: cap of the
    fluid step [s]. time_scale, parcel_budget: the factor on a coupled scene's derived coupling interval and
    step cap, and its largest parcel count (hfgpu.defaults).
    """

    name: str
    refinement: float
    time_step_relaxation: float
    newton_tolerance: float
    simple_tolerance: float
    parcels_per_cell: int
    particle_substeps: int
    c_max: float
    dt_max: float
    time_scale: float
    parcel_budget: int


#: The one table of presets, fastest first (read-only).
PRESETS: MappingProxyType[str, Preset] = MappingProxyType({p.name: p for p in (
    Preset("fast", refinement=0.5, time_step_relaxation=1.0, newton_tolerance=1e-4, simple_tolerance=1e-4,
           parcels_per_cell=4, particle_substeps=2, c_max=0.8, dt_max=0.1, time_scale=2.0,
           parcel_budget=20_000),
    Preset("balanced", refinement=1.0, time_step_relaxation=0.5, newton_tolerance=1e-6, simple_tolerance=1e-5,
           parcels_per_cell=16, particle_substeps=4, c_max=0.5, dt_max=0.05, time_scale=1.0,
           parcel_budget=60_000),
    Preset("accurate", refinement=2.0, time_step_relaxation=0.25, newton_tolerance=1e-7,
           simple_tolerance=1e-6, parcels_per_cell=32, particle_substeps=8, c_max=0.3, dt_max=0.02, time_scale=0.4,
           parcel_budget=200_000),
)})
DEFAULT_PRESET = "balanced"
BALANCED = PRESETS[DEFAULT_PRESET]

#: (scene section, key) of each knob a preset sets, and the physics that reads it (None: every scene).
KNOBS: tuple[tuple[str, str, str | None], ...] = (
    ("mesh", "refinement", None),
    ("fracture", "time_step_relaxation", "fracture"),
    ("fracture", "newton_tolerance", "fracture"),
    ("mppic", "simple_tolerance", "proppant"),
    ("mppic", "parcels_per_cell", "proppant"),
    ("mppic", "particle_substeps", "proppant"),
    ("mppic", "c_max", "proppant"),
    ("mppic", "dt_max", "proppant"),
)


def effective_knobs(scene: Any) -> list[tuple[str, Any, str]]:
    """(key path, value in use, where it came from: "scene", "preset <name>" or "from the scene: <reason>", a
    default computed from the scene's scales, hfgpu.defaults) of each preset knob the scene's physics reads and
    of each derived one; the origin is read from the scene's parsed TOML text (``scene.document``)."""
    data = scene.document
    objects = {"mesh": scene.mesh, "fracture": scene.fracture,
               "mppic": scene.proppant.numerics if scene.proppant is not None else None}
    derived = {d.key: d for d in scene.derived}
    rows = []
    for section, key, physics in KNOBS:
        if physics is not None and not scene.has(physics):
            continue
        path = f"{section}.{key}"
        given = isinstance(data.get(section), dict) and key in data[section]
        origin = "scene" if given else (f"from the scene: {derived[path].reason}" if path in derived
                                        else f"preset {scene.run.preset}")
        rows.append((path, getattr(objects[section], key), origin))
    rows += [(d.key, d.value, f"from the scene: {d.reason}") for d in scene.derived
             if d.key not in {path for path, _, _ in rows}]
    return rows


def knob_report(scene: Any, system: str = "SI") -> str:
    """The lines ``hfgpu check`` prints: the preset, the cells in use (lengths in ``system``'s units) and each preset
    knob with its origin."""
    from .units import display_unit, format_number, in_display_units

    def length(value: float) -> str:
        return format_number(in_display_units(value, "length", system))

    unit = display_unit("length", system)
    dx, dz = scene.mesh.scene_cell_size
    lines = [f"preset {scene.run.preset}; numerical knobs in use (docs/presets.md):",
             f"  {'mesh cells in use':32} {length(scene.mesh.dx)} x {length(scene.mesh.dz)} {unit} = cell_size "
             f"{length(dx)} x {length(dz)} {unit} / refinement {scene.mesh.refinement:g}"]
    if scene.mesh.max_cells_across is not None:
        lines.append(f"  {'mesh.max_cells_across in use':32} {scene.mesh.max_cells_across} (scene value x refinement)")
    if scene.coupling is not None:
        size = scene.coupling.cell_size
        shown = "the fracture cells" if size is None else \
            f"{length(size[0])} x {length(size[1])} {unit} (scene value / refinement)"
        lines.append(f"  {'coupling cells in use':32} {shown}")
    lines += [f"  {path:32} {value:<10g} {origin}" for path, value, origin in effective_knobs(scene)]
    return "\n".join(lines)
