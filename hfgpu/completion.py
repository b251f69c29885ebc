"""``[completion]``: the perforation clusters of a stage (docs/scene.md).

The clusters lie on a horizontal lateral at ``[injection] depth`` and ``x``, at ``positions`` along the well (or
``clusters`` of them ``spacing`` apart); the well is normal to the fracture planes, so a cluster's position is its
plane's normal coordinate y (the stress shadow between planes, hfgpu.fracture.shadow). Each cluster has
``perforations`` holes of ``perforation_diameter`` with ``discharge_coefficient`` C_d (one value for all, or a list
of one per cluster; all three, or none: no perforation friction), and an optional ``stress_offsets`` list added to
the rock's minimum stress on that cluster's plane (the perforation friction: hfgpu.perforations).

Refused before any work (one-line SceneError naming the key and the value): a count, a diameter or a spacing of 0,
C_d outside (0, 1], two clusters at one position, a list of the wrong length, clusters at a depth outside the span
of ``[[rock.layers]]``, more than MAX_CLUSTERS clusters or a span over MAX_SPAN, a perforation friction that would
not be finite. Warned about: clusters closer than two cells (the larger of dx, dz in use) of the shared
fracture grid, where the shadow kernel between them is the near field of elements larger than their distance
(tests/fracture/test_shadow.py measures its error on a penny crack's axis against the distance in cells).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import MISSING, SceneError
from .scene_reader import Table, scene_system, warn
from .units import display_text

#: Clusters closer than this many cells (the larger of dx, dz in use) are warned about.
MIN_SPACING_CELLS = 2.0
#: The most clusters a stage may have, and the longest span of their positions [m] (a lateral is a few km).
MAX_CLUSTERS = 50
MAX_SPAN = 1e4


@dataclass(frozen=True)
class Completion:
    """``[completion]``: each cluster's ``positions`` [m] along the well, and per cluster ``perforations``,
    ``perforation_diameter`` [m], ``discharge_coefficient`` (all empty: no perforation friction) and
    ``stress_offsets`` [Pa]."""

    positions: tuple[float, ...]
    perforations: tuple[int, ...] = ()
    perforation_diameter: tuple[float, ...] = ()
    discharge_coefficient: tuple[float, ...] = ()
    stress_offsets: tuple[float, ...] = ()

    @property
    def clusters(self) -> int:
        return len(self.positions)

    @property
    def limited_entry(self) -> bool:
        """Whether the clusters have perforation friction."""
        return bool(self.perforations)

    def entry_coefficients(self, density: float) -> np.ndarray:
        """a_i [Pa s^2/m^6] of dp_perf,i = a_i q_i^2 for a slurry of ``density`` (0 without perforations)."""
        from .perforations import entry_coefficient

        if not self.limited_entry:
            return np.zeros(self.clusters)
        return np.array([entry_coefficient(density, n, d, c) for n, d, c in
                         zip(self.perforations, self.perforation_diameter, self.discharge_coefficient)])

    def offsets(self) -> np.ndarray:
        """Each cluster's stress offset [Pa] (0 where none is given)."""
        return np.array(self.stress_offsets) if self.stress_offsets else np.zeros(self.clusters)


def parse_completion(t: Table, depth: float, layers: tuple[Any, ...], cell: float) -> Completion:
    """``[completion]`` of a scene whose clusters lie at ``depth`` [m] in a rock of ``layers``
    (hfgpu.scene.Layer), on a fracture grid whose larger cell in use is ``cell`` [m] (module docstring)."""
    positions = _positions(t)
    n = len(positions)
    per_cluster = {}
    given = [key for key in ("perforations", "perforation_diameter", "discharge_coefficient") if t.has(key)]
    if given and len(given) < 3:
        missing = next(key for key in ("perforations", "perforation_diameter", "discharge_coefficient")
                       if key not in given)
        t.raw(missing)   # raises: required once one of the three is given
    if given:
        per_cluster["perforations"] = tuple(int(v) for v in _each(t, "perforations", n, "count"))
        per_cluster["perforation_diameter"] = tuple(_each(t, "perforation_diameter", n, "length"))
        per_cluster["discharge_coefficient"] = tuple(_each(t, "discharge_coefficient", n, "dimensionless",
                                                           maximum=1.0))
        _finite_friction(t, per_cluster)
    if t.has("stress_offsets"):
        per_cluster["stress_offsets"] = tuple(_each(t, "stress_offsets", n, "pressure", scalar=False))
    if layers:
        top, bottom = min(layer.top for layer in layers), max(layer.bottom for layer in layers)
        if not top <= depth <= bottom:
            system = scene_system()
            raise SceneError(t.key_path("positions" if t.has("positions") else "clusters"),
                             t.raw("positions" if t.has("positions") else "clusters"),
                             f"the clusters lie at [injection] depth {display_text(depth, 'depth', system, 6)}, "
                             f"outside the layer table ({display_text(top, 'depth', system, 6)} to "
                             f"{display_text(bottom, 'depth', system, 6)}): their stresses would not be given")
    t.finish()
    _close_spacing(t, positions, cell)
    return Completion(positions=positions, **per_cluster)


def _finite_friction(t: Table, per_cluster: dict[str, tuple]) -> None:
    """n^2 d^4 C_d^2 of every cluster must be a positive finite number (the friction coefficient divides by it)."""
    for i, (n, d, c) in enumerate(zip(per_cluster["perforations"], per_cluster["perforation_diameter"],
                                      per_cluster["discharge_coefficient"])):
        product = float(n) ** 2 * d**4 * c**2
        if not 0.0 < product < float("inf"):
            raw = t.data["perforation_diameter"]
            raise SceneError(t.key_path("perforation_diameter"), raw[i] if isinstance(raw, list) else raw,
                             "allowed: a diameter whose perforation friction is finite (n^2 d^4 C_d^2 > 0)")


def _positions(t: Table) -> tuple[float, ...]:
    """``positions`` (a list of lengths), or ``clusters`` and ``spacing`` (positions 0, s, 2 s, ...)."""
    if t.has("positions"):
        for key in ("clusters", "spacing"):
            if t.has(key):
                raise SceneError(t.key_path(key), t.data[key], "give either 'positions' or 'clusters' with "
                                 "'spacing', not both")
        raw = t.raw("positions")
        if not isinstance(raw, list) or not raw:
            raise SceneError(t.key_path("positions"), raw, 'expected a non-empty list of lengths along the well, '
                             'e.g. ["0 ft", "50 ft", "100 ft"]')
        if len(raw) > MAX_CLUSTERS:
            raise SceneError(t.key_path("positions"), raw, f"allowed: at most {MAX_CLUSTERS} clusters")
        positions = tuple(_item(t, "positions", i, v, "position") for i, v in enumerate(raw))
    else:
        count = t.integer("clusters", 1, minimum=1, maximum=MAX_CLUSTERS)
        spacing = t.quantity("spacing", "length", 0.0 if count == 1 else MISSING, minimum=0.0,
                             exclusive_minimum=count > 1)
        positions = tuple(i * spacing for i in range(count))
    order = np.argsort(positions, kind="stable")
    for i, j in zip(order, order[1:]):
        if positions[j] - positions[i] <= 1e-9 * max(1.0, abs(positions[j])):
            raise SceneError(*_where(t, j), f"clusters must not overlap: clusters {i} and {j} are at the same place")
    if positions[order[-1]] - positions[order[0]] > MAX_SPAN:
        raise SceneError(*_where(t, int(order[-1])), f"the clusters span more than {MAX_SPAN:g} m along the well")
    return positions


def _where(t: Table, j: int) -> tuple[str, Any]:
    """The key path and value an error about cluster j names: ``positions[j]``, or ``spacing``."""
    if t.has("positions"):
        return f"{t.key_path('positions')}[{j}]", t.data["positions"][j]
    return t.key_path("spacing"), t.data.get("spacing")


def _item(t: Table, key: str, i: int, value: Any, kind: str, **bounds: Any) -> float:
    """Element i of the list ``key``, checked as a value of ``kind`` (key path ``key[i]``)."""
    item = Table({f"{key}[{i}]": value}, t.path)
    if kind == "count":
        return item.integer(f"{key}[{i}]", minimum=1)
    if kind == "dimensionless":
        return item.number(f"{key}[{i}]", minimum=0.0, exclusive_minimum=True, **bounds)
    if kind in ("pressure", "position"):
        return item.quantity(f"{key}[{i}]", "length" if kind == "position" else kind)
    return item.quantity(f"{key}[{i}]", kind, minimum=0.0, exclusive_minimum=True, **bounds)


def _each(t: Table, key: str, n: int, kind: str, scalar: bool = True, **bounds: Any) -> list[float]:
    """One value per cluster: a list of n, or (``scalar``) one value for all."""
    raw = t.raw(key)
    if isinstance(raw, list):
        if len(raw) != n:
            raise SceneError(t.key_path(key), raw, f"expected one value per cluster ({n}), or one for all")
        return [_item(t, key, i, v, kind, **bounds) for i, v in enumerate(raw)]
    if not scalar:
        raise SceneError(t.key_path(key), raw, f"expected a list of one value per cluster ({n})")
    if kind == "count":
        return [t.integer(key, minimum=1)] * n
    if kind == "dimensionless":
        return [t.number(key, minimum=0.0, exclusive_minimum=True, **bounds)] * n
    return [t.quantity(key, kind, minimum=0.0, exclusive_minimum=True, **bounds)] * n


def _close_spacing(t: Table, positions: tuple[float, ...], cell: float) -> None:
    """The warning of the module docstring, once for the closest pair under MIN_SPACING_CELLS cells."""
    if len(positions) < 2:
        return
    ordered = np.sort(positions)
    gap = float(np.min(np.diff(ordered)))
    if gap < MIN_SPACING_CELLS * cell:
        system = scene_system()
        warn(f"{t.path}: clusters {display_text(gap, 'length', system)} apart are closer than "
             f"{MIN_SPACING_CELLS:g} cells of the fracture grid ({display_text(cell, 'length', system)} in use): the "
             "stress shadow between them is the near field of elements larger than their distance (on a penny "
             "crack's axis its error grows from under 0.01 % at 2 cells to 0.25 % at 1 cell and 3 % at a quarter "
             "cell, more near the fronts); use cells at most half the spacing")
