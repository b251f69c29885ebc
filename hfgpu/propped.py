"""Propped-area analysis of a results file (the paper, section 6.2 and Figs. 16, 18), from the file alone.

Definition (docs/field-case.md gives the reasoning). A cell is *propped* when the proppant it holds, packed at
close packing theta_cp, would make at least ``layers`` grain layers across the cell after closure:

    sum_parcels(n V_p) / (dx dz)  >=  layers * theta_cp * d_cell,

the left side being the areal solid volume theta_p w [m^3 per m^2 of fracture] counted exactly from the parcels
in the cell (nearest cell of each parcel's centre, independent of the scatter kernel) and d_cell the
solid-volume-weighted mean grain diameter of those parcels. One packed layer (``layers = 1``, default) is the
continuous monolayer: the least proppant that keeps both walls apart everywhere in the cell (Brannon et al.
2004, SPE 90698, on partial monolayers: below it the walls close between grains). *Created* area: the open
cells (width > 0) of the same grid.

*Packed* parcels: speed |u_p| below ``speed_threshold`` (default 1 mm/s, far below the ~cm/s hindered
settling speed of 40/70 to 100 mesh sand in a 2 mPa s fluid, so only parcels held in a bed or a bridge count)
or state 1 (bridged). The packed fraction is the share of parcels, as in the paper's probability plots.

*Parcel groups* (:func:`parcel_groups`, where the parcels are): ``bridged`` (state 1); ``bed at rest`` and
``moving bed``: resting in or on a dense bed or on the floor by the rule of bed friction
(hfgpu.proppant.particle_ops_numpy.on_bed: its own cell or the one below at theta_p >= friction_volume_fraction,
or within one diameter of a floor), slower / not slower than ``speed_threshold``; ``suspended``: the rest. Each
group gives its share of the parcels, its median and 90th-percentile speed and, for the bed groups, the share
below the threshold of motion: Shields number tau_b / ((rho_p - rho_f) g d) < theta_cr with tau_b = f_t
sqrt(12) mu |u_f| / w of the fluid's x velocity at the parcel (hfgpu.proppant.closures; docs/proppant-closures.md).

*Headline numbers* (:func:`headline_propped`, the one source of the run summary, ``propped_area.png``, the
sweep's metrics and maps): ``propped_area`` is the area propped after closure (hfgpu.closure: the grains settled
by ``[closure] settling``, at least ``[closure] layers`` packed layers per cell, at ``[closure] time``);
``propped_area_in_place`` is the one-layer rule above on the same snapshot with the grains where it holds them.
Both fractions are of the same ``created_area``: the fracture's final open area (one face; ``/summary`` ``area``),
or the open cells of the proppant grid in a proppant-only run. :data:`DEFINITIONS` words each for a label.

Public API: ``headline_propped(results)``, ``headline_created_area(results)``, ``closure_area_history(results)``,
``areal_solid(snap)``, ``propped_cells(snap, theta_cp, layers=1.0)``, ``created_area(snap)``,
``packed_fraction(parcels, speed_threshold)``, ``shields_ratio(snap, setup, ...)``, ``parcel_groups(snap, setup,
...)``, ``area_history(results, ...)``, ``fracture_area_history(results)``,
``packed_history(results, times, ...)``, ``propped_summary(results, ...)``, ``equivalent_times(start, end)``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .closure.pack import PACKED_SPEED
from .records import ProppantSnapshot

#: The groups of :func:`parcel_groups`, in print order.
GROUPS = ("suspended", "moving bed", "bed at rest", "bridged")
#: Times [s] of the paper's probability plots (Fig. 16).
PAPER_TIMES = (1260.0, 1800.0, 3600.0)
#: Each headline propped-area number by the name every output carries, and its definition in words.
DEFINITIONS = {"propped_area": "after closure (grains settled by [closure] settling)",
               "propped_area_in_place": "one packed grain layer, grains in place (no settling)"}


def equivalent_times(start: float, end: float) -> tuple[float, ...]:
    """The paper's Fig. 16 times (1260, 1800, 3600 s of a 1200-3600 s slurry period) mapped onto a slurry
    period [start, end]: the same fractions 0.025, 0.25 and 1 of it (identical to PAPER_TIMES for the base case)."""
    fractions = [(t - 1200.0) / 2400.0 for t in PAPER_TIMES]
    return tuple(start + f * (end - start) for f in fractions)


def results_times(results: Any) -> tuple[float, ...]:
    """:func:`equivalent_times` over the proppant snapshots' span of a results file."""
    times = _results(results).proppant_snapshots.times
    return equivalent_times(float(times[0]), float(times[-1])) if times.size else PAPER_TIMES


def _results(results: Any):
    """An open :class:`hfgpu.io.results.Results` (a path is opened)."""
    if isinstance(results, (str, Path)):
        from .io.results import open_results

        return open_results(results)
    return results


def areal_solid(snap: ProppantSnapshot) -> tuple[np.ndarray, np.ndarray]:
    """(theta_p w [m], mean diameter [m]) per cell: the parcels' solid volume per unit fracture area and its
    solid-volume-weighted mean grain diameter (0 where the cell holds no parcel)."""
    shape = np.shape(snap.grid["width"])
    f = snap.frame
    solid, moment = np.zeros(shape), np.zeros(shape)
    p = snap.parcels
    if len(p["x"]):
        i = np.clip(np.floor((p["x"] - f.x0) / f.dx + 0.5).astype(int), 0, shape[1] - 1)
        k = np.clip(np.floor((p["z"] - f.z0) / f.dz + 0.5).astype(int), 0, shape[0] - 1)
        radius = np.asarray(p["radius"], dtype=np.float64)
        volume = np.asarray(p["particles"], dtype=np.float64) * 4.0 / 3.0 * np.pi * radius**3
        np.add.at(solid, (k, i), volume)
        np.add.at(moment, (k, i), volume * 2.0 * radius)
    diameter = np.divide(moment, solid, out=np.zeros(shape), where=solid > 0.0)
    return solid / (f.dx * f.dz), diameter


def propped_cells(snap: ProppantSnapshot, theta_cp: float, layers: float = 1.0) -> np.ndarray:
    """Open cells holding at least ``layers`` packed grain layers: theta_p w >= layers theta_cp d_cell."""
    if not (0.0 < theta_cp < 1.0 and layers > 0.0):
        raise ValueError(f"propped_cells: theta_cp = {theta_cp}, layers = {layers}; need 0 < theta_cp < 1, "
                         "layers > 0")
    solid, diameter = areal_solid(snap)
    width = np.asarray(snap.grid["width"])
    return (width > 0.0) & (solid > 0.0) & (solid >= layers * theta_cp * diameter)


def created_area(snap: ProppantSnapshot) -> float:
    """Open (width > 0) area [m^2] of a proppant snapshot's grid (one face of the fracture)."""
    return float(np.count_nonzero(np.asarray(snap.grid["width"]) > 0.0)) * snap.frame.dx * snap.frame.dz


def packed_fraction(parcels: dict[str, np.ndarray], speed_threshold: float = PACKED_SPEED) -> float:
    """Share of parcels that are packed: |u_p| < speed_threshold or bridged (state 1); NaN without parcels."""
    speed = np.hypot(parcels["u"], parcels["v"])
    if speed.size == 0:
        return float("nan")
    return float(np.mean((speed < speed_threshold) | (np.asarray(parcels["state"]) == 1)))


def shields_ratio(snap: ProppantSnapshot, setup: Any, fluid_density: float, viscosity: float) -> np.ndarray:
    """Per parcel, its Shields number over the critical one (hfgpu.kernels.closures.bed): tau_b = f_t sqrt(12) mu
    |u_f| / w of the fluid's x velocity u_f at the parcel (linear between its cell's x faces) and its cell's
    width w; below 1 the grain would rest on a bed surface. ``setup`` is the scene's ProppantSetup."""
    from .kernels.closures import bed
    from .kernels.stencil_numpy import owning_cell

    p, f = snap.parcels, snap.frame
    width = np.asarray(snap.grid["width"])
    k, i, _ = owning_cell(p["x"], p["z"], f, width.shape)
    fluid_u = np.asarray(snap.grid["fluid_u"])  # x faces (nz, nx + 1)
    a = np.clip((p["x"] - f.x0) / f.dx + 0.5 - i, 0.0, 1.0)
    u_f = fluid_u[k, i] + a * (fluid_u[k, i + 1] - fluid_u[k, i])
    diameter, rho_p, g = 2.0 * np.asarray(p["radius"]), np.asarray(p["density"]), setup.numerics.gravity
    tau = bed.bed_shear_stress_numpy(u_f, np.maximum(width[k, i], 1e-300), fluid_density, viscosity,
                                     setup.params.wall_friction_code)
    return bed.shields_number_numpy(tau, diameter, rho_p, fluid_density, g) \
        / bed.critical_shields_number_numpy(diameter, rho_p, fluid_density, viscosity, g)


def parcel_groups(snap: ProppantSnapshot, setup: Any, fluid_density: float, viscosity: float,
                  speed_threshold: float = PACKED_SPEED) -> dict[str, dict[str, dict[str, float]]]:
    """Where the parcels of a snapshot are (module docstring): {class name: {group: {"share", "count",
    "median_speed", "p90_speed", "subcritical"}}} over :data:`GROUPS`, plus the class's ``"all"`` count.
    ``setup`` is the scene's ProppantSetup (classes, params, gravity); ``viscosity`` the clean fluid's [Pa s].
    Shares are of the class's parcels; speeds [m/s] are NaN and ``subcritical`` NaN for an empty group."""
    from .proppant.particle_ops_numpy import on_bed

    p = {k: np.asarray(v) for k, v in snap.parcels.items()}
    width, theta = np.asarray(snap.grid["width"]), np.asarray(snap.grid["volume_fraction"])
    speed = np.hypot(p["u"], p["v"])
    bridged = p["state"] == 1
    bed = on_bed(p["x"], p["z"], p["radius"], snap.frame, width, theta, setup.params) & ~bridged
    member = {"suspended": ~bridged & ~bed, "moving bed": bed & (speed >= speed_threshold),
              "bed at rest": bed & (speed < speed_threshold), "bridged": bridged}
    below = shields_ratio(snap, setup, fluid_density, viscosity) < 1.0
    out = {}
    for cid, cls in enumerate(setup.classes):
        mine = p["class_id"] == cid
        n = int(mine.sum())
        groups: dict[str, dict[str, float]] = {"all": {"count": n}}
        for name in GROUPS:
            m = mine & member[name]
            count = int(m.sum())
            groups[name] = dict(share=count / n if n else float("nan"), count=count,
                                median_speed=float(np.median(speed[m])) if count else float("nan"),
                                p90_speed=float(np.percentile(speed[m], 90.0)) if count else float("nan"),
                                subcritical=float(np.mean(below[m])) if count and "bed" in name else float("nan"))
        out[cls.name] = groups
    return out


def _theta_cp(results, theta_cp: float | None) -> float:
    return theta_cp if theta_cp is not None else results.scene.proppant.params.theta_cp


def area_history(results: Any, theta_cp: float | None = None, layers: float = 1.0) -> dict[str, np.ndarray]:
    """At each proppant snapshot: time [s], created and propped area [m^2], propped fraction.
    ``theta_cp`` defaults to the stored scene's ``[mppic] theta_cp``."""
    results = _results(results)
    cp = _theta_cp(results, theta_cp)
    rows = []
    for snap in results.proppant_snapshots:
        created = created_area(snap)
        propped = float(propped_cells(snap, cp, layers).sum()) * snap.frame.dx * snap.frame.dz
        rows.append((snap.time, created, propped, propped / created if created > 0.0 else np.nan))
    names = ("time", "created", "propped", "fraction")
    columns = np.array(rows, dtype=np.float64).reshape(-1, 4).T
    return dict(zip(names, columns))


def fracture_area_history(results: Any) -> dict[str, np.ndarray]:
    """time [s] and open area [m^2] of every fracture snapshot (the whole treatment, pad included)."""
    results = _results(results)
    rows = [(s.time, float(np.count_nonzero(np.asarray(s.width) > 0.0)) * s.frame.dx * s.frame.dz)
            for s in results.fracture_snapshots]
    time, area = np.array(rows, dtype=np.float64).reshape(-1, 2).T
    return dict(time=time, area=area)


def packed_history(results: Any, times: tuple[float, ...] | None = None,
                   speed_threshold: float = PACKED_SPEED) -> list[tuple[float, float]]:
    """(snapshot time, packed fraction) at the proppant snapshots nearest to ``times`` (default
    :func:`results_times`: the paper's 1260 / 1800 / 3600 s for the base case)."""
    results = _results(results)
    times = results_times(results) if times is None else times
    out = []
    for t in times:
        snap = results.proppant_snapshots.at(t)
        out.append((snap.time, packed_fraction(snap.parcels, speed_threshold)))
    return out


def propped_summary(results: Any, theta_cp: float | None = None, layers: float = 1.0,
                    speed_threshold: float = PACKED_SPEED) -> dict[str, float]:
    """The paper study's numbers (the in-place rule, not the headline: :func:`headline_propped`). At the last
    proppant snapshot: created_area, propped_area [m^2], propped_fraction, packed_fraction,
    screen_out_cells (cells flagged ``bridging_risk``, 0 when the file has no such field), time."""
    results = _results(results)
    snap = results.proppant_snapshots[-1]
    cp = _theta_cp(results, theta_cp)
    created = created_area(snap)
    propped = float(propped_cells(snap, cp, layers).sum()) * snap.frame.dx * snap.frame.dz
    risk = snap.grid.get("bridging_risk")
    return dict(time=snap.time, created_area=created, propped_area=propped,
                propped_fraction=propped / created if created > 0.0 else float("nan"),
                packed_fraction=packed_fraction(snap.parcels, speed_threshold),
                screen_out_cells=int(np.count_nonzero(risk)) if risk is not None else 0)


def headline_created_area(results: Any, snap: ProppantSnapshot | None = None) -> float:
    """The created area [m^2] every headline fraction is of (one face): ``/summary`` ``area`` (``fracture_area``
    in a coupled run), else the open cells of ``snap`` (proppant-only runs; NaN without either)."""
    s = _results(results).summary
    for key in ("area", "fracture_area"):
        if key in s and np.isfinite(float(s[key])):
            return float(s[key])
    return created_area(snap) if snap is not None else float("nan")


def headline_propped(results: Any, scene: Any = None) -> dict[str, float]:
    """The headline propped-area numbers of a results file (module docstring; ``scene`` defaults to the stored
    one): time [s] of the closed snapshot, created_area, propped_area, propped_area_in_place [m^2] and the
    fractions propped_fraction = propped_area / created_area, propped_fraction_in_place likewise."""
    from .closure.conductivity import closure_of

    results = _results(results)
    closure = closure_of(results, scene)
    snap = results.proppant_snapshots.at(closure.scalars["time"])
    theta_cp = (results.scene if scene is None else scene).proppant.params.theta_cp
    in_place = float(propped_cells(snap, theta_cp).sum()) * snap.frame.dx * snap.frame.dz
    created = headline_created_area(results, snap)
    propped = float(closure.scalars["propped_area"])

    def share(area: float) -> float:
        return area / created if created > 0.0 else float("nan")

    return dict(time=float(closure.scalars["time"]), created_area=created, propped_area=propped,
                propped_fraction=share(propped), propped_area_in_place=in_place,
                propped_fraction_in_place=share(in_place))


def closure_area_history(results: Any, scene: Any = None) -> dict[str, np.ndarray]:
    """time [s] and ``propped_area`` [m^2] after closure (:func:`headline_propped`'s definition) of every proppant
    snapshot: the walls closed on each snapshot's grains in turn (``scene`` defaults to the stored one)."""
    from .closure.conductivity import close

    results = _results(results)
    scene = results.scene if scene is None else scene
    rows = [(snap.time, close(snap, scene).scalars["propped_area"]) for snap in results.proppant_snapshots]
    time, area = np.array(rows, dtype=np.float64).reshape(-1, 2).T
    return dict(time=time, propped_area=area)
