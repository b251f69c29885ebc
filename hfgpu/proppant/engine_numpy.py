"""The NumPy particle engine: the seam of hfgpu.proppant.engine_seam over the reference operations of
hfgpu.proppant.particle_ops_numpy. It is the oracle of the Taichi engine (the same sub-loop, arithmetic and
parcel order up to round-off) and a run's ``[mppic] backend = "numpy"``.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SimulationError
from . import particle_ops_numpy as ref
from .engine_seam import SubLoop
from .grid import StaggeredGrid
from .params import MppicParams
from .parcels import Parcels


class NumpyEngine:
    """Parcels as a host :class:`Parcels`; every operation is a NumPy call (see hfgpu.proppant.engine_seam)."""

    name = "numpy"
    arch = "numpy"
    threads = 1

    def __init__(self, grid: StaggeredGrid, params: MppicParams, fluid_density: float, fluid_viscosity: float,
                 gravity: float, outlets: np.ndarray):
        self.params = params
        self.rho_f = fluid_density
        self.mu_f = fluid_viscosity
        self.gravity = gravity
        self.outlets = np.asarray(outlets, dtype=bool)
        self.grid = grid
        self._accepted = Parcels.empty()
        self._work: Parcels | None = None
        self._fluid = None

    # -- state ------------------------------------------------------------------------------------------

    @property
    def _current(self) -> Parcels:
        return self._work if self._work is not None else self._accepted

    @property
    def n(self) -> int:
        """Parcels in the domain."""
        return self._current.n

    @property
    def live(self) -> int:
        """Parcels in the domain."""
        return self._current.n

    def set_grid(self, grid: StaggeredGrid) -> None:
        """A new width field on the same frame."""
        self.grid = grid

    def append(self, batch: Parcels) -> None:
        """Add parcels at the end."""
        self._current.append(batch)

    def parcels(self) -> Parcels:
        """A host copy of the parcels."""
        return self._current.copy()

    def set_parcels(self, parcels: Parcels) -> None:
        """Replace the parcels (accepted state)."""
        self._accepted = parcels.copy()
        self._work = None

    def begin_step(self, u: np.ndarray, v: np.ndarray, p: np.ndarray) -> None:
        """The accepted parcels, sorted by cell, become the work parcels; the fluid of the step's start."""
        ref.check_fluid(self.grid.width, u, v, p)
        self._work = self._accepted.copy()
        self._work.sort_by_cell(self.grid.frame, self.grid.shape)
        self._fluid = (u, v, p)

    def commit(self) -> None:
        """Accept the work parcels."""
        self._accepted, self._work = self._work, None

    # -- the particle phase -----------------------------------------------------------------------------

    def moments(self) -> ref.CellMoments:
        """Cell moments of the parcels (Eq. 38)."""
        width = self.grid.width
        return ref.finish_moments(ref.moment_sums(self._current, self.grid.frame, width), self.grid.frame, width)

    def max_speed(self) -> float:
        """max |u| + |v| over the parcels (0 without any)."""
        p = self._current
        return float(np.max(np.abs(p.u) + np.abs(p.v))) if p.n else 0.0

    def solid_volume(self) -> float:
        """Solid volume of the parcels [m^3]."""
        return float(np.sum(self._current.solid_volume()))

    def substeps(self, dt: float, count: int, t0: float) -> SubLoop:
        """``count`` sub-steps of dt / count in the fluid of begin_step: scatter, grid fields, gather, push,
        exchange (drag deposits, pressure reaction, implicit-drag coefficient), finiteness check (a
        SimulationError at the sub-step's end time), outlets."""
        parcels, frame, width = self._work, self.grid.frame, self.grid.width
        u, v, p = self._fluid
        params = self.params
        h = dt / count
        nz, nx = self.grid.shape
        fx, bx = np.zeros((nz, nx + 1)), np.zeros((nz, nx + 1))
        fz, bz = np.zeros((nz + 1, nx)), np.zeros((nz + 1, nx))
        lag_x, lag_z = np.ones(parcels.n), np.ones(parcels.n)
        outflow = 0.0
        for s in range(count):
            moments = ref.finish_moments(ref.moment_sums(parcels, frame, width), frame, width)
            fields = ref.grid_fields(frame, width, u, v, p, moments, params, self.rho_f, self.gravity)
            seen = ref.gather(parcels, frame, fields)
            drag = ref.push(parcels, seen, frame, fields, h, params, self.rho_f, self.mu_f, self.gravity)
            force = ref.exchange(parcels, seen, drag, frame, width)
            reaction = ref.pressure_reaction(fields)
            fx += (force[0] + reaction[0]) / count
            fz += (force[1] + reaction[1]) / count
            held = seen.volume_fraction >= params.damping_threshold * params.theta_cp
            lag_x = ref.parcel_response(lag_x, parcels.u, drag, h, held)
            lag_z = ref.parcel_response(lag_z, parcels.v, drag, h, held)
            rate = parcels.solid_volume() * parcels.density * drag
            beta = ref.face_sums(parcels, rate * lag_x, rate * lag_z, frame, width)
            bx += beta[0] / count
            bz += beta[1] / count
            check_finite(parcels, frame, t0 + (s + 1) * h)
            leaving = self._leaving(parcels)
            if leaving.any():
                outflow += float(np.sum(parcels.solid_volume()[leaving]))
                parcels.drop(leaving)
                lag_x, lag_z = lag_x[~leaving], lag_z[~leaving]
        return SubLoop(fx, fz, bx, bz, outflow)

    def _leaving(self, parcels: Parcels) -> np.ndarray:
        """The parcels in outlet cells."""
        if not self.outlets.any() or parcels.n == 0:
            return np.zeros(parcels.n, dtype=bool)
        k, i, _ = ref.owning_cell(parcels.x, parcels.z, self.grid.frame, self.grid.shape)
        return self.outlets[k, i]


def check_finite(parcels: Parcels, frame, t: float) -> None:
    """SimulationError naming the first parcel whose position or velocity is not finite, and its cell."""
    p = parcels
    bad = ~(np.isfinite(p.x) & np.isfinite(p.z) & np.isfinite(p.u) & np.isfinite(p.v))
    if bad.any():
        j = int(np.argmax(bad))
        raise bad_parcel(j, p.x[j], p.z[j], frame, t)


def bad_parcel(j: int, x: float, z: float, frame, t: float) -> SimulationError:
    """The error of a parcel j at (x, z) whose state is not finite at time t."""
    cell = (int(math.floor((z - frame.z0) / frame.dz + 0.5)) if np.isfinite(z) else None,
            int(math.floor((x - frame.x0) / frame.dx + 0.5)) if np.isfinite(x) else None)
    return SimulationError(f"non-finite state of parcel {j}", time=t, cell=cell)
