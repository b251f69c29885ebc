"""Lagrangian parcels of the MP-PIC model as a structure of 1-D NumPy arrays (shared data layout).

The fields are those the Taichi engine keeps in its parcel rows (kernels/layout.py FLOAT_FIELDS, INT_FIELDS):
named once there, so that a new parcel field is one edit for both."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..kernels.layout import FLOAT_FIELDS, INT_FIELDS
from ..records import GridFrame


@dataclass
class Parcels:
    """Parcels: x, z [m], u, v [m/s], radius [m], density [kg/m^3], particles (real particles per parcel),
    state (int32: kernels/layout.py SUSPENDED (moving) or BRIDGED), class_id (int32, index of the scene's proppant
    class).

    Arrays are contiguous float64 / int32 of equal length; operations replace or update them in place.
    """

    __annotations__ = {name: "np.ndarray" for name in FLOAT_FIELDS + INT_FIELDS}  # the fields, in that order

    def __post_init__(self) -> None:
        for name in FLOAT_FIELDS:
            setattr(self, name, np.ascontiguousarray(getattr(self, name), dtype=np.float64).reshape(-1))
        for name in INT_FIELDS:
            setattr(self, name, np.ascontiguousarray(getattr(self, name), dtype=np.int32).reshape(-1))
        sizes = {name: getattr(self, name).size for name in FLOAT_FIELDS + INT_FIELDS}
        if len(set(sizes.values())) > 1:
            raise ValueError(f"Parcels: arrays of unequal length {sizes}")

    @classmethod
    def empty(cls) -> "Parcels":
        """No parcels."""
        return cls(**{f.name: np.zeros(0) for f in fields(cls)})

    @classmethod
    def create(cls, x, z, radius, density, particles, u=0.0, v=0.0, class_id=0) -> "Parcels":
        """New suspended parcels; scalars broadcast to the length of ``x``."""
        n = np.size(x)

        def full(a):
            return np.broadcast_to(np.asarray(a), (n,)).copy()

        return cls(x=full(x), z=full(z), u=full(u), v=full(v), radius=full(radius), density=full(density),
                   particles=full(particles), state=np.zeros(n, np.int32), class_id=full(class_id))

    @property
    def n(self) -> int:
        """Number of parcels."""
        return self.x.size

    def append(self, batch: "Parcels") -> None:
        """Add the parcels of ``batch`` at the end."""
        for name in FLOAT_FIELDS + INT_FIELDS:
            setattr(self, name, np.concatenate([getattr(self, name), getattr(batch, name)]))

    def drop(self, mask: np.ndarray) -> None:
        """Remove the parcels where ``mask`` is true."""
        keep = ~np.asarray(mask, dtype=bool)
        for name in FLOAT_FIELDS + INT_FIELDS:
            setattr(self, name, np.ascontiguousarray(getattr(self, name)[keep]))

    def copy(self) -> "Parcels":
        """Deep copy."""
        return Parcels(**{name: getattr(self, name).copy() for name in FLOAT_FIELDS + INT_FIELDS})

    def reorder(self, order: np.ndarray) -> None:
        """Permute all arrays by the index array ``order``."""
        for name in FLOAT_FIELDS + INT_FIELDS:
            setattr(self, name, np.ascontiguousarray(getattr(self, name)[order]))

    def sort_by_cell(self, frame: GridFrame, shape: tuple[int, int]) -> None:
        """Order the parcels by half-cell (cell_keys, a stable sort), so that neighbours in memory share their
        bilinear stencils: the Taichi deposits then sum runs locally and need few atomics. The Taichi engine
        sorts its parcels the same way at the start of every fluid step (kernels/store.py)."""
        self.reorder(np.argsort(self.cell_keys(frame, shape), kind="stable"))

    def cell_keys(self, frame: GridFrame, shape: tuple[int, int]) -> np.ndarray:
        """Half-cell index of each parcel, row-major in depth, then x, clipped into the grid's (2 nz + 2) x
        (2 nx + 2) half cells; ``frame`` is the GridFrame of a grid of ``shape`` (nz, nx)."""
        nz, nx = shape
        kq = np.clip(np.floor(2.0 * (self.z - frame.z0) / frame.dz).astype(np.int64) + 1, 0, 2 * nz + 1)
        iq = np.clip(np.floor(2.0 * (self.x - frame.x0) / frame.dx).astype(np.int64) + 1, 0, 2 * nx + 1)
        return kq * (2 * nx + 2) + iq

    def particle_volume(self) -> np.ndarray:
        """Volume of one particle of each parcel, 4/3 pi r^3 [m^3]."""
        return 4.0 / 3.0 * np.pi * self.radius ** 3

    def solid_volume(self) -> np.ndarray:
        """Solid volume of each parcel, particles x 4/3 pi r^3 [m^3]."""
        return self.particles * self.particle_volume()

    def as_dict(self) -> dict[str, np.ndarray]:
        """Copies of the arrays by name (for ProppantSnapshot.parcels)."""
        return {name: getattr(self, name).copy() for name in FLOAT_FIELDS + INT_FIELDS}
