"""What the exporters share: the injection point of a results file's scene, the note on a run that did not complete,
numbers without round-off noise."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import HfgpuError


def injection_point(results: Any) -> tuple[float, float] | None:
    """(x, depth) [m] of the injection: ``[injection]`` of the stored scene, else its first
    ``[[geometry.inlets]]``; None when it names neither (or the stored scene does not parse)."""
    try:
        scene = results.scene
    except HfgpuError:
        return None
    if scene.injection is not None:
        return scene.injection.x, scene.injection.depth
    inlets = scene.proppant.geometry.inlets if scene.proppant is not None else ()
    return (inlets[0].x, inlets[0].depth) if inlets else None


def status_note(results: Any) -> str | None:
    """The line an export's header carries when the run did not complete (status "failed: ...", "interrupted",
    "running"); None for a complete run."""
    status = results.status
    return None if status == "complete" else f"hfgpu: the run is not complete (status \"{status}\")"


def round_off(values: np.ndarray, scale: float | None = None) -> np.ndarray:
    """``values`` with those below 1e-9 of ``scale`` (default: their largest magnitude) set to 0: a centre at
    9.3e-13 m is written 0."""
    values = np.asarray(values, dtype=np.float64)
    scale = float(np.max(np.abs(values), initial=0.0)) if scale is None else scale
    return np.where(np.abs(values) <= 1e-9 * scale, 0.0, values)
