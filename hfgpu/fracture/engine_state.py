"""Checkpoints of the fracture engine: the state that continues a run exactly, and its restoration.

A state (a nested dict of numbers and arrays, written by hfgpu.io.checkpoint) holds the engine's
``STATE_ATTRIBUTES``, the grid (placement and every field) and the capacity of the elasticity kernel cache:
the FFT size follows from that capacity, hence the round-off of every product, so a restored run reserves it
again and continues bit for bit as the uninterrupted run would. Everything derived (active set, faces, C,
layer properties) is rebuilt from the grid. The layout is that of the results files' ``engine`` group
(docs/results-format.md): add a new persistent attribute to ``STATE_ATTRIBUTES``, never rename one, so files
written before still resume.
"""

from __future__ import annotations

import numpy as np

from .elasticity import ElasticityOperator
from .front_cells import CellFront
from .mesh import Grid

#: Attributes (numbers or arrays) of the engine a checkpoint carries besides the grid.
STATE_ATTRIBUTES = ("t", "t0", "v_front", "t_front", "leaked_total", "steps", "newton_iterations", "retries",
                    "coarsenings", "max_balance_error", "v_tip", "rejected", "dt_failed", "factorisations",
                    "gmres_iterations", "w_peak", "t_closed", "t_receding")
#: Defaults of attributes added after files were written that lack them (the peak width: the grid's widths).
LATER_ATTRIBUTES = {"w_peak": lambda state: float(np.max(state["grid"]["fields"]["w"], initial=0.0)),
                    "t_closed": lambda state: float("nan"), "t_receding": lambda state: float("nan")}


def engine_state(engine) -> dict:
    """Everything needed to continue ``engine`` from now (module docstring)."""
    g = engine.grid
    return {**{name: getattr(engine, name) for name in STATE_ATTRIBUTES},
            "grid": {"dx": g.dx, "dz": g.dz, "x_inj": g.x_inj, "z_inj": g.z_inj, "ix0": g.ix0, "iz0": g.iz0,
                     "fields": {name: array.copy() for name, array in g.fields.items()}},
            "elasticity_capacity": np.array(engine.op.capacity)}


def restore_engine(engine, state: dict) -> None:
    """Continue ``engine`` (built for the same scene) from an ``engine_state``: same fields, same systems."""
    for name in STATE_ATTRIBUTES:
        value = state[name] if name in state else LATER_ATTRIBUTES[name](state)
        setattr(engine, name, np.array(value) if isinstance(value, np.ndarray) else value)
    s = state["grid"]
    engine.grid = Grid(s["dx"], s["dz"], s["x_inj"], s["z_inj"], int(s["ix0"]), int(s["iz0"]),
                       {name: np.array(array) for name, array in s["fields"].items()})
    engine.dx, engine.dz = engine.grid.dx, engine.grid.dz
    engine.area = engine.dx * engine.dz
    engine.op = ElasticityOperator(engine.dx, engine.dz, engine.e_prime)
    engine.op.reserve(*(int(n) for n in state["elasticity_capacity"]))
    if np.isfinite(engine.t_receding):   # a sub-grid front that has handed over to whole cells
        engine.front_tracking = CellFront()
    engine.load_properties()
    engine.rebuild()
