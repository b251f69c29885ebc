"""Snapshots between accepted steps: the fracture's state at an output time that no step lands on.

The time loop never shortens a step to meet an output time, so the steps depend only on the physics and the
numerical knobs (simulator.simulate). An output time t inside an accepted step [t_a, t_b] gets the state

    theta = (t - t_a) / (t_b - t_a),   q(t) = (1 - theta) q(t_a) + theta q(t_b)

for the width w, the fluid pressure p, the leaked volume per unit area and the sub-grid front's wetted
fraction ``fill`` and distance ``advance``, on the step's own grid and footprint: the cells open at either end
(cells never close; a cell that opened during the step, or at its start after the solve there, has w = 0 at
t_a). Where a cell had no solved pressure at t_a (it was not part of the solve ending at t_a: opened at or
after t_a, or the starting fracture, whose pressure is not solved) p(t) = p(t_b). The leak-off rate is the
step's own (the volume it leaked over its length), and the opening, arrival and crossing times are those
of t_b's state; the cells front's filled fractions (geometry.filled_fraction) follow from the interpolated widths.

Volume. The injection rate is constant within a step (schedule breakpoints are step targets), so the
injected volume V_I is linear in time within it; the stored volume V_S = dx dz sum w and the leaked total V_L
are interpolated linearly too, so V_I - V_S - V_L at t is (1 - theta) times its value at t_a plus theta times
its value at t_b: an interpolated snapshot balances exactly as well as the two steps around it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .mesh import Grid


@dataclass(frozen=True)
class StepEnds:
    """Both ends of one accepted step on the step's grid (before the cells the front opens at t_b are added
    and before any coarsening): times, grids, leaked totals [m^3], and K', C' on the step's box."""

    t_a: float
    t_b: float
    start: Grid
    end: Grid
    leaked_a: float
    leaked_b: float
    kprime_box: np.ndarray
    cprime_box: np.ndarray

    def theta(self, t: float) -> float:
        """(t - t_a) / (t_b - t_a)."""
        return (t - self.t_a) / (self.t_b - self.t_a)

    def leaked(self, t: float) -> float:
        """Leaked total at t [m^3], linear within the step."""
        theta = self.theta(t)
        return (1.0 - theta) * self.leaked_a + theta * self.leaked_b

    def state_at(self, t: float, t_start: float) -> Grid:
        """The grid at t_a < t < t_b (module docstring); ``t_start`` is the run's start time (the starting
        fracture's pressure is not solved)."""
        theta = self.theta(t)
        a, b = self.start, self.end
        was = a["active"]
        out = b.copy()
        for name in ("w", "leaked", "fill"):
            out[name][...] = (1.0 - theta) * np.where(was, a[name], 0.0) + theta * b[name]
        solved = was & (a["opened"] < self.t_a) & (self.t_a > t_start)
        out["p"][...] = np.where(solved, (1.0 - theta) * a["p"] + theta * b["p"], b["p"])
        both = np.isfinite(a["advance"]) & np.isfinite(b["advance"])
        out["advance"][...] = np.where(both, (1.0 - theta) * a["advance"] + theta * b["advance"], b["advance"])
        return out
