"""Defaults of the coupled run's numerical knobs, computed from the scene's own scales.

A coupled scene (``physics = ["fracture", "proppant"]``) that leaves a knob out gets a value from its pumping
schedule, scaled by the preset's ``time_scale`` s (fast 2, balanced 1, accurate 0.4) or ``parcel_budget``:

* ``[coupling] fracture_every`` = s min(T / 60, T_stage / 10), T the end time and T_stage the shortest pumped
  stage: the proppant run sees the width linear in time between two fracture snapshots, so a stage (a rate
  step, a ramp) is followed by ten of them and the run by sixty;
* ``[mppic] dt_max`` = s min(T_sand / 100, fracture_every / 2), T_sand the shortest stage carrying proppant: a
  hundred fluid steps over each ramp in ppa, two in each snapshot interval; the Courant limits (Eq. 42 and the
  parcels' own) bind below it;
* ``[mppic] max_parcels`` = the preset's ``parcel_budget`` when ``parcels_per_cell`` is not given: the
  particles per parcel are then raised so that the schedule's proppant makes at most that many parcels
  (:func:`hfgpu.proppant.simulator.particles_per_parcel`), so a long treatment's particle cost per step stays
  bounded.

A scene that gives a key keeps its value. Scenes without a fracture (lab cells, columns, slots) keep the preset's
constants. ``hfgpu check`` prints each value with its reason (:func:`hfgpu.presets.knob_report`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from .presets import Preset

#: Fracture snapshots per run and per shortest pumped stage (balanced).
RUN_SNAPSHOTS = 60
STAGE_SNAPSHOTS = 10
#: Fluid steps per shortest proppant stage and per fracture snapshot interval (balanced).
STAGE_STEPS = 100
INTERVAL_STEPS = 2


@dataclass(frozen=True)
class Derived:
    """One knob's scene-derived default: key path, value in use, and why (in words a user can check)."""

    key: str
    value: float
    reason: str


def stage_durations(schedule: Any) -> list[tuple[float, bool]]:
    """(duration [s], carries proppant) of each pumped stage (rate > 0) of a schedule."""
    out, start = [], 0.0
    for stage in schedule.stages:
        if stage.rate > 0.0 and stage.until > start:
            out.append((stage.until - start, stage.proppant is not None))
        start = stage.until
    return out


def _given(data: dict, section: str, key: str) -> bool:
    table = data.get(section)
    return isinstance(table, dict) and key in table


def derive(scene: Any, data: dict, preset: Preset) -> tuple[Any, tuple[Derived, ...]]:
    """The scene with the module docstring's defaults filled in where ``data`` (the scene's TOML) leaves them
    out, and the list of what was derived. Scenes that are not coupled come back unchanged."""
    if scene.coupling is None or scene.proppant is None or scene.injection is None:
        return scene, ()
    s = preset.time_scale
    end = scene.run.end_time
    stages = [(d, sand) for d, sand in stage_durations(scene.injection.schedule)]
    derived: list[Derived] = []
    coupling = scene.coupling
    if not _given(data, "coupling", "fracture_every"):
        shortest = min((d for d, _ in stages), default=end)
        run_part, stage_part = end / RUN_SNAPSHOTS, shortest / STAGE_SNAPSHOTS
        every = s * min(run_part, stage_part)
        why = (f"end time / {RUN_SNAPSHOTS}" if run_part <= stage_part
               else f"shortest pumped stage ({shortest:g} s) / {STAGE_SNAPSHOTS}")
        coupling = dataclasses.replace(coupling, fracture_every=every)
        derived.append(Derived("coupling.fracture_every", every, f"{why} x preset {s:g}"))
    numerics = scene.proppant.numerics
    if not _given(data, "mppic", "dt_max"):
        sand = min((d for d, carries in stages if carries), default=end)
        stage_part, interval_part = sand / STAGE_STEPS, coupling.fracture_every / INTERVAL_STEPS
        dt_max = min(s * stage_part, interval_part)
        why = (f"shortest proppant stage ({sand:g} s) / {STAGE_STEPS} x preset {s:g}" if s * stage_part <= interval_part
               else f"fracture_every / {INTERVAL_STEPS}")
        numerics = dataclasses.replace(numerics, dt_max=dt_max)
        derived.append(Derived("mppic.dt_max", dt_max, why))
    if numerics.max_parcels is None and numerics.particles_per_parcel is None \
            and not _given(data, "mppic", "parcels_per_cell"):
        numerics = dataclasses.replace(numerics, max_parcels=preset.parcel_budget)
        derived.append(Derived("mppic.max_parcels", preset.parcel_budget,
                               f"preset {preset.name}'s parcel budget: bounds the cost of a step"))
    proppant = dataclasses.replace(scene.proppant, numerics=numerics)
    return scene.replace(coupling=coupling, proppant=proppant, derived=tuple(derived)), tuple(derived)
