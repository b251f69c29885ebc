"""Cases, knob settings and error measures of the speed-accuracy study (bench/study.py).

A :class:`Knobs` value names the numerical settings of one run (None keeps the scene's value); :func:`apply_knobs`
builds the varied scene with ``dataclasses.replace``. Each :class:`Case` loads its scene, runs it with a setting
and returns its observables and its error:

* ``radial_I``, ``radial_III`` (the paper's Table 2): radius R and inlet opening w(0) at the end of injection
  against Dontsov's (2016) universal radial solution (:func:`hfgpu.reference.radial.dontsov_radial`);
  error = max(|R err|, |w(0) err|).
* ``wu2008``: up / down / lateral (mean of left and right) front reach at 22, 60, 144, 376, 665 s against the
  digitised fronts of Wu et al. (2008) (PyFrac's csv, :mod:`hfgpu.reference.wu2008`); error = mean |relative
  error| over the 15 values.
* ``davis1982``: speeds of the upper and lower interfaces of the bidisperse batch test against Kynch theory with
  the Masliyah / Lockett-Bassoon slip velocities (:func:`hfgpu.reference.settling.bidisperse_batch`);
  error = max(|upper err|, |lower err|). The column stays one cell wide (a 1-D batch test, see the scene):
  mesh refinement divides dz only.
* ``field``: the scaled five-layer demo (hfgpu/scenes/five_layer_demo.toml, 90 s; the 3600 s base case is far
  beyond the study's budget): fracture area, propped area (:func:`hfgpu.propped.propped_cells`) and propped
  fraction at the end; error = max relative difference of the three from the study's most accurate run.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from hfgpu.errors import HfgpuError
from hfgpu.records import MemorySink
from hfgpu.scene import Scene, load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "hfgpu" / "scenes"
WU_FRONTS = ROOT.parent / "shared" / "validation-data" / "wu_et_al_2008_fronts_pyfrac.csv"


@dataclass(frozen=True)
class Knobs:
    """Numerical settings of one run; None keeps the scene's value. ``refinement`` divides the cell size;
    ``backend`` ("numpy" or "taichi") picks the MP-PIC particle kernels."""

    refinement: float = 1.0
    time_step_relaxation: float | None = None
    newton_tolerance: float | None = None
    simple_tolerance: float | None = None
    parcels_per_cell: int | None = None
    particle_substeps: int | None = None
    c_max: float | None = None
    dt_max: float | None = None
    seed: int | None = None
    backend: str | None = None

    def label(self) -> str:
        """Short text of the knobs that differ from the scene's values (the backend is left out)."""
        names = dict(refinement="ref", time_step_relaxation="relax", newton_tolerance="newton",
                     simple_tolerance="simple", parcels_per_cell="ppc", particle_substeps="sub", c_max="cmax",
                     dt_max="dtmax", seed="seed")
        shown = [f.name for f in dataclasses.fields(self) if f.name in names and getattr(self, f.name) is not None]
        parts = [f"{names[n]} {getattr(self, n):g}" for n in shown if not (n == "refinement" and self.refinement == 1)]
        return ", ".join(parts) or "scene"


#: The knobs a preset sets.
PRESET_KNOBS = ("refinement", "time_step_relaxation", "newton_tolerance", "simple_tolerance", "parcels_per_cell",
                "particle_substeps", "c_max", "dt_max")
def package_presets() -> dict[str, Knobs]:
    """The presets of :mod:`hfgpu.presets` as Knobs (the study applies them through the knobs)."""
    from hfgpu.presets import PRESETS as package

    return {name: Knobs(**{k: getattr(p, k) for k in PRESET_KNOBS}) for name, p in package.items()}


PRESETS = package_presets()


def apply_knobs(scene: Scene, knobs: Knobs, refine_x: bool = True) -> Scene:
    """The scene with ``knobs`` applied: cell sizes (and ``[coupling] cell_size``) divided by the refinement, dx
    only when ``refine_x``; ``mesh.max_cells_across`` is left as it is (no study scene sets it)."""
    mesh = dataclasses.replace(scene.mesh, dx=scene.mesh.dx / (knobs.refinement if refine_x else 1.0),
                               dz=scene.mesh.dz / knobs.refinement)
    changes: dict = dict(mesh=mesh)
    if knobs.seed is not None:
        changes["run"] = dataclasses.replace(scene.run, seed=knobs.seed)
    if scene.fracture is not None:
        frac = {k: v for k, v in (("time_step_relaxation", knobs.time_step_relaxation),
                                  ("newton_tolerance", knobs.newton_tolerance)) if v is not None}
        changes["fracture"] = dataclasses.replace(scene.fracture, **frac)
    if scene.proppant is not None:
        mp = {k: getattr(knobs, k) for k in ("simple_tolerance", "parcels_per_cell", "particle_substeps", "c_max",
                                              "dt_max", "backend") if getattr(knobs, k) is not None}
        numerics = dataclasses.replace(scene.proppant.numerics, **mp)
        changes["proppant"] = dataclasses.replace(scene.proppant, numerics=numerics)
    if scene.coupling is not None and scene.coupling.cell_size is not None:
        dx, dz = scene.coupling.cell_size
        changes["coupling"] = dataclasses.replace(
            scene.coupling, cell_size=(dx / (knobs.refinement if refine_x else 1.0), dz / knobs.refinement))
    return scene.replace(**changes)


@dataclass
class Run:
    """One run of a case (``group``: the sweep it belongs to): its size, cost and observables. ``error`` is NaN
    until known (a failed run keeps it)."""

    case: str
    label: str
    knobs: Knobs
    group: str = ""
    cells: int = 0
    parcels: int = 0
    steps: int = 0
    cpu: float = math.nan
    wall: float = math.nan
    values: dict = dataclasses.field(default_factory=dict)
    error: float = math.nan
    parts: dict = dataclasses.field(default_factory=dict)
    note: str = ""


def timed(function: Callable[[], dict]) -> tuple[dict, float, float]:
    """(function(), CPU seconds of this process, wall seconds)."""
    c0, w0 = time.process_time(), time.perf_counter()
    out = function()
    return out, time.process_time() - c0, time.perf_counter() - w0


# ------------------------------------------------------------------------------------------------------------
# runners: scene -> (cells, parcels, steps, observables); errors from the observables


def _radial(scene: Scene) -> tuple[int, int, int, dict]:
    from hfgpu.fracture.simulator import simulate

    out = simulate(scene, MemorySink())
    return out["cells"], 0, out["steps"], dict(R=out["radius"], w0=out["w_inlet"])


def _radial_error(scene: Scene, values: dict, reference: dict | None) -> dict:
    """R and w(0) against Dontsov (2016) at the end of injection (K' = sqrt(32/pi) K_Ic, mu' = 12 mu, C' = 2 C_L)."""
    from hfgpu.reference.radial import dontsov_radial

    rock = scene.rock
    ref = dontsov_radial(rock.plane_strain_modulus, math.sqrt(32 / math.pi) * rock.toughness,
                         12 * scene.fluid.viscosity, 2 * rock.leakoff_coefficient,
                         scene.injection.schedule.stages[0].rate, scene.run.end_time)
    return dict(R=values["R"] / float(ref.R[-1]) - 1, w0=values["w0"] / float(ref.w0[-1]) - 1)


WU_TIMES = (22.0, 60.0, 144.0, 376.0, 665.0)


def _wu(scene: Scene) -> tuple[int, int, int, dict]:
    from hfgpu.fracture.simulator import simulate

    sink = MemorySink()
    out = simulate(scene, sink)
    snaps = {round(s.time): s.extras for s in sink.fracture_snapshots}
    values = {}
    unresolved = {k: 0.0 for k in ("front_up", "front_down", "front_left", "front_right")}
    for t in WU_TIMES:
        e = snaps.get(round(t), unresolved)  # before the starting fracture forms: no resolved front (-100 %)
        values[f"up {t:g}"] = float(e["front_up"])
        values[f"down {t:g}"] = float(e["front_down"])
        values[f"lateral {t:g}"] = 0.5 * (float(e["front_left"]) + float(e["front_right"]))
    return out["cells"], 0, out["steps"], values


def _wu_error(scene: Scene, values: dict, reference: dict | None) -> dict:
    """Relative error of each reach against the digitised fronts (Wu et al. 2008, PyFrac's csv)."""
    from hfgpu.reference.wu2008 import extents, read_fronts

    fronts = read_fronts(WU_FRONTS)
    parts = {}
    for t in WU_TIMES:
        m = extents(fronts[t])
        for name, measured in (("up", m.up), ("down", m.down), ("lateral", 0.5 * (m.left + m.right))):
            parts[f"{name} {t:g}"] = values[f"{name} {t:g}"] / measured - 1
    return parts


def _davis_theory(scene: Scene):
    from hfgpu.reference.settling import bidisperse_batch

    heavy, light = scene.proppant.classes
    return bidisperse_batch((heavy.size.mean / 2, heavy.density, heavy.initial_volume_fraction),
                            (light.size.mean / 2, light.density, light.initial_volume_fraction),
                            scene.fluid.density, scene.fluid.viscosity)


#: Depth window [m] over which the interface speeds are fitted (below the top cell, above the rising bed).
DAVIS_WINDOW = (0.02, 0.4)


def _davis(scene: Scene) -> tuple[int, int, int, dict]:
    """Interface depths every step (upper: light theta_p at half phi_L', lower: heavy at half phi_H), then
    least-squares speeds over :data:`DAVIS_WINDOW` (as tests/proppant/test_davis.py)."""
    from hfgpu.proppant.analysis import class_volume_fraction, fitted_speed, interface_depth, row_profile
    from hfgpu.proppant.engine_setup import proppant_engine_setup
    from hfgpu.proppant.simulator import ProppantSimulation

    theory = _davis_theory(scene)
    sim = ProppantSimulation(proppant_engine_setup(scene))
    phi_heavy = scene.proppant.classes[0].initial_volume_fraction
    record = []

    def on_step(info):
        frame, width = sim.grid.frame, sim.grid.width
        profiles = [row_profile(class_volume_fraction(sim.parcels, frame, width, c), width)
                    for c in (1, 0)]
        record.append((sim.time, interface_depth(profiles[0], frame, 0.5 * theory.phi_light_only),
                       interface_depth(profiles[1], frame, 0.5 * phi_heavy)))

    out = sim.run(MemorySink(), on_step=on_step)
    t, upper, lower = np.array(record).T
    speeds = []
    for depth in (upper, lower):
        use = (depth > DAVIS_WINDOW[0]) & (depth < DAVIS_WINDOW[1])
        speeds.append(fitted_speed(t[use], depth[use]) if use.sum() >= 3 else math.nan)
    return int(sim.grid.active.sum()), out["parcels"], out["steps"], dict(upper=speeds[0], lower=speeds[1])


def _davis_error(scene: Scene, values: dict, reference: dict | None) -> dict:
    """Interface speeds against Kynch + MLB theory (Davis et al. 1982; hfgpu.reference.settling)."""
    theory = _davis_theory(scene)
    return dict(upper=values["upper"] / theory.upper_speed - 1, lower=values["lower"] / theory.lower_speed - 1)


def _field(scene: Scene) -> tuple[int, int, int, dict]:
    from hfgpu.coupled import simulate
    from hfgpu.propped import created_area, propped_cells

    sink = MemorySink()
    out = simulate(scene, sink)
    frac = sink.fracture_snapshots[-1]
    snap = sink.proppant_snapshots[-1]
    cell = snap.frame.dx * snap.frame.dz
    created = created_area(snap)
    propped = float(propped_cells(snap, scene.proppant.params.theta_cp).sum()) * cell
    values = dict(fracture_area=float(np.count_nonzero(np.asarray(frac.width) > 0.0)) * frac.frame.dx * frac.frame.dz,
                  propped_area=propped, propped_fraction=propped / created if created > 0.0 else math.nan)
    return (out["fracture_cells"] + out["proppant_nx"] * out["proppant_nz"], out["proppant_parcels"],
            out["fracture_steps"] + out["proppant_steps"], values)


def _relative_to(scene: Scene, values: dict, reference: dict | None) -> dict:
    """Relative difference of each observable from the reference run's."""
    if reference is None:
        return {}
    return {k: values[k] / reference[k] - 1 for k in values}


@dataclass(frozen=True)
class Case:
    """A study case: scene file, runner, error parts (``errors(scene, values, reference)``) and how they combine."""

    name: str
    scene: str
    runner: Callable[[Scene], tuple[int, int, int, dict]]
    errors: Callable[[Scene, dict, dict | None], dict]
    combine: str = "max"          # "max" or "mean" of |parts|
    refine_x: bool = True
    reference: str = ""
    needs: Path | None = None     # a data file the error needs (the case is skipped without it)
    sieve: str | None = None      # another sieve class for every proppant class (ProppantSetup.with_sieve)

    def load(self, knobs: Knobs) -> Scene:
        scene = load_scene(SCENES / self.scene)
        if self.sieve is not None:
            scene = scene.replace(proppant=scene.proppant.with_sieve(self.sieve))
        return apply_knobs(scene, knobs, self.refine_x)


#: The field cases (errors against their most accurate run); those with a parcel-count and seed sweep.
FIELD_CASES = ("field", "field_100mesh")

CASES = {
    "radial_I": Case("radial_I", "radial_I.toml", _radial, _radial_error,
                     reference="Dontsov (2016): max(|R err|, |w(0) err|) at 370 s"),
    "radial_III": Case("radial_III", "radial_III.toml", _radial, _radial_error,
                       reference="Dontsov (2016): max(|R err|, |w(0) err|) at 405.8 s"),
    "wu2008": Case("wu2008", "wu2008.toml", _wu, _wu_error, combine="mean",
                   reference="Wu et al. (2008) digitised fronts: mean |rel. err| of up/down/lateral at 5 times",
                   needs=WU_FRONTS),
    "davis1982": Case("davis1982", "davis1982.toml", _davis, _davis_error, refine_x=False,
                      reference="Kynch + MLB (Davis et al. 1982): max |rel. err| of the two interface speeds"),
    "field": Case("field", "five_layer_demo.toml", _field, _relative_to,
                  reference="most accurate run: max |rel. diff| of fracture area, propped area, propped fraction"),
    "field_base": Case("field_base", "five_layer.toml", _field, _relative_to,
                       reference="the 3600 s base case against its run at refinement 1.5 (3.3 m cells) and "
                                 "relaxation 0.25: max |rel. diff| of fracture area, propped area, propped fraction"),
    "field_100mesh": Case("field_100mesh", "five_layer_demo.toml", _field, _relative_to, sieve="100 mesh",
                          reference="the same with 100 mesh sand (40/70 screens out at the perforation of the "
                                    "scaled demo: its propped area is a few cells)"),
}


def run_case(case: Case, knobs: Knobs, label: str, group: str = "") -> Run:
    """Run one setting of a case: size, CPU and wall seconds, observables, and (when it needs no reference run)
    its error. A run the engine refuses or stops (hfgpu errors) is kept with its message in ``note`` and the
    seconds it took until then."""
    row = Run(case=case.name, label=label, knobs=knobs, group=group)
    scene = case.load(knobs)

    def attempt():
        try:
            return case.runner(scene)
        except HfgpuError as exc:
            row.note = f"failed: {str(exc).splitlines()[0][:120]}"
            return None

    result, row.cpu, row.wall = timed(attempt)
    if result is None:
        return row
    row.cells, row.parcels, row.steps, row.values = result
    if case.errors is not _relative_to:
        score(case, row, None)
    return row


def score(case: Case, row: Run, reference: dict | None) -> None:
    """Fill ``row.parts`` and ``row.error`` (max or mean of the parts' magnitudes) from its observables."""
    if not row.values:
        return
    row.parts = case.errors(case.load(row.knobs), row.values, reference)
    magnitudes = np.abs(np.array(list(row.parts.values()), dtype=np.float64))
    if magnitudes.size:
        row.error = float(magnitudes.max() if case.combine == "max" else magnitudes.mean())
