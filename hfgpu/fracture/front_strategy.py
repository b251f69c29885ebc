"""The front strategies behind one interface, chosen by ``front_tracking``: whole cells or the sub-grid front.

A strategy decides how a step moves the front and what the front is between steps; the engine (simulator.py)
owns the state and calls it for these four jobs only:

* ``step(engine, dt, keep_ends) -> dt taken``: advance the state by one step, front included (Eq. 33-35);
* ``filled_fraction(engine, view)``: the part of every box cell behind the front (the footprint, geometry.py);
* ``tip_normals(engine, view) -> (tips, nx, nz)``: the cells the front crosses and its unit normal there (none
  with whole cells; the front extents, views.py);
* ``carried_front(engine, coarsening) -> (fill, advance)``: the front on the coarse cells of a coarsening.

``FRONT_STRATEGIES`` maps each ``front_tracking`` name to its class (front_cells.py, front_subgrid.py).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from .coarsen import Coarsening
from .front_cells import CellFront
from .front_subgrid import SubgridFront
from .views import View


class FrontStrategy(Protocol):
    """How the front moves and where it is (module docstring)."""

    name: str

    def step(self, engine, dt: float, keep_ends: bool) -> float: ...

    def filled_fraction(self, engine, view: View) -> np.ndarray: ...

    def tip_normals(self, engine, view: View) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]: ...

    def carried_front(self, engine, c: Coarsening) -> tuple[np.ndarray, np.ndarray]: ...


FRONT_STRATEGIES: dict[str, type[FrontStrategy]] = {CellFront.name: CellFront, SubgridFront.name: SubgridFront}


def front_strategy(name: str) -> FrontStrategy:
    """The strategy of ``front_tracking = name`` ("cells" or "subgrid")."""
    return FRONT_STRATEGIES[name]()
