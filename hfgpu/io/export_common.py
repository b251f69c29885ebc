"""What the exporters share: the injection point of a results file's scene."""

from __future__ import annotations

from typing import Any

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
