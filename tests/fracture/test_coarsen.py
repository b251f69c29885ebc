"""3 x 3 coarsening (coarsen.py): fluid volume conserved to round-off, source cell kept at a coarse centre,
fields carried by the stated rules (checked against a brute-force loop over the children)."""

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
    (dict(ix=[0, 1], iz=[0, 1], factor=2), "factor = 2; must be an odd integer >= 3"),
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
