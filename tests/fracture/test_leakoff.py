"""Carter leak-off integrated exactly over a step (Eq. 29's C'/sqrt(t - tau) term)."""

import numpy as np
import pytest
from scipy.integrate import quad

from hfgpu.fracture.leakoff import (available_fraction, carter_cumulative, carter_demand, carter_volume,
                                    exposure_time)


@pytest.mark.parametrize("tau, t0, t1", [(0.0, 1.0, 3.0), (2.0, 1.0, 3.0), (0.5, 0.5, 0.6), (5.0, 1.0, 3.0)])
def test_carter_volume_matches_quadrature_of_the_rate(tau, t0, t1):
    c_prime = 3e-4
    expected = quad(lambda t: c_prime / np.sqrt(t - tau), max(t0, tau), t1)[0] if t1 > tau else 0.0
    assert carter_volume(np.array([c_prime]), np.array([tau]), t0, t1)[0] == pytest.approx(expected, rel=1e-7,
                                                                                         abs=1e-15)


def test_carter_volume_is_additive_over_sub_steps():
    c_prime, tau = np.array([1e-3]), np.array([0.3])
    edges = np.linspace(0.0, 7.0, 23)
    parts = sum(carter_volume(c_prime, tau, a, b)[0] for a, b in zip(edges[:-1], edges[1:]))
    assert parts == pytest.approx(2 * 1e-3 * np.sqrt(7.0 - 0.3), rel=1e-12)


def test_available_fraction_is_a_monotone_ramp_from_zero_to_one():
    w = np.array([-1e-6, 0.0, 1e-7, 5e-6, 1e-3])
    g, dg = available_fraction(w, np.full(5, 1e-6))
    assert g[1] == 0.0 and g[0] < 0.0 and np.all(np.diff(g) > 0)
    assert g[3] == pytest.approx(1 - np.exp(-5)) and g[4] == pytest.approx(1.0)
    h = 1e-12
    fd = (available_fraction(w + h, np.full(5, 1e-6))[0] - available_fraction(w - h, np.full(5, 1e-6))[0]) / (2 * h)
    np.testing.assert_allclose(dg, fd, rtol=1e-4)


@pytest.mark.parametrize("tau, filled, t0, t1", [(0.0, 2.0, 1.0, 3.0), (0.0, 2.0, 2.5, 3.0), (1.0, 4.0, 0.0, 2.0),
                                                 (0.5, 0.5, 1.0, 2.0)])
def test_partially_filled_cell_averages_the_rate_over_its_opening_times(tau, filled, t0, t1):
    """Opening time spread uniformly over [tau, filled]: the cell mean of Eq. 29's integral, by quadrature."""
    c_prime = 3e-4

    def point(tp):
        return quad(lambda t: c_prime / np.sqrt(t - tp), max(t0, tp), t1)[0] if t1 > tp else 0.0

    expected = quad(point, tau, filled)[0] / (filled - tau) if filled > tau else point(tau)
    got = carter_volume(np.array([c_prime]), np.array([tau]), t0, t1, np.array([filled]))[0]
    assert got == pytest.approx(expected, rel=1e-6, abs=1e-15)


@pytest.mark.parametrize("span", [0.0, 2.0])
@pytest.mark.parametrize("u", [0.3, 1.5, 2.0, 7.0])
def test_exposure_time_inverts_the_cumulative_carter_volume(u, span):
    c_prime = np.array([3e-4])
    leaked = carter_cumulative(c_prime, np.array([u]), np.array([span]))
    assert exposure_time(c_prime, leaked, np.array([span]))[0] == pytest.approx(u, rel=1e-10)


@pytest.mark.parametrize("filled", [None, 1.5])
def test_a_cell_that_leaked_its_full_demand_keeps_carters_integral(filled):
    c_prime, tau, t0, t1 = np.array([3e-4]), np.array([0.5]), 2.0, 3.0
    fill = None if filled is None else np.array([filled])
    leaked = carter_volume(c_prime, tau, 0.0, t0, fill)
    assert carter_demand(c_prime, tau, leaked, t0, t1, fill)[0] == pytest.approx(
        carter_volume(c_prime, tau, t0, t1, fill)[0], rel=1e-9)


@pytest.mark.parametrize("span", [0.0, 1.0, 4.0])
def test_a_cell_held_dry_continues_as_if_the_fluid_came_later(span):
    """A cell that opened at 0 but leaked only what a cell opened at d would have (its ramp held it back)
    continues on that later cell's Carter curve (Eq. 29 with tau + d), by quadrature of the rate."""
    c_prime, d, t0, t1 = 3e-4, 1.2, 3.0, 3.7

    def later(a, b):                       # leak-off per unit area over [a, b] with opening times d + [0, span]
        def point(tp):
            return quad(lambda t: c_prime / np.sqrt(t - tp), max(a, tp), b)[0] if b > tp else 0.0
        return quad(point, d, d + span)[0] / span if span > 0 else point(d)

    fill = np.array([span]) if span > 0 else None
    got = carter_demand(np.array([c_prime]), np.array([0.0]), np.array([later(0.0, t0)]), t0, t1, fill)[0]
    assert got == pytest.approx(later(t0, t1), rel=1e-6)


def test_no_leakoff_coefficient_no_demand():
    with np.errstate(all="raise"):
        got = carter_demand(np.zeros(3), np.zeros(3), np.zeros(3), 1.0, 2.0, np.ones(3))
    assert np.all(got == 0.0)
