"""What ``hfgpu check`` and ``hfgpu run`` both do to a scene before any work: the same validation and the same
warnings (docs/scene.md, "Checks and warnings").

:func:`validate` reads the scene (every error of every section in one report, :func:`hfgpu.scene.parse_scene`),
then applies what ``run`` applies: the physics set, :func:`hfgpu.limits.check_limits` and what the fracture engine
would refuse at its first step (:func:`hfgpu.limits.check_engine_start`), on the cells in use after the preset. The
scene it returns carries its warnings (``Scene.warnings``): the reader's (bare numbers) and those of :func:`review`.
The command line prints them with :func:`print_warnings`, one line each, ``hfgpu: warning: ...``, on stderr; a
scene with errors prints only its errors.

Warnings (the scene is valid, but likely not what was meant):

* a preset coarsens the scene's cells (``[run] preset`` with refinement < 1 and no ``[mesh] refinement``);
* ``[mesh] coarsening_factor`` 2 without ``max_cells_across`` (the grid is never coarsened);
* the injection depth lies above or below every layer of ``[[rock.layers]]``;
* ``run.end_time`` ends before the pump schedule (its last stages are not pumped) or after it (the rest is shut in;
  a last stage at rate 0 ending at end_time says so and silences the warning);
* a pad stage (no proppant) at rate 0 before the pumping is done;
* a layer boundary the fracture grid cannot put on a cell face (:func:`hfgpu.fracture.mesh.fit_layers`: the faces
  are placed on the boundary nearest the injection depth, dz in use; a boundary a whole number of cells from it is
  on a face too): one warning per such boundary, naming the cell height that puts every boundary on a face;
* what the fracture's closed-form scales predict (:mod:`hfgpu.estimate`): a grain too large for the expected
  opening at the perforation, a fracture of fewer than 3 cells' radius, leak-off taking nearly all the fluid;
* fewer than :data:`MIN_CELLS_ACROSS` cells (dz in use) across a layer the fracture enters: the layer at the
  injection depth and the layers just above and below it (the outermost layers, which extend to +-infinity, are
  not counted).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TextIO

from .errors import SceneError
from .estimate import Estimate, estimate
from .estimate import report as expected_report
from .estimate import warnings as expected_warnings
from .scene import Scene, load_scene
from .scene_reader import raise_all
from .units import display_text, display_unit, format_number, in_display_units

#: Cells (dz in use) a layer the fracture enters should span at least.
MIN_CELLS_ACROSS = 3


def validate(scene_or_path: Scene | str | Path) -> Scene:
    """The scene (read from a path or TOML text, or as given) checked as ``hfgpu run`` checks it, with every
    warning in ``Scene.warnings``; raises :class:`SceneError` (a ``SceneErrors`` for several) otherwise."""
    from .limits import check_engine_start, check_limits
    from .simulators import check_supported

    scene = scene_or_path if isinstance(scene_or_path, Scene) else load_scene(scene_or_path)
    check_supported(scene)
    errors: list[SceneError] = []
    for check in (check_limits, check_engine_start):
        try:
            check(scene)
        except SceneError as exc:
            errors.append(exc)
    raise_all(errors)
    expected = estimate(scene)
    return scene.replace(warnings=tuple(dict.fromkeys(scene.warnings + tuple(review(scene, expected)))),
                         expected=expected)


def print_warnings(scene: Scene, file: TextIO | None = None) -> None:
    """Each warning of the scene on one line, ``hfgpu: warning: ...`` (stderr by default)."""
    out = file or sys.stderr
    for line in scene.warnings:
        print(f"hfgpu: warning: {' '.join(line.splitlines())}", file=out, flush=True)


def review(scene: Scene, expected: Estimate | None) -> list[str]:
    """The warnings of the module docstring, in that order, in the scene's output units (``expected``: what
    :func:`hfgpu.estimate.estimate` expects of the scene)."""
    system = scene.output.units
    found: list[str] = []
    found += _preset_coarsens(scene, system)
    if scene.mesh.coarsening_factor != 3 and scene.mesh.max_cells_across is None:
        found.append(f"mesh.coarsening_factor {scene.mesh.coarsening_factor} has no effect without "
                     "mesh.max_cells_across: the grid is never coarsened")
    if scene.injection is not None:
        found += _schedule(scene, system)
    if scene.rock is not None and scene.rock.layers and scene.injection is not None and scene.has("fracture"):
        found += _layers(scene, system)
    found += expected_warnings(expected, scene, system)
    return found


def _preset_coarsens(scene: Scene, system: str) -> list[str]:
    refinement = scene.mesh.refinement
    mesh = scene.document.get("mesh")
    if refinement >= 1.0 or not scene.document or (isinstance(mesh, dict) and "refinement" in mesh):
        return []
    dx, dz = scene.mesh.scene_cell_size
    given = display_text(dx, 'length', system) if dx == dz else \
        f"{display_text(dx, 'length', system)} x {display_text(dz, 'length', system)}"
    used = display_text(scene.mesh.dx, 'length', system) if dx == dz else \
        f"{display_text(scene.mesh.dx, 'length', system)} x {display_text(scene.mesh.dz, 'length', system)}"
    return [f"preset \"{scene.run.preset}\" coarsens the cells: [mesh] cell_size {given} is run as {used} "
            f"(refinement {refinement:g}); add 'refinement = 1' to [mesh] to keep your cells"]


def _schedule(scene: Scene, system: str) -> list[str]:
    found = []
    schedule, end = scene.injection.schedule, scene.run.end_time
    tolerance = 1e-9 * max(end, schedule.end)
    if end < schedule.end - tolerance:
        found.append(f"run.end_time {format_number(end)} s ends before the pump schedule ({format_number(schedule.end)}"
                     f" s): what is scheduled after {format_number(end)} s is never pumped")
    elif end > schedule.end + tolerance:
        found.append(f"run.end_time {format_number(end)} s is after the end of the pump schedule "
                     f"({format_number(schedule.end)} s): the last {format_number(end - schedule.end)} s are shut in; "
                     f"a last stage with rate 0 until {format_number(end)} s says so")
    stages = schedule.stages
    start = 0.0
    for i, stage in enumerate(stages):
        later = any(s.rate > 0.0 for s in stages[i + 1:])
        first_refused = i == 0 and scene.has("fracture")  # an error already (the engine needs a first rate > 0)
        if stage.rate <= 0.0 and stage.proppant is None and later and not first_refused:
            found.append(f"injection.schedule[{i}]: a pad stage at rate 0 (nothing pumped from {format_number(start)} "
                         f"to {format_number(stage.until)} s) before pumping goes on; give its rate")
        start = stage.until
    return found


def _layers(scene: Scene, system: str) -> list[str]:
    found = []
    rock, depth, dz = scene.rock, scene.injection.depth, scene.mesh.dz
    ordered = sorted(enumerate(rock.layers), key=lambda item: item[1].top)
    tops, bottoms = [layer.top for _, layer in ordered], [layer.bottom for _, layer in ordered]
    if depth < tops[0] or depth > bottoms[-1]:
        side, edge = ("above", tops[0]) if depth < tops[0] else ("below", bottoms[-1])
        found.append(f"injection.depth {display_text(depth, 'depth', system)} lies {side} every layer of "
                     "[[rock.layers]] "
                     f"({display_text(tops[0], 'depth', system)} to {display_text(bottoms[-1], 'depth', system)}): the "
                     f"{'top' if side == 'above' else 'bottom'} layer's properties are extended to it")
    found += _off_face(scene, system, ordered)
    at = next((k for k, (_, layer) in enumerate(ordered) if layer.top <= depth < layer.bottom), None)
    entered = [] if at is None else [k for k in (at - 1, at, at + 1) if 0 < k < len(ordered) - 1]
    for k in entered:
        i, layer = ordered[k]
        cells = (layer.bottom - layer.top) / dz
        if cells < MIN_CELLS_ACROSS:
            found.append(f"rock.layers[{i}] ({display_text(layer.bottom - layer.top, 'length', system)} thick) is "
                         f"{format_number(cells, 2)} cells of {display_text(dz, 'length', system)} across, fewer than "
                         f"{MIN_CELLS_ACROSS}: the fracture enters it; use finer cells")
    return found


def _off_face(scene: Scene, system: str, ordered: list) -> list[str]:
    """One warning per layer boundary the fracture grid cannot put on a cell face (fit_layers), with the cell
    height that puts every boundary on one."""
    from .fracture.mesh import HONOURING_RANGE, fit_layers, layer_boundaries  # a proppant-only run needs none

    depth, dz, refinement = scene.injection.depth, scene.mesh.dz, scene.mesh.refinement
    fit = fit_layers(depth, dz, layer_boundaries(scene.rock.layers))
    if fit.honouring is None:
        remedy = (f"no cell height from {display_text(dz / HONOURING_RANGE, 'length', system)} to "
                  f"{display_text(dz, 'length', system)} puts every "
                  "layer boundary on a face")
    else:
        setting = display_text(fit.honouring * refinement, 'length', system)
        remedy = (f"cells {display_text(fit.honouring, 'length', system)} tall ([mesh] cell_size height {setting}"
                  f"{'' if refinement == 1.0 else f' / refinement {refinement:g}'}) put every layer boundary on a "
                  "face")
    found = []
    for boundary in fit.off_face:
        keys = [f"rock.layers[{i}].{key}" for k, (i, layer) in enumerate(ordered)
                for key, value, outer in (("top", layer.top, k == 0), ("bottom", layer.bottom, k == len(ordered) - 1))
                if value == boundary and not outer]
        found.append(f"{' = '.join(keys)} {display_text(boundary, 'depth', system)} is not on a cell face: the grid's "
                     f"faces (cells {display_text(dz, 'length', system)} tall) are placed on the boundary at "
                     f"{display_text(fit.anchor, 'depth', system)}, the nearest to injection.depth "
                     f"{display_text(depth, 'depth', system)}, so a row straddles "
                     f"{display_text(boundary, 'depth', system)} "
                     f"with the properties at its centre; {remedy}")
    return found


def units_note(scene: Scene) -> str:
    """Why the output units are what they are: "[output] units" or the counts of the majority rule."""
    from .units import count_systems

    data = scene.document
    output = data.get("output")
    if isinstance(output, dict) and "units" in output:
        return f"units {scene.output.units} ([output] units)"
    counts = count_systems(data)
    return (f"units {scene.output.units} (the scene's values: {counts['field']} in field units, {counts['SI']} in SI; "
            "set [output] units to choose)")


def coupling_line(scene: Scene) -> str:
    """Which coupling a coupled scene runs: ``[coupling] mode`` as given, or the default and that it is one."""
    from .coupling_config import DEFAULT_MODE

    given = scene.document.get("coupling")
    if isinstance(given, dict) and "mode" in given:
        return f"coupling: {scene.coupling.mode} ([coupling] mode)"
    return f"coupling: {DEFAULT_MODE} (the default; set [coupling] mode = \"one-way\" or \"two-way\" to choose)"


def describe(scene: Scene, name: str) -> str:
    """The lines ``hfgpu check`` prints on stdout for a scene :func:`validate` returned, in its output units."""
    from .io.summary import schedule_table
    from .presets import knob_report

    system = scene.output.units
    cells = f"{format_number(in_display_units(scene.mesh.dx, 'length', system))} x " \
            f"{format_number(in_display_units(scene.mesh.dz, 'length', system))} {display_unit('length', system)}"
    lines = [f"{name}: ok; physics {', '.join(scene.run.physics)}, end time {format_number(scene.run.end_time)} s, "
             f"cells {cells}, output every {format_number(scene.output.every)} s, {units_note(scene)}",
             knob_report(scene, system)]
    if scene.coupling is not None:
        lines.append(coupling_line(scene))
    if scene.injection is not None:
        lines.append(schedule_table(scene, system))
    expected = expected_report(scene.expected, scene, system)
    if expected:
        lines.append(expected)
    return "\n".join(lines)
