"""What the fracture engine reports, computed from a view of its state: snapshots, footprint size, front extents.

A :class:`View` is a state of the run at one time: the current one (the engine's ``now``) or one inside the
last step, interpolated between its two ends (its ``between``, interpolate.py), so snapshots need not land on
steps. Everything here reads a view and the engine's front strategy and tip model; nothing changes the state
except the cache of the current state's front distances (``distances``).

* ``geometry``: area, equal-area radius, length and height of the footprint, each cell counted by its filled
  fraction (geometry.py; the front strategy gives the fractions);
* ``front_extents``: the front's mean, smallest and largest distance from the injection point and its extents
  up (-z), down (+z), left (-x) and right (+x): the points x + a n of the sub-grid front's tip cells, or with
  whole cells (and right after a 3x3 merge, when there are no tip cells) the edge cells' centres plus the
  inverted tip distance s (front.front_distances, capped at one cell);
* ``snapshot``: the fields on the footprint's bounding box plus one cell, with the front extents, the footprint
  and the volume balance as scalar extras.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..records import FractureSnapshot, GridFrame
from .front import DIRECTIONS, edge_cells, front_distances
from .geometry import footprint
from .mesh import Grid


@dataclass(frozen=True)
class View:
    """A state of the run that a snapshot is made of: the grid, its time, the leaked total [m^3] and K', C' on
    the grid's box."""

    grid: Grid
    t: float
    leaked: float
    kprime_box: np.ndarray
    cprime_box: np.ndarray


def distances(engine, view: View) -> list[np.ndarray]:
    """front.front_distances of ``view`` (per side, from each edge cell's centre to the front). The current
    state's are computed once and kept in ``engine.distances``: the balance's area, the front summary and the
    next step's front reach share them (the engine clears them when the widths or the active set change)."""
    now = view.grid is engine.grid and view.t == engine.t
    if now and engine.distances is not None:
        return engine.distances
    g = view.grid
    found = front_distances(engine.tip, g["active"], g["w"], g["p"], view.kprime_box, view.cprime_box,
                            g["reached"], view.t, g.dx, g.dz)
    if now:
        engine.distances = found
    return found


def geometry(engine, view: View) -> dict:
    """Area, equal-area radius, length and height of the footprint (geometry.footprint), tip cells by the
    filled fraction the engine's front strategy gives them."""
    g = view.grid
    return footprint(engine.front_tracking.filled_fraction(engine, view), g.dx, g.dz)


def front_extents(engine, view: View) -> dict:
    """radius, radius_min, radius_max (the front's distances from the injection point) and its extents up, down,
    left and right (module docstring)."""
    g, dx, dz = view.grid, view.grid.dx, view.grid.dz
    xo, zo = g.offsets()
    zo = zo + (g.z_inj - engine.setup.injection_depth)   # the injection cell's centre is up to dz/2 off it (mesh.py)
    tips, nx, nz = engine.front_tracking.tip_normals(engine, view)
    if tips.any():
        px, pz = (xo + g["advance"] * nx)[tips], (zo + g["advance"] * nz)[tips]
        radii = np.hypot(px, pz)
        ext = dict(right=px.max(), left=-px.min(), down=pz.max(), up=-pz.min())
    else:
        dist = distances(engine, view)
        best = np.zeros(xo.shape)
        ext = {}
        for name, (dk, di), s in zip(("right", "left", "down", "up"), DIRECTIONS, dist):
            s = np.minimum(s, dz if dk else dx)
            coord = (zo * dk if dk else xo * di) + s
            ext[name] = np.nanmax(coord) if np.isfinite(coord).any() else 0.0
            best = np.fmax(best, s)
        edge = edge_cells(g["active"])
        radii = np.hypot(xo, zo)[edge] + best[edge]
    return dict(radius=float(radii.mean()), radius_min=float(radii.min()), radius_max=float(radii.max()),
                **{k: max(float(v), 0.0) for k, v in ext.items()})


def snapshot(engine, view: View, time: float) -> FractureSnapshot:
    """The snapshot of ``view`` stamped ``time``: the fields on the footprint's bounding box plus one cell, the
    front extents (``front_*``), the footprint's size (``geometry``) and the volume balance
    (``injected_volume``, ``stored_volume``, ``leaked_volume``) as scalar extras."""
    g = view.grid
    rs, cs = g.bounding_box(1)
    x, z = g.centres()
    act = g["active"][rs, cs]
    width = np.where(act, g["w"][rs, cs], 0.0)
    frame = GridFrame(g.dx, g.dz, float(x[rs, cs][0, 0]), float(z[rs, cs][0, 0]))
    scalars = {f"front_{k}": v for k, v in front_extents(engine, view).items()} | geometry(engine, view) | dict(
        injected_volume=engine.schedule.volume(view.t), stored_volume=float(width.sum()) * g.dx * g.dz,
        leaked_volume=view.leaked)
    return FractureSnapshot(
        time=time, frame=frame, width=width, pressure=np.where(act, g["p"][rs, cs], 0.0),
        leakoff_rate=np.where(act, g["leak_rate"][rs, cs], 0.0),
        opening_time=np.where(act, g["opened"][rs, cs], np.nan),
        extras={k: np.array(v) for k, v in scalars.items()})
