"""Sieve classes (ASTM E11 openings) and seeded size distributions."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu.proppant.sieve import make_distribution, sieve_range


@pytest.mark.parametrize("label, low, high", [
    ("30/50", 0.300e-3, 0.600e-3), ("40/70", 0.212e-3, 0.425e-3), ("100 mesh", 0.106e-3, 0.212e-3),
    ("20/40", 0.425e-3, 0.850e-3), ("70/140", 0.106e-3, 0.212e-3),
])
def test_sieve_ranges(label, low, high):
    assert sieve_range(label) == pytest.approx((low, high), rel=1e-12)


@pytest.mark.parametrize("label", ["50/30", "31/50", "fine", "30-50"])
def test_bad_sieve_labels(label):
    with pytest.raises(ValueError):
        sieve_range(label)


@pytest.mark.parametrize("kind", ["uniform", "normal"])
def test_distribution_is_within_range_seeded_and_has_its_mean_volume(kind):
    dist = make_distribution(kind, *sieve_range("30/50"))
    a = dist.sample(np.random.default_rng(7), 200_000)
    b = dist.sample(np.random.default_rng(7), 200_000)
    np.testing.assert_array_equal(a, b)
    assert a.min() >= 0.300e-3 and a.max() <= 0.600e-3
    assert np.mean(a) == pytest.approx(0.45e-3, rel=3e-3)  # symmetric about the mid-range
    assert np.mean(np.pi / 6 * a**3) == pytest.approx(dist.mean_particle_volume(), rel=5e-3)


def test_uniform_mean_volume_closed_form_and_normal_spread():
    d0, d1 = 0.2e-3, 0.4e-3
    uniform = make_distribution("uniform", d0, d1)
    # E[pi d^3/6] for d ~ U(d0, d1) = pi/24 (d1^4 - d0^4)/(d1 - d0)
    assert uniform.mean_particle_volume() == pytest.approx(np.pi / 24 * (d1**4 - d0**4) / (d1 - d0))
    normal = make_distribution("normal", d0, d1)
    sample = normal.sample(np.random.default_rng(1), 100_000)
    # std of a normal with sigma = range/6 truncated at +-3 sigma: sigma sqrt(1 - 6 phi(3)/(2 Phi(3) - 1))
    from scipy.stats import norm
    expected = (d1 - d0) / 6 * np.sqrt(1 - 2 * 3 * norm.pdf(3) / (2 * norm.cdf(3) - 1))
    assert np.std(sample) == pytest.approx(expected, rel=1e-2)
