"""The Parcels container (shared data layout) and the particle engines on an empty parcel set."""

import numpy as np
import pytest

from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

from .engine_step import engine_for


def test_append_drop_copy_and_dict():
    a = Parcels.create(np.array([0.1, 0.2]), 0.5, radius=1e-4, density=2650.0, particles=3.0, class_id=1)
    b = Parcels.create(np.array([0.3]), 0.7, radius=2e-4, density=2500.0, particles=5.0)
    a.append(b)
    assert a.n == 3 and a.x.dtype == np.float64 and a.state.dtype == np.int32
    np.testing.assert_array_equal(a.class_id, [1, 1, 0])
    c = a.copy()
    a.drop(np.array([True, False, False]))
    assert a.n == 2 and c.n == 3
    np.testing.assert_array_equal(a.x, [0.2, 0.3])
    d = c.as_dict()
    assert set(d) == {"x", "z", "u", "v", "radius", "density", "particles", "state", "class_id"}
    assert c.solid_volume()[2] == pytest.approx(5.0 * 4 / 3 * np.pi * 2e-4 ** 3, rel=1e-15)
    with pytest.raises(ValueError, match="unequal length"):
        Parcels(x=[0.0], z=[0.0, 1.0], u=[0], v=[0], radius=[1], density=[1], particles=[1], state=[0],
                class_id=[0])


def test_sort_by_cell_orders_by_half_cells():
    frame = GridFrame(1.0, 1.0, 0.5, 0.5)
    p = Parcels.create(np.array([2.7, 0.2, 0.7, 0.2]), np.array([0.1, 1.9, 0.1, 0.4]), radius=1e-4,
                       density=1.0, particles=1.0)
    p.sort_by_cell(frame, (2, 3))
    np.testing.assert_array_equal(p.x, [0.2, 0.7, 2.7, 0.2])


@pytest.mark.parametrize("name", ["numpy", "taichi"])
def test_engines_accept_no_parcels(name):
    frame = GridFrame(0.01, 0.01, 0.005, 0.005)
    width = np.full((3, 4), 1e-3)
    engine = engine_for(name, frame, width, MppicParams())
    engine.set_parcels(Parcels.empty())
    assert np.all(engine.moments().volume_fraction == 0) and engine.max_speed() == 0.0
    engine.begin_step(np.zeros((3, 5)), np.zeros((4, 4)), np.zeros((3, 4)))
    loop = engine.substeps(1e-3, 2, 0.0)
    engine.commit()
    assert engine.parcels().n == 0 and loop.outflow == 0.0
    assert np.all(loop.force_x == 0) and np.all(loop.force_z == 0) and np.all(loop.beta_x == 0)
