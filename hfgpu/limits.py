"""Limits checked before a run does any work: scenes the engines cannot run are refused with a SceneError that
names the key, the value and the allowed range (``check_limits(scene)``, called by :func:`hfgpu.runner.run`).

Only real limits are here, each with its reason (docs/stability.md has the matrix that found them):

* slurry denser than close packing: a stage's proppant volume fraction (and the initial suspension) must not
  exceed theta_cp, the close-packing fraction at which the interparticle stress of the paper's Eq. 16 diverges
  and the slurry viscosity of Eq. 10 is singular: no fluid can carry such a slurry;
* parcel memory: the MP-PIC state holds every parcel in memory (plus per-step work arrays); a scene whose
  initial suspension and scheduled proppant would make more parcels than fit in the machine's memory is
  refused up front instead of failing hours in.

:func:`check_engine_start` (called by :func:`hfgpu.scene_checks.validate`, so by ``hfgpu check`` and ``hfgpu run``,
not by ``check_limits``) raises what the fracture engine would refuse at its first step: a first stage with rate 0,
and a starting fracture of ``fracture.initial_radius_cells`` cells (of the cells in use, after the preset's
refinement) that would take longer than half the schedule to form.
"""

from __future__ import annotations

import os

import numpy as np

from .errors import SceneError

#: Host memory one parcel costs during a run [bytes]: its 9 state arrays (7 float64, 2 int32: 64 B), the
#: step's saved copy, the gathered fluid and the bilinear weights of the particle kernels, the snapshot copy.
#: Measured: 434 B (peak resident memory of a 1.02e6-parcel Taichi run less a 1e4-parcel one, per parcel,
#: docs/stability.md); about twice that leaves room for the copies made when parcels are appended.
BYTES_PER_PARCEL = 1024
#: Host memory one proppant grid cell costs [bytes]: the grid's fields, the fluid state and the SIMPLE matrices.
#: Measured: ~1.3 kB (peak resident memory of a 1e5-cell box after one step less a 1e4-cell one, per cell, less
#: their parcels); rounded up as BYTES_PER_PARCEL is.
BYTES_PER_CELL = 2048


def physical_memory() -> int:
    """This machine's physical memory [bytes] (os.sysconf), or 0 where it cannot be read."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 0


def check_limits(scene, memory: int | None = None) -> None:
    """Raise :class:`SceneError` for a scene beyond the limits above; ``memory`` [bytes] defaults to
    :func:`physical_memory`."""
    if scene.proppant is None:
        return
    _check_packing(scene)
    memory = physical_memory() if memory is None else memory
    if memory > 0:  # 0: the platform does not report it
        grid = _check_grid_memory(scene, memory)  # before the parcel estimate, which builds the grid
        _check_parcel_memory(scene, memory - grid)


def check_engine_start(scene) -> None:
    """The fracture engine's start-up checks (hfgpu.fracture.simulator): what it would refuse at its first step."""
    if scene.fracture is None:
        return
    import importlib

    engine = importlib.import_module("hfgpu.fracture.simulator")
    if hasattr(engine, "start_time"):  # (a stand-in simulator of the tests has neither check)
        engine.check_scene(scene)
        _start_check(scene, engine)


def _start_check(scene, engine) -> None:
    """The starting radial fracture (``fracture.initial_radius_cells`` x the larger cell in use) must form, at the
    schedule's rates (divided among the clusters of a stage), within half the schedule and while a stage injects
    (as :func:`hfgpu.fracture.simulator.simulate` requires)."""
    import math

    K_PRIME_FACTOR, start_time = engine.K_PRIME_FACTOR, engine.start_time
    rock, inj, numerics = scene.rock, scene.injection, scene.fracture
    r0 = numerics.initial_radius_cells * max(scene.mesh.dx, scene.mesh.dz)
    k0 = K_PRIME_FACTOR * float(rock.toughness_at(np.array(inj.depth)))
    c0 = 2.0 * float(rock.leakoff_at(np.array(inj.depth)))
    schedule = inj.schedule
    completion = getattr(scene, "completion", None)
    if completion is not None and completion.clusters > 1:   # each cluster's fracture starts at Q / N
        from .fracture.stage import ClusterInlet

        schedule = ClusterInlet(schedule, 1.0 / completion.clusters)
    t0, _ = start_time(schedule, rock.plane_strain_modulus, 12.0 * scene.fluid.viscosity, k0, c0, r0)
    if t0 >= 0.5 * inj.schedule.end or inj.schedule.rate(t0) <= 0.0:
        from .units import display_unit, format_number, in_display_units

        def length(value: float) -> str:
            system = scene.output.units
            return f"{format_number(in_display_units(value, 'length', system), 3)} {display_unit('length', system)}"

        took = "longer than the schedule" if math.isinf(t0) else f"{t0:.3g} s"
        raise SceneError("fracture.initial_radius_cells", numerics.initial_radius_cells,
                         f"the starting fracture (radius {length(r0)}: this many cells of {length(scene.mesh.dx)} x "
                         f"{length(scene.mesh.dz)} in use) would take {took} to form, past half the schedule "
                         f"({inj.schedule.end:g} s) or in a stage that does not inject; use finer cells (or a "
                         "preset that does not coarsen them)")


def _check_packing(scene) -> None:
    """Slurry and initial suspension volume fractions <= theta_cp (Eq. 10, 16 diverge there)."""
    theta_cp = scene.proppant.params.theta_cp
    allowed = (f"at most theta_cp = {theta_cp:g} (mppic.theta_cp): a slurry denser than close packing cannot "
               "flow (Eq. 10 and 16 of the paper diverge at theta_cp)")
    if scene.injection is not None:
        for i, stage in enumerate(scene.injection.schedule.stages):
            for key in ("volume_fraction", "end_volume_fraction"):
                value = getattr(stage, key)
                if value > theta_cp:
                    raise SceneError(f"injection.schedule[{i}].{key}", value, allowed)
    total = sum(c.initial_volume_fraction for c in scene.proppant.classes)
    if total > theta_cp:
        raise SceneError("proppant[*].initial_volume_fraction", total, f"their sum must be {allowed}")


def estimated_parcels(scene) -> float | None:
    """Parcels the scene will create: its initial suspension plus the scheduled proppant over parcels of
    ``particles_per_parcel`` particles (hfgpu.proppant.simulator.particles_per_parcel); None for a coupled
    scene without a fixed ``particles_per_parcel`` (its grid is known only once the fracture has run)."""
    from .proppant.simulator import build_grid, particles_per_parcel

    setup = scene.proppant
    schedule = scene.injection.schedule if scene.injection is not None else None
    if setup.geometry.kind == "fracture":
        if setup.numerics.particles_per_parcel is None:
            return None
        cell_volumes = np.zeros(0)
        ppp = [setup.numerics.particles_per_parcel] * len(setup.classes)
    else:
        grid = build_grid(setup.geometry, scene.mesh.dx, scene.mesh.dz)
        cell_volumes = grid.cell_volume[grid.active]
        ppp = particles_per_parcel(setup, schedule, float(np.median(cell_volumes)))
    total = 0.0
    for c, cls in enumerate(setup.classes):
        parcel = ppp[c] * cls.size.mean_particle_volume()
        if cls.initial_volume_fraction > 0.0:
            total += float(np.sum(np.maximum(1.0, np.rint(cls.initial_volume_fraction * cell_volumes / parcel))))
        start = 0.0
        for stage in (schedule.stages if schedule is not None else ()):
            if stage.proppant == cls.name:
                mean_fraction = 0.5 * (stage.volume_fraction + stage.end_volume_fraction)
                total += stage.rate * (stage.until - start) * mean_fraction / parcel
            start = stage.until
    return total


def grid_cells(scene) -> float:
    """Cells of a box or slot scene's proppant grid (hfgpu.proppant.simulator.box_shape) without building it; 0
    for other geometries (a coupled grid is known only once the fracture has run; a width file's grid is already
    read)."""
    from .proppant.simulator import box_shape

    geometry = scene.proppant.geometry
    if geometry.kind not in ("box", "slot"):
        return 0.0
    nz, nx = box_shape(geometry, scene.mesh.dx, scene.mesh.dz)
    return float(nz) * float(nx)


def _check_grid_memory(scene, memory: int) -> int:
    """grid_cells x BYTES_PER_CELL must fit in ``memory``; returns those bytes."""
    geometry, cells = scene.proppant.geometry, grid_cells(scene)
    most = memory / BYTES_PER_CELL
    if cells > most:
        raise SceneError("mesh.cell_size", f"{scene.mesh.dx:g} x {scene.mesh.dz:g} m",
                         f"the {geometry.length:g} x {geometry.height:g} m {geometry.kind} would have ~{cells:.3g} "
                         f"cells; at most {most:.3g} fit in this machine's {memory / 2**30:.3g} GiB "
                         f"({BYTES_PER_CELL} bytes per cell): use larger cells or a smaller geometry")
    return int(cells * BYTES_PER_CELL)


def _check_parcel_memory(scene, memory: int) -> None:
    """Estimated parcels x BYTES_PER_PARCEL must fit in ``memory`` (what the grid leaves)."""
    count = estimated_parcels(scene)
    if count is None:
        return
    most = memory / BYTES_PER_PARCEL
    if count <= most:
        return
    numerics = scene.proppant.numerics
    if numerics.particles_per_parcel is not None:
        key, value = "mppic.particles_per_parcel", numerics.particles_per_parcel
    else:
        key, value = "mppic.parcels_per_cell", numerics.parcels_per_cell
    change = "raise it" if key.endswith("particles_per_parcel") else "lower it"
    raise SceneError(key, value, f"this scene would make ~{count:.3g} parcels; at most {most:.3g} fit in this "
                     f"machine's {memory / 2**30:.3g} GiB ({BYTES_PER_PARCEL} bytes per parcel): {change} by a "
                     f"factor of at least {count / most:.3g}")
