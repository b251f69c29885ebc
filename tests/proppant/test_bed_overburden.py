"""A packed bed under a flow over it (MppicParams.bed_stress, hfgpu.kernels.closures.bed): a closed slot 10 cm
x 4 cm, gap 5 mm, 5 mm cells, its bottom 4 rows packed with 0.3 mm sand (theta_p 0.58, 2650 kg/m^3), clear water
(1 cP) entering through the left end above the bed and leaving through the right end. The bed shear stress of
the flow over it, tau_b = sqrt(12) mu U / w (closures.bed), is below the critical Shields stress of Soulsby &
Whitehouse (1997) at U = 0.22 m/s (the critical speed is 0.266 m/s) and 2.3 times above it at 0.6 m/s.

Measured (NumPy backend, seed 0; by owning row k, the bed rows k = 4 (top) .. 7):
- sub-critical, at 1 s, along the bed (x): the bed below its top cell at rest (0 m/s) with either bed stress,
  "overburden" or "grain" (with damping_scheme "implicit", whose lag holds a dense cell's mean, "grain" lets it
  creep at up to 4.9e-5 m/s and "overburden" at 1.0e-6). The top cell, whose grains have the own-weight
  friction under either closure, creeps at up to 1.6e-3 m/s (a grain is held where mu_b g' exceeds the drag
  D u_f of the fluid in the bed, D ~ 6e3 1/s: u_f < 0.6 mm/s).
- supercritical, at 0.5 s, mean |u| with "overburden": the surface layer (k = 3, grains on the bed) 3.9e-2 m/s,
  then 1.9e-3, 3.3e-4, 3.7e-6 and 0 down the bed: the surface moves as bed load, the interior does not follow.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from hfgpu import load_scene
from hfgpu.kernels.closures import bed
from hfgpu.kernels.closures.wall_friction import wall_friction_code
from hfgpu.proppant.parcels import Parcels
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from bed_validation import load_scene_text  # noqa: E402

L, H, W, DZ, ROWS = 0.10, 0.04, 5e-3, 5e-3, 4
RHO_P, RADIUS, THETA = 2650.0, 0.15e-3, 0.58
TOP = int(H / DZ) - ROWS  # the bed's top row


def scene(speed: float, bed_stress: str, end: float) -> str:
    """The slot of bench/bed_validation.py's bed-load set-up, L long, in 1 cP water, with ``bed_stress``."""
    return load_scene_text(speed, end, f'bed_stress = "{bed_stress}"', length=L, viscosity=1e-3)


def run_bed(speed: float, bed_stress: str, end: float) -> ProppantSimulation:
    """The slot with its packed bed (16 parcels a cell, uniform at random) and the fluid at rest, run to ``end``."""
    sim = ProppantSimulation(proppant_engine_setup(load_scene(scene(speed, bed_stress, end))))
    rng = np.random.default_rng(0)
    n = int(L / DZ) * ROWS * 16
    per = THETA * L * ROWS * DZ * W / (4 / 3 * np.pi * RADIUS ** 3) / n
    sim.set_parcels(Parcels.create(rng.uniform(0, L, n), H - rng.uniform(0, ROWS * DZ, n), radius=RADIUS,
                                   density=RHO_P, particles=per))
    sim.fluid = sim.solver.initial_state(sim._fluid_theta_p())  # the fluid's storage with the bed in place
    while sim.time < end - 1e-9:
        sim.step(limit=end - sim.time)
    return sim


def rows_and_shields(sim: ProppantSimulation) -> tuple[np.ndarray, float]:
    """The owning row of each parcel, and the Shields number over critical of the mean x speed of the fluid in
    the row above the bed's top cell."""
    p = sim.parcels
    k = np.floor((p.z - sim.grid.frame.z0) / DZ + 0.5).astype(int)
    speed = float(np.mean(np.abs(sim.fluid.u[TOP - 2, 1:-1])))
    tau = bed.bed_shear_stress_numpy(speed, W, 1000.0, 1e-3, wall_friction_code("laminar"))
    ratio = bed.shields_number_numpy(tau, 2 * RADIUS, RHO_P, 1000.0, 9.81) \
        / bed.critical_shields_number_numpy(2 * RADIUS, RHO_P, 1000.0, 1e-3, 9.81)
    return k, ratio


@pytest.mark.parametrize("bed_stress", ["overburden", "grain"])
def test_bed_under_subcritical_flow_is_at_rest_below_its_top_cell(bed_stress):
    """Sub-critical (Shields number 0.8-0.95 of the critical one over the bed), after 1 s: every parcel of the
    bed below its top cell slower than 1e-5 m/s along the bed (measured 0 with either bed stress), and no parcel
    of the bed moving up (the bed still compacts: grains sink at up to ~1e-3 m/s)."""
    sim = run_bed(0.22, bed_stress, 1.0)
    k, ratio = rows_and_shields(sim)
    assert 0.8 < ratio < 0.95
    p = sim.parcels
    deep = k > TOP
    assert deep.sum() > 0.7 * 3 / 4 * p.n
    assert np.abs(p.u[deep]).max() < 1e-5
    assert (-p.v[k >= TOP]).max() <= 0.0


def test_bed_surface_moves_above_the_critical_shields_stress():
    """Supercritical (Shields number 2-3 times the critical one), at 0.5 s: the grains on the bed (the row above
    its top cell) move at a mean |u| > 1e-2 m/s (measured 3.9e-2), more than 20 times those of the bed's second
    row (3.3e-4); the bed's top cell more than 3 times its second row (1.9e-3 against 3.3e-4), which is more
    than 15 times its third (3.7e-6)."""
    sim = run_bed(0.6, "overburden", 0.5)
    k, ratio = rows_and_shields(sim)
    assert 2.0 < ratio < 3.0
    u = np.abs(sim.parcels.u)
    mean = {row: u[k == row].mean() for row in range(TOP - 1, TOP + 3)}
    assert mean[TOP - 1] > 1e-2 and mean[TOP - 1] > 20 * mean[TOP + 1]
    assert mean[TOP] > 3 * mean[TOP + 1] > 15 * mean[TOP + 2]


def test_bed_stress_key():
    """[mppic] bed_stress: default "grain"; "overburden" accepted; another value refused in one line naming the
    key, the value and the allowed ones."""
    from hfgpu.errors import SceneError

    assert load_scene(scene(0.1, "overburden", 1.0)).proppant.params.bed_stress == "overburden"
    assert load_scene(scene(0.1, "overburden", 1.0).replace('bed_stress = "overburden"', "")) \
        .proppant.params.bed_stress == "grain"
    with pytest.raises(SceneError) as err:
        load_scene(scene(0.1, "janssen", 1.0))
    assert str(err.value) == "scene key 'mppic.bed_stress': got 'janssen'; allowed: one of ['grain', 'overburden']"
