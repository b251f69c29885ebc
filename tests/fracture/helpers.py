"""Shared helpers of the fracture-engine tests: scene builders (records go to hfgpu.records.MemorySink)."""

from __future__ import annotations

from pathlib import Path

from hfgpu.scene import load_scene

SCENES = Path(__file__).resolve().parents[2] / "hfgpu" / "scenes"


def scene_text(end_time="100 s", rate="1e-3 m**3/s", cell="2 m", E="30 GPa", nu=0.25, K="0.1 MPa*m**0.5",
               CL="0 m/s**0.5", mu="1 Pa*s", every=None, schedule=None, layers="", fracture=""):
    """A small fracture scene as TOML text (SI strings)."""
    schedule = schedule or f'[{{ until = "{end_time}", rate = "{rate}" }}]'
    every = every or end_time
    return f"""
[run]
end_time = "{end_time}"
[rock]
youngs_modulus = "{E}"
poisson_ratio = {nu}
toughness = "{K}"
leakoff_coefficient = "{CL}"
min_stress = "10 MPa"
{layers}
[fluid]
viscosity = "{mu}"
[injection]
depth = "500 m"
schedule = {schedule}
[mesh]
cell_size = "{cell}"
[output]
every = "{every}"
{fracture}
"""


def scene(**kw):
    return load_scene(scene_text(**kw))
