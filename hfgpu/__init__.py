"""hfgpu: planar-3D hydraulic fracture propagation and MP-PIC proppant transport.

Python API::

    import hfgpu
    scene = hfgpu.load_scene("scene.toml")
    hfgpu.run(scene, "results.h5")
    results = hfgpu.open_results("results.h5")
"""

from .errors import HfgpuError, SceneError, SimulationError
from .scene import Scene, load_scene

__version__ = "0.1.0"


def run(scene, out, **options):
    """Run a scene (a :class:`Scene` or a path) and write the results file ``out``; see hfgpu.runner."""
    from .runner import run as _run

    return _run(scene, out, **options)


def open_results(path):
    """Open a results file for reading; see :class:`hfgpu.io.results.Results`."""
    from .io.results import open_results as _open

    return _open(path)


__all__ = ["HfgpuError", "Scene", "SceneError", "SimulationError", "load_scene", "open_results", "run"]
