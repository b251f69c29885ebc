"""Wall friction of the fluid between the fracture faces (hfgpu.proppant.momentum, MppicParams.wall_friction).

References: plane Poiseuille flow, -dp/dx = 12 mu U / w^2 (Eq. 9 of the paper); Dean (1978, J. Fluids Eng.
100, 215), fully developed turbulent flow between smooth parallel plates: c_f = tau_w / (rho U^2 / 2) =
0.073 Re^(-1/4), Re = rho U w / mu (bulk velocity U, full gap w), so that -dp/dx = 2 tau_w / w =
c_f rho U^2 / w.
"""

from importlib.resources import files

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.errors import SceneError
from hfgpu.kernels.closures.wall_friction import wall_friction_code, wall_friction_factor_numpy
from hfgpu.proppant.fluid import FluidNumerics, FluidSolver
from hfgpu.proppant.grid import StaggeredGrid
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

RHO, MU, GAP, HEIGHT = 1000.0, 1e-3, 5e-3, 0.1


def steady_gradient(reynolds: float, wall_friction: str) -> tuple[float, np.ndarray]:
    """Steady flow through a uniform slot (inflow over column 0, outlet column 39) at the gap Reynolds number
    ``reynolds`` (one row of cells: the flow is uniform); returns the bulk velocity and the pressure gradient
    over columns 10-30."""
    grid = StaggeredGrid.slot(1.0, HEIGHT, GAP, nx=40, nz=1)
    speed = reynolds * MU / (RHO * GAP)
    solver = FluidSolver(grid, RHO, MU, FluidNumerics(tolerance=1e-10), wall_friction=wall_friction)
    state = solver.initial_state()
    sources = np.zeros(grid.shape)
    sources[:, 0] = speed * HEIGHT * GAP / grid.nz
    outlets = np.zeros(grid.shape, dtype=bool)
    outlets[:, -1] = True
    dt = 0.4 * grid.frame.dx / speed
    for _ in range(10):
        solver.step(state, dt, sources=sources, outlets=outlets)
    np.testing.assert_allclose(state.u[:, 5:35], speed, rtol=1e-8)
    return speed, (state.p[:, 30] - state.p[:, 10]) / (20 * grid.frame.dx)


def test_dean_pressure_drop_at_re_5000():
    """Past the transition the "dean" law gives Dean's turbulent pressure drop c_f rho U^2 / w (3.6 times the
    laminar one at Re 5000), the "laminar" law still Eq. 9's."""
    speed, dpdx = steady_gradient(5000.0, "dean")
    c_f = 0.073 * 5000.0 ** -0.25
    np.testing.assert_allclose(-dpdx, c_f * RHO * speed ** 2 / GAP, rtol=1e-8)
    speed, dpdx = steady_gradient(5000.0, "laminar")
    np.testing.assert_allclose(-dpdx, 12.0 * MU * speed / GAP ** 2, rtol=1e-8)


def test_dean_is_laminar_below_the_crossing():
    """At Re 100 (and up to Re = (12/0.073)^(4/3) = 899) "dean" is Eq. 9 exactly: -dp/dx = 12 mu U / w^2."""
    speed, dpdx = steady_gradient(100.0, "dean")
    np.testing.assert_allclose(-dpdx, 12.0 * MU * speed / GAP ** 2, rtol=1e-8)
    np.testing.assert_array_equal(dpdx, steady_gradient(100.0, "laminar")[1])
    crossing = (12.0 / 0.073) ** (4.0 / 3.0)
    speeds = np.array([0.999, 1.001]) * crossing * MU / (RHO * GAP)
    factor = wall_friction_factor_numpy(speeds, GAP, MU, RHO, wall_friction_code("dean"))
    assert factor[0] == 1.0 and 1.0 < factor[1] < 1.001


def test_wall_friction_knob():
    """[mppic] wall_friction: default "laminar", "dean" in the Chun slot scene (gap Re past 899); other values
    are refused."""
    assert MppicParams().wall_friction == "laminar"
    text = (files("hfgpu") / "scenes" / "chun2020_slot.toml").read_text()
    assert load_scene(text).proppant.params.wall_friction == "dean"
    sim = ProppantSimulation(proppant_engine_setup(load_scene(text.replace("[mppic]", '[mppic]\nbackend = "numpy"'))))
    assert sim.solver.wall_friction == "dean"  # what the momentum predictor is given
    assert load_scene(text.replace('wall_friction = "dean"', "")).proppant.params.wall_friction == "laminar"
    with pytest.raises(SceneError, match="wall_friction"):
        load_scene(text.replace('wall_friction = "dean"', 'wall_friction = "turbulent"'))
    with pytest.raises(ValueError):
        wall_friction_code("turbulent")
