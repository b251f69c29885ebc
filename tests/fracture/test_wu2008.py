"""Wu et al. (2008) layered-stress experiment (REFERENCE.md section 4): simulated front extents against
the digitised fronts (PyFrac's examples/wu_et_al_data.csv, via the shared_dir fixture)."""

import numpy as np
import pytest

from hfgpu.fracture.simulator import simulate
from hfgpu.scene import load_scene

from .helpers import SCENES, ListSink

TIMES = (665.0, 376.0, 144.0, 60.0, 22.0)   # column pairs of the csv, in this order


def measured_extents(shared_dir):
    """{t: (up, down, left, right)} [m]; the file's +y points down, into the 5 MPa layer (README there)."""
    data = np.genfromtxt(shared_dir / "validation-data" / "wu_et_al_2008_fronts_pyfrac.csv", delimiter=",")
    out = {}
    for k, t in enumerate(TIMES):
        x, y = data[:, 2 * k], data[:, 2 * k + 1]
        ok = np.isfinite(x) & np.isfinite(y)
        x, y = x[ok] / 1000.0, y[ok] / 1000.0
        out[t] = (-y.min(), y.max(), -x.min(), x.max())
    return out


def simulated_extents():
    sink = ListSink()
    simulate(load_scene(SCENES / "wu2008.toml"), sink)
    snaps = {round(s.time): s.extras for s in sink.snapshots}
    return {t: tuple(float(snaps[round(t)][f"front_{k}"]) for k in ("up", "down", "left", "right"))
            for t in TIMES}


def test_measured_extents_match_the_reference_table(shared_dir):
    up, down, left, right = measured_extents(shared_dir)[60.0]
    assert (up, down, left, right) == pytest.approx((0.0300, 0.0463, 0.0410, 0.0385), abs=2e-4)


@pytest.mark.slow
def test_wu2008_front_extents(shared_dir):
    measured = measured_extents(shared_dir)
    simulated = simulated_extents()
    for t in TIMES:
        up, down, left, right = simulated[t]
        m_up, m_down, m_left, m_right = measured[t]
        # downward growth and the lateral half-width (mean of left and right) within 15 %
        assert down == pytest.approx(m_down, rel=0.15), (t, simulated[t], measured[t])
        assert 0.5 * (left + right) == pytest.approx(0.5 * (m_left + m_right), rel=0.15), (t, simulated[t])
        # the front enters the 11.2 MPa layer (above 25 mm) but stays far shorter upward than downward
        if t >= 144.0:
            assert 0.025 < up < 0.6 * down, (t, simulated[t])
