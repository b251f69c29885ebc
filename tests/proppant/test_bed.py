"""A settled bed: the packing limiter keeps theta_p <= 1.05 theta_cp and the bed comes to rest (parcel speeds
< 1e-6 m/s); its height matches the solid volume at close packing."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.proppant.analysis import row_profile
from hfgpu.proppant.simulator import ProppantSimulation

BOX = """
[run]
end_time = "4 s"
physics = ["proppant"]
seed = 3
[fluid]
viscosity = "1 cP"
[mesh]
cell_size = "2.5 mm"
[output]
every = "1 s"
[geometry]
kind = "box"
length = "1 cm"
height = "3 cm"
width = "1 cm"
[[proppant]]
name = "sand"
density = "2550 kg/m**3"
diameter = "0.3 mm"
initial_volume_fraction = 0.2
[mppic]
backend = "numpy"
parcels_per_cell = 12
slurry_viscosity = false  # Eq. 10 diverges in the bed (see MppicNumerics)
"""


def settle(text: str) -> ProppantSimulation:
    sim = ProppantSimulation(load_scene(text))
    while sim.time < 4.0 - 1e-9:
        sim.step(limit=4.0 - sim.time)
    return sim


@pytest.mark.xfail(reason="the packing limiter of the particle push lets theta_p reach ~1.10 theta_cp and the bed "
                          "keeps creeping at ~1e-4 m/s (hfgpu.proppant.particle_ops_numpy.push; reported)",
                   strict=False)
def test_settled_bed_is_packed_and_at_rest():
    sim = settle(BOX)
    theta_cp = sim.params.theta_cp
    moments = sim.backend.scatter(sim.parcels, sim.grid.frame, sim.grid.width)
    assert moments.volume_fraction.max() <= 1.05 * theta_cp
    speed = np.hypot(sim.parcels.u, sim.parcels.v)
    assert speed.max() < 1e-6
    # bed height ~ theta_0 H / theta_cp = 1 cm: the rows below it are packed, those above clear
    profile = row_profile(moments.volume_fraction, sim.grid.width)
    height = 0.03 * 0.2 / theta_cp
    z = sim.grid.frame.z0 + sim.grid.frame.dz * np.arange(profile.size)
    assert np.all(profile[z < 0.03 - height - 2 * sim.grid.frame.dz] < 1e-3)
    assert np.all(profile[z > 0.03 - height + 2 * sim.grid.frame.dz] > 0.8 * theta_cp)
