"""hfgpu.proppant.analysis.alternation: the share of a bed's dense cells that are a local extreme of theta_p along
x, on fields drawn by hand."""

from __future__ import annotations

import numpy as np

from hfgpu.proppant.analysis import alternation


def test_a_checkerboard_alternates_everywhere_and_a_smooth_bed_nowhere():
    rows, columns = 4, 10
    k, i = np.indices((rows, columns))
    checkerboard = np.where((k + i) % 2 == 0, 0.61, 0.50)
    assert alternation(checkerboard) == ((rows * (columns - 2)), 1.0)
    ramp = np.tile(np.linspace(0.45, 0.6, columns), (rows, 1))
    assert alternation(ramp) == ((rows * (columns - 2)), 0.0)


def test_only_dense_cells_with_dense_neighbours_count_and_small_steps_do_not():
    theta = np.array([[0.0, 0.55, 0.61, 0.55, 0.2, 0.6, 0.57, 0.6, 0.58]])
    # dense cells with dense neighbours: i = 2 (a peak by 0.06), 6 (a dip by 0.03) and 7 (a peak by 0.02)
    n, share = alternation(theta)
    assert n == 3 and share == 1 / 3
    assert alternation(theta, by=0.1) == (3, 0.0)
    assert alternation(np.zeros((3, 5))) == (0, 0.0)
