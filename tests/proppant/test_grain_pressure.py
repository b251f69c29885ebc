"""[mppic] grain_pressure (hfgpu.proppant.simulator.ProppantSimulation.grain_pressure): the pressure the parcels
take in a fluid step is the last fluid step's ("last") or the mean of the last two ("two-step"), exactly."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

SLOT = """
[run]
end_time = "0.4 s"
physics = ["proppant"]
[fluid]
viscosity = "1 cP"
[mesh]
cell_size = "1 cm"
[output]
every = "0.4 s"
[geometry]
kind = "slot"
length = "20 cm"
height = "10 cm"
width = "5 mm"
[[geometry.inlets]]
kind = "segment"
x = 0
depth = "2 cm"
x_end = 0
depth_end = "4 cm"
[[geometry.outlets]]
kind = "segment"
x = "20 cm"
depth = "2 cm"
x_end = "20 cm"
depth_end = "4 cm"
[[proppant]]
name = "sand"
density = 2650
size = "40/70"
[injection]
schedule = [{rate = "0.05 L/s", duration = "0.4 s", proppant = "sand", concentration = "2 ppa"}]
[mppic]
backend = "numpy"
grain_pressure = "{mode}"
"""


def run_steps(mode: str, steps: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The pressure the engine received at each step's (last) begin_step (a retried step calls it again with the
    same pressure), and the fluid pressure before each step."""
    sim = ProppantSimulation(proppant_engine_setup(load_scene(SLOT.replace("{mode}", mode))))
    calls, seen, before = [], [], []
    begin = sim.engine.begin_step
    sim.engine.begin_step = lambda u, v, p: (calls.append(np.array(p)), begin(u, v, p))[1]
    for _ in range(steps):
        before.append(sim.fluid.p.copy())
        calls.clear()
        sim.step(limit=0.4 - sim.time)
        assert all(np.array_equal(c, calls[0]) for c in calls)
        seen.append(calls[-1])
    return seen, before


@pytest.mark.parametrize("mode", ["last", "two-step"])
def test_the_parcels_take_the_last_or_the_mean_of_the_last_two_pressures(mode):
    seen, before = run_steps(mode, 6)
    assert len(seen) == 6 and np.abs(before[-1]).max() > 0.0
    assert np.array_equal(seen[0], before[0])  # the first step: no step before it
    for n in range(1, 6):
        want = before[n] if mode == "last" else 0.5 * (before[n] + before[n - 1])
        assert np.array_equal(seen[n], want), n
