"""Whole-cell front (``front_tracking = "cells"``): cells open whole when the front criterion says so.

A step solves the implicit system on the current active set (the engine's ``solve``, simulator.py), then opens
every inactive cell whose tip element satisfies the front criterion at the shared edge (Eq. 33,
front.cells_to_open), records the opening tip speed V_T = h / (t - t_parent) (Eq. 34) that sets the next step
(Eq. 35), and the time the front will have crossed each new cell, h / V_T after its opening (the Carter
average of partially filled tip cells, leakoff.carter_cumulative). A step whose Newton iteration fails, or in
which the front reconstructed from the widths (front.front_distances, the tip asymptote inverted, capped at two
cells) moves more than ``max_front_advance`` cells, is redone with half the step.

The footprint counts an edge cell by the part of it behind the straight front at the inverted tip distance
(geometry.filled_fraction with ``distances``). A cell the criterion has just opened (width 0, no solve has seen
it) counts as an edge cell with the front at its centre, unless it lies in rock of a higher minimum stress than
its open neighbours and their fluid pressure is below that stress: the next solve will hold it shut (contact),
so it is left out (``held``): a barrier row the front reached at the last step is not fracture height. A
coarsening carries no front (every coarse cell a channel cell, the next step's distances place it again).
"""

from __future__ import annotations

import numpy as np

from .coarsen import Coarsening, channel_front
from .front import DIRECTIONS, cells_to_open, front_distances, shift
from .geometry import filled_fraction
from .views import View, distances


class CellFront:
    """The whole-cell front strategy (module docstring); holds no state of its own."""

    name = "cells"

    def step(self, engine, dt: float, keep_ends: bool) -> float:
        """Advance ``engine`` by dt, halving the step on a Newton failure or a too-long front advance; returns
        the step taken. With ``keep_ends`` the step's two ends are kept in ``engine.ends``."""
        g = engine.grid
        start = g.copy() if keep_ends else None
        reach_old = self._reach(engine, distances(engine, engine.now()))
        h = min(engine.dx, engine.dz)
        for attempt in range(engine.num.max_step_retries + 1):
            res = engine.solve(dt)
            if res.converged:   # a closed fracture's front (no open cell) does not move
                advance = self._advance(engine, reach_old, res.w, res.p, engine.t + dt) if res.w.any() else 0.0
                if advance <= engine.num.max_front_advance * h or attempt == engine.num.max_step_retries:
                    break
                engine.rejected += 1
            elif attempt == engine.num.max_step_retries:
                engine.newton_failed(res, dt)
            else:
                engine.newton_retry(dt)
            dt *= 0.5
        engine.accept(res, dt, advance, start)
        if engine.grid["w"].any():   # the front criterion needs an open cell to open its neighbours
            self._open_cells(engine)
        return dt

    def filled_fraction(self, engine, view: View) -> np.ndarray:
        """Each box cell's filled fraction: edge cells by their inverted tip distances (geometry.py), without
        the cells ``held`` shut by a higher stress (module docstring)."""
        g = view.grid
        held = self.held(engine, view)
        if not held.any():
            return filled_fraction(self.name, g["active"], g["fill"], distances(engine, view), g.dx, g.dz,
                                   g.shut(view.t))
        active = g["active"] & ~held
        found = front_distances(engine.tip, active, g["w"], g["p"], view.kprime_box, view.cprime_box,
                                g["reached"], view.t, g.dx, g.dz)
        return filled_fraction(self.name, active, g["fill"], found, g.dx, g.dz, g.shut(view.t))

    @staticmethod
    def held(engine, view: View) -> np.ndarray:
        """Cells the front criterion opened at the view's time (no solve has seen them, ``Grid.unsolved``) in
        rock of a higher minimum stress than each open neighbour's, where that neighbour's fluid pressure is
        below their own stress: the next solve holds them shut (contact)."""
        g = view.grid
        new = g.unsolved(view.t)
        if not new.any():
            return new
        sigma = engine.setup.rock.min_stress_at(g.centres()[1])
        wet = g["active"] & ~new & (g["w"] > 0.0)
        fed = np.zeros(new.shape, bool)
        for dk, di in DIRECTIONS:
            beside, p, s = shift(wet, dk, di, False), shift(g["p"], dk, di, 0.0), shift(sigma, dk, di, np.inf)
            fed |= beside & ((sigma <= s) | (p > sigma))
        return new & ~fed

    def tip_normals(self, engine, view: View) -> tuple[np.ndarray, None, None]:
        """No tip cells (the front lies on cell edges): an all-False mask and no normals."""
        return np.zeros(view.grid.shape, bool), None, None

    def carried_front(self, engine, c: Coarsening) -> tuple[np.ndarray, np.ndarray]:
        """(fill, advance) of the coarse cells: wholly wetted, no advance (coarsen.channel_front)."""
        return channel_front(c)

    @staticmethod
    def _reach(engine, found: list[np.ndarray]) -> np.ndarray:
        """Largest front distance s (Eq. 33 inverted, front.front_distances) of every box cell, capped at 2
        cells; 0 where a cell faces no inactive cell."""
        return np.minimum(np.nan_to_num(np.fmax.reduce(found), nan=0.0), 2.0 * max(engine.dx, engine.dz))

    def _advance(self, engine, reach_old: np.ndarray, w: np.ndarray, p: np.ndarray, t: float) -> float:
        """Largest distance any front point moved over a step that ends at t with active widths w and
        pressures p (the measured tip advance of Eq. 34)."""
        g, sel = engine.grid, (engine.rows, engine.cols)
        w_box, p_box = g["w"].copy(), g["p"].copy()
        w_box[sel], p_box[sel] = w, p
        reach = self._reach(engine, front_distances(engine.tip, g["active"], w_box, p_box, engine.kprime_box,
                                                    engine.cprime_box, g["reached"], t, engine.dx, engine.dz))
        return float(np.max(reach - reach_old))

    @staticmethod
    def _open_cells(engine) -> None:
        """Open the cells the front criterion selects (Eq. 33) and record the tip speed (Eq. 34)."""
        g = engine.grid
        to_open, speed = cells_to_open(engine.tip, g["active"], g["w"], g["p"], engine.kprime_box,
                                       engine.cprime_box, g["reached"], engine.t, engine.dx, engine.dz,
                                       engine.blocked_box)
        if not to_open.any():
            return
        g.fields["active"] = g["active"] | to_open
        g["reached"][to_open] = engine.t
        g["opened"][to_open] = engine.t
        g["filled"][to_open] = engine.t + min(engine.dx, engine.dz) / speed[to_open]
        g["w"][to_open] = 0.0
        engine.v_front = float(np.nanmax(speed))
        engine.t_front = engine.t
        before = g.shape
        g.ensure_margin()
        if g.shape != before:
            engine.load_properties()
        engine.rebuild()
