"""The proppant part of a scene: ``[geometry]``, ``[[proppant]]`` and ``[mppic]``, parsed into a frozen
:class:`ProppantSetup` before any work starts.

Coordinates: x along the slot/fracture length, depth z positive downward, both in metres. For "box" and "slot"
the domain is [0, length] x [0, height] (depth 0 at the top); for "field" the grid is the one of the width file.

``[geometry]``
    ``kind = "box"`` (closed vessel, e.g. a settling column) | ``"slot"`` (uniform gap with inlets and
    outlets, e.g. Chun et al. 2020) | ``"field"`` (width map from a file). ``length, height, width`` (box,
    slot). ``file`` (field): ``.npz`` or ``.h5`` holding 1-D ``x`` (nx) and ``z`` (nz) cell-centre
    coordinates on a uniform grid [m] and ``w`` (nz, nx) [m], 0 = closed cell; a relative path is taken from
    the working directory. ``[[geometry.inlets]]`` and ``[[geometry.outlets]]``: ports (see :class:`Port`).
``[[proppant]]``
    ``name, density``, either ``diameter = "198 um"`` or ``size = "40/70"`` (sieve class, see
    :mod:`hfgpu.proppant.sieve`), ``distribution = "fixed" | "uniform" | "normal"`` (default fixed for a
    diameter, normal for a sieve class), ``mean_diameter``, ``std``, ``initial_volume_fraction`` (uniform
    suspension over the open domain at t = 0, default 0).
``[mppic]``
    numerics (:class:`MppicNumerics`) and every field of :class:`hfgpu.proppant.params.MppicParams` under its
    own name (closure constants).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError
from ..presets import BALANCED, PRESETS, Preset
from ..closure.config import ClassClosure, parse_class_closure
from ..kernels.arches import ARCHES
from ..scene_reader import Table
from .sieve import DISTRIBUTIONS, SizeDistribution, make_distribution, sieve_range

GEOMETRY_KINDS = ("box", "slot", "field")
PORT_KINDS = ("point", "segment", "annulus")
#: Directions an inlet's slurry may enter along as a jet (``jet``; "none": a source without momentum).
JET_DIRECTIONS = ("none", "+x", "-x", "+z", "-z")
BACKENDS = ("taichi", "numpy")
#: Placements of the initial suspension's parcels in their cells (hfgpu.proppant.injection.initial_suspension).
PLACEMENTS = ("lattice", "stratified")
GRAIN_PRESSURES = ("last", "two-step")


@dataclass(frozen=True)
class Port:
    """An inlet or outlet region in the (x, depth) plane.

    kind "point": the cell holding (x, depth); "segment": the cells crossed by the segment (x, depth) ->
    (x_end, depth_end); "annulus": the cells whose centres lie at a distance in [inner_radius, outer_radius]
    from (x, depth) (the cells around a perforation). ``share`` weights an inlet's part of the slurry rate
    (shares are normalised over the inlets). ``jet`` (inlets): "none" (default), the slurry appears in the
    cells without momentum (a perforation feeding the fracture from its face); "+x", "-x", "+z" or "-z", it
    enters through the domain's end wall along that axis (depth +z downward) at the speed Q_inlet / A, A the
    inlet's cross-section normal to the jet (:meth:`hfgpu.proppant.injection.Injector.jet_momentum`).
    """

    kind: str
    x: float
    depth: float
    x_end: float = 0.0
    depth_end: float = 0.0
    inner_radius: float = 0.0
    outer_radius: float = 0.0
    share: float = 1.0
    jet: str = "none"


@dataclass(frozen=True)
class Geometry:
    """The proppant domain: a uniform gap (box, slot) or a width map (field)."""

    kind: str
    length: float
    height: float
    width: float | None = None
    file: str | None = None
    field_x: np.ndarray | None = field(default=None, repr=False, compare=False)
    field_z: np.ndarray | None = field(default=None, repr=False, compare=False)
    field_w: np.ndarray | None = field(default=None, repr=False, compare=False)
    inlets: tuple[Port, ...] = ()
    outlets: tuple[Port, ...] = ()


@dataclass(frozen=True)
class ProppantClass:
    """One proppant: name, particle density [kg/m^3], size distribution, initial suspension fraction, closure keys
    (conductivity table, lab loading, factor: :class:`hfgpu.closure.config.ClassClosure`)."""

    name: str
    density: float
    size: SizeDistribution
    initial_volume_fraction: float = 0.0
    sieve: str | None = None
    closure: ClassClosure = ClassClosure()


@dataclass(frozen=True)
class MppicNumerics:
    """Numerical knobs of the MP-PIC run loop.

    backend/arch: particle engine and momentum kernels ("taichi" default, "numpy" reference); arch "cpu" or
    "cuda" (float64 kernels: Taichi's other backends lack it), None: HFGPU_ARCH or cpu.
    particles_per_parcel: real particles per parcel for every class; when None, it is chosen per class so
    that ``parcels_per_cell`` parcels fill a cell at the class's largest volume fraction (initial or
    injected).
    max_parcels: when set (and particles_per_parcel is not), the particles per parcel are raised so that the
    schedule's proppant makes at most this many parcels (a coupled scene's default, hfgpu.defaults).
    particle_substeps: particle sub-steps inside each fluid step (section 4.3).
    c_max: Courant limit of Eq. 42 (< 1); dt_max caps the fluid step [s]; max_step_retries: halvings of a
    step whose Courant number came out above c_max before giving up.
    simple_tolerance / simple_max_iterations: Algorithm 1 stopping rule (relative |p'|).
    gravity [m/s^2] acts along +depth.
    initial_placement: where the initial suspension's parcels sit in their cells, "lattice" (a quiet start:
    theta_p starts without sampling noise) or "stratified" (random; hfgpu.proppant.injection.initial_suspension).
    grain_pressure: the fluid pressure the parcels take during a fluid step (simulator.ProppantSimulation.step):
    "two-step" (default) = the mean of the two fluid steps before, which cancels a pressure that changes sign
    from one step to the next, "last" = that of the fluid step before (docs/proppant-closures.md, "Pressure the grains take").
    slurry_viscosity: the fluid phase uses the slurry viscosity of Eq. 10 (MppicParams.viscosity_law); false
    uses the clean-fluid viscosity. Eq. 10 diverges at close packing; the momentum predictor takes the
    in-plane diffusion and wall friction implicitly and MppicParams.max_relative_viscosity caps mu_f / mu_0,
    so it is on by default (the fluid of a packed bed is then held by its wall friction, Eq. 9). Known limit:
    that friction acts on the fluid velocity, not on the mixture's, so it also resists the fluid a growing bed
    expels through its top (Darcy flow, already in the drag); in a slow viscous sedimentation (the hindered-
    settling scene, theta_0 = 0.2) the pressure this builds lifts the suspension, and that scene turns it off.
    """

    backend: str = "taichi"
    arch: str | None = None
    particles_per_parcel: float | None = None
    parcels_per_cell: int = BALANCED.parcels_per_cell
    max_parcels: int | None = None
    particle_substeps: int = BALANCED.particle_substeps
    c_max: float = BALANCED.c_max
    dt_max: float = BALANCED.dt_max
    max_step_retries: int = 6
    simple_tolerance: float = BALANCED.simple_tolerance
    simple_max_iterations: int = 50
    gravity: float = 9.81
    slurry_viscosity: bool = True
    initial_placement: str = "lattice"
    grain_pressure: str = "two-step"


@dataclass(frozen=True)
class ProppantSetup:
    geometry: Geometry
    classes: tuple[ProppantClass, ...]
    numerics: MppicNumerics
    params: Any  # hfgpu.proppant.params.MppicParams

    def class_densities(self) -> dict[str, float]:
        """{class name: particle density [kg/m^3]} (used to turn ppa concentrations into fractions)."""
        return {c.name: c.density for c in self.classes}

    def class_index(self, name: str) -> int:
        return [c.name for c in self.classes].index(name)

    def with_sieve(self, size: str) -> "ProppantSetup":
        """Every class with the sieve class ``size`` ("30/50", "100 mesh", ...; normal distribution over its
        range), names kept so the schedule still refers to them: the size study's one change."""
        distribution = make_distribution("normal", *sieve_range(size))
        return dataclasses.replace(self, classes=tuple(dataclasses.replace(c, size=distribution, sieve=size)
                                                       for c in self.classes))


def parse_proppant_setup(top: Table, run: Any, fluid: Any, mesh: Any) -> ProppantSetup:
    """Read ``[geometry]``, ``[[proppant]]`` and ``[mppic]`` from the scene's top table."""
    if "fracture" in run.physics:  # coupled: grid and annular inlet come from the fracture (hfgpu.coupled)
        if top.has("geometry"):
            raise SceneError("geometry", "(table)", 'leave [geometry] out when run.physics has "fracture": the '
                             "proppant grid follows the fracture ([coupling] sets cell size and inlet ring)")
        geometry = Geometry(kind="fracture", length=0.0, height=0.0)
    else:
        geometry = _parse_geometry(top.table("geometry"))
    classes = _parse_classes(top)
    numerics, params = _parse_mppic(top.table("mppic", {}), PRESETS[run.preset])
    if geometry.kind == "field":
        _check_field_spacing(geometry, mesh)
    return ProppantSetup(geometry=geometry, classes=classes, numerics=numerics, params=params)


# ----------------------------------------------------------------------------------------------
# [geometry]


def _parse_geometry(t: Table) -> Geometry:
    kind = t.choice("kind", GEOMETRY_KINDS)
    inlets = tuple(_parse_port(p, inlet=True) for p in t.tables("inlets"))
    outlets = tuple(_parse_port(p, inlet=False) for p in t.tables("outlets"))
    if kind == "field":
        path = t.string("file")
        x, z, w = _read_width_file(t.key_path("file"), path)
        geometry = Geometry(kind=kind, length=float(x[-1] - x[0] + _spacing(x)),
                            height=float(z[-1] - z[0] + _spacing(z)), file=path, field_x=x, field_z=z,
                            field_w=w, inlets=inlets, outlets=outlets)
    else:
        positive = dict(minimum=0.0, exclusive_minimum=True)
        geometry = Geometry(kind=kind, length=t.quantity("length", "length", **positive),
                            height=t.quantity("height", "length", **positive),
                            width=t.quantity("width", "length", **positive), inlets=inlets, outlets=outlets)
    if kind == "slot" and (not inlets or not outlets):
        raise SceneError(t.key_path("inlets" if not inlets else "outlets"), "(none)",
                         'a "slot" needs at least one [[geometry.inlets]] and one [[geometry.outlets]]')
    t.finish()
    return geometry


def _parse_port(t: Table, inlet: bool) -> Port:
    kind = t.choice("kind", PORT_KINDS)
    values: dict[str, Any] = dict(kind=kind, x=t.quantity("x", "length"), depth=t.quantity("depth", "length"))
    if kind == "segment":
        values.update(x_end=t.quantity("x_end", "length"), depth_end=t.quantity("depth_end", "length"))
    if kind == "annulus":
        values.update(inner_radius=t.quantity("inner_radius", "length", 0.0, minimum=0.0))
        values.update(outer_radius=t.quantity("outer_radius", "length", minimum=values["inner_radius"],
                                              exclusive_minimum=True))
    if inlet:
        values.update(share=t.number("share", 1.0, minimum=0.0, exclusive_minimum=True),
                      jet=t.choice("jet", JET_DIRECTIONS, "none"))
    t.finish()
    return Port(**values)


def _read_width_file(path_key: str, path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x (nx), z (nz), w (nz, nx) from an .npz or .h5 width file, checked."""
    file = Path(path)
    if not file.is_file():
        raise SceneError(path_key, path, "no such width file (.npz or .h5 with arrays x, z, w)")
    try:
        if file.suffix == ".npz":
            with np.load(file) as data:
                x, z, w = (np.asarray(data[k], dtype=float) for k in ("x", "z", "w"))
        elif file.suffix in (".h5", ".hdf5"):
            import h5py

            with h5py.File(file, "r") as data:
                x, z, w = (np.asarray(data[k][()], dtype=float) for k in ("x", "z", "w"))
        else:
            raise SceneError(path_key, path, "allowed width files: .npz, .h5, .hdf5")
    except KeyError as exc:
        raise SceneError(path_key, path, f"the width file lacks array {exc}; it needs x, z, w") from None
    if x.ndim != 1 or z.ndim != 1 or w.shape != (z.size, x.size) or x.size < 2 or z.size < 2:
        raise SceneError(path_key, path, f"expected x (nx >= 2), z (nz >= 2) and w (nz, nx); got shapes "
                         f"{x.shape}, {z.shape}, {w.shape}")
    for name, axis in (("x", x), ("z", z)):
        steps = np.diff(axis)
        if np.any(steps <= 0) or np.ptp(steps) > 1e-9 * abs(steps[0]):
            raise SceneError(path_key, path, f"{name} must be uniformly spaced and increasing")
    if not np.all(np.isfinite(w)) or np.any(w < 0):
        raise SceneError(path_key, path, "w must be finite and >= 0 (0 = closed cell)")
    return x, z, w


def _spacing(axis: np.ndarray) -> float:
    return float(axis[1] - axis[0])


def _check_field_spacing(geometry: Geometry, mesh: Any) -> None:
    for name, axis, size in zip("xz", (geometry.field_x, geometry.field_z), mesh.scene_cell_size):
        if abs(_spacing(axis) - size) > 1e-9 * size:
            raise SceneError("mesh.cell_size", size, f"must equal the width file's {name} spacing "
                             f"{_spacing(axis):g} m for a \"field\" geometry")


# ----------------------------------------------------------------------------------------------
# [[proppant]]


def _parse_classes(top: Table) -> tuple[ProppantClass, ...]:
    tables = top.tables("proppant")
    if not tables:
        raise SceneError("proppant", "(none)", "at least one [[proppant]] class is required")
    classes = []
    for t in tables:
        name = t.string("name")
        if name in [c.name for c in classes]:
            raise SceneError(t.key_path("name"), name, "class names must be distinct")
        classes.append(ProppantClass(
            name=name,
            density=t.quantity("density", "density", minimum=0.0, exclusive_minimum=True),
            size=_parse_size(t),
            initial_volume_fraction=t.number("initial_volume_fraction", 0.0, minimum=0.0, maximum=0.6),
            sieve=t.data.get("size"),
            closure=parse_class_closure(t),
        ))
        t.finish()
    total = sum(c.initial_volume_fraction for c in classes)
    if total > 0.6:
        raise SceneError("proppant[*].initial_volume_fraction", total, "the classes' sum must be <= 0.6")
    return tuple(classes)


def _parse_size(t: Table) -> SizeDistribution:
    if t.has("diameter") == t.has("size"):
        raise SceneError(t.key_path("diameter"), t.data.get("diameter", t.data.get("size")),
                         'give exactly one of diameter = "198 um" or size = "40/70" (sieve class)')
    if t.has("diameter"):
        d = t.quantity("diameter", "length", minimum=0.0, exclusive_minimum=True)
        kind = t.choice("distribution", ("fixed",), "fixed")
        return make_distribution(kind, d, d)
    label = t.raw("size")
    try:
        d_min, d_max = sieve_range(str(label))
    except ValueError as exc:
        raise SceneError(t.key_path("size"), label, str(exc)) from None
    kind = t.choice("distribution", DISTRIBUTIONS, "normal")
    within = dict(minimum=d_min, maximum=d_max)
    mean = t.quantity("mean_diameter", "length", None, **within)
    std = t.quantity("std", "length", None, minimum=0.0, exclusive_minimum=True)
    return make_distribution(kind, d_min, d_max, mean, std)


# ----------------------------------------------------------------------------------------------
# [mppic]


def _parse_mppic(t: Table, preset: Preset = BALANCED) -> tuple[MppicNumerics, Any]:
    """``[mppic]``: numerics (the preset gives the defaults of its knobs) and closure constants."""
    d = MppicNumerics()
    positive = dict(minimum=0.0, exclusive_minimum=True)
    backend = t.choice("backend", BACKENDS, d.backend)
    arch = t.raw("arch", None)
    if arch is not None:
        arch = t.choice("arch", ARCHES)
    numerics = MppicNumerics(
        backend=backend,
        arch=arch,
        particles_per_parcel=t.number("particles_per_parcel", None, minimum=1.0),
        parcels_per_cell=t.integer("parcels_per_cell", preset.parcels_per_cell, minimum=1),
        max_parcels=t.integer("max_parcels", minimum=100) if t.has("max_parcels") else None,
        particle_substeps=t.integer("particle_substeps", preset.particle_substeps, minimum=1, maximum=1000),
        c_max=t.number("c_max", preset.c_max, maximum=1.0, exclusive_maximum=True, **positive),
        dt_max=t.quantity("dt_max", "time", preset.dt_max, **positive),
        max_step_retries=t.integer("max_step_retries", d.max_step_retries, minimum=0, maximum=30),
        simple_tolerance=t.number("simple_tolerance", preset.simple_tolerance, maximum=0.1, **positive),
        simple_max_iterations=t.integer("simple_max_iterations", d.simple_max_iterations, minimum=1),
        gravity=t.quantity("gravity", "acceleration", d.gravity, minimum=0.0),
        slurry_viscosity=t.boolean("slurry_viscosity", d.slurry_viscosity),
        initial_placement=t.choice("initial_placement", PLACEMENTS, d.initial_placement),
        grain_pressure=t.choice("grain_pressure", GRAIN_PRESSURES, d.grain_pressure),
    )
    params = _parse_params(t)
    t.finish()
    return numerics, params


def _parse_params(t: Table) -> Any:
    """MppicParams from the keys named like its fields; each value checked against the default's type."""
    from .params import MppicParams

    values: dict[str, Any] = {}
    for f in dataclasses.fields(MppicParams):
        if not t.has(f.name):
            continue
        default = getattr(MppicParams(), f.name)
        if isinstance(default, bool):
            values[f.name] = t.boolean(f.name)
        elif isinstance(default, int):
            values[f.name] = t.integer(f.name, minimum=1)
        elif isinstance(default, str):
            values[f.name] = t.string(f.name)
        else:
            values[f.name] = t.number(f.name)
    try:
        return MppicParams(**values)
    except SceneError:
        raise
    except (ValueError, TypeError) as exc:
        raise SceneError(t.path or "mppic", values, f"invalid closure parameters: {exc}") from None
