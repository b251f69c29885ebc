"""Numerical settings of the fracture engine, from the scene's optional ``[fracture]`` table."""

from __future__ import annotations

from dataclasses import dataclass

from ..scene_reader import Table


@dataclass(frozen=True)
class FractureNumerics:
    """Knobs of the planar-3D engine (each documented in docs/scene.md).

    time_step_relaxation: lambda of Eq. 35, dt = lambda min(dx, dz) / max(V_T).
    newton_tolerance: epsilon of Eq. 32 (relative).
    linear_solver: "auto" (direct below ``krylov_threshold`` cells, Newton-Krylov above), "direct", "krylov".
    """

    time_step_relaxation: float = 0.5
    newton_tolerance: float = 1e-6
    newton_max_iterations: int = 30
    linear_solver: str = "auto"
    krylov_threshold: int = 3000
    max_step_retries: int = 8


def parse_fracture_numerics(t: Table) -> FractureNumerics:
    d = FractureNumerics()
    numerics = FractureNumerics(
        time_step_relaxation=t.number("time_step_relaxation", d.time_step_relaxation, minimum=0.0,
                                      maximum=1.0, exclusive_minimum=True),
        newton_tolerance=t.number("newton_tolerance", d.newton_tolerance, minimum=0.0,
                                  exclusive_minimum=True, maximum=0.1),
        newton_max_iterations=t.integer("newton_max_iterations", d.newton_max_iterations, minimum=1),
        linear_solver=t.choice("linear_solver", ("auto", "direct", "krylov"), d.linear_solver),
        krylov_threshold=t.integer("krylov_threshold", d.krylov_threshold, minimum=1),
        max_step_retries=t.integer("max_step_retries", d.max_step_retries, minimum=0),
    )
    t.finish()
    return numerics
