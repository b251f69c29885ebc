"""Chun, Li & Wu (2020) slot test (the paper's Table 3; GEOS's proppantSlotTest set-up): the scene's set-up, and
(slow) the proppant bank's length and area at 10-30 s against the experiment as digitised by GEOS
(../shared/validation-data/chun_2020_bank_length_area_geos.txt).

Bank: the cells whose theta_p >= half of close packing (hfgpu.proppant.analysis.bank); its length is the
x-extent of the columns holding bank cells / slot length, its area the bank cells' area / slot area.
"""

from __future__ import annotations

from importlib.resources import files

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.proppant.analysis import bank
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

SCENE = (files("hfgpu") / "scenes" / "chun2020_slot.toml").read_text()


def test_slot_scene_matches_the_experiment():
    scene = load_scene(SCENE.replace("[mppic]", '[mppic]\nbackend = "numpy"'))
    g = scene.proppant.geometry
    assert (g.length, g.height, g.width) == pytest.approx((1.2192, 0.3048, 7.62e-3))
    q = scene.injection.schedule.rate(1.0)
    assert q == pytest.approx(6 * 3.785411784e-3 / 60)  # 6 gpm
    # 1.5 ppg of 2550 kg/m^3 sand: slurry fraction (c/rho)/(1 + c/rho) = 0.065845
    c = 1.5 * 0.45359237 / 3.785411784e-3
    assert scene.injection.schedule.proppant_fraction(1.0)[1] == pytest.approx((c / 2550) / (1 + c / 2550), rel=1e-5)
    assert scene.proppant.classes[0].size.d_min == pytest.approx(0.3e-3)  # 30/50 mesh
    sim = ProppantSimulation(proppant_engine_setup(scene))
    sources = sim.injector.fluid_sources(0.0, 0.1)
    assert sources.sum() == pytest.approx((1 - 0.065845) * q, rel=1e-5)
    assert np.all(np.nonzero(sources)[1] == 0) and len(sim.injector.inlets) == 3  # three inlets, left end
    assert np.all(np.nonzero(sim.outlets)[1] == sim.grid.nx - 1)  # outlet on the far end


@pytest.mark.slow
@pytest.mark.xfail(reason="bank LENGTH too long early: 0.703 / 0.703 / 0.719 at 10 / 12.5 / 15 s (exp. "
                          "0.55-0.57, +28 / +26 / +26 %), within 15 % from 20 s and 2.4 % at 30 s; bank AREA +24 % at "
                          "10 s, within 2.1 % from 20 s (python demos/slot.py). The length follows the grains' "
                          "settling speed (Wen-Yu / Schiller-Naumann, "
                          "6.7 cm/s at 0.45 mm): Stokes' law (drag_re_coefficient = 0, 2.6x faster) gives 0.344 "
                          "at 10 s (-37.5 %). GEOS's reference model meets the experiment's length with Stokes "
                          "settling. One-way coupling, mono-size 0.45 mm grains, wall friction, parcels, "
                          "steps, grid, bank threshold and bed rules do not explain it; docs/proppant-closures.md "
                          "has the measurements.",
                   strict=False)
def test_chun_bank_length_and_area(shared_dir):
    data = np.loadtxt(shared_dir / "validation-data" / "chun_2020_bank_length_area_geos.txt")

    class Sink:
        def __init__(self):
            self.snapshots = []

        def proppant_snapshot(self, record):
            self.snapshots.append(record)

        def proppant_balance(self, record):
            pass

    sim = ProppantSimulation(proppant_engine_setup(load_scene(SCENE)))
    sink = Sink()
    sim.run(sink)
    by_time = {round(s.time, 6): s for s in sink.snapshots}
    for t, length, area in data:
        snap = by_time[round(t, 6)]
        b = bank(snap.grid["volume_fraction"], snap.grid["width"], snap.frame, 0.5 * sim.params.theta_cp)
        assert b.normalised_length == pytest.approx(length, rel=0.15), t
        assert b.normalised_area == pytest.approx(area, rel=0.15), t
