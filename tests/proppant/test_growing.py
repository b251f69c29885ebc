"""Coupling to a growing fracture: cells that open between fluid steps get their fluid as a storage source
(hfgpu.proppant.fluid.FluidSolver.step) instead of drawing it through their faces, so a width field growing
radially from a point runs stably, with the fluid balance (injected + opened = stored + leaked + outflow) and
the solid balance (injected = in domain + outflow) held to round-off."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

BOX = """
[run]
end_time = "2 s"
physics = ["proppant"]
seed = 11
[fluid]
viscosity = "1 cP"
[mesh]
cell_size = "5 mm"
[output]
every = "1 s"
[geometry]
kind = "box"
length = "10 cm"
height = "10 cm"
width = "2 mm"
[[geometry.outlets]]
kind = "point"
x = "5 cm"
depth = "5 cm"
[[proppant]]
name = "sand"
density = "2550 kg/m**3"
diameter = "0.2 mm"
initial_volume_fraction = 0.1
[mppic]
backend = "numpy"
parcels_per_cell = 4
"""


def radial_width(t: float) -> tuple[np.ndarray, np.ndarray]:
    """A disc of uniform width w = 2 mm (1 + t/2) within R = 1.2 cm + 1.8 cm/s x t of the box centre (the
    outlet cell, the fracture's source); uniform leak-off 1e-6 m/s on open cells. A cell opens at full width:
    drawn through its faces within dt its fluid would give a Courant number ~ 1 whatever dt."""
    centres = 2.5e-3 + 5e-3 * np.arange(20)
    x, z = np.meshgrid(centres, centres)
    r = np.hypot(x - 0.0525, z - 0.0525)
    radius = 0.012 + 0.018 * t
    width = np.where(r < radius, 2e-3 * (1.0 + 0.5 * t), 0.0)
    return width, np.where(width > 0.0, 1e-6, 0.0)


def test_radially_growing_width_field_runs_stably_and_conserves_fluid_and_solids():
    sim = ProppantSimulation(proppant_engine_setup(load_scene(BOX)), width_field=radial_width)
    start = int(np.count_nonzero(sim.grid.active))
    dts = []
    while sim.time < 2.0 - 1e-9:
        info = sim.step(limit=2.0 - sim.time)
        dts.append(info.dt)
        assert info.continuity_residual < 1e-12
    assert np.count_nonzero(sim.grid.active) > 4 * start  # the fracture grew
    assert min(dts) > 1e-4  # no collapse of the step (cells opening needed none)
    totals = sim.fluid_totals
    assert totals["opened"] > 0.0
    scale = totals["opened"] + abs(totals["stored"])
    assert totals["injected"] + totals["opened"] == pytest.approx(
        totals["stored"] + totals["leaked"] + totals["outflow"], abs=1e-12 * scale)
    assert sim.injected == pytest.approx(float(np.sum(sim.parcels.solid_volume())) + sim.outflow, rel=1e-12)
    assert np.all(np.isfinite(sim.fluid.u)) and np.all(np.isfinite(sim.fluid.v))
