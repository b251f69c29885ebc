"""Chun, Li & Wu (2020) slot test (the paper's Table 3, REFERENCE.md 5): the scene's set-up, and (slow) the
proppant bank's length and area at 10-30 s against the experiment as digitised by GEOS
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
from hfgpu.proppant.simulator import ProppantSimulation

SCENE = (files("hfgpu") / "scenes" / "chun2020_slot.toml").read_text()


def test_slot_scene_matches_the_experiment():
    scene = load_scene(SCENE.replace("[mppic]", '[mppic]\nbackend = "numpy"'))
    g = scene.proppant.geometry
    assert (g.length, g.height, g.width) == pytest.approx((1.2192, 0.3048, 7.62e-3))
    q = scene.injection.schedule.rate(1.0)
    assert q == pytest.approx(6 * 3.785411784e-3 / 60)  # 6 gpm
    # 1.5 ppg of 2550 kg/m^3 sand: slurry fraction (c/rho)/(1 + c/rho) = 0.065845 (REFERENCE.md 5)
    c = 1.5 * 0.45359237 / 3.785411784e-3
    assert scene.injection.schedule.proppant_fraction(1.0)[1] == pytest.approx((c / 2550) / (1 + c / 2550), rel=1e-5)
    assert scene.proppant.classes[0].size.d_min == pytest.approx(0.3e-3)  # 30/50 mesh
    sim = ProppantSimulation(scene)
    sources = sim.injector.fluid_sources(0.0, 0.1)
    assert sources.sum() == pytest.approx((1 - 0.065845) * q, rel=1e-5)
    assert np.all(np.nonzero(sources)[1] == 0) and len(sim.injector.inlets) == 3  # three inlets, left end
    assert np.all(np.nonzero(sim.outlets)[1] == sim.grid.nx - 1)  # outlet on the far end


@pytest.mark.slow
@pytest.mark.xfail(reason="bank AREA within 3 % from 17.5 s (+28 % at 10 s, +12 % at 15 s) but bank LENGTH too long: "
                          "0.75-0.77 at 10-20 s (exp. 0.55-0.63, +36 % to +22 %), 0.78-0.80 at 22.5-30 s (exp. 0.65-0.75, "
                          "+20 % to +7 %); the bank is a flat ~6 cm slab over 0.07-0.70 of the slot at 10 s whose length "
                          "is set by 5 s (0.67), while the experiment's grows with time. At 1-5 s the slurry plunges "
                          "and the whole inflow runs under the plume as a bottom underflow (0.35-0.5 m/s, 2-3x the mean "
                          "0.163 m/s) that carries grains settling at ~0.06 m/s along the slot. Not the cause: "
                          "the wall friction (Dean's turbulent law, on in the scene, at gap Re 1000-3000: length within "
                          "one column of the laminar Eq. 9 at 10-27.5 s, 0.83 -> 0.80 at 30 s, area at 10 s +33 -> +28 "
                          "%); parcels and sub-steps (16 / 4: 0.75 at 10 s) or the step (c_max 0.25: 0.77); the bank "
                          "threshold (0.45 / 0.54 instead of 0.3: 0.72); the inlet jets (they lengthen it by 0.03-0.05); "
                          "the grid (9.525 mm cells: longer, 0.80 at 10 s). Bed friction six times tan(28.5 deg) (a "
                          "diagnostic, not a value) only gives 0.69. At 10 s the bank cells hold 81 % of the injected "
                          "sand; the experiment's bank, packed at 0.6, 68 % (area 0.10 of the 0.147 all of it would "
                          "fill). The threshold of motion on the bed surface ([mppic] shields_deposition = true, "
                          "on in the scene) shortens it by 3 columns: 0.70-0.72 at 10-20 s (+28 % to +14 %), "
                          "0.73-0.77 at 22.5-30 s (+13 % to +2 %), area unchanged; it holds the grains that reach "
                          "the floor, but the early sand travels in suspension in the underflow (counting every "
                          "parcel of the bottom row as on the floor, a diagnostic: 0.67 at 10 s). The underflow is "
                          "not too fast for the model: a lock exchange of a fine suspension runs at Fr = 0.38-0.41, "
                          "below Benjamin's energy-conserving 0.5 (tests/proppant/test_lock_exchange.py), and the "
                          "slot's 0.35-0.5 m/s is the critical speed (g' Q / w)^(1/3) = 0.37 m/s of the inflow as a "
                          "heavy current; the implicit drag holding the parcels' response (that test: 0.03 "
                          "before) gives 0.688/0.703 at 10/12.5 s, the same from 15 s, area within 4 % from "
                          "17.5 s. The Shields rule's bed shear (sqrt(12)/6 of Dean's face stress) leaves the "
                          "underflow above the threshold of motion (0.23 m/s; 0.17 with the full face stress). "
                          "Open: what holds the early sand back near the inlet in the experiment.",
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

    sim = ProppantSimulation(load_scene(SCENE))
    sink = Sink()
    sim.run(sink)
    by_time = {round(s.time, 6): s for s in sink.snapshots}
    for t, length, area in data:
        snap = by_time[round(t, 6)]
        b = bank(snap.grid["volume_fraction"], snap.grid["width"], snap.frame, 0.5 * sim.params.theta_cp)
        assert b.normalised_length == pytest.approx(length, rel=0.15), t
        assert b.normalised_area == pytest.approx(area, rel=0.15), t
