"""The seam between the MP-PIC run loop and the particle phase: an *engine* owns the parcels and the grid fields
the particle phase needs, and runs a whole particle sub-loop per call.

``make_engine("taichi" | "numpy", grid, params, ...)`` gives a :class:`hfgpu.proppant.engine_taichi.TaichiEngine`
(state in Taichi ndarrays on the device, one launch per sub-step) or a
:class:`hfgpu.proppant.engine_numpy.NumpyEngine` (plain NumPy, the test oracle). Both do the same arithmetic in
the same order up to round-off and keep the parcels in the same order. One fluid step (hfgpu.proppant.simulator):

    engine.set_grid(grid)                    # only when the width field changed
    engine.begin_step(u, v, p)               # parcels sorted by cell, those that left dropped; the fluid now
    engine.append(batch)                     # the inlets' parcels (room from engine.moments().solid_volume)
    loop = engine.substeps(dt, n, t0)        # n x (scatter, gather, push, exchange, outlets): a SubLoop
    moments = engine.moments()               # theta_p at the step's end, for the fluid's storage term
    ... fluid step on the host with loop.force_x, ...
    engine.commit()                          # accept the step; without it the next begin_step starts again
                                             # from the last accepted parcels (a retry)

``parcels()`` reads the parcels back (snapshots, checkpoints), ``set_parcels`` replaces them; ``max_speed`` and
``solid_volume`` are the reductions of the last ``moments`` or sub-loop. u (nz, nx+1), v (nz+1, nx), p (nz, nx)
are the fluid face velocities and dynamic pressure; the SubLoop's arrays are on the same faces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ENGINES = ("taichi", "numpy")


@dataclass(frozen=True)
class SubLoop:
    """What a particle sub-loop hands the fluid step: the interphase force F of Eq. 39 per unit volume on the
    x- and z-faces (drag deposited from the parcels plus the pressure reaction, simulator.pressure_reaction),
    the implicit drag coefficient beta on the same faces (simulator module docstring), both averaged over the
    sub-steps, and the solid volume that left through outlets [m^3]."""

    force_x: np.ndarray
    force_z: np.ndarray
    beta_x: np.ndarray
    beta_z: np.ndarray
    outflow: float


def make_engine(name: str, grid, params, fluid_density: float, fluid_viscosity: float, gravity: float,
                outlets: np.ndarray, arch: str | None = None):
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
