"""Fluid and parcel speeds beside a packed inlet stay of the order the injection allows (no spurious eddies).

Scene: a square fracture patch with a narrow band (0.5 mm, like the perforated layer of the five-layer field
case) between wider layers (1 mm), fed at its centre by an annulus of 3 x 3 cells at a high slurry rate; 40/70
sand bridges in the band (2 d_max > 0.5 mm) and packs the inlet cells to close packing (screen-out), while the
fluid leaves through the ring's perimeter to outlet rows at the top and bottom. The scene is mirror-symmetric
about the inlet's vertical and horizontal lines (gravity acts on the parcels only: the fluid pressure is the
excess over its hydrostatic), so each half of the domain takes half of the slurry rate Q; Hele-Shaw flow
(friction-dominated, q = -w^3/(12 mu) grad p, Eq. 8-9) has no closed streamlines, so no face of a half can carry
more than that half's share:

    |u_f| (theta_f w)_f l_f <= Q / 2   on every open face,  i.e.  |u_f| <= Q / (2 (theta_f w)_f l_f),

the speed bound from the injection rate and the face's open cross-section (l_f = dz for x-faces, dx for z-faces).
The pressure part of the interphase force, taken at the parcels (Eq. 39 with the gradient of Eq. 41), moved the
packed ring's gradient (100-1000 times the open fracture's) onto the faces one cell away and drove eddies that
carried 0.8-0.9 Q through a single face at 4-6 m/s (the mean exit speed is about 0.5 m/s); with the pressure
part on each face with the face's own gradient (hfgpu.proppant.simulator.pressure_reaction) the largest
face carries a quarter of Q at most, at up to 2 m/s while the ring packs.
Parcels: none may outrun the fastest flow the bound allows through the narrowest face of the ring, a packed
face, Q / (2 min (theta_f w)_f l_f). Conservation: solids (injected = in domain + outflow + screened out) and
fluid (injected + opened + supplied = stored + leaked + outflow) to 1e-12 relative, on every step.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.proppant.config import Geometry, Port
from hfgpu.proppant.grid import face_mean
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

RATE = 3e-4  # slurry rate Q [m^3/s]
CELL = 0.1  # [m]
NARROW, WIDE = 0.5e-3, 1e-3  # [m]

SCENE = f"""
[run]
end_time = "1.5 s"
physics = ["proppant"]
seed = 3
[fluid]
viscosity = "2 mPa*s"
[mesh]
cell_size = "{CELL} m"
[output]
every = "0.5 s"
[geometry]
kind = "slot"
length = "1 m"
height = "1 m"
width = "1 mm"
[[geometry.inlets]]
kind = "point"
x = "0.5 m"
depth = "0.5 m"
[[geometry.outlets]]
kind = "point"
x = "0.05 m"
depth = "0.05 m"
[injection]
schedule = [{{ until = "1.5 s", rate = "{RATE} m**3/s", proppant = "sand", volume_fraction = 0.2 }}]
[[proppant]]
name = "sand"
size = "40/70"
density = "2650 kg/m**3"
[mppic]
backend = "numpy"
parcels_per_cell = 8
"""


def packed_inlet_scene(nx: int = 11, nz: int = 9):
    """The scene of the module docstring: a field geometry (rows nz//2 +- 1 narrow), annular inlet of the
    central 3 x 3 cells, outlet rows at the top and bottom."""
    scene = load_scene(SCENE)
    x, z = (np.arange(nx) + 0.5) * CELL, (np.arange(nz) + 0.5) * CELL
    width = np.full((nz, nx), WIDE)
    width[nz // 2 - 1:nz // 2 + 2] = NARROW
    inlet = Port("annulus", x=x[nx // 2], depth=z[nz // 2], outer_radius=1.5 * CELL)
    outlets = tuple(Port("segment", x=x[0], depth=row, x_end=x[-1], depth_end=row) for row in (z[0], z[-1]))
    geometry = Geometry(kind="field", length=nx * CELL, height=nz * CELL, field_x=x, field_z=z, field_w=width,
                        inlets=(inlet,), outlets=outlets)
    return scene.replace(proppant=dataclasses.replace(scene.proppant, geometry=geometry))


def face_flux_ratio(sim: ProppantSimulation) -> float:
    """max over open faces of |u_f| (theta_f w)_f l_f / (Q / 2) (the bound of the module docstring)."""
    fluid, grid = sim.fluid, sim.grid
    q = fluid.theta_f * fluid.width
    flux_u = face_mean(q, grid.active, axis=1) * grid.frame.dz * np.abs(fluid.u)
    flux_v = face_mean(q, grid.active, axis=0) * grid.frame.dx * np.abs(fluid.v)
    return max(flux_u.max(), flux_v.max()) / (0.5 * RATE)


def parcel_speed_bound(sim: ProppantSimulation) -> float:
    """Q / (2 min (theta_f w)_f l_f) over the open faces of the inlet ring's cells [m/s]."""
    fluid, grid = sim.fluid, sim.grid
    ring = np.zeros(grid.shape, dtype=bool)
    for inlet in sim.injector.inlets:
        ring[inlet.k, inlet.i] = True
    q = fluid.theta_f * fluid.width
    areas = []
    for axis, spacing in ((1, grid.frame.dz), (0, grid.frame.dx)):
        face_q = face_mean(q, grid.active, axis=axis)
        touches = face_mean(ring.astype(float), np.ones(grid.shape, dtype=bool), axis=axis) > 0.0
        areas.append(face_q[touches & (face_q > 0.0)] * spacing)
    return 0.5 * RATE / np.min(np.concatenate(areas))


def test_packed_inlet_drives_no_eddies():
    sim = ProppantSimulation(proppant_engine_setup(packed_inlet_scene()))
    end = sim.setup.end_time
    worst_flux = worst_parcel = 0.0
    while sim.time < end - 1e-12:
        sim.step(limit=end - sim.time)
        worst_flux = max(worst_flux, face_flux_ratio(sim))
        if sim.parcels.n:
            speed = float(np.max(np.hypot(sim.parcels.u, sim.parcels.v)))
            worst_parcel = max(worst_parcel, speed / parcel_speed_bound(sim))
        balance = sim.balance()
        solids = balance.in_domain + balance.outflow + balance.screened_out
        assert solids == pytest.approx(balance.injected, rel=1e-12, abs=0.0)
        totals = sim.fluid_totals
        supplied = totals["injected"] + totals["opened"] + totals["supplied"]
        assert totals["stored"] + totals["leaked"] + totals["outflow"] == pytest.approx(supplied, rel=1e-12)
    # the regime of the test: the inlet cells reached close packing and the inlet screened out
    inlet = sim.injector.inlets[0]
    assert sim.moments.volume_fraction[inlet.k, inlet.i].max() >= 0.99 * sim.params.theta_cp
    assert sim.screened_out > 0.0
    assert worst_flux <= 1.0, f"a face carried {worst_flux / 2:.2f} Q (bound: Q/2)"
    assert worst_parcel <= 1.0, f"a parcel ran at {worst_parcel:.2f} x the packed-face bound"

