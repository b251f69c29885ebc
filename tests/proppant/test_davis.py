"""Davis, Herbolzheimer & Acrivos (1982) bimodal batch sedimentation with the paper's parameters (section 5.2.1):
the speeds of the two interfaces (clear | light-only suspension | mixture) against Kynch theory with the
Masliyah / Lockett-Bassoon slip velocities (hfgpu.reference.settling.bidisperse_batch; Masliyah 1979, Lockett &
Bassoon 1979, Kynch 1952).

The upper interface is where the light class's theta_p crosses half the light-only fraction phi_L', the lower one
where the heavy class's crosses half phi_H; speeds are least-squares slopes over the time the interface needs to
fall from one cell below the top to ~40 % of the column (above the rising sediment). The default test runs a
20 cm column one cell wide (1-D batch test); the slow one the paper's full 1 m vessel (one column: see the scene).
"""

from __future__ import annotations

from importlib.resources import files

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.proppant.analysis import class_volume_fraction, fitted_speed, interface_depth, row_profile
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation
from hfgpu.reference.settling import bidisperse_batch

SCENE = (files("hfgpu") / "scenes" / "davis1982.toml").read_text()


def kynch(scene):
    heavy, light = scene.proppant.classes
    return bidisperse_batch((heavy.size.mean / 2, heavy.density, heavy.initial_volume_fraction),
                            (light.size.mean / 2, light.density, light.initial_volume_fraction),
                            scene.fluid.density, scene.fluid.viscosity)


def interfaces(sim: ProppantSimulation, phi_light_only: float) -> tuple[float, float]:
    """(upper, lower) interface depths [m] now."""
    frame, width, parcels = sim.grid.frame, sim.grid.width, sim.parcels
    heavy, light = sim.setup.classes
    theta_h = class_volume_fraction(parcels, frame, width, 0)
    theta_l = class_volume_fraction(parcels, frame, width, 1)
    return (interface_depth(row_profile(theta_l, width), frame, 0.5 * phi_light_only),
            interface_depth(row_profile(theta_h, width), frame, 0.5 * heavy.initial_volume_fraction))


def measured_speeds(text: str, end: float, window_depths: tuple[float, float]) -> tuple[float, float, float]:
    scene = load_scene(text)
    theory = kynch(scene)
    sim = ProppantSimulation(proppant_engine_setup(scene))
    record = []
    while sim.time < end - 1e-9:
        sim.step(limit=end - sim.time)
        record.append((sim.time, *interfaces(sim, theory.phi_light_only)))
    t, upper, lower = np.array(record).T
    speeds = []
    for depth in (upper, lower):
        use = (depth > window_depths[0]) & (depth < window_depths[1])
        speeds.append(fitted_speed(t[use], depth[use]))
    return speeds[0], speeds[1], theory


def test_davis_interface_speeds_short_column():
    text = (SCENE.replace('length = "1 cm"', 'length = "5 mm"').replace('height = "100 cm"', 'height = "20 cm"')
            .replace('cell_size = "1 cm"', 'cell_size = "5 mm"').replace("[mppic]", '[mppic]\nbackend = "numpy"'))
    theory = kynch(load_scene(text))
    assert theory.lower_speed == pytest.approx(5.4485e-4, rel=1e-3)  # MLB, n = 4.65, Davis et al.'s parameters
    assert theory.upper_speed == pytest.approx(1.9316e-4, rel=1e-3)
    upper, lower, _ = measured_speeds(text, 200.0, (0.01, 0.09))
    assert lower == pytest.approx(theory.lower_speed, rel=0.05)
    assert upper == pytest.approx(theory.upper_speed, rel=0.05)


@pytest.mark.slow
def test_davis_interface_speeds_full_vessel():
    upper, lower, theory = measured_speeds(SCENE.replace("[mppic]", '[mppic]\nbackend = "numpy"'), 600.0, (0.02, 0.4))
    assert lower == pytest.approx(theory.lower_speed, rel=0.05)
    assert upper == pytest.approx(theory.upper_speed, rel=0.05)
