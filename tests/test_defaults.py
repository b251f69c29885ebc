"""Defaults a coupled scene computes from its own scales (hfgpu.defaults): the values from the schedule's
closed forms, the presets' scaling, a scene's own values kept, scenes without a fracture untouched, `check`
printing the reasons, and the parcel budget of particles_per_parcel."""

import subprocess
import sys
from pathlib import Path

import pytest

import hfgpu
from hfgpu.presets import PRESETS
from hfgpu.proppant.simulator import particles_per_parcel, scheduled_solid_volume
from hfgpu.scene_text import edit_scene

#: The issue's stage in field units: a 15-minute pad, 15 min of 100 mesh and 20 min of 40/70, 50 min in all.
STAGE = """
[run]
end_time = "50 min"
physics = ["fracture", "proppant"]

[rock]
youngs_modulus = "4.5e6 psi"
poisson_ratio = 0.22
min_stress = "7000 psi"

[fluid]
viscosity = "2 cP"

[injection]
depth = "9500 ft"
schedule = [
  { duration = "15 min", rate = "80 bbl/min" },
  { duration = "15 min", rate = "80 bbl/min", proppant = "100 mesh", concentration = "0.5 ppa", end_concentration = "1 ppa" },
  { duration = "20 min", rate = "80 bbl/min", proppant = "40/70", concentration = "1 ppa", end_concentration = "2 ppa" },
]

[[proppant]]
name = "100 mesh"
size = "100 mesh"
density = "2650 kg/m**3"

[[proppant]]
name = "40/70"
size = "40/70"
density = "2650 kg/m**3"

[mesh]
cell_size = "20 ft"
"""


def derived(scene):
    return {d.key: d.value for d in scene.derived}


def test_stage_defaults_follow_the_schedule():
    """fracture_every = min(3000 s / 60, 900 s / 10) = 50 s; dt_max = min(900 s / 100, 50 s / 2) = 9 s."""
    scene = hfgpu.load_scene(STAGE)
    assert scene.coupling.fracture_every == pytest.approx(50.0)
    assert scene.proppant.numerics.dt_max == pytest.approx(9.0)
    assert scene.proppant.numerics.max_parcels == PRESETS["balanced"].parcel_budget
    assert set(derived(scene)) == {"coupling.fracture_every", "mppic.dt_max", "mppic.max_parcels"}


@pytest.mark.parametrize("preset, every, dt_max", [("fast", 100.0, 18.0), ("accurate", 20.0, 3.6)])
def test_presets_scale_the_derived_values(preset, every, dt_max):
    scene = edit_scene(hfgpu.load_scene(STAGE), {"run.preset": preset})
    assert scene.coupling.fracture_every == pytest.approx(every)
    assert scene.proppant.numerics.dt_max == pytest.approx(dt_max)
    assert scene.proppant.numerics.max_parcels == PRESETS[preset].parcel_budget


def test_a_short_stage_sets_the_interval():
    """A 2-minute rate step: fracture_every = 120 s / 10 = 12 s (below 3000 s / 60), dt_max = 12 s / 2."""
    text = STAGE.replace('{ duration = "15 min", rate = "80 bbl/min" },',
                         '{ duration = "13 min", rate = "80 bbl/min" }, { duration = "2 min", rate = "40 bbl/min" },')
    scene = hfgpu.load_scene(text)
    assert scene.coupling.fracture_every == pytest.approx(12.0)
    assert scene.proppant.numerics.dt_max == pytest.approx(6.0)


def test_scene_values_are_kept():
    scene = hfgpu.load_scene(STAGE + '[mppic]\ndt_max = "5 s"\nparcels_per_cell = 8\n'
                             '[coupling]\nfracture_every = "15 s"\n')
    assert scene.proppant.numerics.dt_max == 5.0
    assert scene.coupling.fracture_every == 15.0
    assert scene.proppant.numerics.max_parcels is None
    assert scene.derived == ()


def test_scenes_without_a_fracture_keep_the_preset_constants():
    scene = hfgpu.load_scene(Path(hfgpu.__file__).parent / "scenes" / "settling_stokes.toml")
    assert scene.proppant.numerics.dt_max == PRESETS["balanced"].dt_max
    assert scene.derived == ()


def test_check_prints_each_derived_value_with_its_reason(tmp_path):
    path = tmp_path / "stage.toml"
    path.write_text(STAGE)
    out = subprocess.run([sys.executable, "-m", "hfgpu.cli", "check", str(path)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "mppic.dt_max                     9          from the scene: shortest proppant stage (900 s) / 100" \
        in out.stdout
    assert "coupling.fracture_every          50         from the scene: end time / 60" in out.stdout


def test_parcel_budget_bounds_the_parcel_count():
    """Without the budget: n = sum_c V_c / (ppp_c v_c) parcels; with max_parcels below it, ppp rises by n /
    max_parcels, so the schedule makes exactly max_parcels parcels."""
    scene = hfgpu.load_scene(STAGE)
    setup, schedule = scene.proppant, scene.injection.schedule
    free = particles_per_parcel(type(setup)(**{**setup.__dict__, "numerics": type(setup.numerics)(
        **{**setup.numerics.__dict__, "max_parcels": None})}), schedule, cell_volume=0.05)
    count = sum(scheduled_solid_volume(schedule, c.name) / (p * c.size.mean_particle_volume())
                for c, p in zip(setup.classes, free))
    budget = setup.numerics.max_parcels
    assert count > budget  # 130 000 lb of sand at 16 parcels per cell of 0.05 m^3 (20 ft cells, 1.5 mm wide)
    bounded = particles_per_parcel(setup, schedule, cell_volume=0.05)
    made = sum(scheduled_solid_volume(schedule, c.name) / (p * c.size.mean_particle_volume())
               for c, p in zip(setup.classes, bounded))
    assert made == pytest.approx(budget, rel=1e-12)
    # 130 000 lb: 36 430 lb of 100 mesh and 93 770 lb of 40/70 (hfgpu check's pump-schedule table)
    solid = sum(scheduled_solid_volume(schedule, c.name) for c in setup.classes)
    assert solid * 2650.0 / 0.45359237 == pytest.approx(130_200, rel=2e-3)
