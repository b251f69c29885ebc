"""kernels/layout.py names each list once: the SEEN rows are the fields of ParcelFluid, the moment channels index
the NumPy scatter's sums by name, and param_vector fills the run constants PR by the names of PARAMS (plain
Python: no Taichi)."""

import dataclasses

import numpy as np
import pytest

from hfgpu.kernels import layout as L
from hfgpu.proppant import particle_ops_numpy as ref
from hfgpu.proppant.engine_taichi import param_vector
from hfgpu.proppant.grid import StaggeredGrid
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

#: each S_* row and the ParcelFluid field it holds
SEEN_ROWS = {"S_UF": "fluid_u", "S_VF": "fluid_v", "S_DPDX": "dpdx", "S_DPDZ": "dpdz", "S_DTDX": "dtaudx",
             "S_DTDZ": "dtaudz", "S_THETA": "volume_fraction", "S_MEAN_U": "mean_u", "S_MEAN_V": "mean_v",
             "S_DAMPING": "damping_rate", "S_WIDTH": "width"}
#: each M_* channel and the moment it sums
MOMENT_CHANNELS = {"M_VOLUME": "volume", "M_MASS": "mass", "M_MASS_U": "mass_u", "M_MASS_V": "mass_v",
                   "M_MASS_SPEED2": "mass_speed2", "M_NR3": "n_r3", "M_NR2": "n_r2", "M_OWN": "own_volume",
                   "M_OWN_X": "own_volume_x", "M_OWN_Z": "own_volume_z"}
#: each P_* slot and the name of the constant it holds
PARAM_SLOTS = {"P_X0": "x0", "P_Z0": "z0", "P_DX": "dx", "P_DZ": "dz", "P_THETA_CP": "theta_cp",
               "P_EPSILON": "epsilon", "P_PACKING_RESTITUTION": "packing_restitution",
               "P_DRAG_LAW": "drag_law_code", "P_RE_COEFFICIENT": "drag_re_coefficient",
               "P_BRIDGING": "bridging_factor", "P_DRAG_ITERATIONS": "drag_iterations",
               "P_BED_FRICTION": "bed_friction", "P_BED_STRESS": "bed_stress_code",
               "P_BED_SLOPE": "bed_slope", "P_FRICTION_FRACTION": "friction_volume_fraction",
               "P_SHIELDS": "shields_deposition", "P_WALL_LAW": "wall_friction_code", "P_RHO_F": "rho_f",
               "P_MU": "mu_f", "P_GRAVITY": "gravity", "P_STRESS_P": "P_s", "P_STRESS_BETA": "beta",
               "P_RESTITUTION": "restitution", "P_DAMPING": "damping", "P_DAMPING_THRESHOLD": "damping_threshold",
               "P_DAMPING_SCHEME": "damping_scheme_code", "P_AVERAGING": "averaging_code"}


def test_parcel_fluid_fields_are_the_seen_rows():
    """ParcelFluid's fields are SEEN_FIELDS in order; each S_* row names its field; the work rows DRAG, LAG_X,
    LAG_Z follow the SEEN rows."""
    assert tuple(f.name for f in dataclasses.fields(ref.ParcelFluid)) == L.SEEN_FIELDS
    assert ref.ParcelFluid.__doc__.startswith("What a parcel sees")
    assert L.SEEN == len(L.SEEN_FIELDS) == len(SEEN_ROWS)
    for constant, name in SEEN_ROWS.items():
        assert L.SEEN_FIELDS[getattr(L, constant)] == name, constant
    assert sorted(getattr(L, c) for c in SEEN_ROWS) == list(range(L.SEEN))
    assert (L.DRAG, L.LAG_X, L.LAG_Z, L.WORK_ROWS) == (L.SEEN, L.SEEN + 1, L.SEEN + 2, L.SEEN + 3)
    assert L.WORK_FIELDS[:L.SEEN] == L.SEEN_FIELDS


def test_moment_channels_index_the_sums_by_name():
    """Two parcels, each at the centre of its own cell of a uniform grid (all its weight on that cell): the
    channel M_* of moment_sums holds the sum of that name; finish_moments reads them by name."""
    frame = GridFrame(dx=0.1, dz=0.2, x0=0.0, z0=0.0)
    width = np.full((3, 4), 2e-3)
    cells = [(1, 2), (2, 0)]
    radius, density, particles = np.array([1e-4, 3e-4]), np.array([2650.0, 1000.0]), np.array([7.0, 3.0])
    u, v = np.array([0.3, -0.1]), np.array([-0.2, 0.05])
    parcels = Parcels.create([frame.x0 + i * frame.dx for _, i in cells], [frame.z0 + k * frame.dz for k, _ in cells],
                             radius=radius, density=density, particles=particles, u=u, v=v)
    vol = particles * 4.0 / 3.0 * np.pi * radius ** 3
    mass = vol * density
    expected = {"volume": vol, "mass": mass, "mass_u": mass * u, "mass_v": mass * v,
                "mass_speed2": mass * (u ** 2 + v ** 2), "n_r3": particles * radius ** 3,
                "n_r2": particles * radius ** 2, "own_volume": vol, "own_volume_x": 0.0 * vol,
                "own_volume_z": 0.0 * vol}   # at the cell centres: no offset
    assert set(expected) == set(L.MOMENT_FIELDS)
    sums = ref.moment_sums(parcels, frame, width)
    assert sums.shape == (L.MOMENT_COUNT, *width.shape) == (len(MOMENT_CHANNELS), *width.shape)
    for constant, name in MOMENT_CHANNELS.items():
        c = getattr(L, constant)
        assert L.MOMENT_FIELDS[c] == name, constant
        for p, (k, i) in enumerate(cells):
            assert sums[c, k, i] == pytest.approx(expected[name][p], rel=1e-12), (constant, p)
        assert np.count_nonzero(sums[c]) == (0 if name in ("own_volume_x", "own_volume_z") else 2), constant
    moments = ref.finish_moments(sums, frame, width)
    for p, (k, i) in enumerate(cells):
        assert moments.solid_volume[k, i] == sums[L.M_VOLUME, k, i]
        assert moments.mass[k, i] == sums[L.M_MASS, k, i]
        assert moments.mean_u[k, i] == pytest.approx(u[p], rel=1e-12)
        assert moments.mean_v[k, i] == pytest.approx(v[p], rel=1e-12)
        assert moments.sauter_radius[k, i] == pytest.approx(radius[p], rel=1e-12)
        assert moments.velocity_variance[k, i] == pytest.approx(0.0, abs=1e-15)


def test_cell_channels_follow_the_moments():
    """The cell channels WIDTH ... LOAD_OWN come after the MOMENT_COUNT moment sums, each once."""
    names = ("WIDTH", "CELL", "PRESSURE", "THETA", "MEAN_U", "MEAN_V", "VARIANCE", "SAUTER", "TAU", "DAMPING",
             "OUTLET", "BED_STRENGTH", "LOAD_TOP", "LOAD_OWN")
    assert [getattr(L, n) for n in names] == list(range(L.MOMENT_COUNT, L.CELL_CHANNELS))


def distinctive_params() -> MppicParams:
    """MppicParams with every field off its default (allowed values)."""
    return dataclasses.replace(
        MppicParams(), theta_cp=0.61, P_s=4.5, beta=2.5, epsilon=3e-7, restitution=0.85, drag_law="snider",
        drag_re_coefficient=0.17, bridging_factor=2.3, drag_iterations=5, packing_restitution=0.1, damping=False,
        damping_threshold=0.45, damping_scheme="relaxation", bed_friction=0.6, bed_stress="grain", bed_slope=True,
        friction_volume_fraction=0.52,
        wall_friction="dean", shields_deposition=False)


def test_param_vector_fills_each_slot_by_name():
    """Each MppicParams attribute named in PARAMS lands at its P_* slot, the run's values at theirs, and every
    slot is filled (the vector equals one built independently from the names)."""
    params = distinctive_params()
    grid = StaggeredGrid(GridFrame(dx=0.11, dz=0.23, x0=-0.7, z0=1.3), np.ones((2, 3)))
    rho_f, mu_f, gravity = 1010.0, 2.5e-3, 9.79
    out = param_vector(params, grid, rho_f, mu_f, gravity)
    run = {"x0": -0.7, "z0": 1.3, "dx": 0.11, "dz": 0.23, "rho_f": rho_f, "mu_f": mu_f, "gravity": gravity}
    assert out.shape == (L.PARAM_COUNT,) == (len(L.PARAMS),) == (len(PARAM_SLOTS),)
    assert sorted(getattr(L, c) for c in PARAM_SLOTS) == list(range(L.PARAM_COUNT))
    for constant, name in PARAM_SLOTS.items():
        slot = getattr(L, constant)
        assert L.PARAMS[slot] == name, constant
        value = run[name] if name in run else float(getattr(params, name))
        assert out[slot] == value, constant
    assert out[L.P_DRAG_LAW] == 1.0 and out[L.P_WALL_LAW] == 1.0 and out[L.P_DRAG_ITERATIONS] == 5.0
    assert out[L.P_STRESS_P] == 4.5 and out[L.P_STRESS_BETA] == 2.5 and out[L.P_THETA_CP] == 0.61
    assert out[L.P_DAMPING] == 0.0 and out[L.P_SHIELDS] == 0.0 and out[L.P_BED_STRESS] == 0.0
    on = param_vector(dataclasses.replace(params, damping=True, shields_deposition=True), grid, rho_f, mu_f,
                      gravity)
    assert on[L.P_DAMPING] == 1.0 and on[L.P_SHIELDS] == 1.0
    assert set(n for n in L.PARAMS if n not in run) <= set(dir(params))


def test_param_vector_refuses_an_unknown_name(monkeypatch):
    """A name added to PARAMS that is neither an MppicParams attribute nor a run value fails loudly."""
    grid = StaggeredGrid(GridFrame(dx=0.1, dz=0.1, x0=0.0, z0=0.0), np.ones((2, 2)))
    monkeypatch.setattr(L, "PARAMS", L.PARAMS + ("no_such_constant",))
    monkeypatch.setattr(L, "PARAM_COUNT", L.PARAM_COUNT + 1)
    with pytest.raises(ValueError, match="no_such_constant"):
        param_vector(MppicParams(), grid, 1000.0, 1e-3, 9.81)
