"""The seam between the MP-PIC run loop and the particle phase: what the run loop (hfgpu.proppant.simulator)
calls on a particle engine (:class:`ParticleEngine`), and what a particle sub-loop hands back
(:class:`SubLoop`). Both engines (hfgpu.proppant.engine_taichi, hfgpu.proppant.engine_numpy) implement it;
:func:`hfgpu.proppant.engine.make_engine` picks one by name. The seam imports no engine, so an engine can import
the seam without an import cycle.

An engine owns the parcels and the grid fields the particle phase needs, and runs a whole particle sub-loop per
call. Both engines do the same arithmetic in the same order up to round-off and keep the parcels in the same
order. One fluid step:

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
from typing import Protocol

import numpy as np

from .grid import StaggeredGrid
from .parcels import Parcels
from .particle_ops_numpy import CellMoments


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


class ParticleEngine(Protocol):
    """A particle engine as the run loop uses it (module docstring): ``name`` ("taichi" or "numpy"), ``arch``
    and ``threads`` (what runs it, for the summary), ``live`` (parcels in the domain)."""

    name: str
    arch: str
    threads: int | None

    @property
    def live(self) -> int: ...

    def set_grid(self, grid: StaggeredGrid) -> None: ...

    def append(self, batch: Parcels) -> None: ...

    def parcels(self) -> Parcels: ...

    def set_parcels(self, parcels: Parcels) -> None: ...

    def begin_step(self, u: np.ndarray, v: np.ndarray, p: np.ndarray) -> None: ...

    def substeps(self, dt: float, count: int, t0: float) -> SubLoop: ...

    def moments(self) -> CellMoments: ...

    def commit(self) -> None: ...

    def max_speed(self) -> float: ...

    def solid_volume(self) -> float: ...
