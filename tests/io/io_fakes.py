"""Fake simulators for the io tests: they emit records as the real ones do (hfgpu/records.py)."""

from __future__ import annotations

import numpy as np

from hfgpu.records import (BalanceRecord, FractureSnapshot, GridFrame, ProppantSnapshot,
                           SolidBalanceRecord)
from hfgpu.scene import Fluid, Mesh, Output, RunConfig, Scene

FRACTURE_SCENE = """
[run]
end_time = "10 s"
physics = ["fracture"]
[rock]
youngs_modulus = "40 GPa"
poisson_ratio = 0.15
min_stress = "60 MPa"
[fluid]
viscosity = "0.08 Pa*s"
[injection]
depth = "0 m"
schedule = [{ until = "10 s", rate = "0.05 m**3/s" }]
[mesh]
cell_size = "2 m"
[output]
every = "2.5 s"
"""

RATE = 0.05


def proppant_scene() -> Scene:
    """A proppant-only scene built directly (its TOML section is parsed by hfgpu.proppant.config)."""
    return Scene(run=RunConfig(end_time=1.0, physics=("proppant",)), fluid=Fluid(viscosity=1e-3),
                 mesh=Mesh(dx=0.01, dz=0.01), output=Output(every=0.25), source="# proppant test scene\n")


def fracture_snapshot(t: float, n: int = 11) -> FractureSnapshot:
    """A radial opening of radius 2 t [m] on an n x n grid of 2 m cells centred on the origin."""
    frame = GridFrame(dx=2.0, dz=2.0, x0=-(n - 1), z0=-(n - 1))
    x, z = frame.centres(n, n)
    r = np.hypot(*np.meshgrid(x, z))
    radius = 2.0 * t
    inside = r < radius
    width = np.where(inside, 1e-3 * np.sqrt(np.clip(1 - (r / max(radius, 1e-9)) ** 2, 0, None)), 0.0)
    return FractureSnapshot(time=t, frame=frame, width=width, pressure=np.where(inside, 61e6 - 1e5 * r, 0.0),
                            leakoff_rate=np.where(inside, 1e-6, 0.0),
                            opening_time=np.where(inside, r / 2.0, np.nan),
                            extras={"net_pressure": np.where(inside, 1e6 - 1e5 * r, 0.0)})


def proppant_snapshot(t: float, n_parcels: int = 50, nz: int = 8, nx: int = 12) -> ProppantSnapshot:
    rng = np.random.default_rng(int(t * 1000))
    frame = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)
    parcels = {
        "x": rng.uniform(0, nx * 0.01, n_parcels), "z": rng.uniform(0, nz * 0.01, n_parcels),
        "u": rng.normal(0, 0.01, n_parcels), "v": 0.005 + rng.normal(0, 0.001, n_parcels),
        "radius": rng.uniform(1e-4, 2e-4, n_parcels), "density": np.full(n_parcels, 2650.0),
        "particles": np.full(n_parcels, 100.0), "state": (rng.random(n_parcels) < t).astype(np.int32),
        "class_id": rng.integers(0, 2, n_parcels).astype(np.int32),
    }
    grid = {"volume_fraction": rng.uniform(0, 0.3, (nz, nx)), "pressure": np.full((nz, nx), 1e5),
            "width": np.full((nz, nx), 0.005), "fluid_u": np.zeros((nz, nx + 1)),
            "fluid_v": np.zeros((nz + 1, nx))}
    return ProppantSnapshot(time=t, frame=frame, parcels=parcels, grid=grid)


def simulate_fracture(scene, sink, progress=None, steps: int = 40, snapshot_every: int = 10,
                      fail_at: int | None = None, checkpoint=None, resume=None):
    """Fake fracture run: constant-rate injection, 80 % stored, snapshots every few steps (no checkpoints)."""
    from hfgpu.errors import SimulationError

    dt = scene.run.end_time / steps
    for i in range(1, steps + 1):
        t = i * dt
        if fail_at is not None and i == fail_at:
            raise SimulationError("Newton did not converge", time=t, cell=(3, 4), residual=1.5e-2)
        net = 2e6 * t ** -0.2  # a radial fracture's falling net pressure
        sink.fracture_balance(BalanceRecord(time=t, injected=RATE * t, stored=0.8 * RATE * t,
                                            leaked=0.2 * RATE * t, injection_pressure=60e6 + net,
                                            net_pressure=net, efficiency=0.8, area=10.0 * t, length=3.0 * t ** 0.5,
                                            height=3.0 * t ** 0.5))
        if progress is not None:
            progress(t)
        if i % snapshot_every == 0:
            sink.fracture_snapshot(fracture_snapshot(t))
    return {"steps": steps, "note": "fake"}


def simulate_proppant(scene, sink, progress=None, steps: int = 20, snapshot_every: int = 5, checkpoint=None,
                      resume=None):
    """Fake proppant run: solids injected at a constant rate, 10 % leaving through the outlet (no checkpoints)."""
    dt = scene.run.end_time / steps
    for i in range(1, steps + 1):
        t = i * dt
        sink.proppant_balance(SolidBalanceRecord(time=t, injected=1e-4 * t, in_domain=0.9e-4 * t,
                                                 outflow=0.1e-4 * t))
        if progress is not None:
            progress(t)
        if i % snapshot_every == 0:
            sink.proppant_snapshot(proppant_snapshot(t))
    return {"steps": steps}
