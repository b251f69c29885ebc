"""``hfgpu export --format vtk``: VTK XML files ParaView opens as time series (written with numpy, no VTK library).

For ``--out STEM`` (a ``.pvd`` suffix is dropped) it writes, with the pieces in ``STEM_vtk/``:

- ``STEM_fracture.pvd``: the fracture snapshots as ImageData (``.vti``), cell data ``width``, ``pressure``,
  ``leakoff_rate``, ``opening_time`` and the grid extras;
- ``STEM_proppant.pvd``: the proppant snapshots' grid fields as ImageData;
- ``STEM_parcels.pvd``: the parcels of each proppant snapshot as points (PolyData ``.vtp``, one vertex per
  parcel, point data ``u``, ``v``, ``radius``, ``density``, ``particles``, ``state``, ``class_id``);
- ``STEM_closure.vti``: the closure map (``propped_width``, ``conductivity``, ...).

Each ``.pvd`` lists its pieces with ``timestep`` = the snapshot time [s]; a series without snapshots is not
written. Coordinates: X = x, Y = -depth (elevation, so depth points down in ParaView), Z = 0; every value SI.
Arrays are inline base64 binary (little-endian, UInt64 byte-count header, uncompressed), the VTK XML layout.
Face-centred grid fields (``fluid_u``, ``fluid_v``) are left out (not cell data).
"""

from __future__ import annotations

import base64
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from ..records import GridFrame

_TYPES = {"f": "Float64", "i": "Int64", "u": "UInt64", "b": "UInt8"}


def _data_array(name: str, values: np.ndarray, components: int = 1) -> str:
    kind = values.dtype.kind
    array = values.astype({"f": "<f8", "i": "<i8", "u": "<u8", "b": "u1"}[kind])
    raw = array.tobytes()
    encoded = base64.b64encode(np.uint64(len(raw)).astype("<u8").tobytes() + raw).decode("ascii")
    return (f'<DataArray type="{_TYPES[kind]}" Name={quoteattr(name)} NumberOfComponents="{components}" '
            f'format="binary">{encoded}</DataArray>')


def _file(kind: str, body: str) -> str:
    return (f'<?xml version="1.0"?>\n<VTKFile type="{kind}" version="1.0" byte_order="LittleEndian" '
            f'header_type="UInt64">\n{body}\n</VTKFile>\n')


def image_data(frame: GridFrame, fields: dict[str, np.ndarray]) -> str:
    """A ``.vti`` document of (nz, nx) cell fields on ``frame``: X = x, Y = -depth (rows flipped so the first
    cell is the deepest, leftmost one, as VTK orders cells)."""
    nz, nx = next(iter(fields.values())).shape
    origin = (frame.x0 - frame.dx / 2, -(frame.z0 + (nz - 0.5) * frame.dz), 0.0)
    extent = f"0 {nx} 0 {nz} 0 0"
    arrays = "\n".join(_data_array(name, np.asarray(v)[::-1].ravel()) for name, v in fields.items())
    return _file("ImageData", f'<ImageData WholeExtent="{extent}" Origin="{origin[0]!r} {origin[1]!r} 0" '
                 f'Spacing="{frame.dx!r} {frame.dz!r} 1">\n<Piece Extent="{extent}">\n<CellData>\n{arrays}\n'
                 '</CellData>\n</Piece>\n</ImageData>')


def poly_points(parcels: dict[str, np.ndarray]) -> str:
    """A ``.vtp`` document of the parcels as vertices at (x, -depth, 0) with their fields as point data."""
    x = np.asarray(parcels["x"], dtype=np.float64)
    n = x.size
    points = np.column_stack([x, -np.asarray(parcels["z"], dtype=np.float64), np.zeros(n)]).ravel()
    data = "\n".join(_data_array(name, np.asarray(v)) for name, v in parcels.items() if name not in ("x", "z"))
    verts = (_data_array("connectivity", np.arange(n, dtype=np.int64)) + "\n"
             + _data_array("offsets", np.arange(1, n + 1, dtype=np.int64)))
    return _file("PolyData", f'<PolyData>\n<Piece NumberOfPoints="{n}" NumberOfVerts="{n}">\n<PointData>\n{data}\n'
                 f'</PointData>\n<Points>\n{_data_array("points", points, 3)}\n</Points>\n<Verts>\n{verts}\n'
                 '</Verts>\n</Piece>\n</PolyData>')


def _collection(entries: list[tuple[float, str]]) -> str:
    rows = "\n".join(f'<DataSet timestep="{t!r}" part="0" file={quoteattr(name)}/>' for t, name in entries)
    return ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f"<Collection>\n{rows}\n</Collection>\n</VTKFile>\n")


def write_vtk(results: Any, closure: Any, out: Path) -> list[Path]:
    """Write the series of the module docstring for ``--out`` ``out``; return the files written (the ``.pvd``
    files and the closure ``.vti``)."""
    stem = out.with_suffix("") if out.suffix == ".pvd" else out
    pieces = stem.with_name(stem.name + "_vtk")
    pieces.mkdir(parents=True, exist_ok=True)
    series: dict[str, list[tuple[float, str]]] = {"fracture": [], "proppant": [], "parcels": []}
    for n, snap in enumerate(results.fracture_snapshots):
        grid = {k: v for k, v in {"width": snap.width, "pressure": snap.pressure, "leakoff_rate": snap.leakoff_rate,
                                  "opening_time": snap.opening_time, **snap.extras}.items() if np.ndim(v) == 2}
        series["fracture"].append((snap.time, _write(pieces / f"fracture_{n:06d}.vti", image_data(snap.frame, grid))))
    for n, snap in enumerate(results.proppant_snapshots):
        shape = np.shape(snap.grid["width"])
        grid = {k: v for k, v in snap.grid.items() if np.shape(v) == shape}
        series["proppant"].append((snap.time, _write(pieces / f"proppant_{n:06d}.vti", image_data(snap.frame, grid))))
        series["parcels"].append((snap.time, _write(pieces / f"parcels_{n:06d}.vtp", poly_points(snap.parcels))))
    written = []
    for name, entries in series.items():
        if entries:
            target = stem.with_name(f"{stem.name}_{name}.pvd")
            target.write_text(_collection([(t, f"{pieces.name}/{piece}") for t, piece in entries]))
            written.append(target)
    if closure is not None:
        target = stem.with_name(f"{stem.name}_closure.vti")
        target.write_text(image_data(closure.frame, closure.fields))
        written.append(target)
    return written


def _write(path: Path, text: str) -> str:
    path.write_text(text)
    return path.name
