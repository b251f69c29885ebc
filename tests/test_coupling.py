"""Fracture -> proppant coupling (hfgpu/coupling.py): conservative resampling (sum w dA kept to round-off on
refined, coarsened and shifted grids), linear time interpolation, opening of cells as the footprint grows,
the proppant grid, and the HDF5 path matching the in-memory one."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from hfgpu.coupling import (_SLIVER, FractureHistory, bridging_risk, overlap_lengths, proppant_frame, resample_earliest,
                            resample_mean)
from hfgpu.fracture.coarsen import coarsen
from hfgpu.io.results import ResultsWriter
from hfgpu.records import FractureSnapshot, GridFrame

SRC = GridFrame(dx=0.3, dz=0.2, x0=1.0, z0=5.0)


def _snapshot(t, frame, width, leak=None, opened=None):
    width = np.asarray(width, dtype=float)
    is_open = width > 0.0
    leak = np.where(is_open, 1e-5, 0.0) if leak is None else leak
    opened = np.where(is_open, 0.0, np.nan) if opened is None else opened
    return FractureSnapshot(time=float(t), frame=frame, width=width, pressure=np.where(is_open, 1e6, 0.0),
                            leakoff_rate=np.asarray(leak, dtype=float), opening_time=opened)


def _field(rng, shape):
    """Positive widths with a closed rim (a fracture's bounding box plus its one-cell margin)."""
    w = rng.uniform(1e-4, 3e-3, shape)
    w[[0, -1], :] = 0.0
    w[:, [0, -1]] = 0.0
    return w


def _volume(w, frame):
    return float(np.sum(w)) * frame.dx * frame.dz


# --- conservative resampling ----------------------------------------------------------------------------

def _targets(shape):
    nz, nx = shape
    return {
        "refine x3": (GridFrame(SRC.dx / 3, SRC.dz / 3, SRC.x0 - SRC.dx / 3, SRC.z0 - SRC.dz / 3), (3 * nz, 3 * nx)),
        "coarsen x3": (GridFrame(3 * SRC.dx, 3 * SRC.dz, SRC.x0 + SRC.dx, SRC.z0 + SRC.dz), (nz // 3, nx // 3)),
        "shift": (GridFrame(SRC.dx, SRC.dz, SRC.x0 - 0.37 * SRC.dx, SRC.z0 + 0.61 * SRC.dz), (nz + 1, nx + 1)),
        "other size": (GridFrame(0.7 * SRC.dx, 1.3 * SRC.dz, SRC.x0 - 0.9 * SRC.dx, SRC.z0 - 0.4 * SRC.dz),
                       (int(nz / 1.3) + 2, int(nx / 0.7) + 3)),
    }


@pytest.mark.parametrize("case", ["refine x3", "coarsen x3", "shift", "other size"])
def test_resampling_conserves_volume_and_leakoff(case):
    rng = np.random.default_rng(1)
    w, q = _field(rng, (9, 12)), _field(rng, (9, 12)) * 1e-3
    frame, shape = _targets(w.shape)[case]
    wt = resample_mean(w, SRC, frame, shape)
    assert wt.shape == shape and np.all(wt >= 0.0)
    assert _volume(wt, frame) == pytest.approx(_volume(w, SRC), rel=1e-13)
    assert _volume(resample_mean(q, SRC, frame, shape), frame) == pytest.approx(_volume(q, SRC), rel=1e-13)


def test_refinement_copies_and_aligned_coarsening_matches_the_engines_merge():
    rng = np.random.default_rng(2)
    w = _field(rng, (9, 12))
    targets = _targets(w.shape)
    fine = resample_mean(w, SRC, *targets["refine x3"])
    np.testing.assert_allclose(fine, np.kron(w, np.ones((3, 3))), rtol=1e-13, atol=1e-18)
    # hfgpu.fracture.coarsen: all cells of the 9 x 12 box, blocks aligned on cell (1, 1)
    iz, ix = np.nonzero(np.ones(w.shape, dtype=bool))
    merge = coarsen(ix, iz, source=(1, 1))
    expected = np.zeros((3, 4))
    expected[merge.iz, merge.ix] = merge.width(w[iz, ix])
    np.testing.assert_allclose(resample_mean(w, SRC, *targets["coarsen x3"]), expected, rtol=1e-13)


def test_whole_cell_shift_moves_values_and_closed_cells_stay_exactly_zero():
    rng = np.random.default_rng(3)
    w = _field(rng, (6, 7))
    moved = resample_mean(w, SRC, GridFrame(SRC.dx, SRC.dz, SRC.x0 - 2 * SRC.dx, SRC.z0 - SRC.dz), (8, 10))
    np.testing.assert_allclose(moved[1:7, 2:9], w, rtol=1e-13)
    assert np.all(moved[:, :2] == 0.0) and np.all(moved[0] == 0.0) and np.all(moved[7:] == 0.0)
    # coinciding edges: no round-off sliver opens a neighbour of the fracture
    assert np.array_equal(moved[1:7, 2:9] > 0.0, w > 0.0)


@settings(max_examples=60, deadline=None)
@given(st.floats(0.05, 3.0), st.floats(0.05, 3.0), st.floats(-50.0, 50.0), st.floats(0.0, 0.999),
       st.integers(1, 9), st.integers(0, 3))
@example(2.0, 1.0, 0.0, 1.9082149292705877e-10, 1, 0)
def test_overlap_keeps_every_covered_source_length(h_src, h_dst, c_src, u, n_src, extra):
    """1-D: a target covering the source gives each source cell its full length (column sums = h_src); a
    target cell's overlaps sum to at most its length, within the sliver tolerance (an overlap shorter than
    _SLIVER x the smaller cell is dropped and its length returned to the column's other overlaps: hypothesis
    found u = 1.9e-10, h_src = 2, h_dst = 1, where that pushes one target cell 2e-10 over its length)."""
    left = c_src - 0.5 * h_src - u * h_dst
    n_dst = int(np.ceil((n_src * h_src + u * h_dst) / h_dst)) + extra
    a = overlap_lengths(c_src, h_src, n_src, left + 0.5 * h_dst, h_dst, n_dst)
    np.testing.assert_allclose(a.sum(axis=0), h_src, rtol=1e-12)
    assert np.all(a >= 0.0) and np.all(a.sum(axis=1) <= h_dst * (1 + 1e-12) + _SLIVER * min(h_src, h_dst))


def test_target_smaller_than_source_keeps_only_the_covered_part():
    w = np.ones((3, 3)) * 1e-3
    half = resample_mean(w, SRC, GridFrame(SRC.dx, SRC.dz, SRC.x0 + 1.5 * SRC.dx, SRC.z0), (3, 1))
    # the target column spans the right half of column 1 and the left half of column 2
    np.testing.assert_allclose(half, 1e-3, rtol=1e-14)
    assert _volume(half, SRC) == pytest.approx(_volume(w, SRC) / 3, rel=1e-14)


# --- history in time ---------------------------------------------------------------------------------------

def test_linear_in_time_field_is_interpolated_exactly_zero_before_and_last_after():
    rng = np.random.default_rng(4)
    a, b = _field(rng, (9, 12)), _field(rng, (9, 12))
    times = [1.0, 2.0, 4.5]
    history = FractureHistory([_snapshot(t, SRC, a + b * t, leak=(a + b * t) * 1e-3) for t in times])
    np.testing.assert_array_equal(history.times, times)
    frame, shape = _targets(a.shape)["other size"]
    for t in (1.0, 1.25, 2.0, 3.1, 4.5):
        width, leak, is_open = history.fields_at(t, frame, shape)
        exact = resample_mean(a + b * t, SRC, frame, shape)
        np.testing.assert_allclose(width, exact, rtol=1e-12, atol=1e-18)
        np.testing.assert_allclose(leak, exact * 1e-3, rtol=1e-12, atol=1e-21)
        assert np.array_equal(is_open, exact > 0.0)
    width, leak, is_open = history.fields_at(0.999, frame, shape)
    assert not width.any() and not leak.any() and not is_open.any() and width.shape == shape
    last = history.fields_at(4.5, frame, shape)
    for later, at_end in zip(history.fields_at(100.0, frame, shape), last):
        np.testing.assert_array_equal(later, at_end)
    np.testing.assert_array_equal(history.width_field(frame, shape)(100.0)[0], last[0])


def test_cells_narrower_than_min_width_are_closed_with_no_leakoff():
    """A cell opening between two snapshots passes through every width from 0 (linear in time): with
    min_width those below it are closed (width 0, no leak-off), the others unchanged."""
    rng = np.random.default_rng(5)
    a = _field(rng, (9, 12))
    w1 = np.where(a > 0.0, 2e-3, 0.0)
    history = FractureHistory([_snapshot(0.0, SRC, np.zeros_like(a), leak=np.zeros_like(a)),
                               _snapshot(1.0, SRC, w1, leak=w1 * 1e-4)])
    width, leak, is_open = history.fields_at(1e-3, SRC, a.shape, min_width=1e-6)  # 2 um where opening
    np.testing.assert_allclose(width, np.where(a > 0.0, 2e-6, 0.0), rtol=1e-12, atol=0.0)
    width, leak, is_open = history.fields_at(4e-4, SRC, a.shape, min_width=1e-6)  # 0.8 um: all closed
    assert not width.any() and not leak.any() and not is_open.any()
    assert history.fields_at(4e-4, SRC, a.shape)[2].sum() == np.count_nonzero(a > 0.0)  # default: open
    np.testing.assert_array_equal(history.width_field(SRC, a.shape, 1e-6)(4e-4)[0], width)


def test_growing_and_coarsened_footprint_opens_cells_and_keeps_volume():
    """t = 1: 5 x 5 fine cells open around the injection cell; t = 3: the engine's 3x coarser grid (blocks
    centred on the injection cell) with a 5 x 3 coarse footprint; the proppant grid is the fine one."""
    x_inj, z_inj, h = 10.0, 200.0, 0.5
    fine = GridFrame(h, h, x_inj - 3 * h, z_inj - 3 * h)                  # 7 x 7 box, injection at [3, 3]
    w0 = np.zeros((7, 7))
    w0[1:6, 1:6] = 2e-3
    t0 = np.where(w0 > 0, 0.0, np.nan)
    t0[[1, 1, 5, 5], [1, 5, 1, 5]] = 0.5                                   # corners opened later
    coarse = GridFrame(3 * h, 3 * h, x_inj - 3 * 3 * h, z_inj - 2 * 3 * h)  # 5 x 7 box, injection at [2, 3]
    w1 = np.zeros((5, 7))
    w1[1:4, 1:6] = 1e-3
    t1 = np.where(w1 > 0, 2.0, np.nan)
    t1[2, 3] = 0.0
    history = FractureHistory([_snapshot(1.0, fine, w0, opened=t0), _snapshot(3.0, coarse, w1, opened=t1)])
    assert history.injection_point() == (x_inj, z_inj)
    frame, shape = proppant_frame(history)
    assert (frame.dx, frame.dz) == (h, h)
    assert shape == (9 * 1 + 2, 15 + 2)                                   # 3 x 5 coarse cells + 1 fine margin
    ix, iz = (x_inj - frame.x0) / h, (z_inj - frame.z0) / h
    assert ix == round(ix) and iz == round(iz)                             # injection point at a cell centre
    for t, w, f in ((1.0, w0, fine), (3.0, w1, coarse)):
        width = history.fields_at(t, frame, shape)[0]
        assert _volume(width, frame) == pytest.approx(_volume(w, f), rel=1e-13)
    at_1, at_2 = history.fields_at(1.0, frame, shape)[2], history.fields_at(2.0, frame, shape)[2]
    assert at_1.sum() == 25 and at_2.sum() == 9 * 15                       # cells open as the footprint grows
    assert np.all(at_2[at_1])
    assert not at_2[0].any() and not at_2[:, 0].any() and not at_2[-1].any() and not at_2[:, -1].any()
    width = history.fields_at(2.0, frame, shape)[0]
    k, i = int(iz), int(ix) + 4                                            # outside the first footprint
    assert width[k, i] == pytest.approx(0.5 * 1e-3, rel=1e-13)
    opened = history.opening_time_on(frame, shape)
    assert opened[int(iz), int(ix)] == 0.0
    assert opened[k, i] == 2.0 and opened[int(iz) - 2, int(ix) - 2] == 0.5
    assert np.array_equal(np.isfinite(opened), at_2)
    sized, (nz, nx) = proppant_frame(history, cell_size=(0.4, 0.7), margin=2)
    for centre0, size, n, inj, half in ((sized.x0, 0.4, nx, x_inj, 7.5 * h), (sized.z0, 0.7, nz, z_inj, 4.5 * h)):
        assert (inj - centre0) / size == pytest.approx(round((inj - centre0) / size), abs=1e-9)
        # footprint +- half, plus 2 cells each side, and not one cell more
        assert centre0 - 0.5 * size <= inj - half - 2 * size < centre0 + 0.5 * size
        assert centre0 + (n - 1.5) * size < inj + half + 2 * size <= centre0 + (n - 0.5) * size


def test_earliest_opening_time_resampled():
    opened = np.array([[np.nan, 4.0, 3.0], [2.0, 1.0, np.nan]])
    frame = GridFrame(2 * SRC.dx, SRC.dz, SRC.x0 + 0.5 * SRC.dx, SRC.z0)  # columns (0, 1) and (2, none)
    np.testing.assert_array_equal(resample_earliest(opened, SRC, frame, (2, 2)), [[4.0, 3.0], [1.0, np.nan]])
    far = GridFrame(SRC.dx, SRC.dz, SRC.x0 + 10.0, SRC.z0)
    assert np.isnan(resample_earliest(opened, SRC, far, (2, 2))).all()


# --- results file -------------------------------------------------------------------------------------------

def _write_raw(path, snapshots):
    """The layout of docs/results-format.md, written with h5py directly."""
    with h5py.File(path, "w") as f:
        f.attrs.update(format="hfgpu-results", format_version=1, status="complete")
        group = f.create_group("fracture/snapshots")
        for k, s in enumerate(snapshots):
            g = group.create_group(f"{k:06d}")
            g.attrs.update(time=s.time, dx=s.frame.dx, dz=s.frame.dz, x0=s.frame.x0, z0=s.frame.z0)
            for name in ("width", "pressure", "leakoff_rate", "opening_time"):
                g.create_dataset(name, data=getattr(s, name))


def _write_sink(path, snapshots):
    with ResultsWriter(path, scene=None) as sink:
        for s in snapshots:
            sink.fracture_snapshot(s)


@pytest.mark.parametrize("write", [_write_raw, _write_sink])
def test_history_read_from_a_results_file_matches_memory(tmp_path, write):
    rng = np.random.default_rng(5)
    snaps = [_snapshot(1.0, SRC, _field(rng, (6, 8))),
             _snapshot(2.5, GridFrame(3 * SRC.dx, 3 * SRC.dz, SRC.x0 - SRC.dx, SRC.z0), _field(rng, (4, 5)))]
    path = tmp_path / "run.h5"
    write(path, snaps)
    memory, stored = FractureHistory(snaps), FractureHistory.from_results(path)
    np.testing.assert_array_equal(stored.times, memory.times)
    frame, shape = proppant_frame(memory, cell_size=0.25, source=(SRC.x0, SRC.z0))
    assert proppant_frame(stored, cell_size=0.25, source=(SRC.x0, SRC.z0)) == (frame, shape)
    for t in (0.5, 1.0, 1.7, 2.5, 9.0):
        for a, b in zip(memory.fields_at(t, frame, shape), stored.fields_at(t, frame, shape)):
            np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(memory.opening_time_on(frame, shape), stored.opening_time_on(frame, shape))


# --- diagnostics and bad input --------------------------------------------------------------------------------

def test_bridging_risk_flags_open_cells_narrower_than_factor_diameters():
    width = np.array([[0.0, 0.5e-3, 0.9e-3], [1.0e-3, 2e-3, -1e-6]])
    np.testing.assert_array_equal(bridging_risk(width, diameter=0.4e-3, factor=2.5),
                                  [[False, True, True], [False, False, False]])
    with pytest.raises(ValueError, match="diameter = 0.0"):
        bridging_risk(width, 0.0, 2.0)
    with pytest.raises(ValueError, match="factor = nan"):
        bridging_risk(width, 1e-3, float("nan"))


def test_equal_times_keep_the_last_snapshot_and_bad_input_is_named():
    one, two = _snapshot(1.0, SRC, np.full((2, 2), 1e-3)), _snapshot(1.0, SRC, np.full((2, 2), 2e-3))
    history = FractureHistory([one, two])
    assert len(history) == 1 and history.fields_at(1.0, SRC, (2, 2))[0][0, 0] == pytest.approx(2e-3)
    with pytest.raises(ValueError, match="snapshot 1 has time 0.5"):
        FractureHistory([one, _snapshot(0.5, SRC, np.ones((2, 2)))])
    with pytest.raises(ValueError, match="no fracture snapshots"):
        FractureHistory([])
    bad = FractureSnapshot(1.0, SRC, np.ones((2, 2)), np.ones((2, 2)), np.ones((2, 3)), np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"leakoff_rate of shape \(2, 3\)"):
        FractureHistory([bad]).fields_at(1.0, SRC, (2, 2))
    with pytest.raises(ValueError, match="cell_size = -1.0"):
        proppant_frame(history, cell_size=-1.0)
    with pytest.raises(ValueError, match="margin = -1"):
        proppant_frame(history, margin=-1)


def test_negative_widths_are_closed_with_no_leakoff():
    """The fracture engine has no contact constraint: a pinched cell may come out with w < 0. The proppant
    grid sees it closed (w = 0, leak-off 0), and negative leak-off rates are cut to 0."""
    frame = GridFrame(dx=1.0, dz=1.0, x0=0.0, z0=0.0)
    width = np.array([[1e-3, -8e-4], [2e-3, 5e-4]])
    leak = np.array([[1e-6, 2e-6], [-1e-9, 3e-6]])
    history = FractureHistory([_snapshot(1.0, frame, width, leak=leak, opened=np.zeros((2, 2)))])
    w, q, is_open = history.fields_at(2.0, frame, (2, 2))
    np.testing.assert_array_equal(w, [[1e-3, 0.0], [2e-3, 5e-4]])
    np.testing.assert_array_equal(q, [[1e-6, 0.0], [0.0, 3e-6]])
    np.testing.assert_array_equal(is_open, [[True, False], [True, True]])
