"""What the speed-accuracy study runs (bench/study.py): the presets as each case's scene gets them, the one-knob
sweeps per case, the driver that runs them, and the printed table."""

from __future__ import annotations

import dataclasses
import tomllib


from _study_cases import CASES, FIELD_CASES, PRESETS, SCENES, Case, Knobs, Run, run_case, score

COLUMNS = ("case", "group", "setting", "cells", "parcels", "steps", "cpu_s", "wall_s", "error")
#: (case, preset) pairs the quick study leaves out for their cost (Wu 2008 on 3 mm cells: thousands of elements).
QUICK_SKIP = {("wu2008", "accurate")}
#: (case, preset) pairs every study leaves out: the base case on the accurate preset's 2.5 m cells (~1 h of CPU;
#: its reference is the run at refinement 1.5 instead, see sweeps).
SKIP = {("field_base", "accurate")}


# ------------------------------------------------------------------------------------------------------------
# what to run


def pinned_keys(case: Case) -> set[str]:
    """Preset knobs the case's scene file sets itself (they win over a preset, as in hfgpu.presets)."""
    data = tomllib.loads((SCENES / case.scene).read_text())
    keys = set()
    for section in ("fracture", "mppic"):
        keys |= set(data.get(section, {}))
    if "refinement" in data.get("mesh", {}):
        keys.add("refinement")
    return keys


def preset_knobs(case: Case, name: str) -> Knobs:
    """The preset's knobs as the case's scene gets them: keys its scene file sets keep the scene's value."""
    pinned = pinned_keys(case)
    changes = {f.name: None for f in dataclasses.fields(Knobs) if f.name in pinned}
    if "refinement" in pinned:
        changes["refinement"] = 1.0
    return dataclasses.replace(PRESETS[name], **changes)


#: Sweeps per case: group -> list of Knobs (the quick variant runs the first entries of each list).
def sweeps(name: str, quick: bool) -> list[tuple[str, Knobs]]:
    """(group, knobs) of every run of a case. Groups: preset, space (cell size at relaxation 0.25), time
    (relaxation at the scene's cells), newton, parcels, substeps, dt, seeds, reference."""
    out: list[tuple[str, Knobs]] = []
    if name in ("radial_I", "radial_III"):
        refinements = (0.5, 0.75, 1.0, 1.5, 2.0) if quick else (0.5, 0.75, 1.0, 1.5, 2.0, 3.0)
        out += [("space", Knobs(refinement=r, time_step_relaxation=0.25)) for r in refinements]
        relax = (1.0, 0.5, 0.25, 0.125) if quick else (1.0, 0.5, 0.25, 0.125, 0.0625)
        out += [("time", Knobs(time_step_relaxation=lam)) for lam in relax]
        if not quick:
            out += [("newton", Knobs(newton_tolerance=tol)) for tol in (1e-4, 1e-8)]
    elif name == "wu2008":
        if not quick:
            out += [("space", Knobs(refinement=r)) for r in (1.0, 1.5)]
        out += [("time", Knobs(time_step_relaxation=lam)) for lam in ((1.0,) if quick else (1.0, 0.25))]
    elif name == "davis1982":
        out += [("space", Knobs(refinement=r)) for r in ((0.5, 2.0) if quick else (0.5, 2.0, 4.0))]
        out += [("parcels", Knobs(parcels_per_cell=n)) for n in ((4, 32) if quick else (4, 8, 32, 64))]
        out += [("dt", Knobs(dt_max=dt)) for dt in ((0.5, 8.0) if quick else (0.5, 1.0, 8.0))]
        out += [("substeps", Knobs(particle_substeps=n)) for n in ((1, 16) if quick else (1, 2, 8, 16))]
    elif name in FIELD_CASES:
        counts = (4, 16, 64) if quick else (4, 8, 16, 32, 64)
        seeds = (1, 2, 3) if quick else (1, 2, 3, 4, 5)
        out += [("seeds", Knobs(parcels_per_cell=n, seed=s)) for n in counts for s in seeds]
        out += [("time", Knobs(time_step_relaxation=lam)) for lam in ((1.0, 0.25) if quick else (1.0, 0.25))]
        if not quick:
            out += [("reference", field_reference())]
    elif name == "field_base":
        out += [("reference", Knobs(refinement=1.5, time_step_relaxation=0.25))]
    return out


def field_reference() -> Knobs:
    """The full study's most accurate field run: the accurate preset with 64 parcels per cell (the quick study
    takes the accurate preset's run itself, see :func:`score_relative`)."""
    return dataclasses.replace(PRESETS["accurate"], parcels_per_cell=64, seed=1)


def score_relative(runs: list[Run]) -> None:
    """Errors of the cases measured against their most accurate run (the field case): the run of group
    "reference", else the accurate preset's run; that run's own error is 0."""
    for name in dict.fromkeys(r.case for r in runs):
        case = CASES[name]
        if case.errors.__name__ != "_relative_to":
            continue
        rows = [r for r in runs if r.case == name]
        best = ([r for r in rows if r.group == "reference" and r.values]
                or [r for r in rows if r.group == "preset" and r.label == "accurate" and r.values])
        for row in rows:
            if best:
                score(case, row, best[0].values)
        if best:
            best[0].note = "reference: the others' errors are relative to this run"


def table_rows(runs: list[Run]) -> list[dict]:
    """One dict per run with :data:`COLUMNS` (and the run's note)."""
    return [dict(case=r.case, group=r.group, setting=r.label, cells=r.cells, parcels=r.parcels,
                 steps=r.steps, cpu_s=r.cpu, wall_s=r.wall, error=r.error, note=r.note) for r in runs]


def format_table(rows: list[dict]) -> str:
    """The printed table."""
    head = (f"{'case':10} {'group':9} {'setting':42} {'cells':>6} {'parcels':>8} {'steps':>6} {'CPU s':>8} "
            f"{'wall s':>8} {'error':>9}  note")
    lines = [head]
    for r in rows:
        lines.append(f"{r['case']:10} {r['group']:9} {r['setting'][:42]:42} {r['cells']:6d} {r['parcels']:8d} "
                     f"{r['steps']:6d} {r['cpu_s']:8.2f} {r['wall_s']:8.2f} {r['error']:9.2e}  {r['note']}")
    return "\n".join(lines)


# ------------------------------------------------------------------------------------------------------------
# driver


def run_study(case_names: list[str], quick: bool, backend: str | None, log=print) -> list[Run]:
    """Run every setting of the named cases; returns the runs. Cases whose data file is
    absent are skipped with a printed reason. The field case's errors are filled in against its most accurate
    run (:func:`score_relative`)."""
    runs: list[Run] = []
    for name in case_names:
        case = CASES[name]
        if case.needs is not None and not case.needs.is_file():
            log(f"skipping {name}: {case.needs} not found (third-party data, not shipped with hfgpu)")
            continue
        plan = [("preset", preset_knobs(case, p), p) for p in PRESETS
                if (name, p) not in SKIP and not (quick and (name, p) in QUICK_SKIP)]
        plan += [(group, knobs, knobs.label()) for group, knobs in sweeps(name, quick)]
        if backend == "taichi" and case.runner.__name__ in ("_davis", "_field"):
            warm_up(case, backend)
        case_runs = []
        for group, knobs, label in plan:
            knobs = dataclasses.replace(knobs, backend=backend)
            row = run_case(case, knobs, label, group)
            case_runs.append(row)
            log(format_table(table_rows([row])).splitlines()[1])
        score_relative(case_runs)
        runs += case_runs
    return runs


def warm_up(case: Case, backend: str | None) -> None:
    """Compile / load the Taichi kernels before timing: a short untimed run of the case's scene."""
    scene = case.load(Knobs(backend=backend))
    end = 2.0 if scene.coupling is None else min(scene.run.end_time, 40.0)
    scene = scene.replace(run=dataclasses.replace(scene.run, end_time=end))
    if scene.coupling is not None:
        scene = scene.replace(coupling=dataclasses.replace(scene.coupling, fracture_every=5.0))
    try:
        case.runner(scene)
    except Exception as exc:  # noqa: BLE001 - a failing warm-up shows up again in the timed runs
        print(f"warm-up of {case.name} failed: {exc}")
