"""What an MP-PIC run watches for after each step: unphysical states, caught at the step where they start.

* **theta_p above close packing**: the largest cell volume fraction above ``OVERPACKED`` x theta_cp (the packing
  cap of the push lets a cell exceed theta_cp by one step's inflow at most, so more means the width under the
  parcels shrank: a closing cell of the width history; where the width is fixed, the parcels were placed there
  above close packing or one step's inflow overfilled the cell);
* **proppant in cells narrower than a grain**: a cell holding proppant (theta_p >= ``HOLDS``: more than the trace
  a neighbour's parcels deposit on it) whose width is below the smallest grain diameter of the scene's classes
  (parcels cannot enter such a cell, so its width shrank under them: a point parcel there stands for grains that
  cannot fit);
* **a collapsing step**: the accepted step below ``COLLAPSE_WARNING`` x its nominal size (the smaller of dt_max
  and the time to the next output or stage end) warns; below ``COLLAPSE_FLOOR`` x it the run stops with a
  :class:`~hfgpu.errors.SimulationError` naming what bounds the step, where, and the key that would change it,
  within seconds instead of after hours of ever smaller steps.

Each kind is reported once, at its first occurrence, as a RuntimeWarning line with the time on the scene's
clock, the place (x and depth in the scene's output units) and the value; :meth:`Watch.summary` gives the run's
summary entries (``unphysical_states``: one line per kind found, empty when none).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import SimulationError
from ..units import display_unit, format_number, in_display_units

#: A cell's theta_p above this multiple of theta_cp is reported.
OVERPACKED = 1.1
#: A cell holds proppant from this theta_p on (below: a share of a neighbour's deposit, Eq. 38).
HOLDS = 0.01
#: A step below this fraction of its nominal size warns; below COLLAPSE_FLOOR the run stops.
COLLAPSE_WARNING = 1e-3
COLLAPSE_FLOOR = 1e-6

#: What bounds a step (hfgpu.proppant.simulator.ProppantSimulation.step_limits) -> the scene key that moves it.
KEYS = {"dt_max": "[mppic] dt_max", "output": "[output] every or the schedule's stage ends",
        "fluid Courant": "[mppic] c_max, or [coupling] min_width where the fast cell is narrow",
        "parcel Courant": "[mppic] particle_substeps or c_max"}


@dataclass
class Watch:
    """The checks of the module docstring for one run (times on the scene's clock); ``units`` is the scene's
    output system; ``stride`` > 0: the grid holds a stage's clusters side by side every ``stride`` columns
    (hfgpu.stage_blocks), and a cell is named by its cluster and its x on that cluster's plane;
    ``width_history``: the width follows a fracture's history (False: fixed), which the messages name as a cause;
    ``two_way``: the fracture feels the slurry (``[coupling] mode = "two-way"``), so no message suggests it."""

    theta_cp: float
    smallest_grain: float
    units: str = "SI"
    stride: int = 0
    width_history: bool = True
    two_way: bool = False
    found: dict[str, str] = field(default_factory=dict)

    def _where(self, frame, k: int, i: int) -> str:
        unit = display_unit("length", self.units)
        cluster, i = divmod(i, self.stride) if self.stride else (-1, i)
        x = in_display_units(frame.x0 + i * frame.dx, "length", self.units)
        z = in_display_units(frame.z0 + k * frame.dz, "length", self.units)
        where = f"x = {format_number(x)} {unit}, depth {format_number(z)} {unit}"
        return where if cluster < 0 else f"cluster {cluster + 1}, {where}"

    def _width(self, value: float) -> str:
        return f"{format_number(in_display_units(value, 'width', self.units))} {display_unit('width', self.units)}"

    def _report(self, kind: str, t: float, text: str) -> None:
        if kind in self.found:
            return
        line = f"{kind} at t = {format_number(t)} s: {text}"
        self.found[kind] = line
        warnings.warn(line, RuntimeWarning, stacklevel=3)

    def after_step(self, t: float, frame, width: np.ndarray, theta: np.ndarray) -> None:
        """Check the cell fields after an accepted step ending at ``t`` (the simulation's clock)."""
        k, i = np.unravel_index(int(np.argmax(theta)), theta.shape)
        if theta[k, i] > OVERPACKED * self.theta_cp and "theta_p above close packing" not in self.found:
            cause = ("the width under its parcels shrank (the fracture history closes it); [coupling] "
                     "fracture_every resolves the width history" if self.width_history else
                     "the width is fixed, so its parcels were placed there above close packing or one step's "
                     "inflow overfilled it")
            self._report("theta_p above close packing", t,
                         f"theta_p {theta[k, i]:.3g} (close packing {self.theta_cp:g}) in the cell at "
                         f"{self._where(frame, k, i)}, {self._width(width[k, i])} wide: {cause}")
        narrow = (theta >= HOLDS) & (width > 0.0) & (width < self.smallest_grain)
        if narrow.any() and "proppant in cells narrower than a grain" not in self.found:
            k, i = np.argwhere(narrow)[0]
            self._report("proppant in cells narrower than a grain", t,
                         f"theta_p {theta[k, i]:.3g} in the cell at {self._where(frame, k, i)}, "
                         f"{self._width(width[k, i])} wide, below the smallest grain "
                         f"({self._width(self.smallest_grain)}); the cell is closing around its proppant"
                         + ("" if self.two_way else ", which a one-way coupled fracture does not feel ([coupling] "
                                                    "mode = \"two-way\" does)"))

    def check_step(self, t: float, dt: float, nominal: float, limits: dict[str, float], frame, fast_cell,
                   width: np.ndarray, theta: np.ndarray) -> None:
        """After a step of ``dt`` whose nominal size was ``nominal``: warn at a collapsing step and stop at a
        collapsed one. ``limits`` maps what bounds a step (KEYS) to its value; ``fast_cell()`` gives the (k, i)
        of the fluid's largest Courant rate (called only for a short step)."""
        if not (nominal > 0.0 and math.isfinite(nominal)) or dt >= COLLAPSE_WARNING * nominal:
            return
        bound = min(limits, key=limits.get)
        text = (f"step {dt:.3g} s against {nominal:.3g} s, bounded by the {bound} ({KEYS[bound]}); "
                + self.fastest(frame, fast_cell(), width, theta))
        if dt < COLLAPSE_FLOOR * nominal:
            raise SimulationError(f"the proppant step collapsed: {text}", time=t)
        self._report("collapsing step", t, text)

    def fastest(self, frame, cell: tuple[int, int], width: np.ndarray, theta: np.ndarray) -> str:
        """Where the fluid's largest Courant rate is, in the scene's units (``cell`` its (k, i))."""
        k, i = cell
        return (f"the fastest fluid cell is at {self._where(frame, k, i)}, {self._width(width[k, i])} wide, "
                f"theta_p {theta[k, i]:.3g}")

    def summary(self) -> dict:
        return {"unphysical_states": "; ".join(self.found.values())}
