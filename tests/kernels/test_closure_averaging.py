"""The averaging family (kernels/closures/averaging.py): the Taichi twin of the own cell's volume fraction against
its NumPy reference, a sub-step of the Taichi engine against the NumPy engine under each averaging, and what the
moment reconstruction must do: a linear density read back, the interface cell's parcels seeing the fraction of
the part they fill, "basic" the cell's own parcels only."""

import numpy as np
import pytest

from hfgpu.kernels.closures import averaging
from hfgpu.kernels.runtime import ti
from hfgpu.proppant import particle_ops_numpy as ref
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

from .engine_step import particle_step
from .test_particles import assert_steps_agree, random_case

pytestmark = pytest.mark.usefixtures("taichi_cpu")
F1 = ti.types.ndarray(dtype=ti.f64, ndim=1)


@ti.kernel
def _own(volume: F1, vx: F1, vz: F1, ox: F1, oz: F1, cell: F1, moment: ti.i32, out: F1):
    for p in volume:
        out[p] = averaging.own_cell_fraction(volume[p], vx[p], vz[p], ox[p], oz[p], cell[p], moment)


@pytest.mark.parametrize("moment", [False, True])
def test_own_cell_fraction_twin_matches_numpy(moment):
    """Random sums and offsets, closed cells (volume 0) and reconstructions below 0 (clipped) included."""
    rng = np.random.default_rng(5)
    n = 4000
    volume = rng.uniform(0.0, 1e-6, n)
    vx, vz = rng.uniform(-0.5, 0.5, (2, n)) * volume
    ox, oz = rng.uniform(-0.5, 0.5, (2, n))
    cell = np.where(rng.random(n) < 0.1, 0.0, rng.uniform(1e-6, 4e-6, n))
    want = averaging.own_cell_fraction_numpy(volume, vx, vz, ox, oz, cell, moment)
    got = np.zeros(n)
    _own(volume, vx, vz, ox, oz, cell, int(moment), got)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0.0)
    assert np.all(want[cell == 0.0] == 0.0) and np.all(want >= 0.0)
    if moment:
        assert np.any(volume + 12.0 * (vx * ox + vz * oz) < 0.0)   # the clip was exercised


@pytest.mark.parametrize("name", averaging.AVERAGINGS)
def test_substep_twin_under_each_averaging(name):
    """One sub-step of the Taichi engine (CPU) against the NumPy engine on the random grid of test_particles
    (closed cells, parcels near walls): moments (the S, S_x, S_z sums included), exchange and parcel states to
    1e-12, states equal."""
    frame, width, parcels, fluid = random_case(seed=7)
    params = MppicParams(averaging=name, P_s=100.0)
    a, b = parcels.copy(), parcels.copy()
    taichi = particle_step("taichi", frame, width, a, fluid, params, substeps=2)
    numpy = particle_step("numpy", frame, width, b, fluid, params, substeps=2)
    assert_steps_agree((*taichi, a), (*numpy, b))


def _seen(x, z, volume, frame, width, name):
    """theta_p the parcels (x, z) of solid volumes ``volume`` see under averaging ``name`` (NumPy reference)."""
    parcels = Parcels.create(x, z, radius=1e-4, density=2650.0, particles=volume / (4 / 3 * np.pi * 1e-12))
    moments = ref.finish_moments(ref.moment_sums(parcels, frame, width), frame, width)
    zero = np.zeros((width.shape[0], width.shape[1] + 1)), np.zeros((width.shape[0] + 1, width.shape[1]))
    fields = ref.grid_fields(frame, width, *zero, np.zeros(width.shape), moments, MppicParams(averaging=name),
                             1000.0, 9.81)
    return ref.gather(parcels, frame, fields).volume_fraction


FRAME = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)   # cell (k, i) centred at ((i + 1/2) dx, (k + 1/2) dz)


def test_moment_reads_back_a_linear_density():
    """Parcels on a fine lattice of one cell carrying volumes theta_0 (1 + c o_z) dV: "moment" returns the
    linear density at each parcel (to the lattice's quadrature error: its second moment is (1 - 1/q^2) / 12,
    an error below 1e-3 theta_0 at q = 40), "basic" its mean theta_0."""
    q, c, theta0, w = 40, 1.2, 0.1, 2e-3
    width = np.full((3, 3), w)
    o = (np.arange(q) + 0.5) / q - 0.5
    ox, oz = (a.ravel() for a in np.meshgrid(o, o))
    dv = FRAME.dx * FRAME.dz * w / q ** 2
    x, z = 0.015 + ox * FRAME.dx, 0.015 + oz * FRAME.dz
    seen = _seen(x, z, theta0 * (1 + c * oz) * dv, FRAME, width, "moment")
    np.testing.assert_allclose(seen, theta0 * (1 + c * oz), rtol=0, atol=1e-3 * theta0)
    np.testing.assert_allclose(_seen(x, z, theta0 * (1 + c * oz) * dv, FRAME, width, "basic"), theta0,
                               rtol=1e-12)


def test_an_interface_cells_parcels_see_the_part_they_fill():
    """The lower half of the middle cell filled uniformly at theta_0, the cell below full, the one above empty:
    "moment" gives the parcels of the half cell 0.875 theta_0 at its centre (theta_0 / 2 x (1 + 12 x 1/4 x 1/4)),
    "dual" less than 0.7 theta_0 there (measured 0.61-0.64: it reads the empty cell above)."""
    q, theta0, w = 20, 0.06, 2e-3
    width = np.full((3, 1), w)
    frame = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)
    o = (np.arange(q) + 0.5) / q - 0.5
    ox, oz = (a.ravel() for a in np.meshgrid(o, o))
    half = oz > 0.0   # the lower half (depth grows with z)
    x = np.concatenate([0.005 + ox[half] * 0.01, 0.005 + ox * 0.01])
    z = np.concatenate([0.015 + oz[half] * 0.01, 0.025 + oz * 0.01])
    volume = np.full(x.size, theta0 * 0.01 * 0.01 * w / q ** 2)
    middle = np.arange(x.size) < half.sum()
    centre = middle & (np.abs(z - 0.0175) < 0.26 * 0.01 / q * 2)
    moment = _seen(x, z, volume, frame, width, "moment")
    assert moment[centre].mean() == pytest.approx(0.875 * theta0, rel=1e-9)   # the two rows either side
    assert np.all(_seen(x, z, volume, frame, width, "dual")[centre] < 0.7 * theta0)
