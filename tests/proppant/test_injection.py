"""Parcels from inlets and the initial suspension: exact solid volumes, ports on the grid, reproducibility."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu import SceneError
from hfgpu.proppant.config import Port, ProppantClass
from hfgpu.proppant.injection import (Injector, batch_solid_volume, initial_suspension, port_cells,
                                      ports_to_cells)
from hfgpu.proppant.sieve import make_distribution
from hfgpu.records import GridFrame

FRAME = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)
WIDTH = np.full((20, 40), 5e-3)
SAND = ProppantClass("sand", 2550.0, make_distribution("normal", 3e-4, 6e-4))
FIXED = ProppantClass("fixed", 2990.0, make_distribution("fixed", 2e-4, 2e-4), initial_volume_fraction=0.02)


def test_port_cells():
    k, i = port_cells(Port("point", x=0.123, depth=0.051), FRAME, WIDTH)
    assert (k.tolist(), i.tolist()) == ([5], [12])
    k, i = port_cells(Port("segment", x=0.0, depth=0.07, x_end=0.0, depth_end=0.095), FRAME, WIDTH)
    assert i.tolist() == [0, 0, 0] and k.tolist() == [7, 8, 9]
    k, i = port_cells(Port("annulus", x=0.2, depth=0.1, inner_radius=0.0, outer_radius=0.0151), FRAME, WIDTH)
    assert k.size == 4  # the four cells whose centres lie 0.0071 m from the point
    closed = WIDTH.copy()
    closed[5, 12] = 0.0
    with pytest.raises(SceneError, match="no open cell"):
        ports_to_cells((Port("point", x=0.123, depth=0.051),), FRAME, closed, "geometry.inlets")


def test_injected_solid_volume_is_the_schedules_and_split_by_share():
    ports = (Port("point", x=0.0, depth=0.055, share=1.0), Port("point", x=0.0, depth=0.155, share=3.0))
    q, c = 3.79e-4, 0.065845
    inj = Injector(ports, FRAME, WIDTH, (SAND,), [20.0], rate=lambda t0, t1: q,
                   loadings=lambda t: [(0, c)], rng=np.random.default_rng(3))
    emitted, t = 0.0, 0.0
    counts = np.zeros(2)
    for dt in np.full(200, 1e-3):
        batch = inj.emit(t, t + dt)
        emitted += batch_solid_volume(batch)
        counts += np.bincount((batch["z"] > 0.1).astype(int), weights=batch["particles"]
                              * np.pi / 6 * (2 * batch["radius"]) ** 3, minlength=2)
        t += dt
    # solids c Q t = emitted + what the inlets still owe (< one parcel each), to round-off
    assert emitted + inj.owed_volume() == pytest.approx(c * q * t, rel=1e-12)
    assert inj.owed_volume() < 2 * 20 * np.pi / 6 * 6e-4**3
    assert counts[1] / counts[0] == pytest.approx(3.0, rel=0.05)
    sources = inj.fluid_sources(0.0, 1.0)
    assert sources.sum() == pytest.approx((1 - c) * q, rel=1e-14)
    assert sources[15, 0] == pytest.approx(3 * sources[5, 0])


def test_emission_is_reproducible_with_the_seed():
    def run(seed):
        inj = Injector((Port("point", x=0.1, depth=0.1),), FRAME, WIDTH, (SAND,), [5.0],
                       rate=lambda t0, t1: 1e-4, loadings=lambda t: [(0, 0.05)],
                       rng=np.random.default_rng(seed))
        return inj.emit(0.0, 0.01)
    a, b, c = run(1), run(1), run(2)
    assert a["x"].size > 10
    np.testing.assert_array_equal(a["radius"], b["radius"])
    assert not np.array_equal(a["radius"][:5], c["radius"][:5])


def test_initial_suspension_is_uniform_and_exact():
    width = WIDTH.copy()
    width[:, 30:] = 2e-3
    width[0, 0] = 0.0
    batch = initial_suspension((FIXED, SAND), FRAME, width, [3.0, 1.0], np.random.default_rng(0))
    assert set(batch["class_id"].tolist()) == {0}
    volume = FRAME.dx * FRAME.dz * width
    assert batch_solid_volume(batch) == pytest.approx(0.02 * volume.sum(), rel=1e-12)
    i = np.floor(batch["x"] / FRAME.dx).astype(int)
    k = np.floor(batch["z"] / FRAME.dz).astype(int)
    per_cell = np.zeros_like(width)
    np.add.at(per_cell, (k, i), batch["particles"] * 4 / 3 * np.pi * batch["radius"] ** 3)
    np.testing.assert_allclose(per_cell, 0.02 * volume, rtol=1e-12, atol=1e-20)
