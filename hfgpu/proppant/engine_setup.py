"""What the MP-PIC proppant engine reads, as one typed frozen value (:class:`ProppantEngineSetup`), and the one
function that builds it from a scene (:func:`proppant_engine_setup`). The engine (simulator.ProppantSimulation)
takes only this, never the scene."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .config import Geometry, MppicNumerics, Port, ProppantClass

if TYPE_CHECKING:
    from ..scene import Fluid, Schedule
    from .params import MppicParams


@dataclass(frozen=True)
class ProppantEngineSetup:
    """One proppant run's engine configuration (SI units, the scene's clock).

    The run starts at ``start`` (0; a coupled run's proppant start) and ends at ``end_time``, with snapshots at
    ``start`` + k ``output_every`` and at the end. ``geometry`` is the domain the engine runs and its ports: the
    scene's ``[geometry]``, or a coupled run's field on the fracture's grid; a schedule's slurry enters through
    its inlets (a point at the perforation when it has none). ``schedule``: the injection on the scene's clock
    (None: no inlet). ``cell_size``: (dx, dz) [m] of a box or slot grid (a field brings its own). ``two_way``:
    the scene's ``[coupling] mode`` is "two-way" (the fracture feels the slurry; the run's warnings say so)."""

    classes: tuple[ProppantClass, ...]
    params: MppicParams
    numerics: MppicNumerics
    geometry: Geometry
    fluid: Fluid
    cell_size: tuple[float, float]
    schedule: Schedule | None
    start: float
    end_time: float
    output_every: float
    seed: int
    units: str                           # the unit system of its messages ([output] units)
    two_way: bool = False


def proppant_engine_setup(scene, geometry: Geometry | None = None, start: float = 0.0) -> ProppantEngineSetup:
    """The proppant engine's setup of a scene with ``[[proppant]]``: its classes, ``[mppic]`` closures and
    numerics, fluid, cell size, schedule, seed, end time and output interval; ``geometry`` in place of the
    scene's (a coupled run's field), ``start`` [s] the time the run starts at (a coupled run's proppant
    start)."""
    proppant, injection = scene.proppant, scene.injection
    geometry = proppant.geometry if geometry is None else geometry
    schedule = injection.schedule if injection is not None else None
    if schedule is not None and not geometry.inlets:
        geometry = dataclasses.replace(geometry, inlets=(Port("point", x=injection.x, depth=injection.depth),))
    return ProppantEngineSetup(classes=proppant.classes, params=proppant.params, numerics=proppant.numerics,
                               geometry=geometry, fluid=scene.fluid, cell_size=(scene.mesh.dx, scene.mesh.dz),
                               schedule=schedule, start=start, end_time=scene.run.end_time,
                               output_every=scene.output.every, seed=scene.run.seed, units=scene.output.units,
                               two_way=scene.coupling is not None and scene.coupling.mode == "two-way")
