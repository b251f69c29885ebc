"""Scene files: TOML in, typed frozen configuration out, validated before any work starts.

Contract keys (outside tools rely on them; extend, never rename): ``[run] end_time, physics``;
``[rock] youngs_modulus, poisson_ratio, toughness, leakoff_coefficient, min_stress, pore_pressure,
[[rock.layers]] top, bottom, min_stress, toughness, leakoff_coefficient, pore_pressure``; ``[fluid] viscosity,
density``; ``[injection] depth, schedule = [{until, rate, proppant, volume_fraction, concentration,
end_concentration}]``; ``[mesh] cell_size``; ``[output] every, units``; ``[geometry]`` and ``[[proppant]]``
(see :mod:`hfgpu.proppant.config`); ``[closure]`` (see :mod:`hfgpu.closure.config`); ``[completion]`` (see
:mod:`hfgpu.completion`). Depth z is positive
downward; x is along the fracture length.

Physics-specific sections are parsed by their own folder (``hfgpu.fracture.config``,
``hfgpu.proppant.config``), imported only when the scene asks for that physics.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from .errors import SceneError
from .presets import DEFAULT_PRESET, PRESETS, Preset
from .scene_reader import Table, collecting_warnings, raise_all, scene_system, warn
from .units import SYSTEMS, convert, display_text, majority_system

if TYPE_CHECKING:  # the sections' own modules, imported at run time only when the scene has the section
    from .closure.config import ClosureConfig
    from .completion import Completion
    from .coupling_config import CouplingConfig
    from .defaults import Derived
    from .estimate import Estimate
    from .fracture.config import FractureNumerics
    from .proppant.config import ProppantSetup
    from .wellbore import Wellbore

PHYSICS = ("fracture", "proppant")


@dataclass(frozen=True)
class RunConfig:
    """``[run]``; ``preset`` names the entry of :data:`hfgpu.presets.PRESETS` that gave the numerical
    knobs' defaults."""

    end_time: float
    physics: tuple[str, ...]
    seed: int = 0
    preset: str = DEFAULT_PRESET


@dataclass(frozen=True)
class Layer:
    """A horizontal layer between depths ``top`` < ``bottom`` [m]; None means "use the rock's value".

    The layer's stress at depth z is sigma_0(z) = ``min_stress`` + ``min_stress_gradient`` z (a scene's
    ``min_stress = "0.75 psi/ft"`` gives min_stress 0 and the gradient; a pressure gives gradient 0)."""

    top: float
    bottom: float
    min_stress: float | None = None
    toughness: float | None = None
    leakoff_coefficient: float | None = None
    pore_pressure: float | None = None
    min_stress_gradient: float = 0.0


@dataclass(frozen=True)
class Rock:
    """``[rock]``: sigma_0(z) = ``min_stress`` + ``min_stress_gradient`` z [Pa] where no layer gives a stress (as
    :class:`Layer`)."""

    youngs_modulus: float
    poisson_ratio: float
    toughness: float
    leakoff_coefficient: float
    min_stress: float
    layers: tuple[Layer, ...] = ()
    pore_pressure: float = 0.0
    min_stress_gradient: float = 0.0

    @property
    def plane_strain_modulus(self) -> float:
        """E' = E / (1 - nu^2), Eq. 1."""
        return self.youngs_modulus / (1.0 - self.poisson_ratio**2)

    def _layered(self, z: np.ndarray, name: str, gradient: str | None = None) -> np.ndarray:
        """Property ``name`` (+ ``gradient`` x z when given) at depths ``z``; the outermost layers extend to
        +-infinity."""
        z = np.asarray(z, dtype=float)
        out = np.full(z.shape, float(getattr(self, name)))
        if gradient:
            out += getattr(self, gradient) * z
        if not self.layers:
            return out
        ordered = sorted(self.layers, key=lambda layer: layer.top)
        for i, layer in enumerate(ordered):
            value = getattr(layer, name)
            if value is None:
                continue
            top = -math.inf if i == 0 else layer.top
            bottom = math.inf if i == len(ordered) - 1 else layer.bottom
            inside = (z >= top) & (z < bottom)
            out[inside] = value + (getattr(layer, gradient) if gradient else 0.0) * z[inside]
        return out

    def min_stress_at(self, z: np.ndarray) -> np.ndarray:
        """Minimum in-situ stress sigma_0(z) = sigma_c + (d sigma/dz) z [Pa] from the layer table, at each depth
        z (the cell centres: a gradient is evaluated per cell)."""
        return self._layered(z, "min_stress", "min_stress_gradient")

    def toughness_at(self, z: np.ndarray) -> np.ndarray:
        """K_Ic(z) [Pa m^0.5]."""
        return self._layered(z, "toughness")

    def leakoff_at(self, z: np.ndarray) -> np.ndarray:
        """Carter coefficient C_L(z) [m/s^0.5]."""
        return self._layered(z, "leakoff_coefficient")

    def pore_pressure_at(self, z: np.ndarray) -> np.ndarray:
        """Reservoir (pore) pressure p_r(z) [Pa] (closure stress on a proppant pack: sigma_0 - p_r)."""
        return self._layered(z, "pore_pressure")


@dataclass(frozen=True)
class Fluid:
    viscosity: float
    density: float = 1000.0


@dataclass(frozen=True)
class Stage:
    """A piecewise-constant pumping stage ending at ``until`` [s] with fluid rate ``rate`` [m^3/s].

    ``volume_fraction`` / ``end_volume_fraction`` is the proppant volume fraction of the slurry at the
    start / end of the stage (linear ramp in time); 0 for a pad stage.
    """

    until: float
    rate: float
    proppant: str | None = None
    volume_fraction: float = 0.0
    end_volume_fraction: float = 0.0

    def fraction_at(self, t: float, start: float) -> float:
        """Slurry volume fraction at time t of this stage, which began at ``start`` (linear ramp)."""
        s = (t - start) / (self.until - start)
        return self.volume_fraction + s * (self.end_volume_fraction - self.volume_fraction)


@dataclass(frozen=True)
class Schedule:
    stages: tuple[Stage, ...]

    @property
    def end(self) -> float:
        return self.stages[-1].until if self.stages else 0.0

    @property
    def pump_end(self) -> float | None:
        """The time [s] the pumps stop: the end of the last stage pumping at a rate > 0; None when none does."""
        pumping = [stage.until for stage in self.stages if stage.rate > 0.0]
        return float(pumping[-1]) if pumping else None

    def stage_index(self, t: float) -> int:
        """Index of the stage active during (t_prev, t]; -1 after the last stage (shut in)."""
        for i, stage in enumerate(self.stages):
            if t < stage.until:
                return i
        return -1

    def rate(self, t: float) -> float:
        """Injection rate Q(t) [m^3/s], constant within a stage, 0 after the last one."""
        i = self.stage_index(t)
        return 0.0 if i < 0 else self.stages[i].rate

    def volume(self, t: float) -> float:
        """Cumulative injected volume int_0^t Q dt [m^3] (exact for piecewise-constant Q)."""
        total, start = 0.0, 0.0
        for stage in self.stages:
            if t <= start:
                break
            total += stage.rate * (min(t, stage.until) - start)
            start = stage.until
        return total

    def mean_rate(self, t0: float, t1: float) -> float:
        """(V(t1) - V(t0)) / (t1 - t0): the rate that injects exactly the scheduled volume over a step."""
        return (self.volume(t1) - self.volume(t0)) / (t1 - t0)

    def breakpoints(self) -> tuple[float, ...]:
        return tuple(stage.until for stage in self.stages)

    def proppant_fraction(self, t: float) -> tuple[str | None, float]:
        """(class name, slurry volume fraction) injected at time t, ramped linearly within a stage."""
        i = self.stage_index(t)
        if i < 0:
            return None, 0.0
        start = 0.0 if i == 0 else self.stages[i - 1].until
        return self.stages[i].proppant, self.stages[i].fraction_at(t, start)

    def solid_volume(self, t0: float, t1: float) -> float:
        """Solids pumped over [t0, t1] [m^3]: int Q c dt, exact (Q constant and c linear within a stage)."""
        total, start = 0.0, 0.0
        for stage in self.stages:
            a, b = max(t0, start), min(t1, stage.until)
            if b > a:
                total += stage.rate * 0.5 * (stage.fraction_at(a, start) + stage.fraction_at(b, start)) * (b - a)
            start = stage.until
        return total


@dataclass(frozen=True)
class Injection:
    depth: float
    schedule: Schedule
    x: float = 0.0


@dataclass(frozen=True)
class Mesh:
    """The cell sizes in use [m]: ``dx``, ``dz`` = the scene's ``[mesh] cell_size`` / ``refinement``.

    ``max_cells_across`` (in use, i.e. the scene's value x refinement, at least 8) caps the footprint's cells
    along x or z (the fracture grid is coarsened beyond it, by ``coarsening_factor``: 3, merging 3 x 3, or 2,
    PyFrac's remeshing; see docs/scene.md), None for no cap.
    """

    dx: float
    dz: float
    max_cells_across: int | None = None
    refinement: float = 1.0
    coarsening_factor: int = 3

    @property
    def scene_cell_size(self) -> tuple[float, float]:
        """The scene's ``[mesh] cell_size`` (dx, dz) [m]: the cells at refinement 1."""
        return self.dx * self.refinement, self.dz * self.refinement


@dataclass(frozen=True)
class Output:
    every: float
    checkpoint_every: float | None = None
    units: str = "SI"  # "SI" or "field": the units of what is printed, plotted and exported (docs/scene.md)


@dataclass(frozen=True)
class Scene:
    """A scene as read: one typed frozen configuration per section (None where the scene has not the section or
    its physics), the TOML text and what was found while reading and checking it."""

    run: RunConfig
    fluid: Fluid
    mesh: Mesh
    output: Output
    rock: Rock | None = None
    injection: Injection | None = None
    fracture: FractureNumerics | None = None  # when "fracture" in physics
    proppant: ProppantSetup | None = None  # when "proppant" in physics
    coupling: CouplingConfig | None = None  # when physics has both "fracture" and "proppant"
    closure: ClosureConfig | None = None  # when "proppant" in physics
    wellbore: Wellbore | None = None  # when the scene has [wellbore] (with [injection])
    completion: Completion | None = None  # when the scene has [completion] (with "fracture")
    source: str = field(default="", repr=False, compare=False)  # the TOML text, stored in results
    #: The TOML text parsed (read-only; {} for a scene built in code): which keys the scene gives.
    document: dict = field(default_factory=dict, repr=False, compare=False)
    #: One line each: what the scene reader found suspect but valid (bare numbers); hfgpu.scene_checks adds more.
    warnings: tuple[str, ...] = field(default=(), repr=False, compare=False)
    #: The knobs given defaults from the scene's own scales (hfgpu.defaults.Derived: key, value, reason).
    derived: tuple[Derived, ...] = field(default=(), repr=False, compare=False)
    #: What hfgpu.estimate expects of the scene, set by hfgpu.scene_checks.validate; None before it or when there
    #: is nothing to expect.
    expected: Estimate | None = field(default=None, repr=False, compare=False)

    def has(self, physics: str) -> bool:
        return physics in self.run.physics

    def replace(self, **changes: Any) -> "Scene":
        return dataclasses.replace(self, **changes)


# ----------------------------------------------------------------------------------------------
# parsing


def load_scene(path_or_text: str | Path) -> Scene:
    """Read and validate a scene from a TOML file path or TOML text.

    Raises :class:`hfgpu.errors.SceneError` naming the key path, value and what is allowed.
    """
    text = _read_text(path_or_text)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError("(file)", str(path_or_text)[:80], f"not valid TOML: {exc}") from None
    return parse_scene(data, source=text)


def _read_text(path_or_text: str | Path) -> str:
    if isinstance(path_or_text, Path):
        return _read_file(path_or_text)
    if "\n" in path_or_text or "=" in path_or_text:
        return path_or_text
    return _read_file(Path(path_or_text))


def _read_file(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError("(file)", str(path), f"cannot read the scene file: {exc.strerror}") from None


def parse_scene(data: dict, source: str = "") -> Scene:
    """Validate a parsed TOML document into a :class:`Scene`.

    Every section is read even after another failed, so one :class:`~hfgpu.scene_reader.SceneErrors` reports the
    errors of all sections (within a section, the first error stops it); a section that needs a failed one
    (``[[proppant]]`` needs ``[run]``, ``[fluid]`` and ``[mesh]``; ``[closure]`` needs ``[[proppant]]`` and
    ``[rock]``; ``[coupling]`` needs ``[run]`` and ``[mesh]``) is skipped, so that one mistake is reported once. The
    warnings found while reading (bare numbers, :mod:`hfgpu.scene_reader`; gaps between layers; high proppant
    concentrations) are in ``Scene.warnings``. Bare numbers are judged by the scene's unit system
    (:func:`unit_system`). ``data`` is kept as ``Scene.document`` (not copied: the caller hands it over).
    """
    with collecting_warnings(unit_system(data)) as found:
        scene = _parse(data, source)
    return dataclasses.replace(scene, warnings=tuple(found))


def unit_system(data: dict) -> str:
    """The unit system a scene is written in: ``[output] units`` when it names one, else the system most of its
    unit-bearing values use (:func:`hfgpu.units.majority_system`)."""
    output = data.get("output")
    units = output.get("units") if isinstance(output, dict) else None
    return units if isinstance(units, str) and units in SYSTEMS else majority_system(data)


class _Sections:
    """Runs the parse of each section, keeping its SceneErrors; a failed section gives None."""

    def __init__(self, top: Table):
        self.top = top
        self.errors: list[SceneError] = []

    def __call__(self, keys: tuple[str, ...], parse, *args):
        try:
            return parse(*args)
        except SceneError as exc:
            self.errors.append(exc)
            for key in keys:  # read, so that the top table does not call them unknown
                self.top.raw(key, None)
            return None

    def skip(self, *keys: str) -> None:
        for key in keys:
            self.top.raw(key, None)


def _physics_of(data: dict) -> tuple[str, ...] | None:
    """``run.physics`` when ``[run]`` failed for another reason (else None)."""
    run = data.get("run")
    physics = run.get("physics", ["fracture"]) if isinstance(run, dict) else None
    physics = [physics] if isinstance(physics, str) else physics
    if isinstance(physics, list) and physics and all(p in PHYSICS for p in physics if isinstance(p, str)) \
            and all(isinstance(p, str) for p in physics) and len(set(physics)) == len(physics):
        return tuple(p for p in PHYSICS if p in physics)
    return None


def _parse(data: dict, source: str) -> Scene:
    top = Table(data, "")
    sections = _Sections(top)
    run = sections(("run",), lambda: _parse_run(top.table("run")))
    if run is not None:
        preset, physics = PRESETS[run.preset], run.physics
    else:
        given = data.get("run", {}).get("preset") if isinstance(data.get("run"), dict) else None
        preset = PRESETS.get(given, PRESETS[DEFAULT_PRESET]) if isinstance(given, str) else PRESETS[DEFAULT_PRESET]
        physics = _physics_of(data)
    fluid = sections(("fluid",), lambda: _parse_fluid(top.table("fluid")))
    mesh = sections(("mesh",), lambda: _parse_mesh(top.table("mesh"), preset))
    output = sections(("output",), lambda: _parse_output(top.table("output", {}),
                                                         run.end_time if run is not None else None, data))

    rock = injection = fracture = proppant = closure = coupling = None
    if physics is None:  # unknown physics: the sections below cannot be judged
        sections.skip("rock", "injection", "fracture", "proppant", "geometry", "mppic", "closure", "coupling")
        raise_all(sections.errors)
    needs_rock = "fracture" in physics
    rock_failed = False
    if needs_rock or top.has("rock"):
        rock = sections(("rock",), lambda: _parse_rock(top.table("rock")))
        rock_failed = rock is None
    if "fracture" in physics:
        from .fracture.config import parse_fracture_numerics

        fracture = sections(("fracture",), lambda: parse_fracture_numerics(top.table("fracture", {}), preset))
    proppant_failed = False
    if "proppant" in physics:
        keys = ("proppant", "geometry", "mppic")
        if run is None or fluid is None or mesh is None:
            sections.skip(*keys, "closure")
            proppant_failed = True
        else:
            from .proppant.config import parse_proppant_setup

            proppant = sections(keys, parse_proppant_setup, top, run, fluid, mesh)
            proppant_failed = proppant is None
            if proppant is not None and not rock_failed:
                from .closure.config import parse_closure

                closure = sections(("closure",), lambda: parse_closure(top.table("closure", {}), proppant, rock))
            else:
                sections.skip("closure")
    else:
        for key in ("proppant", "geometry", "mppic", "closure"):
            if top.has(key):
                top.raw(key)
                sections.errors.append(SceneError(key, "(table)", 'this section needs "proppant" in run.physics'))
    if needs_rock or top.has("injection"):
        densities = None if proppant_failed else (proppant.class_densities() if proppant is not None else {})
        injection = sections(("injection",), lambda: _parse_injection(top.table("injection"), densities))
    wellbore = None
    if top.has("wellbore") and injection is not None:
        from .wellbore import parse_wellbore

        wellbore = sections(("wellbore",), lambda: parse_wellbore(top.table("wellbore"), injection.depth))
    elif top.has("wellbore"):
        top.raw("wellbore")
        if not top.has("injection"):
            sections.errors.append(SceneError("wellbore", "(table)", "this section needs [injection]"))
    completion = _completion(top, sections, physics, injection, rock, mesh)
    if len(physics) > 1:
        if run is None or mesh is None:
            sections.skip("coupling")
        else:
            from .coupling_config import parse_coupling

            coupling = sections(("coupling",), lambda: parse_coupling(
                top.table("coupling", {}), run.end_time, mesh.refinement,
                fracture.front_tracking if fracture is not None else None))
        if completion is not None and coupling is not None and coupling.mode == "two-way":
            sections.errors.append(SceneError("coupling.mode", coupling.mode, 'a stage of clusters ([completion]) '
                                              'runs one-way only: set "one-way" or leave mode out'))
    elif top.has("coupling"):
        top.raw("coupling")
        sections.errors.append(SceneError("coupling", "(table)",
                                          'this section needs both "fracture" and "proppant" in run.physics'))
    sections((), top.finish)
    raise_all(sections.errors)
    from .defaults import derive

    scene = Scene(run=run, fluid=fluid, mesh=mesh, output=output, rock=rock, injection=injection,
                  fracture=fracture, proppant=proppant, coupling=coupling, closure=closure, wellbore=wellbore,
                  completion=completion, source=source, document=data)
    return derive(scene, data, preset)[0]


def _completion(top: Table, sections: _Sections, physics: tuple[str, ...], injection: Injection | None,
                rock: Rock | None, mesh: Mesh | None):
    """``[completion]`` (hfgpu.completion) when the scene has it: it needs "fracture" in run.physics ("proppant"
    beside it runs each cluster's proppant, hfgpu.coupled_stage), [injection], [rock] and [mesh], and no
    ``mesh.max_cells_across`` with several clusters (the planes share one grid, which is not coarsened)."""
    if not top.has("completion"):
        return None
    if "fracture" not in physics:
        top.raw("completion")
        sections.errors.append(SceneError("completion", "(table)", 'this section needs "fracture" in run.physics'))
        return None
    if injection is None or rock is None or mesh is None:
        sections.skip("completion")
        return None
    from .completion import parse_completion

    completion = sections(("completion",), lambda: parse_completion(top.table("completion"), injection.depth,
                                                                   rock.layers, max(mesh.dx, mesh.dz)))
    if completion is not None and completion.clusters > 1 and mesh.max_cells_across is not None:
        sections.errors.append(SceneError("mesh.max_cells_across", mesh.max_cells_across,
                                          "not with several [completion] clusters: their planes share one grid, "
                                          "which is not coarsened; remove it"))
    return completion


def _parse_run(t: Table) -> RunConfig:
    end_time = t.quantity("end_time", "time", minimum=0.0, exclusive_minimum=True)
    physics = t.raw("physics", ["fracture"])
    if isinstance(physics, str):
        physics = [physics]
    if (not isinstance(physics, list) or not physics or any(p not in PHYSICS for p in physics)
            or len(set(physics)) != len(physics)):
        raise SceneError(t.key_path("physics"), physics,
                         f"expected a non-empty list of distinct names from {list(PHYSICS)}")
    seed = t.integer("seed", 0, minimum=0)
    preset = t.choice("preset", PRESETS, DEFAULT_PRESET)
    t.finish()
    return RunConfig(end_time=end_time, physics=tuple(p for p in PHYSICS if p in physics), seed=seed,
                     preset=preset)


def _parse_fluid(t: Table) -> Fluid:
    fluid = Fluid(
        viscosity=t.quantity("viscosity", "viscosity", minimum=0.0, exclusive_minimum=True),
        density=t.quantity("density", "density", 1000.0, minimum=0.0, exclusive_minimum=True),
    )
    t.finish()
    return fluid


def _parse_mesh(t: Table, preset: Preset) -> Mesh:
    """``[mesh]``: cells in use = cell_size / refinement (default the preset's), cap x refinement (>= 8)."""
    size = t.raw("cell_size")
    path = t.key_path("cell_size")
    if isinstance(size, list):
        if len(size) != 2:
            raise SceneError(path, size, 'expected one length or two, ["dx", "dz"]')
        sizes = [Table({"cell_size": s}, t.path).quantity("cell_size", "length", minimum=0.0,
                                                          exclusive_minimum=True) for s in size]
    else:
        sizes = [t.quantity("cell_size", "length", minimum=0.0, exclusive_minimum=True)] * 2
    refinement = t.number("refinement", preset.refinement, minimum=0.01, maximum=100.0)
    cap = t.raw("max_cells_across", None)
    if cap is not None:
        cap = max(8, round(t.integer("max_cells_across", minimum=8) * refinement))
    factor = t.integer("coarsening_factor", 3, minimum=2, maximum=3)
    t.finish()
    return Mesh(dx=sizes[0] / refinement, dz=sizes[1] / refinement, max_cells_across=cap,
                refinement=refinement, coarsening_factor=factor)


#: Snapshots a run writes when ``[output] every`` is not given: every = end_time / DEFAULT_SNAPSHOTS.
DEFAULT_SNAPSHOTS = 10


def _parse_output(t: Table, end_time: float | None, data: dict) -> Output:
    """``[output]`` (optional, every key too): ``every`` defaults to end_time / DEFAULT_SNAPSHOTS;
    ``checkpoint_every`` is None when absent (the default rule of hfgpu.io.checkpoint), 0 for "0 s" or false (no
    checkpoints); ``units`` defaults to the system most unit-bearing values of the scene use
    (:func:`hfgpu.units.majority_system`). ``end_time`` None: [run] failed (the default spacing is then moot)."""
    default_every = (end_time if end_time is not None else 1.0) / DEFAULT_SNAPSHOTS
    every = t.quantity("every", "time", default_every, minimum=0.0, exclusive_minimum=True)
    off = t.raw("checkpoint_every", None) is False
    checkpoint = 0.0 if off else t.quantity("checkpoint_every", "time", None, minimum=0.0)
    units = t.choice("units", ("SI", "field"), None) if t.raw("units", None) is not None else majority_system(data)
    t.finish()
    return Output(every=every, checkpoint_every=checkpoint, units=units)


def _parse_rock(t: Table) -> Rock:
    """``[rock]`` and its ``[[rock.layers]]``: the errors of every layer are reported together."""
    errors: list[SceneError] = []
    try:
        rock = dict(
            youngs_modulus=t.quantity("youngs_modulus", "pressure", minimum=0.0, exclusive_minimum=True),
            poisson_ratio=t.number("poisson_ratio", minimum=0.0, maximum=0.5, exclusive_maximum=True),
            toughness=t.quantity("toughness", "toughness", 0.0, minimum=0.0),
            leakoff_coefficient=t.quantity("leakoff_coefficient", "leakoff", 0.0, minimum=0.0),
        )
        rock["min_stress"], rock["min_stress_gradient"] = t.stress("min_stress", 0.0)
        rock["pore_pressure"] = t.quantity("pore_pressure", "pressure", 0.0)
    except SceneError as exc:
        errors.append(exc)
    layers: list[tuple[int, Layer]] = []
    for i, lt in enumerate(t.tables("layers")):
        try:
            layers.append((i, _parse_layer(lt)))
        except SceneError as exc:
            errors.append(exc)
    raise_all(errors)
    background = Rock(**rock) if t.has("min_stress") else None
    raise_all(_tiling(t, layers, background))
    t.finish()
    return Rock(layers=tuple(layer for _, layer in layers), **rock)


def _tiling(t: Table, layers: list[tuple[int, Layer]], background: Rock | None) -> list[SceneError]:
    """The layers must tile the span from the shallowest top to the deepest bottom: an overlap is an error; a gap
    is an error too unless the scene gives ``[rock] min_stress`` (``background``): then the gap takes the rock's
    values, with a warning. Depths are shown in the scene's units (a boundary within 1e-9 relative is shared)."""
    system = scene_system()
    path = t.key_path("layers")

    def depth(z: float) -> str:
        return display_text(z, "depth", system, digits=6)

    errors: list[SceneError] = []
    ordered = sorted(layers, key=lambda item: item[1].top)
    for (i, above), (j, below) in zip(ordered, ordered[1:]):
        tolerance = 1e-9 * max(1.0, abs(above.bottom))
        top = t.data["layers"][j]["top"]
        if below.top < above.bottom - tolerance:
            errors.append(SceneError(f"{path}[{j}].top", top, f"layers must not overlap: {path}[{i}] spans "
                                     f"{depth(above.top)} to {depth(above.bottom)}, {path}[{j}] spans "
                                     f"{depth(below.top)} to {depth(below.bottom)}"))
        elif below.top > above.bottom + tolerance:
            gap = (f"a gap of {display_text(below.top - above.bottom, 'length', system, digits=6)} between "
                   f"{path}[{i}] (bottom {depth(above.bottom)}) and {path}[{j}] (top {depth(below.top)})")
            if background is not None:
                sigma = float(background.min_stress_at(np.array(above.bottom)))
                warn(f"{path}[{j}].top {depth(below.top)}: {gap} takes [rock]'s values there (min_stress "
                     f"{display_text(sigma, 'pressure', system)} at {depth(above.bottom)})")
            else:
                errors.append(SceneError(f"{path}[{j}].top", top, f"layers must tile their span: {gap}; close "
                                         "it, add a layer there, or give [rock] min_stress (gaps then take the "
                                         "rock's values)"))
    return errors


def _parse_layer(lt: Table) -> Layer:
    top, bottom = lt.quantity("top", "length"), lt.quantity("bottom", "length")
    min_stress, gradient = lt.stress("min_stress", None)
    layer = Layer(
        top=top,
        bottom=bottom,
        min_stress=min_stress,
        toughness=lt.quantity("toughness", "toughness", None, minimum=0.0),
        leakoff_coefficient=lt.quantity("leakoff_coefficient", "leakoff", None, minimum=0.0),
        pore_pressure=lt.quantity("pore_pressure", "pressure", None),
        min_stress_gradient=gradient,
    )
    if layer.bottom <= layer.top:
        raise SceneError(lt.key_path("bottom"), lt.data["bottom"],
                         f"a layer's bottom must lie below its top ({lt.data['top']!r}); depth is "
                         "positive downward")
    lt.finish()
    return layer


STAGE_ENDS = ("until", "duration", "clean_volume")


def _parse_injection(t: Table, proppant_densities: dict[str, float] | None) -> Injection:
    """``[injection]``; ``proppant_densities`` None: [[proppant]] failed, so any class name is taken (and a
    concentration's fraction is not checked)."""
    depth = t.quantity("depth", "length", 0.0)
    x = t.quantity("x", "length", 0.0)
    stages = []
    start = 0.0
    raw = t.raw("schedule")
    if not isinstance(raw, list) or not raw:
        raise SceneError(t.key_path("schedule"), raw, "expected a non-empty list of stages "
                         '[{ until = "370 s", rate = "0.053 m**3/s" }, ...]')
    for i, item in enumerate(raw):
        st = Table(item, f"{t.key_path('schedule')}[{i}]")
        ends = [key for key in STAGE_ENDS if st.has(key)]
        if len(ends) > 1:
            raise SceneError(st.key_path(ends[1]), item[ends[1]], f"give one of {list(STAGE_ENDS)}, not "
                             f"{ends}")
        rate = st.quantity("rate", "rate", minimum=0.0)
        name = st.string("proppant") if st.has("proppant") else None
        fraction = end_fraction = 0.0
        if name is not None and proppant_densities is None:  # [[proppant]] failed: its errors are reported
            fraction, end_fraction = _stage_fractions(st, None)
        elif name is not None:
            if name not in proppant_densities:
                raise SceneError(st.key_path("proppant"), name, "must name a [[proppant]] class: "
                                 f"{sorted(proppant_densities) or 'none defined'}")
            fraction, end_fraction = _stage_fractions(st, proppant_densities[name])
        else:
            for key in ("volume_fraction", "end_volume_fraction", "concentration", "end_concentration"):
                if st.has(key):
                    raise SceneError(st.key_path(key), item[key], "a proppant loading needs "
                                     "'proppant = \"<class name>\"' in the same stage")
        until = _stage_end(st, ends[0] if ends else "until", start, rate, 0.5 * (fraction + end_fraction))
        st.finish()
        stages.append(Stage(until=until, rate=rate, proppant=name, volume_fraction=fraction,
                            end_volume_fraction=end_fraction))
        start = until
    t.finish()
    return Injection(depth=depth, schedule=Schedule(tuple(stages)), x=x)


def _stage_end(st: Table, key: str, start: float, rate: float, mean_fraction: float) -> float:
    """End time of a stage that starts at ``start`` from ``until``, ``duration`` or ``clean_volume``.

    A clean volume V_c [m^3 of fluid without proppant] at slurry rate Q and slurry fraction phi(t), linear in
    time, lasts V_c / (Q (1 - mean phi)): the clean-fluid rate Q (1 - phi) is linear, so its mean is exact.
    """
    if key == "until":
        until = st.quantity("until", "time")
    elif key == "duration":
        until = start + st.quantity("duration", "time", minimum=0.0, exclusive_minimum=True)
    else:
        volume = st.quantity("clean_volume", "volume", minimum=0.0, exclusive_minimum=True)
        if rate <= 0.0:
            raise SceneError(st.key_path("clean_volume"), st.data["clean_volume"], "a stage that ends by "
                             "its clean volume needs a rate > 0; give 'until' or 'duration' for a shut-in")
        until = start + volume / (rate * (1.0 - mean_fraction))
    if until <= start:
        raise SceneError(st.key_path(key), st.data.get(key), f"stages must end in increasing time; this one "
                         f"must end after {start:g} s")
    return until


#: Proppant concentrations above this [ppa] are warned about: treatments pump up to about 8-12 ppa, so a larger
#: value is likely a typo (the error bound is the slurry volume fraction 0.6).
HIGH_CONCENTRATION_PPA = 12.0


def _stage_fractions(st: Table, density: float | None) -> tuple[float, float]:
    """Start/end slurry volume fraction of a stage from volume_fraction or concentration (ppa).

    A concentration c [kg per m^3 of clean fluid] gives the slurry fraction (c/rho_p) / (1 + c/rho_p): an error
    above 0.6, a warning for c above :data:`HIGH_CONCENTRATION_PPA`.
    """
    if st.has("volume_fraction") and st.has("concentration"):
        raise SceneError(st.key_path("concentration"), st.data["concentration"],
                         "give either 'volume_fraction' or 'concentration', not both")
    bounds = dict(minimum=0.0, maximum=0.6)
    if st.has("concentration"):
        c0 = st.quantity("concentration", "concentration", minimum=0.0)
        c1 = st.quantity("end_concentration", "concentration", c0, minimum=0.0)
        if density is None:
            return 0.0, 0.0
        fractions = [(c / density) / (1.0 + c / density) for c in (c0, c1)]
        high = convert(HIGH_CONCENTRATION_PPA, "ppa", "kg/m**3")
        for key, c, f in zip(("concentration", "end_concentration"), (c0, c1), fractions):
            if f > bounds["maximum"]:
                raise SceneError(st.key_path(key), st.data.get(key), "this loading gives a slurry "
                                 f"volume fraction {f:.3f}; allowed: <= 0.6")
            if c > high and st.has(key):
                system = scene_system()
                warn(f"scene key '{st.key_path(key)}': {st.data[key]!r} (slurry volume fraction {f:.3f}) is more "
                     f"than {display_text(high, 'concentration', system)}, about the most a treatment pumps: check "
                     "the value")
        return fractions[0], fractions[1]
    f0 = st.number("volume_fraction", **bounds)
    f1 = st.number("end_volume_fraction", f0, **bounds)
    return f0, f1
