"""Grains rising in dense cells on the five-layer base case (issue 34's check; bench/rising_grains.py), seed 1,
with the defaults ([mppic] grain_pressure "two-step", damping_scheme "relaxation") and with the parcels taking
the last fluid step's pressure under the implicit damping ("last", "implicit").

Measured (docs/proppant-closures.md, "Pressure the grains take"): the defaults 1 parcel-snapshot faster than
1 mm/s upward in cells at theta_p >= 0.5, at 1.2 mm/s; "last" with "implicit" 700, the fastest 103 mm/s."""

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
    """With the defaults at most 10 rising parcel-snapshots, none faster than 5 mm/s; with "last" and "implicit"
    the fastest is more than 10 times faster (a pressure that changes sign every fluid step lifts them)."""
    counts = {}
    for name, changes in (("default", {}),
                          ("last", {"mppic.grain_pressure": "last", "mppic.damping_scheme": "implicit"})):
        scene = edit_scene(load_scene(ROOT / "hfgpu" / "scenes" / "five_layer.toml"), {"run.seed": 1, **changes})
        path = tmp_path / f"{name}.h5"
        run(scene, path, progress=False)
        counts[name] = rising(path, dense=0.5, speed=1e-3)
    assert counts["default"]["up"] <= 10 and counts["default"]["fastest"] < 5e-3
    assert counts["last"]["fastest"] > 10 * counts["default"]["fastest"]
