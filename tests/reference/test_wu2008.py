"""Wu et al. (2008) digitised fronts (PyFrac's examples/wu_et_al_data.csv, read from ../shared) against their
extents tabulated independently from that csv."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu.reference import wu2008 as wu

# extents of the csv's fronts: t -> (up, down, left, right) in mm, relative to the injection point
TABLE = {22.0: (15.0, 18.4, 19.2, 15.8), 60.0: (30.0, 46.3, 41.0, 38.5), 144.0: (34.3, 94.7, 68.8, 65.4),
         376.0: (34.3, 132.9, 101.7, 92.7), 665.0: (34.7, 163.7, 127.8, 118.4)}


@pytest.fixture(scope="module")
def fronts(shared_dir):
    return wu.read_fronts(shared_dir / "validation-data" / "wu_et_al_2008_fronts_pyfrac.csv")


def test_fronts_read_with_depth_positive_downward(fronts):
    assert list(fronts) == sorted(TABLE)
    for t, (up, down, left, right) in TABLE.items():
        e = wu.extents(fronts[t])
        np.testing.assert_allclose([e.up, e.down, e.left, e.right], np.array([up, down, left, right]) * 1e-3,
                                   atol=0.06e-3)


def test_front_is_contained_above_and_grows_down(fronts):
    # the front stops ~9-10 mm past the +25 mm interface into the 11.2 MPa layer and runs into the 5 MPa layer
    ext = [wu.extents(fronts[t]) for t in sorted(fronts)]
    assert all(e.up < 0.036 for e in ext)
    assert all(b.down > a.down for a, b in zip(ext, ext[1:]))
    assert ext[-1].down > 4 * ext[-1].up


def test_injected_volume_of_paper_schedule():
    # PyFrac Experiment_Wu_et_al.py schedule integrated independently: 0.0198, 0.2164, 0.7624, 1.3254, 1.9901 mL
    np.testing.assert_allclose(wu.injected_volume([22.0, 60.0, 144.0, 376.0, 665.0]),
                               np.array([0.0198, 0.2164, 0.7624, 1.3254, 1.9901]) * 1e-6, rtol=2e-4)
    assert float(wu.injected_volume(1000.0)) == pytest.approx(
        (31 * 0.0009 + 120 * 0.0065 + 550 * 0.0023) * 1e-6, rel=1e-12)


def test_bad_input():
    with pytest.raises(ValueError, match="polyline"):
        wu.extents(np.zeros((2, 2)))
    with pytest.raises(FileNotFoundError):
        wu.read_fronts("/nonexistent/fronts.csv")
