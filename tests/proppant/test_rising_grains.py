"""Grains rising in dense cells on the five-layer base case (issue 34's check; bench/rising_grains.py), seed 1,
with the parcels taking the last fluid step's pressure and the mean of the last two ([mppic] grain_pressure).

Measured (docs/proppant-closures.md, "Pressure the grains take"): "last" 1 054 parcel-snapshots faster than 1 mm/s
upward in cells at theta_p >= 0.5, the fastest 106 mm/s; "two-step" 25, the fastest 3.0 mm/s; "two-step" with
damping_scheme "relaxation" 1, 1.2 mm/s."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from hfgpu import load_scene, run
from hfgpu.scene_text import edit_scene

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
from rising_grains import rising  # noqa: E402


@pytest.mark.slow
def test_the_two_step_pressure_keeps_dense_cells_from_lifting_their_grains(tmp_path):
    """With "two-step" at most 200 rising parcel-snapshots and none faster than 10 mm/s; with "last" the fastest
    is more than 10 times faster (a pressure that changes sign every fluid step lifts them); with "two-step" and
    the relaxation damping at most 10, none faster than 5 mm/s."""
    counts = {}
    for name, changes in (("last", {}), ("two-step", {"mppic.grain_pressure": "two-step"}),
                          ("both", {"mppic.grain_pressure": "two-step", "mppic.damping_scheme": "relaxation"})):
        scene = edit_scene(load_scene(ROOT / "hfgpu" / "scenes" / "five_layer.toml"), {"run.seed": 1, **changes})
        path = tmp_path / f"{name}.h5"
        run(scene, path, progress=False)
        counts[name] = rising(path, dense=0.5, speed=1e-3)
    assert counts["two-step"]["up"] <= 200 and counts["two-step"]["fastest"] < 1e-2
    assert counts["last"]["fastest"] > 10 * counts["two-step"]["fastest"]
    assert counts["both"]["up"] <= 10 and counts["both"]["fastest"] < 5e-3
