"""Numerical settings of the fracture engine, from the scene's optional ``[fracture]`` table."""

from __future__ import annotations

from dataclasses import dataclass

from ..presets import BALANCED, Preset
from ..scene_reader import Table
from .tip_cells import RIBBON_FITS


@dataclass(frozen=True)
class FractureNumerics:
    """Knobs of the planar-3D engine (each documented in docs/scene.md).

    time_step_relaxation: lambda of Eq. 35, dt = lambda min(dx, dz) / max(V_T).
    newton_tolerance: epsilon of Eq. 32 (relative).
    linear_solver: "auto" (per active set, dense LU or Newton-Krylov, whichever the cost model of
        solver_choice.py says is cheaper per Newton iteration; with ``krylov_threshold`` set: direct below that
        many cells, Newton-Krylov from it), "direct", "krylov".
    krylov_threshold: the fixed cell count of "auto" (None: the cost model chooses).
    newton_max_iterations: Newton iterations per step before the step is retried with half the time step.
    max_step_retries: halvings of a failed step before the run stops with a SimulationError.
    initial_radius_cells: radius of the starting radial fracture, in cells (see front.initial_fracture).
    tip_asymptote: "olson" (Eq. 33, toughness only: 0.806 w = K'/E' s^1/2), "km" (the larger of the
        toughness and viscosity (M-vertex) tip asymptotes, see front.py) or "universal" (Dontsov & Peirce's
        2015 universal K-M-M~ asymptote with leak-off, tip_universal.py) used for front advance.
    leakoff_width_fraction: width scale of the leak-off positivity ramp (leakoff.available_fraction) as a
        fraction of the step's Carter demand; a cell never leaks fluid it does not hold.
    max_step_growth: largest ratio of one time step to the previous one.
    tip_velocity: V of the viscous tip asymptote: "fluid" (velocity through the tip element's inner face) or
        "front" (at least the mean front speed through the tip element, Eq. 34), see front.tip_velocity.
    partial_tip_cells: spread a newly opened cell's Carter opening time over the time the front takes to
        cross it (its parent's crossing time, Eq. 34), so leak-off follows the wetted part of the cell.
    max_front_advance: the most the sub-grid front may move in one step, in cells; a longer step is redone
        with half the time step, so the front does not over-run on long steps.
    front_tracking: "cells" (a cell opens whole when its neighbour meets the front criterion, Eq. 33) or
        "subgrid" (tip cells: the front crosses the cells around the channel by a distance found from the
        channel's widths through the inverted tip asymptote, their widths are the asymptote's mean over the
        crossed part and only that part leaks; see simulator.py).
    ribbon_fit: with the sub-grid front, how a ribbon cell's width places the front: "two_term" (the tip
        asymptote times a linear correction fitted through the ribbon and its inner neighbour) or "asymptote"
        (the asymptote's inverse alone); tip_cells.py has the equation and the measurements.
    closure_width_fraction: a cell whose width falls over a step without injection below this fraction of the
        largest width the fracture has had, with Carter's demand over the step at least that width, is closed
        (simulator.py, "Closure"): its walls meet (contact, width 0) and the film left in it leaks off with it.
    leakoff_clock: a cell whose leak-off the positivity ramp held below Carter's demand continues from the
        exposure time its leaked volume corresponds to (leakoff.carter_demand), so time spent dry does not
        count as exposure; off: Carter's law from the opening time, whatever the cell leaked.
    """

    time_step_relaxation: float = BALANCED.time_step_relaxation
    newton_tolerance: float = BALANCED.newton_tolerance
    newton_max_iterations: int = 30
    linear_solver: str = "auto"
    krylov_threshold: int | None = None
    max_step_retries: int = 8
    initial_radius_cells: float = 2.5
    tip_asymptote: str = "km"
    leakoff_width_fraction: float = 0.01
    max_step_growth: float = 1.5
    tip_velocity: str = "front"
    partial_tip_cells: bool = True
    max_front_advance: float = 1.0
    leakoff_clock: bool = True
    closure_width_fraction: float = 1e-3
    front_tracking: str = "cells"
    ribbon_fit: str = "two_term"


def parse_fracture_numerics(t: Table, preset: Preset = BALANCED) -> FractureNumerics:
    """``[fracture]``; the preset gives the defaults of lambda (Eq. 35) and epsilon (Eq. 32)."""
    d = FractureNumerics()
    numerics = FractureNumerics(
        time_step_relaxation=t.number("time_step_relaxation", preset.time_step_relaxation, minimum=0.0,
                                      maximum=1.0, exclusive_minimum=True),
        newton_tolerance=t.number("newton_tolerance", preset.newton_tolerance, minimum=0.0,
                                  exclusive_minimum=True, maximum=0.1),
        newton_max_iterations=t.integer("newton_max_iterations", d.newton_max_iterations, minimum=1),
        linear_solver=t.choice("linear_solver", ("auto", "direct", "krylov"), d.linear_solver),
        krylov_threshold=t.integer("krylov_threshold", minimum=1) if t.has("krylov_threshold") else None,
        max_step_retries=t.integer("max_step_retries", d.max_step_retries, minimum=0),
        initial_radius_cells=t.number("initial_radius_cells", d.initial_radius_cells, minimum=1.0,
                                      maximum=50.0),
        tip_asymptote=t.choice("tip_asymptote", ("olson", "km", "universal"), d.tip_asymptote),
        leakoff_width_fraction=t.number("leakoff_width_fraction", d.leakoff_width_fraction, minimum=0.0,
                                        maximum=1.0, exclusive_minimum=True),
        max_step_growth=t.number("max_step_growth", d.max_step_growth, minimum=1.0, maximum=10.0),
        tip_velocity=t.choice("tip_velocity", ("fluid", "front"), d.tip_velocity),
        partial_tip_cells=t.boolean("partial_tip_cells", d.partial_tip_cells),
        max_front_advance=t.number("max_front_advance", d.max_front_advance, minimum=0.1, maximum=10.0),
        leakoff_clock=t.boolean("leakoff_clock", d.leakoff_clock),
        closure_width_fraction=t.number("closure_width_fraction", d.closure_width_fraction, minimum=0.0,
                                        maximum=0.1, exclusive_minimum=True),
        front_tracking=t.choice("front_tracking", ("cells", "subgrid"), d.front_tracking),
        ribbon_fit=t.choice("ribbon_fit", RIBBON_FITS, d.ribbon_fit),
    )
    t.finish()
    return numerics
