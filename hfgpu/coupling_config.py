"""``[coupling]`` of a coupled scene (the paper, section 4.3): how the proppant run reads the fracture history
(:mod:`hfgpu.coupled` runs it). Read by the scene reader, so it imports neither simulator."""

from __future__ import annotations

from dataclasses import dataclass

from .errors import SceneError
from .scene_reader import Table

#: Snapshots of the fracture per run when ``fracture_every`` is not given.
DEFAULT_FRACTURE_SNAPSHOTS = 60
#: Default outer radius of the inlet annulus, in (larger) proppant cell sizes.
DEFAULT_INLET_CELLS = 1.5
#: Default ``[coupling] min_width`` [m]: narrower cells are closed for the proppant run (parse_coupling).
DEFAULT_MIN_WIDTH = 10e-6
#: ``[coupling] mode``: "one-way" (fracture first, proppant on its history) or "two-way" (the fracture sees the
#: slurry interval by interval); hfgpu.coupled.
MODES = ("one-way", "two-way")
#: ``[coupling] mode`` when the scene does not give it (docs/coupling.md has the measurements behind it).
DEFAULT_MODE = "one-way"


@dataclass(frozen=True)
class CouplingConfig:
    """``[coupling]``: how the proppant run reads the fracture (see the module docstring)."""

    fracture_every: float
    cell_size: tuple[float, float] | None = None
    inlet_inner_radius: float = 0.0
    inlet_radius: float | None = None
    proppant_start: float | None = None
    margin: int = 1
    min_width: float = DEFAULT_MIN_WIDTH
    mode: str = DEFAULT_MODE


def parse_coupling(t: Table, end_time: float, refinement: float = 1.0,
                   front_tracking: str | None = "cells") -> CouplingConfig:
    """Read ``[coupling]`` (every key optional) into a :class:`CouplingConfig`; the proppant cells in use are
    ``cell_size`` / ``refinement`` (``[mesh] refinement``, as the fracture cells).

    ``mode``: "one-way" or "two-way" (:data:`MODES`); "two-way" needs the whole-cell front (``[fracture]
    front_tracking``, given here; None when [fracture] did not parse): bridged cells stop it
    (hfgpu.fracture.slurry).

    ``min_width``: proppant cells narrower than this are closed for the proppant run. A cell that opens between
    two fracture snapshots passes through every width from 0 (the width is linear in time), and the fluid must
    supply the leak-off of its faces: u ~ 2 q_L dx / w, ~300 m/s at w = 20 nm (measured on 2.5 m cells of the
    field case), so the fluid Courant limit (Eq. 42) stops the run. At the default 10 um, u ~ 0.05 m/s for
    q_L = 1e-7 m/s on 2.5 m cells; the fluid such cells hold (w dx dz) is dropped as in any closing cell."""
    positive = dict(minimum=0.0, exclusive_minimum=True)
    every = t.quantity("fracture_every", "time", end_time / DEFAULT_FRACTURE_SNAPSHOTS, **positive)
    size = t.raw("cell_size", None)
    cell_size = None
    if size is not None:
        items = size if isinstance(size, list) else [size, size]
        if len(items) != 2:
            raise SceneError(t.key_path("cell_size"), size, 'expected one length or two, ["dx", "dz"]')
        cell_size = tuple(Table({"cell_size": s}, t.path).quantity("cell_size", "length", **positive)
                          / refinement for s in items)
    inner = t.quantity("inlet_inner_radius", "length", 0.0, minimum=0.0)
    outer = t.quantity("inlet_radius", "length", None, minimum=inner, exclusive_minimum=True)
    start = t.quantity("proppant_start", "time", None, minimum=0.0, maximum=end_time, exclusive_maximum=True)
    margin = t.integer("margin", 1, minimum=0)
    min_width = t.quantity("min_width", "length", DEFAULT_MIN_WIDTH, minimum=0.0)
    mode = t.choice("mode", MODES, DEFAULT_MODE)
    if mode == "two-way" and front_tracking not in ("cells", None):
        raise SceneError(t.key_path("mode"), mode, 'two-way coupling needs [fracture] front_tracking = "cells"')
    t.finish()
    return CouplingConfig(fracture_every=every, cell_size=cell_size, inlet_inner_radius=inner,
                          inlet_radius=outer, proppant_start=start, margin=margin, min_width=min_width,
                          mode=mode)
