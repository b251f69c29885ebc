"""The Taichi momentum predictor (kernels/momentum.py) equals the NumPy reference (CPU backend, float64)."""

import numpy as np
import pytest

from hfgpu.proppant.fluid import momentum_predictor
from hfgpu.proppant.momentum import momentum_predictor as reference


def random_fields(rng, nz, nx, closed_fraction):
    """Random old/new widths with some closed cells, fractions, viscosities, velocities and forces."""
    def width():
        w = rng.uniform(0.5e-3, 5e-3, (nz, nx))
        w[rng.random((nz, nx)) < closed_fraction] = 0.0
        return w

    return dict(u0=rng.normal(0.0, 0.3, (nz, nx + 1)), v0=rng.normal(0.0, 0.3, (nz + 1, nx)),
                p=rng.normal(0.0, 1e3, (nz, nx)), width0=width(), theta_f0=rng.uniform(0.4, 1.0, (nz, nx)),
                width=width(), theta_f=rng.uniform(0.4, 1.0, (nz, nx)),
                mu=rng.uniform(1e-3, 2.0, (nz, nx)), force_x=rng.normal(0.0, 50.0, (nz, nx + 1)),
                force_z=rng.normal(0.0, 50.0, (nz + 1, nx)), rho=1030.0, dx=0.013, dz=0.007, dt=3e-3)


@pytest.mark.parametrize("wall_friction", ["laminar", "dean"])
@pytest.mark.parametrize("nz, nx, closed", [(9, 13, 0.0), (17, 11, 0.25), (1, 7, 0.1), (6, 1, 0.0)])
def test_kernel_matches_numpy(nz, nx, closed, wall_friction):
    rng = np.random.default_rng(nz * 100 + nx)
    fields = random_fields(rng, nz, nx, closed)
    if wall_friction == "dean":
        # gap Reynolds numbers rho |U| w / mu from ~1 to ~1e4: both branches of max(1, 0.073 Re^0.75 / 12)
        fields["mu"] = np.exp(rng.uniform(np.log(1e-4), np.log(1e-2), (nz, nx)))
        fields["wall_friction"] = "dean"
    # cell Peclet numbers span both branches of the power law (|P| < 10 and A = 0 beyond)
    expected = reference(**fields)
    got = momentum_predictor("taichi")(**fields)
    for name, e, g in zip(("u*", "v*", "d_u", "d_v"), expected, got):
        assert g.shape == e.shape, name
        scale = np.max(np.abs(e)) + 1e-300
        assert np.max(np.abs(g - e)) <= 1e-12 * scale, name
    if nx > 1:
        assert np.any(expected[0] != 0.0)
    if nz > 1:
        assert np.any(expected[1] != 0.0)


def test_numpy_backend_is_reference():
    rng = np.random.default_rng(3)
    fields = random_fields(rng, 5, 6, 0.2)
    for e, g in zip(reference(**fields), momentum_predictor("numpy")(**fields)):
        np.testing.assert_array_equal(g, e)
