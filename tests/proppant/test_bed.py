"""A settled bed: the packing limiter keeps theta_p <= 1.05 theta_cp, its height matches the solid volume at
close packing, its fluid is held by the slurry viscosity's wall friction, and its parcels come to rest (parcel
speeds < 1e-6 m/s; the surface grains thanks to bed friction, once the circulation of the clear fluid above has
decayed and the surface cells have consolidated: the box is settled for 16 s)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.proppant.analysis import row_profile
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from settled_bed import BOX  # noqa: E402


def settle(text: str) -> ProppantSimulation:
    sim = ProppantSimulation(proppant_engine_setup(load_scene(text)))
    end = sim.setup.end_time
    while sim.time < end - 1e-9:
        sim.step(limit=end - sim.time)
    return sim


@pytest.fixture(scope="module")
def settled() -> ProppantSimulation:
    return settle(BOX)


def test_settled_bed_is_packed_and_its_fluid_at_rest(settled):
    """theta_p <= 1.05 theta_cp; bed height = theta_0 H / theta_cp (solid volume at close packing); the fluid
    in the packed rows is at rest (< 1e-6 m/s: the drag of the packed parcels holds it, Eq. 9-10's wall friction
    adds to it) and so are its parcels (< 1e-6 m/s, median < 1e-9 m/s)."""
    sim = settled
    theta_cp = sim.params.theta_cp
    moments = sim.engine.moments()
    assert moments.volume_fraction.max() <= 1.05 * theta_cp
    profile = row_profile(moments.volume_fraction, sim.grid.width)
    height = 0.03 * 0.2 / theta_cp
    z = sim.grid.frame.z0 + sim.grid.frame.dz * np.arange(profile.size)
    assert np.all(profile[z < 0.03 - height - 2 * sim.grid.frame.dz] < 1e-3)
    packed = z > 0.03 - height + 2 * sim.grid.frame.dz
    assert np.all(profile[packed] > 0.8 * theta_cp)
    rows = np.flatnonzero(packed)
    assert np.abs(sim.fluid.u[rows]).max() < 1e-6 and np.abs(sim.fluid.v[rows[1:]]).max() < 1e-6
    speed = np.hypot(sim.parcels.u, sim.parcels.v)
    deep = sim.parcels.z > 0.03 - height + 2 * sim.grid.frame.dz
    assert np.median(speed[deep]) < 1e-9  # most of the bed is at rest ...
    assert speed[deep].max() < 1e-6  # ... and all of it below the surface rows (wall half cells included)


def test_settled_bed_parcels_at_rest(settled):
    """Every parcel, bed surface included, at < 1e-6 m/s once settled: the grains on the surface, dragged
    sideways by the decaying circulation of the clear fluid above, are held by bed friction (Coulomb, mu_b =
    0.543 x their submerged weight; without it they move at up to ~5e-5 m/s at t = 4 s). Two slow motions
    outlast the forming of the bed, both decaying: surface grains in a loose cell above a surface cell below
    friction_volume_fraction (not on a bed for bed friction) drift with the circulation, whose viscous decay
    rate is nu (12/w^2 + pi^2/L^2 + pi^2/H_clear^2) = 0.24 1/s (Eq. 9 wall friction of the 1 cm gap plus
    in-plane diffusion over the 1 cm x 2 cm clear fluid; measured 0.26 1/s at 8-14 s; the grains' speeds
    0.14-0.31 1/s), and grains in a surface cell still consolidating under Eq. 16 sink (e-folding ~3 s).
    This box (the quiet start, "lattice") is at rest, every parcel at 0 m/s, from 4 s. With random placement
    ("stratified"), over 30 seeds the maximum is above 1e-6 m/s in 9 at 4 s (up to 7.4e-5), 9 at 10 s and 1 at
    16 s (1.0e-6), the bed below its surface rows at 0 m/s in all
    (`python bench/settled_bed.py --seeds 30`; docs/proppant-closures.md, "Threshold of motion")."""
    speed = np.hypot(settled.parcels.u, settled.parcels.v)
    assert speed.max() < 1e-6


@pytest.mark.parametrize("backend_name", ["numpy", "taichi"])
def test_dense_cell_holds_parcels_in_its_wall_half(backend_name):
    """Below the centre of a bottom cell the bilinear weights (Eq. 37) stop changing, so the packing cap alone
    would let parcels there fall onto the wall (the ~7e-5 m/s compaction measured in the settled bed). In a
    dense cell (theta_p >= friction_volume_fraction, packed or not: a bottom cell at 0.585 let its wall half
    hop down at up to 5e-3 m/s; over 30 seeds of the settled bed its deep part was above 1e-6 m/s at 4 s in 8,
    up to 1.8e-3, and is in none now) they stay (the wall is its mirror image); in a loose one they settle."""
    from hfgpu.proppant.params import MppicParams
    from hfgpu.proppant.parcels import Parcels
    from hfgpu.records import GridFrame

    from ..kernels.engine_step import particle_step

    d, w, r = 5e-3, 2e-3, 0.225e-3
    frame = GridFrame(d, d, d / 2, d / 2)
    width = np.full((4, 2), w)
    params = MppicParams()
    u, v, p = np.zeros((4, 3)), np.zeros((5, 2)), np.zeros((4, 2))
    for theta, falls in ((1.02 * params.theta_cp, False), (0.9 * params.theta_cp, False),
                         (0.5 * params.theta_cp, True)):
        n = 200
        x = np.linspace(0.1 * d, 1.9 * d, n)
        z = np.full(n, 3.8 * d)  # lower half of the bottom row (centre 3.5 d, wall 4 d)
        per = theta * 2 * d * d * w / (4 / 3 * np.pi * r ** 3) / n
        parcels = Parcels.create(x, z, radius=r, density=2550.0, particles=per)
        parcels.v[:] = 0.05
        particle_step(backend_name, frame, width, parcels, dict(u=u, v=v, pressure=p), params, dt=1e-3)
        if falls:
            assert np.all(parcels.z > 3.8 * d)
        else:
            assert np.all(parcels.z == 3.8 * d) and np.all(parcels.v == 0.0)
