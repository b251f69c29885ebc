"""Synthetic results files for the closure tests: a proppant-only box scene and hand-made snapshots."""

from __future__ import annotations

import numpy as np

from hfgpu.io.results import ResultsWriter
from hfgpu.records import FractureSnapshot, GridFrame, ProppantSnapshot
from hfgpu.scene import load_scene

BOX = """
[run]
end_time = "1 s"
physics = ["proppant"]
[fluid]
viscosity = "1 cP"
[mesh]
cell_size = "1 cm"
[output]
every = "0.5 s"
[geometry]
kind = "box"
length = "6 cm"
height = "4 cm"
width = "5 mm"
[[proppant]]
name = "sand"
density = "2650 kg/m**3"
diameter = "200 um"
{extra_class}
[mppic]
backend = "numpy"
{closure}
"""

FRAME = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)
NZ, NX = 4, 6


def box_text(closure: str = "", extra_class: str = "") -> str:
    """The box scene's TOML, with ``closure`` lines (e.g. a ``[closure]`` table) and keys of the first class."""
    return BOX.format(closure=closure, extra_class=extra_class)


def parcels(x, z, diameter, particles, *, class_id=0, moving=False) -> dict[str, np.ndarray]:
    """Parcel arrays at (x, z) [m] (all packed, or all settling at 1 cm/s with ``moving``)."""
    x, z = np.atleast_1d(np.asarray(x, dtype=float)), np.atleast_1d(np.asarray(z, dtype=float))
    n = x.size
    full = lambda v: np.broadcast_to(np.asarray(v, dtype=float), (n,)).copy()  # noqa: E731
    return {"x": x, "z": z, "u": np.zeros(n), "v": full(0.01 if moving else 0.0), "radius": full(diameter) / 2,
            "density": np.full(n, 2650.0), "particles": full(particles), "state": np.zeros(n, dtype=np.int32),
            "class_id": np.broadcast_to(np.asarray(class_id, dtype=np.int32), (n,)).copy()}


def join(*groups: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    return {k: np.concatenate([g[k] for g in groups]) for k in groups[0]}


def snapshot(parcel_arrays: dict[str, np.ndarray], time: float = 1.0, width: float = 0.005) -> ProppantSnapshot:
    grid = {"volume_fraction": np.zeros((NZ, NX)), "pressure": np.full((NZ, NX), 2e5),
            "width": np.full((NZ, NX), width)}
    return ProppantSnapshot(time=time, frame=FRAME, parcels=parcel_arrays, grid=grid)


def cell_centres() -> tuple[np.ndarray, np.ndarray]:
    """(x, z) of every cell, flattened, row-major."""
    x, z = FRAME.centres(NZ, NX)
    gx, gz = np.meshgrid(x, z)
    return gx.ravel(), gz.ravel()


def write_results(path, text: str, snaps: list[ProppantSnapshot],
                  fracture: list[FractureSnapshot] = ()) -> None:
    """A complete results file of scene ``text`` holding ``snaps`` (and fracture snapshots)."""
    writer = ResultsWriter(path, load_scene(text))
    for snap in fracture:
        writer.fracture_snapshot(snap)
    for snap in snaps:
        writer.proppant_snapshot(snap)
    writer.close("complete", {})
