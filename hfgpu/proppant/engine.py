"""The particle engine by name: ``make_engine("taichi" | "numpy", grid, params, ...)`` gives a
:class:`hfgpu.proppant.engine_taichi.TaichiEngine` (state in Taichi ndarrays on the device, one launch per
sub-step) or a :class:`hfgpu.proppant.engine_numpy.NumpyEngine` (plain NumPy, the test oracle). What the run
loop calls on either is the seam of :mod:`hfgpu.proppant.engine_seam`. Only the engine asked for is imported
(the NumPy one starts no Taichi).
"""

from __future__ import annotations

import numpy as np

from .engine_seam import ParticleEngine
from .grid import StaggeredGrid
from .params import MppicParams

ENGINES = ("taichi", "numpy")


def make_engine(name: str, grid: StaggeredGrid, params: MppicParams, fluid_density: float,
                fluid_viscosity: float, gravity: float, outlets: np.ndarray, arch: str | None = None
                ) -> ParticleEngine:
    """The particle engine ``name`` ("taichi" or "numpy") on ``grid`` (StaggeredGrid) with the closures
    ``params`` (MppicParams), fluid density [kg/m^3], clean-fluid viscosity [Pa s], gravity [m/s^2] along +z,
    and the outlet cells (bool (nz, nx)); ``arch`` for Taichi ("cpu" or "cuda"; else HFGPU_ARCH, else cpu)."""
    if name == "numpy":
        from .engine_numpy import NumpyEngine

        return NumpyEngine(grid, params, fluid_density, fluid_viscosity, gravity, outlets)
    if name == "taichi":
        from .engine_taichi import TaichiEngine

        return TaichiEngine(grid, params, fluid_density, fluid_viscosity, gravity, outlets, arch=arch)
    raise ValueError(f"mppic.backend: got {name!r}; allowed: one of {list(ENGINES)}")
