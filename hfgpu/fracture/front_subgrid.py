"""Sub-grid front (``front_tracking = "subgrid"``): the front lies inside tip cells, placed by a level set.

Instead of opening whole cells, the front lies inside tip cells (tip_cells.py): their widths are pinned to the tip
asymptote's mean over the part behind the front (their fluid pressure is then the unknown of their mass balance,
newton.py), only that part leaks (``fill``, the wetted fraction; the leak-off clock runs per wetted area), and the
front is placed by the level set from the ribbon cells' widths (the tip asymptote inverted, refined by the
two-term fit of tip_cells.py with ``ribbon_fit = "two_term"``), with the viscous asymptote's V at least the
front's own speed over the step, (s - s_0) / dt (s_0: the ribbon's distance at the step's start, kept in
``advance``). Each step iterates solve -> front -> solve until the front's position at every tip cell
reproduces itself (``SubgridFront.front_iterations``; Newton's first iterate is the widths extrapolated along the
last step's dw/dt, grid field ``w_rate``); cells the front enters become tip cells, cells it has crossed join the
channel once the step is accepted. This removes the whole-ring openings of the whole-cell front that, in
leak-off dominated growth, starve the fracture after each opening. The time step follows the measured front
advance (Eq. 35 with V_T = advance / dt).

Closure. The pinned tip widths are a propagating front's; once a cell drains after shut-in the engine hands the
front over to whole cells (simulator.py, "Closure").

Coarsening. The 2x remeshing carries the front: a coarse cell it crosses is a tip cell wetted by the overlap
mean of the fine fractions (coarsen.coarse_front; the coarse ribbons' s_0 is unknown until the next step places
the front). A 3x3 merge makes every coarse cell a channel cell and the next step places the front again: a front
carried through a 3x3 merge steadies the radius across merges but can fail Newton on coarse grids of 2-3 cells
per radius.
"""

from __future__ import annotations

import numpy as np

from .coarsen import Coarsening, channel_front, coarse_front
from .front import DIRECTIONS, shift
from .geometry import filled_fraction
from .tip_cells import fill_and_width, level_set, ribbon_distances
from .views import View

FRONT_ITERATIONS = 30
FRONT_TOLERANCE = 1e-2
FRONT_SOLVE_TOLERANCE = 1e-3   # Newton's tolerance in the front iterations (SubgridFront.front_iterations)


class Brackets:
    """Per-cell brackets [lo, hi] of the root of r(ell) = F(ell) - ell, r decreasing (positive below the
    root), with r at both ends, for ``SubgridFront.front_iterations``."""

    def __init__(self, shape: tuple[int, int]):
        self.lo, self.r_lo, self.hi, self.r_hi = (np.full(shape, np.nan) for _ in range(4))
        self.side = np.zeros(shape, int)

    def next(self, ell: np.ndarray, target: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """The next iterate from ell and F(ell) = target: regula falsi inside the bracket where both ends
        are known (Illinois: an end kept twice in a row has its residual halved), else F(ell)."""
        r = target - ell
        up, down = cells & (r > 0.0), cells & (r <= 0.0)
        self.r_hi[up & (self.side == 1)] *= 0.5
        self.r_lo[down & (self.side == -1)] *= 0.5
        self.lo[up], self.r_lo[up] = ell[up], r[up]
        self.hi[down], self.r_hi[down] = ell[down], r[down]
        self.side[up], self.side[down] = 1, -1
        both = np.isfinite(self.lo) & np.isfinite(self.hi)
        with np.errstate(invalid="ignore", divide="ignore"):
            falsi = self.lo + self.r_lo * (self.hi - self.lo) / (self.r_lo - self.r_hi)
        return np.where(both, falsi, target)

    def width(self) -> np.ndarray:
        """|hi - lo| where both ends are known, inf elsewhere."""
        return np.where(np.isfinite(self.lo) & np.isfinite(self.hi), np.abs(self.hi - self.lo), np.inf)


class SubgridFront:
    """The sub-grid front strategy (module docstring); holds no state of its own (the front lives in the grid
    fields ``fill`` and ``advance``)."""

    name = "subgrid"

    def step(self, engine, dt: float, keep_ends: bool) -> float:
        """One step with tip cells: the front's position at the tip cells and the step's solution are iterated
        to a fixed point (``front_iterations``). A step whose Newton iteration fails, or in which the front moves
        more than ``max_front_advance`` cells, is redone with half the step; returns the step taken. With
        ``keep_ends`` the step's two ends are kept in ``engine.ends``."""
        h = min(engine.dx, engine.dz)
        before = engine.grid.shape
        engine.grid.ensure_margin(4)   # room for the front to move within the step without growing the box
        if engine.grid.shape != before:
            engine.use_grid(engine.grid)
        start = engine.grid.copy()
        for attempt in range(engine.num.max_step_retries + 1):
            res, advance, ok = self.front_iterations(engine, dt, start)
            if ok and (advance <= engine.num.max_front_advance * h or attempt == engine.num.max_step_retries):
                break
            if not ok and attempt == engine.num.max_step_retries:
                engine.newton_failed(res, dt)
            if ok:
                engine.rejected += 1
            else:
                engine.newton_retry(dt)
            engine.use_grid(start.copy())
            dt *= 0.5
        tips = ~(start["active"] & (start["fill"] >= 1.0))   # pinned in this step (front_iterations)
        engine.accept(res, dt, advance, start if keep_ends else None, tips[engine.rows, engine.cols])
        engine.v_front, engine.t_front = engine.v_tip, engine.t
        g = engine.grid
        g["w_rate"][...] = np.where(g["active"] & start["active"], (g["w"] - start["w"]) / dt, 0.0)
        return dt

    def front_iterations(self, engine, dt: float, start) -> tuple:
        """(result, front advance [m], converged) of a step from the grid ``start``: solve with the tip
        widths pinned, place the front (tip_cells: ribbon distances, level set; never backwards), until the
        front's position at every tip cell reproduces itself, |F(a) - a| < FRONT_TOLERANCE cells (a = how far
        the front is past the cell's centre). F decreases with a (a wider tip leaves less fluid to the
        ribbon), so each cell's root is bracketed as the iterations go and found by regula falsi (Illinois)
        inside its bracket, plain iteration a = F(a) until it has one. The channel and its ribbon cells are
        those of the step's start throughout the step (as in PyFrac's ILSA, Zia & Lecampion 2020): a cell the
        front enters becomes a tip cell (active, its Carter opening time the step's middle, which restarts the
        brackets), and one it crosses stays a pinned tip cell, wholly wetted, until the step is accepted
        (turning it into a channel cell within the step would swap its width from the asymptote's mean to the
        elastic solution, a jump that moves the front by most of a cell). The ribbons' distances take the
        step's own front speed (tip_cells.ribbon_distances with s_0 = their ``advance`` at the start), and the
        converged ones are kept there for the next step. An iterate that puts the front more than twice
        ``max_front_advance`` past its start ends the iterations: the step is redone shorter (the level set
        reaches LAYERS cells out, and pinning tip cells that far out in one go can stop Newton). Newton starts
        from the widths extrapolated along the last step's dw/dt (``w_rate``), then from the last iterate's.
        The iterates' solves stop at FRONT_SOLVE_TOLERANCE (their widths only place the front, to
        FRONT_TOLERANCE cells); once it has converged the step is solved to ``newton_tolerance`` with that
        front, so the accepted solution has the scene's accuracy at the cost of one tight solve a step."""
        g = engine.grid
        h = min(engine.dx, engine.dz)
        channel = start["active"] & (start["fill"] >= 1.0)
        was_tip = start["active"] & ~channel
        floor = np.where(was_tip, start["advance"], -np.inf)
        pinned_box = np.where(was_tip, g["w"], np.nan)
        advance = 0.0
        # Newton's first iterate: the widths extrapolated along the last step's rate, then the last solved ones
        last = g["w"] + g["w_rate"] * dt
        bracket = Brackets(g.shape)
        s_start = np.where(channel, start["advance"], np.nan)   # the ribbons' distances at the start, if known
        precond = None     # the last solve's Newton-Krylov preconditioner, while the active set stays
        loose = max(FRONT_SOLVE_TOLERANCE, engine.num.newton_tolerance)
        for _ in range(FRONT_ITERATIONS):
            res = engine.solve(dt, pinned_box[engine.rows, engine.cols], last[engine.rows, engine.cols], precond,
                               loose, simplified_exit=True)
            precond = res.preconditioner
            if not res.converged:
                return res, advance, False
            w_box, p_box = g["w"].copy(), g["p"].copy()
            w_box[engine.rows, engine.cols], p_box[engine.rows, engine.cols] = res.w, res.p
            last = np.where(g["active"], w_box, 0.0)
            s_rib, v_rib = ribbon_distances(engine.tip, channel, w_box, p_box, engine.kprime_box,
                                            engine.cprime_box, g["reached"], engine.t + dt, engine.dx, engine.dz,
                                            (s_start, dt), engine.num.ribbon_fit)
            target, nx, nz, src = level_set(s_rib, channel, engine.dx, engine.dz)
            cand = np.isfinite(target)
            target = np.where(cand, np.fmax(target, floor), np.nan)
            reach = -0.5 * (np.abs(nx) * engine.dx + np.abs(nz) * engine.dz)   # the front at the nearest corner
            known = g["active"] & np.isfinite(g["advance"])
            now = np.where(known, g["advance"], reach)
            # how far each cell's front position is from reproducing itself; settled: a cell the front has
            # not reached either way (both below reach: dry), or whose root the bracket holds to the
            # tolerance (F may jump across its root)
            gap = np.where(cand & (bracket.width() >= FRONT_TOLERANCE * h),
                           np.abs(np.maximum(target, reach) - np.maximum(now, reach)), 0.0)
            ribbon = np.isfinite(s_rib)
            g["advance"][ribbon] = s_rib[ribbon]   # the ribbons' distances: the next step's s_0
            if float(gap.max()) < FRONT_TOLERANCE * h:
                if loose > engine.num.newton_tolerance:   # the step itself to the scene's tolerance
                    res = engine.solve(dt, pinned_box[engine.rows, engine.cols], last[engine.rows, engine.cols],
                                       precond, simplified_exit=True)
                return res, advance, res.converged
            moved = np.where(cand, bracket.next(np.where(cand, now, 0.0), np.where(cand, target, 0.0), cand), np.nan)
            advance, entered = self._place_front(engine, moved, (cand, nx, nz, src, v_rib), pinned_box, was_tip,
                                                 floor, dt)
            if advance > 2.0 * engine.num.max_front_advance * h:
                break   # far past the limit already: the step will be redone shorter
            if entered:
                bracket = Brackets(g.shape)
                precond = None
        res = engine.solve(dt, pinned_box[engine.rows, engine.cols], simplified_exit=True)   # the last front
        return res, advance, res.converged

    @staticmethod
    def _place_front(engine, moved: np.ndarray, geometry: tuple, pinned_box: np.ndarray, was_tip: np.ndarray,
                     floor: np.ndarray, dt: float) -> tuple[float, bool]:
        """Put the front ``moved`` past the centres of the level set's cells (``geometry``: those cells, the
        normal, the ribbon each leans on, its tip velocity): their wetted fraction, ``advance`` and pinned
        width (in ``pinned_box``, in place: the asymptote's mean, which may fall below the step's start width:
        a tip width floored there would hold back fluid the front needs, and Newton can then fail); a cell the
        front enters (one next to an active cell: one layer per iteration, so a start whose ribbons put the
        front two layers out, as the initial fracture's can, does not pin both at once and stop Newton) becomes
        active with its Carter opening time at the step's middle.
        Returns (the farthest the front now is past where it was at the step's start, in m; whether cells
        entered)."""
        g, h = engine.grid, min(engine.dx, engine.dz)
        cand, nx, nz, src, v_rib = geometry
        ks = src[cand]
        fill, width = fill_and_width(engine.tip, moved[cand], nx[cand], nz[cand], engine.kprime_box.ravel()[ks],
                                     engine.cprime_box.ravel()[ks], v_rib.ravel()[ks], engine.dx, engine.dz)
        fill_box, width_box = np.zeros(g.shape), np.zeros(g.shape)
        fill_box[cand], width_box[cand] = fill, width
        beside = np.zeros(g.shape, bool)   # next to an active cell: the front enters one layer per iteration
        for dk, di in DIRECTIONS:
            beside |= shift(g["active"], dk, di, False)
        tip = cand & (fill_box > 0.0)
        entered = tip & ~g["active"] & beside
        if entered.any():
            g.fields["active"] = g["active"] | entered
            for name in ("opened", "reached", "filled"):
                g[name][entered] = engine.t + 0.5 * dt
            g["w"][entered] = 0.0
        update = cand & g["active"]   # an entered cell the front has left again keeps fill 0 and width 0
        moved_by = float(np.max((moved - np.where(was_tip, floor, -0.5 * h))[update & tip], initial=0.0))
        g["advance"][update] = moved[update]
        g["fill"][update] = fill_box[update]
        pinned_box[update] = width_box[update]
        if entered.any():
            engine.rebuild()
        return moved_by, bool(entered.any())

    def filled_fraction(self, engine, view: View) -> np.ndarray:
        """Each box cell's filled fraction: the tip cells' wetted fraction ``fill`` (geometry.py)."""
        g = view.grid
        return filled_fraction(self.name, g["active"], g["fill"], None, g.dx, g.dz, g.shut(view.t))

    def tip_normals(self, engine, view: View) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tips, nx, nz): the tip cells (active, not wholly wetted, placed) and the level set's unit normal
        (tip_cells.level_set from the ribbons' inverted widths; NaN off its cells)."""
        g = view.grid
        channel = g["active"] & (g["fill"] >= 1.0)
        s_rib, _ = ribbon_distances(engine.tip, channel, g["w"], g["p"], view.kprime_box, view.cprime_box,
                                    g["reached"], view.t, g.dx, g.dz, fit=engine.num.ribbon_fit)
        _, nx, nz, _ = level_set(s_rib, channel, g.dx, g.dz)
        return g["active"] & ~channel & np.isfinite(g["advance"]) & np.isfinite(nx), nx, nz

    def carried_front(self, engine, c: Coarsening) -> tuple[np.ndarray, np.ndarray]:
        """(fill, advance) of the coarse cells of ``c``: the front carried by the 2x remeshing
        (coarsen.coarse_front), none through an odd merge (coarsen.channel_front; module docstring)."""
        if c.factor != 2:
            return channel_front(c)
        g, sel = engine.grid, (engine.rows, engine.cols)
        tips, nx, nz = self.tip_normals(engine, engine.now())
        return coarse_front(c, engine.ix, engine.iz, g["fill"][sel], np.where(tips, nx, 0.0)[sel],
                            np.where(tips, nz, 0.0)[sel], engine.dx, engine.dz)
