"""Scene builders and invariant checks of the stability matrix (tests/test_extremes.py).

Each check reads a results file (:func:`hfgpu.open_results`) and returns the margin it measured, so the tests
can assert it and docs/stability.md can quote it. The invariants (issue 5):

* fracture volume balance: injected = stored + leaked within 0.1 % at every step (conservation);
* no NaN/Inf in width, pressure, parcel positions and velocities, grid fields;
* the footprint never shrinks and the front extents never retreat while the rate is > 0;
* theta_p <= 1.05 theta_cp in every proppant snapshot (close packing, Eq. 16 of the paper);
* solid balance: injected = in_domain + outflow + screened_out (conservation).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hfgpu import load_scene, open_results, run

#: Largest relative fracture volume-balance error allowed (issue 5).
BALANCE_TOLERANCE = 1e-3
#: Largest theta_p / theta_cp allowed in a snapshot (issue 5).
PACKING_TOLERANCE = 1.05
#: Largest relative solid-balance error (the simulator keeps it to round-off).
SOLID_TOLERANCE = 1e-9
FRONT_NAMES = ("up", "down", "left", "right")


def fracture_text(end_time="30 s", rate="1e-3 m**3/s", cell="1 m", K="0.5 MPa*m**0.5", CL="0 m/s**0.5",
                  mu="0.1 Pa*s", stress="10 MPa", layers="", schedule=None, every=None, fracture="",
                  max_cells=None, physics='["fracture"]', extra="") -> str:
    """A small fracture scene (TOML text): 30 GPa rock at 500 m, one stage unless ``schedule``; ``extra`` is
    appended (the proppant sections of a coupled scene)."""
    schedule = schedule or f'[{{ until = "{end_time}", rate = "{rate}" }}]'
    every = every or end_time
    cap = f"max_cells_across = {max_cells}" if max_cells else ""
    return f"""
[run]
end_time = "{end_time}"
physics = {physics}
seed = 1
[rock]
youngs_modulus = "30 GPa"
poisson_ratio = 0.25
toughness = "{K}"
leakoff_coefficient = "{CL}"
min_stress = "{stress}"
{layers}
[fluid]
viscosity = "{mu}"
[injection]
depth = "500 m"
schedule = {schedule}
[mesh]
cell_size = "{cell}"
{cap}
[output]
every = "{every}"
[fracture]
{fracture}
{extra}
"""


def coupled_text(diameter: str) -> str:
    """tests/scenes/tiny_coupled.toml (a 12 m pay between 2 MPa barriers, 20 s pad then 20 s of 10 % slurry)
    with ``diameter`` grains."""
    text = (Path(__file__).parent / "scenes" / "tiny_coupled.toml").read_text()
    return text.replace('diameter = "300 um"', f'diameter = "{diameter}"')


def barrier_layers(thickness: float, contrast_mpa: float, base_mpa: float = 10.0) -> str:
    """[[rock.layers]] of a pay ``thickness`` m thick centred on 500 m at ``base_mpa``, between barriers
    ``contrast_mpa`` higher."""
    top, bottom = 500.0 - thickness / 2, 500.0 + thickness / 2
    barrier = base_mpa + contrast_mpa
    return f"""
[[rock.layers]]
top = "0 m"
bottom = "{top} m"
min_stress = "{barrier} MPa"
[[rock.layers]]
top = "{top} m"
bottom = "{bottom} m"
min_stress = "{base_mpa} MPa"
[[rock.layers]]
top = "{bottom} m"
bottom = "1000 m"
min_stress = "{barrier} MPa"
"""


def proppant_text(end_time="2 s", length="0.3 m", height="0.15 m", width="5 mm", cell="25 mm",
                  diameter="300 um", density="2650 kg/m**3", fluid_density="1000 kg/m**3", mu="1 cP",
                  rate="1e-5 m**3/s", fraction=0.1, initial=0.0, every=None, mppic="", outlet=True) -> str:
    """A small proppant-only slot (TOML text): inlet segment on the left end at mid-height, outlet segment on
    the right end (``outlet``); ``mppic`` is extra [mppic] lines (backend numpy unless given)."""
    every = every or end_time
    backend = "" if "backend" in mppic else 'backend = "numpy"'
    kind = "slot" if outlet else "box"
    out = """
[[geometry.outlets]]
kind = "segment"
x = "0.299 m"
depth = "0.06 m"
x_end = "0.299 m"
depth_end = "0.09 m"
""" if outlet else ""
    injection = ("" if rate is None else f"""
[injection]
schedule = [{{ until = "{end_time}", rate = "{rate}", proppant = "sand", volume_fraction = {fraction} }}]
""")
    return f"""
[run]
end_time = "{end_time}"
physics = ["proppant"]
seed = 5
[fluid]
viscosity = "{mu}"
density = "{fluid_density}"
[mesh]
cell_size = "{cell}"
[output]
every = "{every}"
[geometry]
kind = "{kind}"
length = "{length}"
height = "{height}"
width = "{width}"
[[geometry.inlets]]
kind = "segment"
x = "1 mm"
depth = "0.06 m"
x_end = "1 mm"
depth_end = "0.09 m"
{out}
{injection}
[[proppant]]
name = "sand"
density = "{density}"
diameter = "{diameter}"
initial_volume_fraction = {initial}
[mppic]
{backend}
{mppic}
"""


@dataclass
class Outcome:
    """What a case run produced: its summary, the results file read back, wall seconds, the margins and the
    warnings the run issued."""

    summary: dict[str, Any]
    results: Any
    wall: float
    margins: dict[str, float] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def run_case(text: str, path: Path) -> Outcome:
    """Run a scene (TOML text) through :func:`hfgpu.run` to ``path`` (its warnings recorded, not shown) and
    read the results file back."""
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        summary = run(load_scene(text), path, progress=False)
    wall = time.perf_counter() - t0
    results = open_results(path)
    assert results.status == "complete", results.status
    return Outcome(summary, results, wall, warnings=[str(w.message) for w in caught])


def injecting(schedule, times: np.ndarray) -> np.ndarray:
    """True where the scheduled rate over (previous time, time] is > 0."""
    starts = np.concatenate([[0.0], times[:-1]])
    return np.array([schedule.volume(t1) > schedule.volume(t0) for t0, t1 in zip(starts, times)])


def check_fracture(outcome: Outcome) -> dict[str, float]:
    """Fracture invariants from the results file; returns the margins (balance_error, front_retreat_cells,
    snapshots, steps). Asserts: balance within BALANCE_TOLERANCE at every step, finite width/pressure,
    footprint area and whole-cell extents never shrinking while injecting, the sub-grid front extents
    retreating less than one cell while injecting."""
    r = outcome.results
    b = r.fracture_balance
    assert b and len(b["time"]) > 0, "no fracture balance records"
    for name in ("injected", "stored", "leaked"):
        assert np.all(np.isfinite(b[name])), f"non-finite {name} in the fracture balance"
    error = np.abs(b["injected"] - b["stored"] - b["leaked"]) / b["injected"]
    worst = float(error.max())
    assert worst < BALANCE_TOLERANCE, f"fracture volume balance error {worst:.3e}"
    snaps = list(r.fracture_snapshots)
    assert snaps, "no fracture snapshots"
    schedule = r.scene.injection.schedule
    area, extents, subgrid, cells = [], [], [], []
    for s in snaps:
        for name in ("width", "pressure"):
            a = getattr(s, name)
            assert np.all(np.isfinite(a)), f"non-finite {name} at t = {s.time:g} s"
        inside = np.isfinite(s.opening_time)
        area.append(inside.sum() * s.frame.dx * s.frame.dz)
        x, z = s.frame.centres(*inside.shape)
        zs, xs = z[np.nonzero(inside)[0]], x[np.nonzero(inside)[1]]
        depth, x_inj = r.scene.injection.depth, r.scene.injection.x
        half = 0.5 * np.array([s.frame.dz, s.frame.dz, s.frame.dx, s.frame.dx])
        extents.append(np.array([depth - zs.min(), zs.max() - depth, x_inj - xs.min(), xs.max() - x_inj]) + half)
        subgrid.append(np.array([float(s.extras[f"front_{n}"]) for n in FRONT_NAMES]))
        cells.append(max(s.frame.dx, s.frame.dz))
    times = np.array([s.time for s in snaps])
    pumping = injecting(schedule, times)
    retreat = 0.0
    for j in range(1, len(snaps)):
        if not pumping[j]:
            continue
        assert area[j] >= area[j - 1] * (1 - 1e-12), f"footprint shrank at t = {times[j]:g} s"
        assert np.all(extents[j] >= extents[j - 1] - 1e-9), f"front extents retreated at t = {times[j]:g} s"
        retreat = max(retreat, float(np.max(subgrid[j - 1] - subgrid[j])) / cells[j])
    assert retreat < 1.0, f"sub-grid front retreated {retreat:.2f} cells"
    summary = outcome.summary
    prefix = "fracture_" if "fracture_retries" in summary else ""
    margins = dict(balance_error=worst, front_retreat_cells=max(retreat, 0.0), snapshots=len(snaps),
                   steps=int(summary[prefix + "steps"]), retries=int(summary[prefix + "retries"]),
                   rejected=int(summary.get(prefix + "rejected", 0)),
                   efficiency=float(b["stored"][-1] / b["injected"][-1]), radius=float(summary[prefix + "radius"]))
    outcome.margins.update(margins)
    return margins


def mean_position(parcels: dict[str, np.ndarray]) -> tuple[float, float]:
    """Solid-volume-weighted mean (x, z) of parcels [m]; NaN when there are none."""
    volume = parcels["particles"] * parcels["radius"] ** 3
    if not volume.size:
        return math.nan, math.nan
    return float(np.sum(volume * parcels["x"]) / np.sum(volume)), float(np.sum(volume * parcels["z"]) / np.sum(volume))


def check_proppant(outcome: Outcome) -> dict[str, float]:
    """Proppant invariants from the results file; returns the margins (packing = max theta_p / theta_cp,
    solid_error, screened_out fraction). Asserts finite parcels and grid fields, theta_p <= 1.05 theta_cp,
    the solid balance to SOLID_TOLERANCE at every step."""
    r = outcome.results
    theta_cp = r.scene.proppant.params.theta_cp
    packing = 0.0
    snaps = list(r.proppant_snapshots)
    assert snaps, "no proppant snapshots"
    for s in snaps:
        for name in ("x", "z", "u", "v"):
            assert np.all(np.isfinite(s.parcels[name])), f"non-finite parcel {name} at t = {s.time:g} s"
        for name in ("volume_fraction", "pressure", "fluid_u", "fluid_v"):
            assert np.all(np.isfinite(s.grid[name])), f"non-finite {name} at t = {s.time:g} s"
        packing = max(packing, float(np.max(s.grid["volume_fraction"])) / theta_cp)
    assert packing <= PACKING_TOLERANCE, f"theta_p reached {packing:.3f} theta_cp"
    b = r.proppant_balance
    assert b and len(b["time"]) > 0, "no solid balance records"
    scale = max(float(np.max(b["injected"])), 1e-300)
    solid = np.abs(b["injected"] - b["in_domain"] - b["outflow"] - b["screened_out"]) / scale
    solid_error = float(solid.max())
    assert solid_error <= SOLID_TOLERANCE, f"solid balance error {solid_error:.3e}"
    final = {k: float(v[-1]) for k, v in b.items()}
    last = snaps[-1].parcels
    margins = dict(packing=packing, solid_error=solid_error,
                   screened_fraction=final["screened_out"] / scale,
                   fluid_steps=int(outcome.summary.get("steps", outcome.summary.get("proppant_steps", 0))),
                   parcels=int(len(last["x"])),
                   mean_depth=mean_position(last)[1])
    outcome.margins.update(margins)
    return margins
