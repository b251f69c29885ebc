"""What the proppant tells the fracture in a two-way coupled run (hfgpu.coupled): ``Slurry`` fields on a grid.

Three per-cell fields, held on the grid they come from (the proppant grid, ``frame``) and read by the fracture
engine at its own cell centres (nearest cell; outside the frame the clean fluid's values, ``outside`` for the
viscosity ratio):

* ``ratio`` = mu_eff / mu >= 1, the slurry's effective viscosity over the carrier fluid's. The lubrication face
  between cells P and E (Eq. 29) then conducts T_PE = (w_P + w_E)^3 / (8 mu' r_PE) (face length / centre
  distance), r_PE = (r_P + r_E) / 2: the resistances of the two half cells in series (the pressure drop over
  a half cell is proportional to its viscosity at equal flux and width);
* ``blocked``: cells the front cannot advance into or through (bridged or packed slurry at the tip): a blocked
  active cell opens no neighbour, a blocked inactive cell is not opened (front.cells_to_open's ``blocked``);
* the tip asymptote (Eq. 33 with the M vertex, front.py) uses mu' times the mean ratio of the fracture's edge
  cells that are not blocked (simulator._Engine.slurry_faces): one viscosity for the whole front (exact for a
  uniform slurry; a packed bed on the fracture's lower edge, blocked, does not count);
* ``floor`` [m]: the width at which the walls meet the proppant (its grains at close packing). In a step without
  injection (after shut-in) a cell cannot close below it: newton.py holds it there as a contact cell (its
  unknown the fluid pressure, the difference to the elastic pressure the grains' load) that leaks no more.

A uniform slurry (the same ratio everywhere, ``outside`` included) is a fluid of viscosity r mu: the run then
equals the clean-fluid run of that viscosity (tests/fracture/test_slurry.py checks it against the radial
viscosity-vertex solution).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..records import GridFrame


@dataclass(frozen=True, eq=False)
class Slurry:
    """The slurry's fields on the grid ``frame`` (each (nz, nx)); see the module docstring."""

    frame: GridFrame
    ratio: np.ndarray
    blocked: np.ndarray
    floor: np.ndarray | None = None
    outside: float = 1.0

    @classmethod
    def uniform(cls, ratio: float) -> "Slurry":
        """The same viscosity ratio everywhere, nothing blocked."""
        return cls(GridFrame(1.0, 1.0, 0.0, 0.0), np.full((1, 1), float(ratio)), np.zeros((1, 1), bool),
                   outside=float(ratio))

    def at(self, x: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """(ratio, blocked, floor) at the points (x, z) (arrays of one shape): the nearest cell's, the clean
        fluid's (``outside``, False, 0) beyond the frame; floor None without one."""
        nz, nx = self.ratio.shape
        i = np.floor((np.asarray(x) - self.frame.x0) / self.frame.dx + 0.5).astype(int)
        k = np.floor((np.asarray(z) - self.frame.z0) / self.frame.dz + 0.5).astype(int)
        inside = (i >= 0) & (i < nx) & (k >= 0) & (k < nz)
        i, k = np.clip(i, 0, nx - 1), np.clip(k, 0, nz - 1)
        floor = None if self.floor is None else np.where(inside, self.floor[k, i], 0.0)
        return np.where(inside, self.ratio[k, i], self.outside), inside & self.blocked[k, i], floor


def held_tips(active: np.ndarray, blocked: np.ndarray | None) -> int:
    """Active cells at the front's lateral tip that the slurry holds (a tip screen-out): a blocked cell whose
    neighbour along x (the fracture's length) is inactive or beyond the box, or a cell whose inactive neighbour
    along x is blocked (the cell the front would open next, which it does not open: front.cells_to_open); 0
    without blocked cells."""
    if blocked is None:
        return 0
    outside = np.ones((2,) + active.shape, dtype=bool)        # the neighbour to the left, to the right is inactive
    outside[0, :, 1:], outside[1, :, :-1] = ~active[:, :-1], ~active[:, 1:]
    beyond = np.zeros((2,) + active.shape, dtype=bool)        # ... and blocked
    beyond[0, :, 1:], beyond[1, :, :-1] = blocked[:, :-1], blocked[:, 1:]
    held = (blocked & outside.any(axis=0)) | (outside & beyond).any(axis=0)
    return int((active & held).sum())
