"""Checkpoints: when to take one, how a simulator's state is stored, and how a resumed scene is checked.

A checkpoint is the complete state a simulator needs to continue (``_Engine.state()`` of the fracture engine,
``ProppantSimulation.state()``, the coupled run's phase), handed over as a tree: dicts of NumPy arrays
(datasets), numbers and strings (attributes) and dicts (groups). :class:`hfgpu.io.results.ResultsWriter`
stores it in the results file under ``/checkpoint`` (docs/results-format.md), replacing the previous one
atomically, and :meth:`ResultsWriter.reopen` gives it back for ``hfgpu run --resume``.

When: after the first step that ends at or past each multiple of the interval (``[output] checkpoint_every``;
default ``max(end_time / DEFAULT_CHECKPOINTS, output.every)``, "0 s" or false: none). No step is shortened
to land on a checkpoint time, so a run with checkpoints takes exactly the steps of one without.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import h5py
import numpy as np

#: Checkpoints per run when ``[output] checkpoint_every`` is not given (at most: never more often than
#: ``output.every``).
DEFAULT_CHECKPOINTS = 20
#: Scene fields a resumed run may change: the checkpoint interval (it does not change the results) and the
#: proppant run's step control and solver numerics (the state carries no trace of them), so that a run stopped by
#: a collapsing step (hfgpu.proppant.health) continues with, e.g., a smaller [mppic] dt_max or c_max.
RESUME_MAY_CHANGE = ("output.checkpoint_every",) + tuple(
    f"proppant.numerics.{name}" for name in ("backend", "arch", "particle_substeps", "c_max", "dt_max",
                                             "max_step_retries", "simple_tolerance", "simple_max_iterations"))


def checkpoint_interval(scene: Any) -> float:
    """Simulated time between checkpoints [s]: ``output.checkpoint_every``, else max(end_time /
    DEFAULT_CHECKPOINTS, output.every); 0 for none."""
    every = scene.output.checkpoint_every
    if every is None:
        return max(scene.run.end_time / DEFAULT_CHECKPOINTS, scene.output.every)
    return float(every)


class Checkpointer:
    """Says when a checkpoint is due and hands it to ``write(time, state)`` (``ResultsWriter.write_checkpoint``).

    ``due(t)``: true once t reaches the next multiple of ``interval`` after the last checkpoint (or after
    ``start``); never when ``interval`` is 0. ``save(t, state)`` writes and counts (``written``).
    """

    def __init__(self, write: Callable[[float, dict], None], interval: float, start: float = 0.0):
        self._write = write
        self.interval = float(interval)
        self.written = 0
        self.restart(start)

    def restart(self, t: float) -> None:
        """Count intervals from time ``t`` on (a new phase of a coupled run starts on an earlier clock)."""
        self._next = (math.floor(t / self.interval) + 1) * self.interval if self.interval > 0.0 else math.inf

    def due(self, t: float) -> bool:
        return t >= self._next

    def save(self, t: float, state: dict) -> None:
        self._write(t, state)
        self.written += 1
        self.restart(t)

    def within(self, offset: float, wrap: Callable[[dict], dict]) -> "PhaseCheckpointer":
        """This checkpointer as seen by one phase of a run whose clock is ``offset`` behind and whose state
        is stored as ``wrap(state)``."""
        return PhaseCheckpointer(self, offset, wrap)


@dataclasses.dataclass(frozen=True)
class PhaseCheckpointer:
    """:meth:`Checkpointer.within`: times moved by ``offset``, states wrapped by ``wrap``."""

    parent: Checkpointer
    offset: float
    wrap: Callable[[dict], dict]

    def due(self, t: float) -> bool:
        return self.parent.due(t + self.offset)

    def save(self, t: float, state: dict) -> None:
        self.parent.save(t + self.offset, self.wrap(state))


# ----------------------------------------------------------------------------------------------
# the state tree in HDF5


def write_tree(group: h5py.Group, tree: dict) -> None:
    """Store ``tree`` under ``group``: dicts as groups, arrays as datasets, numbers/strings/bools as attributes
    (float64 bit for bit; None is refused)."""
    for key, value in tree.items():
        if isinstance(value, dict):
            write_tree(group.create_group(key), value)
        elif isinstance(value, np.ndarray):
            group.create_dataset(key, data=value)
        elif isinstance(value, (bool, int, float, str, np.generic)):
            group.attrs[key] = value
        else:
            raise TypeError(f"checkpoint entry '{group.name}/{key}': cannot store {type(value).__name__}")


def read_tree(group: h5py.Group) -> dict:
    """The tree :func:`write_tree` stored (attributes as plain Python numbers, bools and strings)."""
    tree: dict[str, Any] = {}
    for key, value in group.attrs.items():
        tree[key] = value.decode("utf-8") if isinstance(value, bytes) else (
            value.item() if isinstance(value, np.generic) else value)
    for key, item in group.items():
        tree[key] = read_tree(item) if isinstance(item, h5py.Group) else item[()]
    return tree


# ----------------------------------------------------------------------------------------------
# the scene of a resumed run


def scene_differences(stored: Any, given: Any, path: str = "", limit: int = 5) -> list[str]:
    """Where two scenes (or parts of them) differ: up to ``limit`` lines "path: <stored> in the file, <given>
    given", walking dataclass fields (those with compare=False skipped), tuples, lists, dicts, arrays (NaN equal
    to NaN) and the attributes of plain objects. Paths in RESUME_MAY_CHANGE are not compared."""
    out: list[str] = []
    _differences(stored, given, path, out, limit)
    return out


def _differences(a: Any, b: Any, path: str, out: list[str], limit: int) -> None:
    if len(out) >= limit or path in RESUME_MAY_CHANGE:
        return
    here = path or "scene"
    if dataclasses.is_dataclass(a) and type(a) is type(b):
        for f in dataclasses.fields(a):
            if f.compare:
                _differences(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}".lstrip("."), out, limit)
    elif isinstance(a, (tuple, list)) and isinstance(b, (tuple, list)) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            _differences(x, y, f"{here}[{i}]", out, limit)
    elif isinstance(a, dict) and isinstance(b, dict) and a.keys() == b.keys():
        for key in a:
            _differences(a[key], b[key], f"{here}.{key}", out, limit)
    elif type(a) is type(b) and hasattr(a, "__dict__") and type(a).__eq__ is object.__eq__:
        _differences(vars(a), vars(b), path, out, limit)  # a plain object: compare what it holds
    elif isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        x, y = np.asarray(a), np.asarray(b)
        if x.shape != y.shape or not np.array_equal(x, y, equal_nan=x.dtype.kind == "f" and y.dtype.kind == "f"):
            out.append(f"{here}: array {x.shape} in the file, {y.shape} given, values differ")
    elif not (a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))):
        out.append(f"{here}: {a!r} in the file, {b!r} given")
