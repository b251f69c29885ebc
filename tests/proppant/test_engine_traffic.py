"""What crosses between host and device in a fluid step of the Taichi engine (CPU backend, where the count is
the same as on a GPU): a fixed number of launches and of host arrays, grid-sized, whatever the number of
parcels; the parcels themselves cross only when injected, snapshotted or checkpointed."""

from __future__ import annotations

import numpy as np

from hfgpu import load_scene
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

from .test_conservation import SLOT


def traffic(per_cell: int) -> tuple[list[int], list[int], list[int], int, int]:
    """Launches, host arrays and their bytes of each of 4 fluid steps of the slot with ``per_cell`` parcels
    per cell, the parcels at the end and the grid's node count."""
    scene = load_scene(SLOT.replace('backend = "numpy"', 'backend = "taichi"').replace(
        "parcels_per_cell = 4", f"parcels_per_cell = {per_cell}"))
    sim = ProppantSimulation(proppant_engine_setup(scene))
    engine = sim.engine
    launches, arrays, volume = [], [], []
    for _ in range(4):
        before = engine.launches, engine.transfers, engine.transfer_bytes
        sim.step()
        launches.append(engine.launches - before[0])
        arrays.append(engine.transfers - before[1])
        volume.append(engine.transfer_bytes - before[2])
    nz, nx = sim.grid.shape
    return launches, arrays, volume, engine.live, (nz + 1) * (nx + 1)


def test_a_fluid_step_is_a_fixed_number_of_launches_and_grid_sized_transfers():
    """Per fluid step with 4 sub-steps and an inlet: begin_step + stats, moments + read (the inlets' room),
    append, 4 sub-steps, read faces, moments + read (theta_p for the fluid): 12 launches and 13 host arrays
    (u, v, p, stats, cells, stats, the new parcels' 2, faces x 2, stats, cells, stats), the same for 4 and
    for 40 parcels per cell; the bytes are the grid's plus the injected parcels'. (The first step is retried
    once with a shorter dt: twice that.)"""
    few = traffic(4)
    many = traffic(40)
    substeps = 4
    for launches, arrays, volume, parcels, nodes in (few, many):
        assert launches[1:] == [substeps + 8] * 3 and launches[0] in (substeps + 8, 2 * (substeps + 8))
        assert arrays[1:] == [13] * 3
        grid_bytes = 8 * nodes * (18 + 2 * 7 + 3 + 18) + 8 * 3 * 8
        assert max(volume[1:]) < grid_bytes + 72 * parcels / 10
    assert many[3] > 8 * few[3]
    assert np.mean(many[2]) < 1.5 * np.mean(few[2])
