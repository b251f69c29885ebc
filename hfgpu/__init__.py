"""hfgpu: planar-3D hydraulic fracture propagation and MP-PIC proppant transport.

Python API::

    import hfgpu
    scene = hfgpu.load_scene("scene.toml")
    finer = hfgpu.edit_scene(scene, {"coupling.cell_size": "2.5 m"})   # keys changed as text (hfgpu.scene_text)
    hfgpu.run(scene, "results.h5")
    results = hfgpu.open_results("results.h5")
    rows = hfgpu.sweep("study.toml", "study")   # an ensemble on Dask (docs/ensembles.md)
"""

from .errors import HfgpuError, SceneError, SimulationError
from .scene import Scene, load_scene
from .scene_text import edit_scene

__version__ = "0.1.0"


def run(scene, out, **options):
    """Run a scene (a :class:`Scene` or a path) and write the results file ``out``; see hfgpu.runner."""
    from .runner import run as _run

    return _run(scene, out, **options)


def open_results(path):
    """Open a results file for reading; see :class:`hfgpu.io.results.Results`."""
    from .io.results import open_results as _open

    return _open(path)


def sweep(sweep_file, out, **options):
    """Run a sweep file's ensemble on Dask into the folder ``out``; return the summary as a list of dicts, one per
    member (docs/ensembles.md; options: workers, scheduler, resume, progress; see hfgpu.ensemble.execute)."""
    from .ensemble.execute import sweep as _sweep

    return _sweep(sweep_file, out, **options)


__all__ = ["HfgpuError", "Scene", "SceneError", "SimulationError", "edit_scene", "load_scene", "open_results", "run",
           "sweep"]
