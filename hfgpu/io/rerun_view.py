"""A sink that logs a run to Rerun (rerun-sdk 0.41): saved to an .rrd file and/or streamed to a viewer.

Entities (timeline ``sim_time``, simulated seconds; 3-D space ``world`` with x along the fracture length,
y across it and z up, so depth d is drawn at z = -d)::

    world/fracture           Mesh3D of the open cells on the fracture plane y = 0, real size, coloured
                             by width (viridis, scaled to this snapshot's largest width)
    world/proppant/parcels   Points3D of the parcels on the plane y = 0, coloured by speed (viridis,
                             scaled to this snapshot's fastest parcel)
    fracture/area            [m^2] open area (cells with width > 0), at each snapshot
    fracture/net_pressure_at_injection   [Pa] p - sigma_0 at the injection cell, at each snapshot
    fracture/injected_volume, fracture/efficiency   [m^3], [-] stored / injected, every step
    proppant/injected, proppant/in_domain, proppant/outflow   [m^3] solid volumes, every fluid step
"""

from __future__ import annotations

import os
import socket
import sys
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import numpy as np

from ..errors import HfgpuError
from ..records import BalanceRecord, FractureSnapshot, ProppantSnapshot, SolidBalanceRecord

TIMELINE = "sim_time"
_SERIES = {
    "fracture/area": "fracture area [m^2]",
    "fracture/net_pressure_at_injection": "net pressure at injection [Pa]",
    "fracture/injected_volume": "injected volume [m^3]",
    "fracture/efficiency": "fluid efficiency [-]",
    "proppant/injected": "proppant injected [m^3]",
    "proppant/in_domain": "proppant in domain [m^3]",
    "proppant/outflow": "proppant outflow [m^3]",
}


def _colours(values: np.ndarray) -> np.ndarray:
    """RGB uint8 colours of ``values`` on the viridis map, scaled from 0 to the largest value."""
    from matplotlib import colormaps

    top = float(np.max(values)) if values.size else 0.0
    scaled = values / top if top > 0 else np.zeros_like(values)
    return (colormaps["viridis"](scaled)[..., :3] * 255).astype(np.uint8)


def cell_quads(x: np.ndarray, z: np.ndarray, dx: float, dz: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (4 per cell, on y = 0 with depth drawn downward) and triangles (2 per cell) of cells
    centred at (x, z) [m]."""
    corners = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    vx = x[:, None] + corners[None, :, 0] * dx
    vz = z[:, None] + corners[None, :, 1] * dz
    vertices = np.stack([vx, np.zeros_like(vx), -vz], axis=-1).reshape(-1, 3)
    base = 4 * np.arange(x.size)[:, None]
    triangles = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]], axis=1).reshape(-1, 3)
    return vertices, triangles.astype(np.uint32)


def viewer_problem(spawn: bool, connect: str | None, timeout: float = 2.0) -> str | None:
    """Why the viewer a run asks for cannot be reached, found before any work; None when it can. ``spawn``
    needs a display on Linux (DISPLAY or WAYLAND_DISPLAY); ``connect`` needs something listening at the URL's
    host and port (one TCP connection attempt, ``timeout`` seconds)."""
    if spawn and sys.platform.startswith("linux") and not (os.environ.get("DISPLAY")
                                                            or os.environ.get("WAYLAND_DISPLAY")):
        return "--view: no display (DISPLAY and WAYLAND_DISPLAY are unset) to show a Rerun viewer on"
    if connect is not None:
        url = urlsplit(connect.removeprefix("rerun+"))
        try:
            host, port = url.hostname, url.port
        except ValueError as exc:
            return f"--connect {connect!r}: {exc}"
        if not host or not port:
            return f"--connect {connect!r}: expected a URL such as rerun+http://127.0.0.1:9876/proxy"
        try:
            socket.create_connection((host, port), timeout=timeout).close()
        except OSError as exc:
            return f"--connect {connect}: nothing reachable at {host}:{port} ({exc.strerror or exc})"
    return None


class RerunRecorder:
    """Log the records of a run to Rerun: to the file ``rrd``, a spawned viewer (``spawn``) and/or a viewer or
    gRPC proxy already running at ``connect`` (a URL such as "rerun+http://127.0.0.1:9876/proxy", e.g. one
    started with ``rerun --serve-grpc`` on another machine)."""

    def __init__(self, scene: Any, *, rrd: str | Path | None = None, spawn: bool = False,
                 connect: str | None = None, application_id: str = "hfgpu"):
        import rerun as rr

        self._rr = rr
        self.rec = rr.RecordingStream(application_id)
        sinks = []
        if spawn:
            try:
                self.rec.spawn(connect=False)
            except Exception as exc:  # the viewer executable is missing or cannot start
                raise HfgpuError(f"cannot start the Rerun viewer (--view): {exc}") from None
            sinks.append(rr.GrpcSink())
        if connect is not None:
            sinks.append(rr.GrpcSink(connect))
        if rrd is not None:
            sinks.append(rr.FileSink(str(rrd)))
        if not sinks:
            raise HfgpuError("RerunRecorder needs an .rrd file, spawn=True or a connect URL")
        self.rec.set_sinks(*sinks)
        self.rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for path, name in _SERIES.items():
            self.rec.log(path, rr.SeriesLines(names=name), static=True)
        self._injection = None
        if scene.injection is not None and scene.rock is not None:
            depth = scene.injection.depth
            sigma0 = float(scene.rock.min_stress_at(np.array([depth]))[0])
            self._injection = (scene.injection.x, depth, sigma0)

    def _at(self, time: float) -> None:
        self.rec.set_time(TIMELINE, duration=float(time))

    def _scalar(self, path: str, value: float) -> None:
        self.rec.log(path, self._rr.Scalars(float(value)))

    def fracture_snapshot(self, snap: FractureSnapshot) -> None:
        """Open cells as a coloured mesh; fracture area and net pressure at the injection cell."""
        rr, f = self._rr, snap.frame
        self._at(snap.time)
        nz, nx = snap.width.shape
        x, z = f.centres(nz, nx)
        open_ = snap.width > 0
        zz, xx = np.meshgrid(z, x, indexing="ij")
        vertices, triangles = cell_quads(xx[open_], zz[open_], f.dx, f.dz)
        colours = np.repeat(_colours(snap.width[open_]), 4, axis=0)
        self.rec.log("world/fracture", rr.Mesh3D(vertex_positions=vertices, triangle_indices=triangles,
                                                 vertex_colors=colours))
        self._scalar("fracture/area", np.count_nonzero(open_) * f.dx * f.dz)
        if self._injection is not None:
            x_inj, depth, sigma0 = self._injection
            i, j = round((depth - f.z0) / f.dz), round((x_inj - f.x0) / f.dx)
            if 0 <= i < nz and 0 <= j < nx and open_[i, j]:
                self._scalar("fracture/net_pressure_at_injection", snap.pressure[i, j] - sigma0)

    def fracture_balance(self, record: BalanceRecord) -> None:
        self._at(record.time)
        self._scalar("fracture/injected_volume", record.injected)
        if record.injected > 0:
            self._scalar("fracture/efficiency", record.stored / record.injected)

    def proppant_snapshot(self, snap: ProppantSnapshot) -> None:
        """Parcels as points on the fracture plane coloured by speed."""
        p = snap.parcels
        self._at(snap.time)
        positions = np.stack([p["x"], np.zeros_like(p["x"]), -np.asarray(p["z"])], axis=-1)
        speed = np.hypot(p["u"], p["v"])
        self.rec.log("world/proppant/parcels", self._rr.Points3D(
            positions, colors=_colours(speed), radii=self._rr.components.Radius.ui_points(2.0)))

    def proppant_balance(self, record: SolidBalanceRecord) -> None:
        self._at(record.time)
        for name in ("injected", "in_domain", "outflow"):
            self._scalar(f"proppant/{name}", getattr(record, name))

    def close(self) -> None:
        """Flush and end the recording (the .rrd file is complete afterwards); a viewer gone since the start
        costs one line on stderr, not the run."""
        try:
            self.rec.flush()
            self.rec.disconnect()
        except Exception as exc:  # a streamed viewer that went away: the results file is what matters
            print(f"hfgpu: the Rerun recording could not be flushed ({exc})", file=sys.stderr)
