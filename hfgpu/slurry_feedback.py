"""The proppant's feedback on the fracture in a two-way coupled run (hfgpu.coupled): the fracture's
:class:`~hfgpu.fracture.slurry.Slurry` fields from a proppant snapshot.

Per cell of the proppant grid, of solid volume fraction theta_p and width w:

* viscosity ratio r = mu(theta_p) / mu_o of ``[mppic] viscosity_law`` (Eq. 10, or Krieger & Dougherty; capped at
  ``max_relative_viscosity``: hfgpu.proppant.closures.slurry_viscosity);
* a packed cell (theta_p >= PACKED_SHARE theta_cp, holding parcels) passes fluid as a porous medium,
  q = -(k w / mu) grad p (Darcy) instead of q = -(w^3 / (12 mu)) grad p (Poiseuille): r = w^2 / (12 k) where
  that is larger, with k of Kozeny-Carman on the cell's grains (hfgpu.closure.permeability.kozeny_carman: the
  Sauter diameter d_32 of the cell's parcels, porosity 1 - theta_cp);
* blocked (the front cannot pass): packed cells, and bridged cells (:func:`hfgpu.coupling.screen_out_cells`:
  width below ``bridging_factor`` x the largest grain in the cell);
* floor: the width at which the cell's grains are at close packing, w_p = theta_p w / theta_cp: after shut-in the
  walls close onto the proppant there and no further (the grains where they are, as ``[closure] settling =
  "in_place"``).
"""

from __future__ import annotations

import numpy as np

from .closure.permeability import kozeny_carman
from .coupling import cell_indices, screen_out_cells
from .fracture.slurry import Slurry
from .proppant.closures import slurry_viscosity
from .proppant.params import MppicParams
from .records import ProppantSnapshot

#: A cell is packed when its solid volume fraction is at least this share of close packing (theta_cp).
PACKED_SHARE = 0.95


def packed_cells(snap: ProppantSnapshot, params: MppicParams) -> np.ndarray:
    """Cells whose solid volume fraction is at least PACKED_SHARE x theta_cp."""
    return np.asarray(snap.grid["volume_fraction"]) >= PACKED_SHARE * params.theta_cp


def sauter_diameter(snap: ProppantSnapshot) -> np.ndarray:
    """d_32 = sum V / sum (V / d) of the parcels in each cell [m] (0 where none)."""
    shape = np.shape(snap.grid["width"])
    p = snap.parcels
    volume, per_d = np.zeros(shape), np.zeros(shape)
    if len(p["x"]):
        k, i = cell_indices(snap.frame, shape, p["x"], p["z"])
        r = np.asarray(p["radius"])
        v = np.asarray(p["particles"]) * 4.0 / 3.0 * np.pi * r**3
        np.add.at(volume, (k, i), v)
        np.add.at(per_d, (k, i), v / (2.0 * r))
    return np.divide(volume, per_d, out=np.zeros(shape), where=per_d > 0.0)


def slurry_of(snap: ProppantSnapshot, params: MppicParams) -> Slurry:
    """The fracture's slurry fields from the proppant snapshot (module docstring)."""
    theta = np.asarray(snap.grid["volume_fraction"], dtype=np.float64)
    width = np.asarray(snap.grid["width"], dtype=np.float64)
    ratio = slurry_viscosity(theta, 1.0, params)
    diameter = sauter_diameter(snap)
    packed = packed_cells(snap, params) & (width > 0.0) & (diameter > 0.0)
    if packed.any():
        k = kozeny_carman(diameter[packed], 1.0 - params.theta_cp)
        ratio[packed] = np.maximum(ratio[packed], width[packed] ** 2 / (12.0 * k))
    blocked = packed | screen_out_cells(snap, params.bridging_factor)
    return Slurry(snap.frame, ratio, blocked, floor=theta * width / params.theta_cp)
