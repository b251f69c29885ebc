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

Speed: the Taichi deposits (scatter, exchange) sum runs of parcels that share a stencil before their atomic
adds, so call ``parcels.sort_by_cell(frame, width.shape)`` every few steps (between steps, never between a
gather and its exchange: it reorders the parcels). Results do not depend on the order beyond round-off.

The fluid engineer registers ``momentum_predictor`` on both classes below (marked place).
"""

from __future__ import annotations

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

    # --- fluid engineer: register momentum_predictor here (same signature as on TaichiBackend) ---
    def momentum_predictor(self, u0: np.ndarray, v0: np.ndarray, p: np.ndarray, width0: np.ndarray,
                           theta_f0: np.ndarray, width: np.ndarray, theta_f: np.ndarray, mu: np.ndarray,
                           force_x: np.ndarray, force_z: np.ndarray, rho: float, dx: float, dz: float,
                           dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Fluid momentum predictor, Eq. 26 / 49 (:func:`hfgpu.proppant.momentum.momentum_predictor`)."""
        from .momentum import momentum_predictor

        return momentum_predictor(u0, v0, p, width0, theta_f0, width, theta_f, mu, force_x, force_z,
                                        rho, dx, dz, dt)


class TaichiBackend:
    """The particle operations as Taichi kernels (``hfgpu.kernels.particles``), float64."""

    name = "taichi"

    def __init__(self, arch: str | None = None):
        from ..kernels.runtime import init

        self.arch = init(arch)
        from ..kernels import particles as kp

        self._k = kp

    def scatter(self, parcels: Parcels, frame: GridFrame, width: np.ndarray) -> CellMoments:
        """Per-cell moments of the parcels (Eq. 38), atomic deposit."""
        nz, nx = ref.check_width(width)
        cell_mask, _, _ = active_nodes(width)
        sums = np.zeros((nz, nx, len(ref.MOMENT_CHANNELS)))
        if parcels.n:
            self._k.moment_sums(parcels.x, parcels.z, parcels.u, parcels.v, parcels.radius, parcels.density,
                                parcels.particles, frame.x0, frame.z0, frame.dx, frame.dz, cell_mask, sums)
        return ref.finish_moments(np.moveaxis(sums, -1, 0), frame, width)

    def gather(self, parcels: Parcels, frame: GridFrame, fields: GridFields) -> ParcelFluid:
        """Grid fields at the parcels (Eq. 40-41)."""
        out = {name: np.empty(parcels.n) for name in ParcelFluid.__dataclass_fields__}
        if parcels.n:
            f = fields
            self._k.gather(parcels.x, parcels.z, frame.x0, frame.z0, frame.dx, frame.dz,
                           f.cell_mask, f.xface_mask, f.zface_mask, f.fluid_u, f.fluid_v, f.dpdx, f.dpdz,
                           f.dtaudx, f.dtaudz, f.volume_fraction, f.mean_u, f.mean_v, f.damping_rate, f.width,
                           out["fluid_u"], out["fluid_v"], out["dpdx"], out["dpdz"], out["dtaudx"],
                           out["dtaudz"], out["volume_fraction"], out["mean_u"], out["mean_v"],
                           out["damping_rate"], out["width"])
        return ParcelFluid(**out)

    def push(self, parcels: Parcels, seen: ParcelFluid, frame: GridFrame, fields: GridFields, dt: float,
             params: MppicParams, fluid_density: float, fluid_viscosity: float, gravity: float = 9.81
             ) -> np.ndarray:
        """Eq. 43-44 in place; returns D_p per parcel."""
        drag = np.empty(parcels.n)
        if parcels.n:
            s = seen
            self._k.push(parcels.x, parcels.z, parcels.u, parcels.v, parcels.radius, parcels.density,
                         parcels.state, s.fluid_u, s.fluid_v, s.dpdx, s.dpdz, s.dtaudx, s.dtaudz,
                         s.volume_fraction, s.mean_u, s.mean_v, s.damping_rate, s.width,
                         frame.x0, frame.z0, frame.dx, frame.dz, fields.width, fields.cell_mask,
                         fields.volume_fraction,
                         dt, fluid_density, fluid_viscosity, gravity, params.theta_cp, params.epsilon,
                         params.packing_restitution, params.drag_law_code, params.drag_re_coefficient,
                         params.bridging_factor, params.drag_iterations, drag)
        return drag

    def exchange(self, parcels: Parcels, seen: ParcelFluid, drag: np.ndarray, frame: GridFrame,
                 width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Interphase momentum transfer per unit volume at faces (Eq. 39), atomic deposit."""
        nz, nx = ref.check_width(width)
        _, xmask, zmask = active_nodes(width)
        sx = np.zeros((nz, nx + 1, 1))
        sz = np.zeros((nz + 1, nx, 1))
        if parcels.n:
            for mask, ox, oz, along_x, out in ((xmask, -0.5, 0.0, 1, sx), (zmask, 0.0, -0.5, 0, sz)):
                self._k.exchange_sums(parcels.x, parcels.z, parcels.u, parcels.v, parcels.radius,
                                      parcels.density, parcels.particles, seen.fluid_u, seen.fluid_v, seen.dpdx,
                                      seen.dpdz, drag, frame.x0, frame.z0, frame.dx, frame.dz, mask, ox, oz,
                                      along_x, out)
        wxf, wzf = face_widths(width)
        return ref.per_face_volume(sx[..., 0], frame, wxf), ref.per_face_volume(sz[..., 0], frame, wzf)

    # --- fluid engineer: register momentum_predictor here (same signature as on NumpyBackend) ---
    def momentum_predictor(self, u0: np.ndarray, v0: np.ndarray, p: np.ndarray, width0: np.ndarray,
                           theta_f0: np.ndarray, width: np.ndarray, theta_f: np.ndarray, mu: np.ndarray,
                           force_x: np.ndarray, force_z: np.ndarray, rho: float, dx: float, dz: float,
                           dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Fluid momentum predictor, Eq. 26 / 49, as a Taichi kernel (:mod:`hfgpu.kernels.momentum`)."""
        from ..kernels.momentum import momentum_predictor

        return momentum_predictor(u0, v0, p, width0, theta_f0, width, theta_f, mu, force_x, force_z,
                                        rho, dx, dz, dt)


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
