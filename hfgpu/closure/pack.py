"""The proppant pack after closure: where the grains are when the walls close, and the propped width.

Per cell of the proppant grid (area A = dx dz) the pack holds the solid volume V = sum over its parcels of
n_p pi d^3 / 6 (nearest cell of each parcel's centre, as :func:`hfgpu.propped.areal_solid`). Packed at the solid
fraction phi_s (``[closure] pack_solid_fraction``) it props the walls apart by

    w_p = V / (A phi_s) - 2 e                                            (e: embedment per face, default 0)

where the cell holds at least ``layers`` grain layers (the criterion of :mod:`hfgpu.propped`,
V / A >= layers phi_s d_v, d_v the solid-volume-weighted mean diameter), else w_p = 0 (a partial monolayer:
the walls close between the grains).

Settling at shut-in (``[closure] settling``): "in_place" closes the walls on every grain where the snapshot
has it; "bed" (default) first lets the suspended grains (:func:`hfgpu.propped.packed_fraction`'s rule: not
bridged and faster than :data:`PACKED_SPEED`) fall down their column of cells onto the bed below:
in each run of open cells of a column, the run's suspended solids fill the room left in its cells (phi_s w A
less the packed solids already there) from the deepest cell upward, with the run's grain mix in every cell
they reach; what the run cannot hold stays where it was. "bed" is the default because a slickwater fracture
closes over minutes to hours of leak-off, while its sand settles at mm/s to cm/s: the suspension has reached
the bed before the walls touch it. "in_place" suits a crosslinked gel that holds its proppant until it closes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..records import ProppantSnapshot

#: Parcels slower than this [m/s] count as packed (hfgpu.propped's groups use the same speed).
PACKED_SPEED = 1e-3


@dataclass(frozen=True)
class Pack:
    """The grains of each cell after settling, per class c: solid volume ``volume[c]`` [m^3], ``volume_diameter[c]``
    = sum V d [m^4] and ``volume_per_diameter[c]`` = sum V / d [m^2] (for the mean and the Sauter diameter);
    each (n_classes, nz, nx)."""

    volume: np.ndarray
    volume_diameter: np.ndarray
    volume_per_diameter: np.ndarray

    @property
    def solid(self) -> np.ndarray:
        """Solid volume per cell [m^3], (nz, nx)."""
        return self.volume.sum(axis=0)

    def mean_diameter(self) -> np.ndarray:
        """Solid-volume-weighted mean grain diameter d_v = sum V d / sum V [m] (0 in empty cells)."""
        return _ratio(self.volume_diameter.sum(axis=0), self.solid)

    def sauter_diameter(self) -> np.ndarray:
        """Sauter mean d_32 = sum V / sum (V / d) [m] (0 in empty cells): the diameter of the grains' specific
        surface, the one a packed bed's permeability follows."""
        return _ratio(self.solid, self.volume_per_diameter.sum(axis=0))


def _ratio(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.divide(a, b, out=np.zeros(np.shape(a)), where=b > 0.0)


def suspended(parcels: dict[str, np.ndarray]) -> np.ndarray:
    """Parcels still in suspension: not bridged (state 0) and not slower than PACKED_SPEED."""
    speed = np.hypot(parcels["u"], parcels["v"])
    return (np.asarray(parcels["state"]) == 0) & (speed >= PACKED_SPEED)


def _gather(snap: ProppantSnapshot, n_classes: int, select: np.ndarray) -> np.ndarray:
    """(3, n_classes, nz, nx): V, V d, V / d of the selected parcels per class and nearest cell."""
    nz, nx = np.shape(snap.grid["width"])
    f, p = snap.frame, snap.parcels
    out = np.zeros((3, n_classes, nz, nx))
    i = np.clip(np.floor((p["x"][select] - f.x0) / f.dx + 0.5).astype(int), 0, nx - 1)
    k = np.clip(np.floor((p["z"][select] - f.z0) / f.dz + 0.5).astype(int), 0, nz - 1)
    c = np.asarray(p["class_id"])[select].astype(int)
    d = 2.0 * np.asarray(p["radius"], dtype=np.float64)[select]
    v = np.asarray(p["particles"], dtype=np.float64)[select] * np.pi / 6.0 * d**3
    for n, values in enumerate((v, v * d, v / d)):
        np.add.at(out[n], (c, k, i), values)
    return out


def settle(snap: ProppantSnapshot, n_classes: int, rule: str, pack_fraction: float) -> Pack:
    """The :class:`Pack` of a proppant snapshot after the settling ``rule`` ("bed" or "in_place")."""
    parcels = snap.parcels
    if rule == "in_place":
        return Pack(*_gather(snap, n_classes, np.ones(len(parcels["x"]), dtype=bool)))
    if rule != "bed":
        raise ValueError(f"settle: rule {rule!r}; allowed: 'bed', 'in_place'")
    moving = suspended(parcels)
    fixed, falling = _gather(snap, n_classes, ~moving), _gather(snap, n_classes, moving)
    width = np.asarray(snap.grid["width"], dtype=np.float64)
    room = np.maximum(pack_fraction * width * snap.frame.dx * snap.frame.dz - fixed[0].sum(axis=0), 0.0)
    for column in range(width.shape[1]):
        for top, bottom in _open_runs(width[:, column] > 0.0):
            cells = slice(top, bottom + 1)
            load = falling[:, :, cells, column].sum(axis=2)  # (3, n_classes): the run's suspended grains
            total = load[0].sum()
            if total <= 0.0:
                continue
            space = room[cells, column]
            below = np.concatenate(([0.0], np.cumsum(space[::-1])))[:-1][::-1]  # room in the cells beneath
            placed = np.clip(total - below, 0.0, space)                      # filled from the bottom up
            kept = 1.0 - placed.sum() / total
            falling[:, :, cells, column] = (kept * falling[:, :, cells, column]
                                            + load[:, :, None] * (placed / total)[None, None, :])
    return Pack(*(fixed + falling))


def _open_runs(open_cells: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) row of each run of consecutive open cells of a column."""
    edges = np.diff(np.concatenate(([0], open_cells.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1))


def propped_width(pack: Pack, area: float, pack_fraction: float, layers: float = 1.0,
                  embedment: float = 0.0, width: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(w_p [m], propped mask): w_p = V / (A phi_s) - 2 e where V / A >= layers phi_s d_v (and the cell is
    open, width > 0, when ``width`` is given) and w_p > 0; 0 elsewhere."""
    solid = pack.solid
    areal = solid / area
    propped = (solid > 0.0) & (areal >= layers * pack_fraction * pack.mean_diameter())
    if width is not None:
        propped &= np.asarray(width) > 0.0
    w = np.where(propped, areal / pack_fraction - 2.0 * embedment, 0.0)
    propped &= w > 0.0
    return np.where(propped, w, 0.0), propped
