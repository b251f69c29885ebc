"""hfgpu: planar-3D hydraulic fracture propagation and MP-PIC proppant transport.

Python API::

    import hfgpu
    scene = hfgpu.load_scene(hfgpu.scene_path("radial_I.toml"))   # a scene shipped with hfgpu, or any path
    finer = hfgpu.edit_scene(scene, {"coupling.cell_size": "2.5 m"})   # keys changed as text (hfgpu.scene_text)
    hfgpu.run(scene, "results.h5")
    results = hfgpu.open_results("results.h5")
    print(hfgpu.summary("results.h5"))          # the run's summary table again, from the file alone
    rows = hfgpu.sweep("study.toml", "study")   # an ensemble on Dask (docs/ensembles.md)
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from .errors import HfgpuError, SceneError, SimulationError
from .scene import Scene, load_scene
from .scene_text import edit_scene

if TYPE_CHECKING:
    from .io.results import Results

from .version import __version__


def run(scene: Scene | str | Path, out: str | Path, *, progress: bool = True, rrd: str | Path | None = None,
        view: bool = False, connect: str | None = None, resume: bool = False,
        viewer_required: bool = False) -> dict[str, Any]:
    """Run a scene (a :class:`Scene` or a path) and write the results file ``out``; return the run's summary.

    ``progress``: a bar and the summary table on the terminal; ``rrd``: also save a Rerun recording there;
    ``view``/``connect``: stream to a spawned Rerun viewer / one running at that URL (``viewer_required``: an
    error when it cannot be reached); ``resume``: continue the killed run in ``out`` from its checkpoint.
    A results file another run is writing is refused before any work. Details: :func:`hfgpu.runner.run`."""
    from .runner import run as _run

    return _run(scene, out, progress=progress, rrd=rrd, view=view, connect=connect, resume=resume,
                viewer_required=viewer_required)


def open_results(path: str | Path) -> Results:
    """Open a results file for reading; see :class:`hfgpu.io.results.Results`."""
    from .io.results import open_results as _open

    return _open(path)


def summary(path: str | Path) -> str:
    """The summary table of the results file ``path`` (the one ``hfgpu run`` printed at its end), in its scene's
    ``[output] units``, headed by a warning line when the run did not complete."""
    from .io.summary import schedule_table, summary_table

    results = open_results(path)
    scene = results.scene
    system = scene.output.units
    lines = [] if results.status == "complete" else [f"warning: {path}: status \"{results.status}\""]
    if scene.injection is not None:
        lines.append(schedule_table(scene, system))
    lines.append(summary_table({**results.summary, "out": str(path)}, system, scene))
    return "\n".join(lines)


def scene_path(name: str) -> Path:
    """The path of the scene ``name`` shipped with hfgpu (a file of ``hfgpu/scenes``, e.g. "radial_I.toml"), usable
    from any folder; :class:`HfgpuError` listing those there when there is none of that name."""
    folder = Path(__file__).parent / "scenes"
    path = folder / name
    if not path.is_file():
        raise HfgpuError(f"no scene '{name}' ships with hfgpu; allowed: "
                         f"{', '.join(sorted(p.name for p in folder.glob('*.toml')))}")
    return path


def sweep(sweep_file: str | Path, out: str | Path, *, workers: int | None = None, scheduler: str | None = None,
          resume: bool = False, progress: bool = True) -> list[dict[str, Any]]:
    """Run a sweep file's ensemble on Dask into the folder ``out``; return the summary as a list of dicts, one per
    member (docs/ensembles.md). ``workers``: local worker processes (default one per core); ``scheduler``: a
    running cluster's address or scheduler file instead; ``resume``: keep the complete members already in ``out``;
    ``progress``: a progress bar. Details: :func:`hfgpu.ensemble.execute.sweep`."""
    from .ensemble.execute import sweep as _sweep

    return _sweep(sweep_file, out, workers=workers, scheduler=scheduler, resume=resume, progress=progress)


__all__ = ["HfgpuError", "Scene", "SceneError", "SimulationError", "edit_scene", "load_scene", "open_results", "run",
           "scene_path", "summary", "sweep"]
