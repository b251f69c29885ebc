"""Backend seam of the MP-PIC particle operations: ``get_backend("numpy")`` (plain NumPy reference, the test
oracle) or ``get_backend("taichi", arch=None)`` (kernels in ``hfgpu.kernels.particles``). Both return an
object with the same methods; inputs and outputs are NumPy arrays. Chosen once per run.

One particle step (what a simulator calls; ``frame`` GridFrame, ``width`` (nz, nx) [m]):

    moments = be.scatter(parcels, frame, width)                        # CellMoments (theta_p, Eq. 38, ...)
    fields = grid_fields(frame, width, u, v, pressure, moments, params)  # shared, O(cells)
    seen = be.gather(parcels, frame, fields)                           # ParcelFluid (Eq. 40-41)
    drag = be.push(parcels, seen, frame, fields, dt, params, rho_f, mu_o, gravity)  # Eq. 43-44, in place
    F_x, F_z = be.exchange(parcels, seen, drag, frame, width)          # Eq. 39, per unit volume at faces

u (nz, nx+1) and v (nz+1, nx) are the fluid face velocities, pressure (nz, nx) the dynamic pressure [Pa],
rho_f [kg/m^3], mu_o the clean-fluid viscosity [Pa s] (Re of Eq. 15), gravity [m/s^2] along +z.
``push`` returns D_p per parcel (the drag rate of its last implicit solve); ``exchange`` uses it with the
parcels' new velocities (u^{n+1}, consistent with the implicit drag) at their new positions, and the u_f and
grad p gathered before the push. Parcels never leave the grid or enter closed cells (walls stop them); a
simulator with an outlet removes the parcels that reach it itself (Parcels.drop) before the push.
Invariant of ``exchange``: sum(F_x V_xface) == sum over parcels n rho_p V_p [D (u_f - u_p) - dp/dx / rho_p]
(likewise z), V_face = dx dz w_face, for every parcel with an active face in its stencil.

Speed: the Taichi deposits (scatter, exchange) sum runs of parcels that share a stencil before they add them to
the grid, so call ``parcels.sort_by_cell(frame, width.shape)`` every few steps (between steps, never between
a gather and its exchange: it reorders the parcels); on the CPU they need no atomics (private grid copies per
parcel block), on a GPU sorted parcels need few atomics. Results do not depend on the order beyond
round-off. The Taichi backend reuses its output arrays (seen, D_p) once nothing refers to them any more.

Both backends also carry the fluid's explicit ``momentum_predictor`` (Eq. 26 / 49).
"""

from __future__ import annotations

import sys

import numpy as np

from ..records import GridFrame
from . import particle_ops_numpy as ref
from .interpolation import active_nodes, face_widths
from .params import MppicParams
from .parcels import Parcels
from .particle_ops_numpy import CellMoments, GridFields, ParcelFluid, grid_fields

BACKENDS = ("taichi", "numpy")


class NumpyBackend:
    """Plain NumPy reference of the particle operations (``particle_ops_numpy``)."""

    name = "numpy"

    def scatter(self, parcels: Parcels, frame: GridFrame, width: np.ndarray) -> CellMoments:
        """Per-cell moments of the parcels (Eq. 38 and the mass averages of O'Rourke & Snider 2010)."""
        return ref.finish_moments(ref.moment_sums(parcels, frame, width), frame, width)

    def gather(self, parcels: Parcels, frame: GridFrame, fields: GridFields) -> ParcelFluid:
        """Grid fields at the parcels (Eq. 40-41)."""
        return ref.gather(parcels, frame, fields)

    def push(self, parcels: Parcels, seen: ParcelFluid, frame: GridFrame, fields: GridFields, dt: float,
             params: MppicParams, fluid_density: float, fluid_viscosity: float, gravity: float = 9.81
             ) -> np.ndarray:
        """Eq. 43-44 in place; returns D_p per parcel."""
        return ref.push(parcels, seen, frame, fields, dt, params, fluid_density, fluid_viscosity, gravity)

    def exchange(self, parcels: Parcels, seen: ParcelFluid, drag: np.ndarray, frame: GridFrame,
                 width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Interphase momentum transfer per unit volume at faces (Eq. 39)."""
        return ref.exchange(parcels, seen, drag, frame, width)

    def momentum_predictor(self, u0: np.ndarray, v0: np.ndarray, p: np.ndarray, width0: np.ndarray,
                           theta_f0: np.ndarray, width: np.ndarray, theta_f: np.ndarray, mu: np.ndarray,
                           force_x: np.ndarray, force_z: np.ndarray, rho: float, dx: float, dz: float,
                           dt: float, wall_friction: str = "laminar"
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Fluid momentum predictor, Eq. 26 / 49 (:func:`hfgpu.proppant.momentum.momentum_predictor`)."""
        from .momentum import momentum_predictor

        return momentum_predictor(u0, v0, p, width0, theta_f0, width, theta_f, mu, force_x, force_z,
                                        rho, dx, dz, dt, wall_friction)


class TaichiBackend:
    """The particle operations as Taichi kernels (``hfgpu.kernels.particles``), float64.

    Deposits (scatter, exchange): on the CPU each of up to ``PRIVATE_COPIES`` parcel blocks sums into its own
    grid copy without atomics (copies reused between calls, summed here; at most ``PRIVATE_BYTES`` in all);
    on a GPU, blocks of 64 parcels add into one grid with atomics."""

    name = "taichi"
    PRIVATE_COPIES = 16
    PRIVATE_BYTES = 64 * 2 ** 20
    PARCELS_PER_COPY = 4096

    def __init__(self, arch: str | None = None):
        from ..kernels.runtime import init

        self.arch = init(arch)
        from ..kernels import particles as kp

        self._k = kp
        self._copies: dict[str, np.ndarray] = {}
        self._outputs: dict[tuple[int, ...], list[np.ndarray]] = {}
        self._interior: tuple[np.ndarray, np.ndarray] | None = None  # (width, its INTERIOR flags)
        self._push_flags = np.empty((0, 0), dtype=np.int32)

    def _output(self, shape: tuple[int, ...]) -> np.ndarray:
        """An uninitialised output array of ``shape``: a cached one that nothing outside this cache refers to
        any more (no array or view of it is alive), else a new one, cached (at most 2 per shape, for the 4
        shapes asked for last: the parcel count changes as parcels are injected). Reuse spares the page faults
        of fresh memory, a tenth of a gather's time at 1e6 parcels."""
        if shape not in self._outputs and len(self._outputs) >= 4:
            del self._outputs[next(iter(self._outputs))]
        pool = self._outputs.setdefault(shape, [])
        for buf in pool:
            if sys.getrefcount(buf) == 3:  # the pool, the loop variable and getrefcount's argument
                return buf
        buf = np.empty(shape)
        if len(pool) < 2:
            pool.append(buf)
        return buf

    def _deposit_buffer(self, key: str, n: int, shape: tuple[int, ...], size: int | None = None
                        ) -> tuple[np.ndarray, int, bool]:
        """Zeroed grid copies (copies, *shape) for a deposit of n parcels, the number of blocks, and whether
        the copies are private to the blocks (CPU) or shared through atomics (GPU). ``size``: the elements per
        copy that bound the number of private copies (default: those of ``shape``; a kernel depositing into
        several grids passes the largest, so that every grid gets the same number of blocks)."""
        private = self.arch == "cpu"
        if private:
            fit = max(1, self.PRIVATE_BYTES // (8 * (size or int(np.prod(shape)))))
            blocks = max(1, min(self.PRIVATE_COPIES, fit, n // self.PARCELS_PER_COPY))
        else:
            blocks = -(-n // self._k.CHUNK)
        copies = blocks if private else 1
        buf = self._copies.get(key)
        if buf is None or buf.shape[1:] != shape or buf.shape[0] < copies:
            buf = np.zeros((copies,) + shape)
            self._copies[key] = buf
        else:
            buf = buf[:copies]
            buf.fill(0.0)
        return buf, blocks, private

    def scatter(self, parcels: Parcels, frame: GridFrame, width: np.ndarray) -> CellMoments:
        """Per-cell moments of the parcels (Eq. 38), blocked deposit."""
        nz, nx = ref.check_width(width)
        cell_mask, _, _ = active_nodes(width)
        buf, blocks, private = self._deposit_buffer("cell", parcels.n, (nz, nx, len(ref.MOMENT_CHANNELS)))
        if parcels.n:
            self._k.moment_sums(parcels.x, parcels.z, parcels.u, parcels.v, parcels.radius, parcels.density,
                                parcels.particles, frame.x0, frame.z0, frame.dx, frame.dz, cell_mask,
                                self._flags(width), blocks, private, buf)
        return ref.finish_moments(np.moveaxis(buf.sum(axis=0), -1, 0), frame, width)

    def _flags(self, width: np.ndarray, theta: np.ndarray | None = None, params: MppicParams | None = None
               ) -> np.ndarray:
        """kernels.particles.stencil_flags of the grid (cells whose parcels take the kernels' fast paths). Without
        theta_p and params (deposits, gather) only the bit INTERIOR counts: those flags are kept and reused
        while the width field stays the same (a launch and a pass over the grid cost about as much as 1e4
        parcels)."""
        if params is None:
            if self._interior is None or not np.array_equal(self._interior[0], width):
                flags = np.empty(width.shape, dtype=np.int32)
                self._k.stencil_flags(width, width, np.inf, np.inf, flags)
                self._interior = (width.copy(), flags)
            return self._interior[1]
        flags = self._push_flags if self._push_flags.shape == width.shape else np.empty(width.shape, np.int32)
        self._k.stencil_flags(width, theta, params.theta_cp, params.friction_volume_fraction, flags)
        self._push_flags = flags
        return flags

    def gather(self, parcels: Parcels, frame: GridFrame, fields: GridFields) -> ParcelFluid:
        """Grid fields at the parcels (Eq. 40-41)."""
        seen = self._output((self._k.SEEN, parcels.n))
        if parcels.n:
            f = fields
            flat = [np.ascontiguousarray(a).reshape(-1) for a in (
                f.fluid_u, f.fluid_v, f.dpdx, f.dpdz, f.dtaudx, f.dtaudz, f.volume_fraction, f.mean_u, f.mean_v,
                f.damping_rate, f.width)]
            self._k.gather(parcels.x, parcels.z, frame.x0, frame.z0, frame.dx, frame.dz, self._flags(f.width),
                           f.cell_mask, f.xface_mask, f.zface_mask, *flat, *seen)
        return ParcelFluid(*seen)

    def push(self, parcels: Parcels, seen: ParcelFluid, frame: GridFrame, fields: GridFields, dt: float,
             params: MppicParams, fluid_density: float, fluid_viscosity: float, gravity: float = 9.81
             ) -> np.ndarray:
        """Eq. 43-44 in place; returns D_p per parcel."""
        drag = self._output((parcels.n,))
        if parcels.n:
            s = seen
            self._k.push(parcels.x, parcels.z, parcels.u, parcels.v, parcels.radius, parcels.density,
                         parcels.state, s.fluid_u, s.fluid_v, s.dpdx, s.dpdz, s.dtaudx, s.dtaudz,
                         s.volume_fraction, s.mean_u, s.mean_v, s.damping_rate, s.width,
                         frame.x0, frame.z0, frame.dx, frame.dz,
                         self._flags(fields.width, fields.volume_fraction, params), fields.width, fields.cell_mask,
                         fields.volume_fraction, dt, fluid_density, fluid_viscosity, gravity,
                         *self._push_constants(params), drag)
        return drag

    @staticmethod
    def _push_constants(params: MppicParams) -> tuple:
        """The closure constants the push kernel takes, in its order."""
        return (params.theta_cp, params.epsilon, params.packing_restitution, params.drag_law_code,
                params.drag_re_coefficient, params.bridging_factor, params.drag_iterations,
                params.bed_friction, params.friction_volume_fraction, int(params.shields_deposition),
                params.wall_friction_code)

    def exchange(self, parcels: Parcels, seen: ParcelFluid, drag: np.ndarray, frame: GridFrame,
                 width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Interphase momentum transfer per unit volume at faces (Eq. 39), blocked deposit."""
        ref.check_width(width)
        _, xmask, zmask = active_nodes(width)
        size = max(xmask.size, zmask.size)
        buf_x, blocks, private = self._deposit_buffer("xface", parcels.n, xmask.shape + (1,), size)
        buf_z, _, _ = self._deposit_buffer("zface", parcels.n, zmask.shape + (1,), size)
        if parcels.n:
            self._k.exchange_sums(parcels.x, parcels.z, parcels.u, parcels.v, parcels.radius, parcels.density,
                                  parcels.particles, seen.fluid_u, seen.fluid_v, seen.dpdx, seen.dpdz, drag,
                                  frame.x0, frame.z0, frame.dx, frame.dz, xmask, zmask, self._flags(width), blocks,
                                  private, buf_x, buf_z)
        wxf, wzf = face_widths(width)
        return (ref.per_face_volume(buf_x.sum(axis=0)[..., 0], frame, wxf),
                ref.per_face_volume(buf_z.sum(axis=0)[..., 0], frame, wzf))

    def momentum_predictor(self, u0: np.ndarray, v0: np.ndarray, p: np.ndarray, width0: np.ndarray,
                           theta_f0: np.ndarray, width: np.ndarray, theta_f: np.ndarray, mu: np.ndarray,
                           force_x: np.ndarray, force_z: np.ndarray, rho: float, dx: float, dz: float,
                           dt: float, wall_friction: str = "laminar"
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Fluid momentum predictor, Eq. 26 / 49, as a Taichi kernel (:mod:`hfgpu.kernels.momentum`)."""
        from ..kernels.momentum import momentum_predictor

        return momentum_predictor(u0, v0, p, width0, theta_f0, width, theta_f, mu, force_x, force_z,
                                        rho, dx, dz, dt, wall_friction)


def get_backend(name: str = "taichi", arch: str | None = None) -> NumpyBackend | TaichiBackend:
    """The particle-operation backend ``name`` ("taichi" or "numpy"); ``arch`` for Taichi (else HFGPU_ARCH,
    else cpu)."""
    if name == "numpy":
        return NumpyBackend()
    if name == "taichi":
        return TaichiBackend(arch)
    raise ValueError(f"mppic.backend: got {name!r}; allowed: one of {list(BACKENDS)}")


__all__ = ["get_backend", "NumpyBackend", "TaichiBackend", "grid_fields", "CellMoments", "GridFields",
           "ParcelFluid", "BACKENDS"]
