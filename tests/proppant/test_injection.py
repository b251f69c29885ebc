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


def _screen_run(width, room, steps=100):
    """An inlet at cell (10, 20) emitting 6.6 % slurry into cells with the given room; returns
    (injector, placed batches, scheduled solid volume, room left)."""
    inj = Injector((Port("point", x=0.205, depth=0.105),), FRAME, width, (SAND,), [20.0],
                   rate=lambda t0, t1: 3.79e-4, loadings=lambda t: [(0, 0.065845)], rng=np.random.default_rng(7))
    room = room.copy()
    batches, t = [], 0.0
    for _ in range(steps):
        batches.append(inj.emit(t, t + 1e-3, room=room, width=width))
        t += 1e-3
    return inj, batches, 0.065845 * 3.79e-4 * t, room


def test_inlet_in_packed_cells_holds_everything_back_with_the_balance_exact():
    inj, batches, scheduled, _ = _screen_run(WIDTH, np.zeros_like(WIDTH))
    assert sum(b["x"].size for b in batches) == 0
    assert inj.screened_out + inj.owed_volume() == pytest.approx(scheduled, rel=1e-12)
    assert inj.screened_out > 0.9 * scheduled


def test_inlet_walled_in_by_closed_cells_fills_its_room_then_screens_out():
    width = np.zeros_like(WIDTH)
    width[10, 20] = 5e-3  # a single open cell: every parcel's bilinear weight lies on it
    capacity = 0.3 * 0.065845 * 3.79e-4 * 0.1  # room for 30 % of the scheduled solids
    room = np.zeros_like(width)
    room[10, 20] = capacity
    inj, batches, scheduled, left = _screen_run(width, room)
    placed = sum(batch_solid_volume(b) for b in batches)
    parcel = 20 * np.pi / 6 * 6e-4**3  # largest parcel of the 300-600 um class
    assert capacity - parcel < placed <= capacity * (1 + 1e-12)
    assert left[10, 20] == pytest.approx(capacity - placed, rel=1e-9, abs=1e-18)
    assert placed + inj.screened_out + inj.owed_volume() == pytest.approx(scheduled, rel=1e-12)
    # nothing held back while the room lasted: the emitted parcels are the first ones scheduled
    assert inj.screened_out == pytest.approx(scheduled - placed - inj.owed_volume(), rel=1e-12)


def test_room_never_overfilled_through_bilinear_spill():
    room = np.full_like(WIDTH, 1e-12)  # neighbours nearly packed
    room[10, 20] = 1e-5
    inj, batches, scheduled, left = _screen_run(WIDTH, room, steps=20)
    assert np.all(left >= -1e-24)
    assert sum(batch_solid_volume(b) for b in batches) + inj.screened_out + inj.owed_volume() \
        == pytest.approx(scheduled, rel=1e-12)


def test_a_zero_length_step_is_a_clear_error():
    from pathlib import Path

    from hfgpu import SimulationError, load_scene
    from hfgpu.proppant.engine_setup import proppant_engine_setup
    from hfgpu.proppant.simulator import ProppantSimulation

    scene = load_scene(Path(__file__).resolve().parents[2] / "hfgpu" / "scenes" / "settling_stokes.toml")
    sim = ProppantSimulation(proppant_engine_setup(scene))
    with pytest.raises(SimulationError, match="zero-length time step"):
        sim.step(limit=0.0)


def test_jet_inlet_momentum_and_parcel_speed():
    """A jet inlet (Port.jet): the slurry enters at Q_inlet / A (A = its cells' width x dz for an x-jet); the
    fluid carries (1 - c) Q_cell U into the face downstream of each of its cells; the grains start at U."""
    q, c = 3.79e-4, 0.065845
    ports = (Port("segment", x=0.0, depth=0.07, x_end=0.0, depth_end=0.095, jet="+x"),  # cells 7, 8, 9
             Port("point", x=0.2, depth=0.1, jet="-z"), Port("point", x=0.3, depth=0.1))
    inj = Injector(ports, FRAME, WIDTH, (SAND,), [20.0], rate=lambda t0, t1: q,
                   loadings=lambda t: [(0, c)], rng=np.random.default_rng(5))
    speed = q / 3 / (3 * FRAME.dz * 5e-3)
    mx, mz = inj.jet_momentum(0.0, 0.1)
    assert mx.shape == (20, 41) and mz.shape == (21, 40)
    np.testing.assert_allclose(mx[7:10, 1], (1 - c) * q / 3 / 3 * speed, rtol=1e-13)
    assert np.count_nonzero(mx) == 3
    point_speed = q / 3 / (FRAME.dx * 5e-3)
    assert mz[10, 20] == pytest.approx(-(1 - c) * q / 3 * point_speed, rel=1e-13)  # -z: the cell's upper face
    assert np.count_nonzero(mz) == 1  # the third inlet has no jet
    batch = inj.emit(0.0, 0.5)
    left, point = batch["x"] < 0.01, np.abs(batch["x"] - 0.2) < 0.01
    assert left.any() and point.any()
    np.testing.assert_allclose(batch["u"][left], speed, rtol=1e-13)
    np.testing.assert_allclose(batch["v"][point], -point_speed, rtol=1e-13)
    rest = ~left & ~point
    assert np.all(batch["u"][rest] == 0.0) and np.all(batch["v"][~point] == 0.0)
