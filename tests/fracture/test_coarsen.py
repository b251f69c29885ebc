"""Coarsening (coarsen.py), 3 x 3 (odd factors) and 2x: fluid volume conserved to round-off, source cell kept
at a coarse centre, fields carried by the stated rules (checked against brute-force overlaps), the sub-grid
front carried with its wetted area."""

from __future__ import annotations

import numpy as np
import pytest

from hfgpu.fracture.coarsen import coarsen


def _cells(rng, nz, nx, fill, shift):
    iz, ix = np.nonzero(rng.random((nz, nx)) < fill)
    return ix + shift[0], iz + shift[1]


@pytest.mark.parametrize("factor", [3, 5])
@pytest.mark.parametrize("seed", range(4))
def test_volume_conserved_and_fields_carried_as_stated(seed, factor):
    rng = np.random.default_rng(seed)
    ix, iz = _cells(rng, 23, 31, 0.6, (-17, -4 - seed))
    source = (int(ix[ix.size // 2]), int(iz[ix.size // 2]))
    dx, dz = 0.8, 1.7
    w = rng.uniform(1e-4, 3e-3, ix.size)
    p = rng.uniform(1e6, 2e6, ix.size)
    tau = rng.uniform(0.0, 100.0, ix.size)
    c = coarsen(ix, iz, source=source, factor=factor)
    # sum w dA is unchanged: the coarse cell area is factor^2 dx dz.
    assert np.sum(c.width(w)) * factor**2 * dx * dz == pytest.approx(np.sum(w) * dx * dz, rel=1e-14)
    assert np.sum(c.total(w)) == pytest.approx(np.sum(w), rel=1e-14)
    half = (factor - 1) // 2
    for k in range(c.ix.size):
        # Brute force: children are the fine cells within half a coarse cell of the coarse centre.
        centre_x, centre_z = source[0] + factor * c.ix[k], source[1] + factor * c.iz[k]
        children = (np.abs(ix - centre_x) <= half) & (np.abs(iz - centre_z) <= half)
        assert np.array_equal(children, c.parent == k)
        assert c.fill[k] == children.sum() / factor**2
        assert c.width(w)[k] == pytest.approx(w[children].sum() / factor**2, rel=1e-14)
        assert c.mean(p)[k] == pytest.approx(p[children].mean(), rel=1e-14)
        assert c.earliest(tau)[k] == tau[children].min()
    assert np.unique(np.stack([c.ix, c.iz]), axis=1).shape[1] == c.ix.size   # coarse cells distinct


def test_source_cell_is_the_centre_of_coarse_cell_zero():
    k = np.arange(-8, 9)
    x, z = np.meshgrid(k + 40, k - 3)                  # a 17 x 17 square around source (40, -3)
    c = coarsen(x.ravel(), z.ravel(), source=(40, -3))
    own = c.parent[(x.ravel() == 40) & (z.ravel() == -3)][0]
    assert (c.ix[own], c.iz[own]) == (0, 0)
    block = c.parent == own
    assert set(zip(x.ravel()[block].tolist(), z.ravel()[block].tolist())) == {
        (40 + a, -3 + b) for a in (-1, 0, 1) for b in (-1, 0, 1)}
    # Half-width 8: coarse 0, ±1, ±2 are full (offsets up to 7), coarse ±3 holds one fine row (offset 8).
    assert c.ix.min() == -3 and c.ix.max() == 3 and c.iz.min() == -3 and c.iz.max() == 3
    assert np.all(c.fill[(np.abs(c.ix) <= 2) & (np.abs(c.iz) <= 2)] == 1.0)
    assert np.all(c.fill[(np.abs(c.ix) == 3) & (np.abs(c.iz) < 3)] == 3 / 9)
    assert np.all(c.fill[(np.abs(c.ix) == 3) & (np.abs(c.iz) == 3)] == 1 / 9)


def test_twice_coarsened_volume_is_still_conserved():
    rng = np.random.default_rng(7)
    ix, iz = _cells(rng, 60, 60, 0.8, (-30, -30))
    w = rng.uniform(0.0, 1e-3, ix.size)
    first = coarsen(ix, iz)
    second = coarsen(first.ix, first.iz)
    assert np.sum(second.width(first.width(w))) * 81 == pytest.approx(np.sum(w), rel=1e-14)


@pytest.mark.parametrize("args, message", [
    (dict(ix=[0, 1], iz=[0, 1], factor=4), "factor = 4; must be 2 or an odd integer >= 3"),
    (dict(ix=[0, 1], iz=[0, 1], factor=1), "factor = 1"),
    (dict(ix=[0, 0], iz=[5, 5]), "repeated cells"),
    (dict(ix=[0.0], iz=[0.0]), "integer arrays"),
    (dict(ix=[0, 1], iz=[0]), "equal length"),
    (dict(ix=[], iz=[]), "non-empty"),
])
def test_bad_input_is_named(args, message):
    with pytest.raises(ValueError, match=message):
        coarsen(np.asarray(args.pop("ix")), np.asarray(args.pop("iz")), **args)


def test_field_of_wrong_length_is_rejected():
    c = coarsen(np.array([0, 1, 2]), np.array([0, 0, 0]))
    with pytest.raises(ValueError, match=r"shape \(3,\)"):
        c.width(np.ones(2))


@pytest.mark.parametrize("seed", range(3))
def test_factor_two_carries_by_area_overlap(seed):
    """2x: each fine cell's area goes to the coarse cells it overlaps (coarse cell K spans fine offsets
    2K - 1 .. 2K + 1 from the source; odd offsets are cut in half), checked against the overlap of the two
    cells' intervals; fluid volume and covered area are conserved to round-off."""
    rng = np.random.default_rng(seed)
    ix, iz = _cells(rng, 19, 25, 0.7, (-11, -8 - seed))
    source = (int(ix[ix.size // 2]), int(iz[ix.size // 2]))
    w = rng.uniform(1e-4, 3e-3, ix.size)
    p = rng.uniform(1e6, 2e6, ix.size)
    tau = rng.uniform(0.0, 100.0, ix.size)
    c = coarsen(ix, iz, source=source, factor=2)
    assert np.sum(c.width(w)) * 4 == pytest.approx(np.sum(w), rel=1e-14)
    assert np.sum(c.fill) * 4 == pytest.approx(ix.size, rel=1e-14)

    def overlap(fine, coarse):   # length of [fine - 1/2, fine + 1/2] inside [2 coarse - 1, 2 coarse + 1]
        return np.clip(np.minimum(fine + 0.5, 2 * coarse + 1) - np.maximum(fine - 0.5, 2 * coarse - 1), 0, None)

    for k in range(c.ix.size):
        share = overlap(ix - source[0], c.ix[k]) * overlap(iz - source[1], c.iz[k])
        inside = share > 0
        assert c.fill[k] == pytest.approx(share.sum() / 4, rel=1e-14)
        assert c.width(w)[k] == pytest.approx((share * w).sum() / 4, rel=1e-14)
        assert c.mean(p)[k] == pytest.approx((share * p).sum() / share.sum(), rel=1e-14)
        assert c.earliest(tau)[k] == tau[inside].min()


def test_factor_two_keeps_the_source_at_a_coarse_centre():
    """The source's fine cell lies wholly inside coarse cell (0, 0); its neighbours are split in half."""
    k = np.arange(-3, 4)
    x, z = np.meshgrid(k + 5, k - 2)
    c = coarsen(x.ravel(), z.ravel(), source=(5, -2), factor=2)
    centre = (c.ix == 0) & (c.iz == 0)
    source = np.flatnonzero((x.ravel() == 5) & (z.ravel() == -2))[0]
    assert set(c.parent[c.child == source]) == {int(np.flatnonzero(centre)[0])}
    assert c.fill[centre][0] == 1.0   # a 7 x 7 block covers coarse cells -1..1 wholly
    assert np.all(c.fill[(np.abs(c.ix) == 2) | (np.abs(c.iz) == 2)] < 1.0)


def _plane_front(angle, dx, dz, d0):
    """Fine cells behind the plane n.x = d0 (n at ``angle``), each wetted by its exact area behind it: (ix, iz,
    fill, normal)."""
    from hfgpu.fracture.tip_cells import wetted_fraction

    n = np.array([np.cos(angle), np.sin(angle)])
    iz, ix = (a.ravel() for a in np.mgrid[-13:14, -13:14])
    advance = d0 - (n[0] * ix * dx + n[1] * iz * dz)
    fill = wetted_fraction(advance, np.full(ix.size, n[0]), np.full(ix.size, n[1]), dx, dz)
    keep = fill > 0.0
    return ix[keep], iz[keep], fill[keep], n


@pytest.mark.parametrize("angle", [0.1, 0.3, np.pi / 4, 2.2])
def test_coarse_front_of_a_plane_front_through_a_3x3_merge(angle):
    """A plane front n.x = d0 across a fine grid: after a 3x3 merge the coarse cells' fill is the exact area
    behind the same plane (area is additive), the wetted area is carried to round-off, and the coarse advance
    is the plane's d0 - n.x_c at the coarse centres."""
    from hfgpu.fracture.coarsen import coarse_front
    from hfgpu.fracture.tip_cells import wetted_fraction

    dx, dz, d0 = 0.7, 1.1, 3.3
    ix, iz, fill, n = _plane_front(angle, dx, dz, d0)
    tip = fill < 1.0
    c = coarsen(ix, iz)
    fill_c, adv_c = coarse_front(c, ix, iz, fill, np.where(tip, n[0], 0.0), np.where(tip, n[1], 0.0), dx, dz)
    exact_adv = d0 - (n[0] * c.ix * 3 * dx + n[1] * c.iz * 3 * dz)
    exact = wetted_fraction(exact_adv, np.full(c.ix.size, n[0]), np.full(c.ix.size, n[1]), 3 * dx, 3 * dz)
    np.testing.assert_allclose(fill_c, exact, rtol=0, atol=1e-12)
    assert np.sum(fill_c) * 9 == pytest.approx(np.sum(fill), rel=1e-14)
    crossed = fill_c < 1.0
    assert crossed.any() and np.all(np.isnan(adv_c[~crossed]))
    np.testing.assert_allclose(adv_c[crossed], exact_adv[crossed], rtol=0, atol=1e-9)


@pytest.mark.parametrize("angle", [0.1, 0.3, np.pi / 4, 2.2])
def test_coarse_front_of_a_plane_front_through_a_2x_remesh(angle):
    """The same through the 2x remesh: a fine cell cut in half gives each half its mean wetted fraction, so the
    coarse fill is the plane's only to within that split (half a fine cell is an eighth of a coarse cell;
    measured at most 0.103, at angle 0.1), while the wetted area is carried to round-off and the advance
    reproduces the fill."""
    from hfgpu.fracture.coarsen import coarse_front
    from hfgpu.fracture.tip_cells import wetted_fraction

    dx, dz, d0 = 0.7, 1.1, 3.3
    ix, iz, fill, n = _plane_front(angle, dx, dz, d0)
    tip = fill < 1.0
    c = coarsen(ix, iz, factor=2)
    fill_c, adv_c = coarse_front(c, ix, iz, fill, np.where(tip, n[0], 0.0), np.where(tip, n[1], 0.0), dx, dz)
    exact_adv = d0 - (n[0] * c.ix * 2 * dx + n[1] * c.iz * 2 * dz)
    exact = wetted_fraction(exact_adv, np.full(c.ix.size, n[0]), np.full(c.ix.size, n[1]), 2 * dx, 2 * dz)
    assert np.sum(fill_c) * 4 == pytest.approx(np.sum(fill), rel=1e-14)
    inner = (np.abs(c.ix) <= 6) & (np.abs(c.iz) <= 6)   # wholly inside the fine block (offsets -13 .. 13)
    assert np.abs(fill_c - exact)[inner].max() < 0.125
    crossed = (fill_c < 1.0) & inner
    back = wetted_fraction(adv_c[crossed], np.full(crossed.sum(), n[0]), np.full(crossed.sum(), n[1]), 2 * dx,
                           2 * dz)
    np.testing.assert_allclose(back, fill_c[crossed], rtol=0, atol=1e-12)


def test_coarse_front_normal_from_the_dry_part_where_no_fine_cell_is_a_tip():
    """A coarse cell whose fine cells are wholly wetted or dry (the front on fine faces) takes its normal from
    its dry part: the left column of a 3 x 3 block wetted, the front a vertical line with normal +x."""
    from hfgpu.fracture.coarsen import coarse_front

    ix, iz = np.array([-1, -1, -1, 0]), np.array([-1, 0, 1, 0])   # the source cell (0, 0) and the left column
    c = coarsen(ix, iz)
    fill_c, adv_c = coarse_front(c, ix, iz, np.ones(4), np.zeros(4), np.zeros(4), 1.0, 1.0)
    assert fill_c[0] == pytest.approx(4 / 9, rel=1e-14)
    assert adv_c[0] == pytest.approx(-1 / 6, abs=1e-9)   # 1/2 + advance / 3 = 4/9
