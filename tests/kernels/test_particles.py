"""The Taichi particle engine (CPU backend) against the NumPy engine, and invariants of the particle ops:
conservation of scattered volume, equal and opposite exchange, exactness of interpolation, rest states,
the drag law's terminal velocity, walls and bridging; the device sort and compaction, the outlets, and the
GPU's atomic deposits run on the CPU."""

import dataclasses

import numpy as np
import pytest
from scipy.optimize import brentq

from hfgpu.kernels import layout as L
from hfgpu.kernels.stencil_numpy import weights
from hfgpu.proppant import closures
from hfgpu.proppant import particle_ops_numpy as ref
from hfgpu.proppant.engine import make_engine
from hfgpu.proppant.interpolation import active_nodes, face_widths, interpolate
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import Parcels
from hfgpu.records import GridFrame

from .engine_step import MU, RHO_F, G, engine_for, particle_step

RTOL = 1e-12
BACKENDS = ["numpy", "taichi"]


def random_case(seed=0, n=3000, nz=12, nx=17):
    """Random grid with closed cells (a block and the first column) and parcels everywhere in open cells,
    many of them within a fraction of a cell from walls and closed cells."""
    rng = np.random.default_rng(seed)
    frame = GridFrame(dx=0.01, dz=0.02, x0=0.005, z0=0.01)
    width = rng.uniform(1e-3, 3e-3, (nz, nx))
    width[4:7, 6:10] = 0.0
    width[:, 0] = 0.0
    xs = rng.uniform(frame.x0 - frame.dx / 2, frame.x0 + (nx - 0.5) * frame.dx, 4 * n)
    zs = rng.uniform(frame.z0 - frame.dz / 2, frame.z0 + (nz - 0.5) * frame.dz, 4 * n)
    i = np.floor((xs - frame.x0) / frame.dx + 0.5).astype(int)
    k = np.floor((zs - frame.z0) / frame.dz + 0.5).astype(int)
    keep = np.flatnonzero(width[k, i] > 0)[:n]
    parcels = Parcels.create(xs[keep], zs[keep], radius=rng.uniform(1e-4, 3e-4, n),
                             density=rng.uniform(2500, 2700, n), particles=rng.uniform(5, 50, n),
                             u=rng.normal(0, 0.02, n), v=rng.normal(0, 0.02, n))
    fluid = dict(u=rng.normal(0, 0.05, (nz, nx + 1)), v=rng.normal(0, 0.05, (nz + 1, nx)),
                 pressure=rng.normal(0, 20.0, (nz, nx)))
    return frame, width, parcels, fluid


def close(a, b, rtol=RTOL):
    """Equal to rtol relative to the largest magnitude of the reference array."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = max(np.max(np.abs(b)), 1e-300)
    np.testing.assert_allclose(a, b, rtol=0, atol=rtol * scale)


@pytest.mark.parametrize("drag_law, theta_cp, shields, private, slope", [
    ("wen-yu", 0.6, None, True, False), ("snider", 0.6, None, True, False), ("wen-yu", 0.045, None, True, False),
    ("wen-yu", 0.6, "laminar", True, False), ("wen-yu", 0.6, "dean", True, False),
    ("wen-yu", 0.6, None, False, False), ("wen-yu", 0.045, None, False, False), ("wen-yu", 0.045, None, True, True),
    ("wen-yu", 0.6, "laminar", True, True), ("wen-yu", 0.045, None, False, True)])
def test_taichi_matches_numpy(drag_law, theta_cp, shields, private, slope):
    """Two sub-steps of each engine from the same parcels: positions, velocities, states, the sub-loop's face
    forces and implicit-drag coefficients, and the moments after it agree to 1e-12. With theta_cp = 0.045
    about half of the cells count as packed, so the packing cap of the push acts, and friction_volume_fraction
    = 0.03 puts many parcels on a "bed", so bed friction stops some and slows others. ``shields``:
    shields_deposition on with that wall-friction law, friction_volume_fraction 0.035 (about half the cells
    dense: many parcels on a bed surface) and fluid velocities x 8 (gap Re up to ~2000), so that some surface
    parcels are below the threshold of motion and some above. ``private`` False: the GPU's deposits (blocks of
    64 parcels adding into one grid with atomics) on the CPU. ``slope``: bed_slope on (the slope's loads and
    push, and the avalanche that the threshold of motion does not hold)."""
    frame, width, parcels, fluid = random_case()
    fraction = 0.03 if theta_cp < 0.1 else 0.035 if shields else 0.5
    params = MppicParams(drag_law=drag_law, P_s=100.0, damping_threshold=0.0, theta_cp=theta_cp,
                         friction_volume_fraction=fraction, shields_deposition=shields is not None,
                         wall_friction=shields or "laminar", bed_slope=slope)
    if shields:
        fluid = {**fluid, "u": 8.0 * fluid["u"]}
    a, b = parcels.copy(), parcels.copy()
    la, ea = particle_step("taichi", frame, width, a, fluid, params, substeps=2, private=private)
    lb, eb = particle_step("numpy", frame, width, b, fluid, params, substeps=2)
    assert ea.max_speed() == pytest.approx(eb.max_speed(), rel=1e-12)
    assert ea.solid_volume() == pytest.approx(eb.solid_volume(), rel=1e-12)
    assert_steps_agree((la, ea, a), (lb, eb, b))


@pytest.mark.parametrize("theta_cp, slope", [(0.6, False), (0.045, False), (0.045, True)])
def test_taichi_matches_numpy_with_relaxation_damping(theta_cp, slope):
    """damping_scheme "relaxation" (closures.damping.DAMPING_SCHEMES): two sub-steps of each engine agree to 1e-12,
    as in test_taichi_matches_numpy, with the damping active in every cell (damping_threshold 0)."""
    frame, width, parcels, fluid = random_case()
    params = MppicParams(P_s=100.0, damping_threshold=0.0, theta_cp=theta_cp, damping_scheme="relaxation",
                         friction_volume_fraction=0.03 if theta_cp < 0.1 else 0.5, bed_slope=slope)
    a, b = parcels.copy(), parcels.copy()
    la, ea = particle_step("taichi", frame, width, a, fluid, params, substeps=2)
    lb, eb = particle_step("numpy", frame, width, b, fluid, params, substeps=2)
    assert_steps_agree((la, ea, a), (lb, eb, b))
    c = parcels.copy()
    particle_step("numpy", frame, width, c, fluid, dataclasses.replace(params, damping_scheme="implicit"), substeps=2)
    assert np.abs(c.u - b.u).max() > 1e-6  # the schemes differ where the damping acts


def assert_steps_agree(taichi, numpy) -> None:
    """Two particle steps, each (SubLoop, engine, parcels): the moments after them, the exchange and the
    parcels' positions and velocities to RTOL, their states equal."""
    (la, ea, a), (lb, eb, b) = taichi, numpy
    ma, mb = ea.moments(), eb.moments()
    for name in ma.__dataclass_fields__:
        close(getattr(ma, name), getattr(mb, name))
    for name in ("force_x", "force_z", "beta_x", "beta_z"):
        close(getattr(la, name), getattr(lb, name))
    for name in ("x", "z", "u", "v"):
        close(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(a.state, b.state)


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_scattered_volume_is_parcel_volume(backend_name):
    """Eq. 38 x cell volume summed over cells == sum of parcel solid volumes, with parcels touching the
    domain edges and closed cells (weights onto them are renormalised)."""
    frame, width, parcels, _ = random_case(seed=1)
    engine = engine_for(backend_name, frame, width, MppicParams())
    engine.set_parcels(parcels)
    moments = engine.moments()
    deposited = np.sum(moments.volume_fraction * frame.dx * frame.dz * width)
    assert deposited == pytest.approx(parcels.solid_volume().sum(), rel=1e-12)
    assert engine.solid_volume() == pytest.approx(parcels.solid_volume().sum(), rel=1e-12)
    assert np.all(moments.volume_fraction[width == 0] == 0)
    assert np.sum(moments.mass) == pytest.approx(np.sum(parcels.solid_volume() * parcels.density), rel=1e-12)


@pytest.mark.parametrize("backend_name", BACKENDS)
@pytest.mark.parametrize("first", [True, False])
def test_parcel_in_the_corner_of_the_first_cell_is_deposited(backend_name, first):
    """A parcel in the upper-left quarter of cell (0, 0) has the stencil base (-1, -1); as the first parcel of
    a deposit block the Taichi scatter once took that base for "no run yet" and dropped the parcel's run."""
    frame = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)
    width = np.full((4, 5), 2e-3)
    x, z = [0.002, 0.03], [0.002, 0.02]
    if not first:
        x, z = x[::-1], z[::-1]
    parcels = Parcels.create(np.array(x), np.array(z), radius=1e-4, density=2650.0, particles=1.0)
    engine = engine_for(backend_name, frame, width, MppicParams())
    engine.set_parcels(parcels)
    deposited = np.sum(engine.moments().volume_fraction * frame.dx * frame.dz * width)
    assert deposited == pytest.approx(parcels.solid_volume().sum(), rel=1e-12)


@pytest.mark.parametrize("private", [True, False])
def test_device_sort_is_the_stable_sort_by_cell_and_drops_what_left(private):
    """begin_step's counting sort gives Parcels.sort_by_cell's order exactly (CPU: the stable scatter; the
    GPU's atomic scatter: the same parcels per half cell, order within it arbitrary); parcels in an outlet
    column leave in the sub-loop (their volume is the outflow) and the next sort drops them."""
    frame, width, parcels, fluid = random_case(seed=5)
    assert not np.array_equal(np.argsort(parcels.cell_keys(frame, width.shape), kind="stable"),
                              np.arange(parcels.n))
    outlets = np.zeros(width.shape, dtype=bool)
    outlets[:, -1] = True
    engine = engine_for("taichi", frame, width, MppicParams(), outlets=outlets, private=private)
    engine.stable_sort = private
    engine.set_parcels(parcels)
    engine.begin_step(fluid["u"], fluid["v"], fluid["pressure"])
    ordered = parcels.copy()
    ordered.sort_by_cell(frame, width.shape)
    got = engine.parcels()
    if private:
        for name in ("x", "z", "u", "v", "radius", "particles"):
            np.testing.assert_array_equal(getattr(got, name), getattr(ordered, name))
    else:
        np.testing.assert_array_equal(got.cell_keys(frame, width.shape), ordered.cell_keys(frame, width.shape))
        np.testing.assert_array_equal(np.sort(got.x), np.sort(ordered.x))
    leaving = outlets[ref.owning_cell(got.x, got.z, frame, width.shape)[:2]]
    loop = engine.substeps(1e-6, 1, 0.0)
    engine.commit()
    assert loop.outflow == pytest.approx(np.sum(got.solid_volume()[leaving]), rel=1e-12)
    assert engine.live == parcels.n - leaving.sum() and leaving.sum() > 50
    engine.begin_step(fluid["u"], fluid["v"], fluid["pressure"])
    assert engine.n == parcels.n - leaving.sum() == engine.parcels().n


@pytest.mark.parametrize("private_bytes, blocks", [(64 * 2 ** 20, 15), (4 * 8 * 13 * 18 * L.MOMENT_COUNT, 4)])
def test_deposits_in_many_private_copies_match_numpy(private_bytes, blocks):
    """The CPU deposits split the parcels into blocks, each summing into its own grid copy: 3000 parcels at
    200 per copy give 15 copies (the most is 16); a budget of 4 copies of the MOMENT_COUNT-channel grid of 13 x 18
    nodes gives 4."""
    frame, width, parcels, fluid = random_case(seed=3)
    params = MppicParams()
    engine = engine_for("taichi", frame, width, params)
    engine.PARCELS_PER_COPY, engine.PRIVATE_BYTES, engine.copies_limit = 200, private_bytes, 16
    a, b = parcels.copy(), parcels.copy()
    la, _ = particle_step("taichi", frame, width, a, fluid, params)
    assert engine._blocks() == (blocks, blocks)
    lb, eb = particle_step("numpy", frame, width, b, fluid, params)
    for name in ("force_x", "force_z", "beta_x", "beta_z"):
        close(getattr(la, name), getattr(lb, name))
    close(a.x, b.x)


def test_exchange_is_equal_and_opposite():
    """sum F V_face == sum over parcels n rho_p V_p D (u_f - u_p) (Eq. 39, drag part) for every parcel with an
    active face in its stencil; the pressure part, sum F V_face == -sum theta_p,f grad p V_face."""
    frame, width, parcels, fluid = random_case(seed=2)
    params = MppicParams()
    moments = ref.finish_moments(ref.moment_sums(parcels, frame, width), frame, width)
    fields = ref.grid_fields(frame, width, fluid["u"], fluid["v"], fluid["pressure"], moments, params, RHO_F, G)
    seen = ref.gather(parcels, frame, fields)
    drag = ref.push(parcels, seen, frame, fields, 2e-3, params, RHO_F, MU, G)
    fx, fz = ref.exchange(parcels, seen, drag, frame, width)
    wxf, wzf = face_widths(width)
    mass = parcels.solid_volume() * parcels.density
    per_x = mass * drag * (seen.fluid_u - parcels.u)
    per_z = mass * drag * (seen.fluid_v - parcels.v)
    _, xmask, zmask = active_nodes(width)
    has_x = weights(parcels.x, parcels.z, frame, "xface", xmask)[2].sum(axis=1) > 0
    has_z = weights(parcels.x, parcels.z, frame, "zface", zmask)[2].sum(axis=1) > 0
    assert np.sum(fx * frame.dx * frame.dz * wxf) == pytest.approx(per_x[has_x].sum(), rel=1e-11)
    assert np.sum(fz * frame.dx * frame.dz * wzf) == pytest.approx(per_z[has_z].sum(), rel=1e-11)
    assert has_x.mean() > 0.95 and has_z.mean() > 0.95


def test_grains_in_a_contact_network_leave_the_pressure_gradient_to_the_skeleton():
    """Parcels whose own cell has theta_p >= friction_volume_fraction see no pressure gradient, the others the
    interpolated one (Eq. 41); the fluid's pressure reaction -theta_p,f grad p takes its load only from the
    cells whose grains take the gradient, so a face between two such cells keeps -theta_p,f grad p and a face
    between two contact-network cells has no reaction (the fluid keeps -grad p)."""
    frame, width, parcels, fluid = random_case(seed=3)
    moments = ref.finish_moments(ref.moment_sums(parcels, frame, width), frame, width)
    fraction = float(np.median(moments.volume_fraction[moments.volume_fraction > 0]))
    params = MppicParams(friction_volume_fraction=fraction)
    fields = ref.grid_fields(frame, width, fluid["u"], fluid["v"], fluid["pressure"], moments, params, RHO_F, G)
    seen = ref.gather(parcels, frame, fields)
    k, i, _ = ref.owning_cell(parcels.x, parcels.z, frame, width.shape)
    network = moments.volume_fraction[k, i] >= fraction
    assert 0.2 < network.mean() < 0.8
    np.testing.assert_array_equal(seen.dpdx[network], 0.0)
    np.testing.assert_array_equal(seen.dpdz[network], 0.0)
    kx, ix, wx = weights(parcels.x, parcels.z, frame, "xface", fields.xface_mask)
    close(seen.dpdx[~network], interpolate(fields.dpdx, kx, ix, wx)[~network])
    rx, _ = ref.pressure_reaction(fields)
    theta, w = moments.volume_fraction, width
    left, right = theta[:, :-1], theta[:, 1:]
    both_free = (left < fraction) & (right < fraction) & (fields.xface_mask[:, 1:-1] > 0)
    both_network = (left >= fraction) & (right >= fraction)
    w_f = 0.5 * (w[:, :-1] + w[:, 1:])
    load = np.divide(0.5 * (left * w[:, :-1] + right * w[:, 1:]), w_f, out=np.zeros_like(w_f), where=w_f > 0)
    close(rx[:, 1:-1][both_free], -(load * fields.dpdx[:, 1:-1])[both_free])
    np.testing.assert_array_equal(rx[:, 1:-1][both_network], 0.0)
    assert both_free.sum() > 10 and both_network.sum() > 10


def test_engine_exchange_is_the_drag_of_its_parcels():
    """Without a pressure gradient the sub-loop's force on the faces sums to the drag on the parcels after
    the push, sum n rho_p V_p D (u_f - u_p), from the D and u_f of the Taichi engine's work rows (equal and
    opposite through the engine)."""
    frame, width, parcels, fluid = random_case(seed=2)
    fluid = {**fluid, "pressure": np.zeros_like(fluid["pressure"])}
    params = MppicParams()
    loop, engine = particle_step("taichi", frame, width, parcels, fluid, params)
    wxf, _ = face_widths(width)
    total = np.sum(loop.force_x * frame.dx * frame.dz * wxf)
    work = engine._work_rows.to_numpy()[:, :parcels.n]
    moved = engine.parcels()
    mass = moved.solid_volume() * moved.density
    per_x = mass * work[L.DRAG] * (work[L.S_UF] - moved.u)
    _, xmask, _ = active_nodes(width)
    has_x = weights(moved.x, moved.z, frame, "xface", xmask)[2].sum(axis=1) > 0
    assert total == pytest.approx(per_x[has_x].sum(), rel=1e-11) and abs(total) > 0.0


@pytest.mark.parametrize("location", ["cell", "xface", "zface"])
def test_interpolation_of_linear_field_is_exact(location):
    """Bilinear weights (Eq. 36-37) reproduce a linear field wherever the 2 x 2 stencil is active."""
    nz, nx = 8, 11
    frame = GridFrame(dx=0.3, dz=0.2, x0=1.0, z0=-0.5)
    masks = dict(zip(("cell", "xface", "zface"), active_nodes(np.ones((nz, nx)))))
    mask = masks[location]
    ox, oz = {"cell": (0, 0), "xface": (-0.5, 0), "zface": (0, -0.5)}[location]
    kk, ii = np.meshgrid(np.arange(mask.shape[0]), np.arange(mask.shape[1]), indexing="ij")
    field = 3.0 + 2.0 * (frame.x0 + (ii + ox) * frame.dx) - 5.0 * (frame.z0 + (kk + oz) * frame.dz)
    rng = np.random.default_rng(3)
    # points whose whole stencil lies on active nodes: 1 cell away from the edges
    x = rng.uniform(frame.x0 + frame.dx, frame.x0 + (nx - 2) * frame.dx, 500)
    z = rng.uniform(frame.z0 + frame.dz, frame.z0 + (nz - 2) * frame.dz, 500)
    k, i, w = weights(x, z, frame, location, mask)
    np.testing.assert_allclose(interpolate(field, k, i, w), 3.0 + 2.0 * x - 5.0 * z, rtol=1e-13)


def test_weights_drop_closed_and_outside_nodes():
    width = np.ones((3, 3))
    width[1, 2] = 0.0
    frame = GridFrame(1.0, 1.0, 0.0, 0.0)
    k, i, w = weights(np.array([1.3, -0.4]), np.array([1.2, 2.4]), frame, "cell", active_nodes(width)[0])
    np.testing.assert_allclose(w.sum(axis=1), 1.0, rtol=1e-15)
    assert np.all(w[0][(k[0] == 1) & (i[0] == 2)] == 0)
    assert w[1].max() == 1.0  # the corner point sits in cell (2, 0) only


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_parcel_at_rest_in_still_fluid_without_gravity_stays(backend_name):
    nz, nx = 6, 6
    frame = GridFrame(0.01, 0.01, 0.005, 0.005)
    width = np.full((nz, nx), 2e-3)
    parcels = Parcels.create(np.array([0.0231, 0.04]), np.array([0.0317, 0.011]), radius=2e-4,
                             density=2650.0, particles=10.0)
    before = parcels.copy()
    still = dict(u=np.zeros((nz, nx + 1)), v=np.zeros((nz + 1, nx)), pressure=np.zeros((nz, nx)))
    for _ in range(20):
        particle_step(backend_name, frame, width, parcels, still, MppicParams(), dt=1e-3, gravity=0.0)
    for name in ("x", "z", "u", "v"):
        np.testing.assert_array_equal(getattr(parcels, name), getattr(before, name))


@pytest.mark.parametrize("backend_name, drag_law, published", [("numpy", "wen-yu", 0.0669),
                                                                ("taichi", "wen-yu", 0.0669),
                                                                ("taichi", "snider", 0.0659)])
def test_single_parcel_reaches_terminal_velocity(backend_name, drag_law, published):
    """Still fluid: the implicit push converges to D_p(v) v = (1 - rho_f/rho_p) g, the analytic fixed point;
    at theta_p -> 0 that is the single-grain terminal velocity (weight = drag; d = 0.45 mm in water: Schiller-Naumann
    0.0669 m/s, Snider C_d 0.0659 m/s). The parcel's own theta_p (~5e-11 in its 1 m^3 cell) moves the fixed
    point by ~1e-10 relative, below the tolerance, and is taken as 0."""
    nz, nx = 4, 3
    frame = GridFrame(dx=1.0, dz=1.0, x0=0.5, z0=0.5)
    width = np.full((nz, nx), 1.0)
    r, rho_p = 0.225e-3, 2550.0
    parcels = Parcels.create(np.array([1.5]), np.array([0.7]), radius=r, density=rho_p, particles=1.0)
    params = MppicParams(drag_iterations=4, drag_law=drag_law)
    still = dict(u=np.zeros((nz, nx + 1)), v=np.zeros((nz + 1, nx)), pressure=np.zeros((nz, nx)))
    for _ in range(4):
        particle_step(backend_name, frame, width, parcels, still, params, dt=0.1, substeps=100)
    theta = 0.0
    g_eff = (1 - RHO_F / rho_p) * G
    exact = brentq(lambda vt: closures.drag_rate(vt, r, rho_p, theta, RHO_F, MU, params) * vt - g_eff,
                   1e-6, 1.0, xtol=1e-15)
    assert parcels.v[0] == pytest.approx(exact, rel=1e-9)
    assert parcels.u[0] == 0.0
    assert parcels.v[0] == pytest.approx(published, rel=2e-3)


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_walls_and_closed_cells_stop_parcels(backend_name):
    nz, nx = 4, 4
    frame = GridFrame(0.01, 0.01, 0.005, 0.005)
    width = np.full((nz, nx), 2e-3)
    width[1, 2] = 0.0
    # one parcel heading right into the closed cell (1, 2); one heading down out of the grid
    parcels = Parcels.create(np.array([0.0195, 0.025]), np.array([0.015, 0.0395]), radius=1e-4,
                             density=2650.0, particles=1.0, u=np.array([1.0, 0.0]), v=np.array([0.0, 1.0]))
    flow = dict(u=np.full((nz, nx + 1), 1.0), v=np.full((nz + 1, nx), 1.0), pressure=np.zeros((nz, nx)))
    params = MppicParams()
    particle_step(backend_name, frame, width, parcels, flow, params, dt=5e-3, gravity=0.0, substeps=5)
    assert parcels.x[0] < 0.02 and parcels.u[0] == 0.0
    assert parcels.z[1] < 0.04 and parcels.v[1] == 0.0


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_bridging_stops_and_releases(backend_name):
    nz, nx = 3, 3
    frame = GridFrame(0.01, 0.01, 0.005, 0.005)
    r = 2e-4
    params = MppicParams(bridging_factor=2.0)
    parcels = Parcels.create(np.array([0.015]), np.array([0.015]), radius=r, density=2650.0, particles=1.0,
                             u=0.1, v=0.1)
    flow = dict(u=np.full((nz, nx + 1), 0.1), v=np.zeros((nz + 1, nx)), pressure=np.zeros((nz, nx)))

    def step(width):
        particle_step(backend_name, frame, width, parcels, flow, params, dt=1e-3)

    narrow = np.full((nz, nx), 2e-3)
    narrow[1, 1] = 0.9 * 2 * params.bridging_factor * r
    x0 = parcels.x.copy()
    for _ in range(3):
        step(narrow)
        assert parcels.state[0] == 1 and parcels.u[0] == 0.0 and parcels.v[0] == 0.0
    assert parcels.x[0] == x0[0]
    step(np.full((nz, nx), 2e-3))
    assert parcels.state[0] == 0 and parcels.x[0] > x0[0]


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_parcels_do_not_enter_cells_they_would_bridge_in(backend_name):
    """A parcel heading into a cell narrower than its bridging width (bridging_factor x 2 r, here 1.5 x 2 r)
    stops at the face with that velocity component 0, and moves on into a cell just wide enough; one already
    inside a cell that is narrow moves within it (bridged, it does not move at all)."""
    nz, nx = 3, 4
    frame = GridFrame(0.01, 0.01, 0.005, 0.005)
    r = 1e-4
    params = MppicParams(bridging_factor=2.0)
    flow = dict(u=np.full((nz, nx + 1), 1.0), v=np.zeros((nz + 1, nx)), pressure=np.zeros((nz, nx)))
    for factor, enters in ((0.75, False), (1.05, True)):
        width = np.full((nz, nx), 2e-3)
        width[1, 2] = factor * params.bridging_factor * 2 * r
        parcels = Parcels.create(np.array([0.0195]), np.array([0.015]), radius=r, density=2650.0, particles=1.0,
                                 u=np.array([1.0]))
        particle_step(backend_name, frame, width, parcels, flow, params, dt=5e-3, gravity=0.0, substeps=5)
        assert (parcels.x[0] > 0.02) == enters
        if not enters:
            assert parcels.u[0] == 0.0


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_deposit_weights_follow_the_width(backend_name):
    """A parcel beside a narrow cell (a fracture's tip: 1 % of its neighbours' width) deposits V I_k w_k /
    sum_j I_j w_j on each node, so node k gets theta_p = V I_k / (dx dz sum_j I_j w_j), its bilinear share over
    the stencil's mean width, and the scattered volume is the parcel's (Eq. 38); with the plain bilinear
    weights the narrow cell would get V I_k / (dx dz w_k), 70 times that."""
    frame = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)
    width = np.full((3, 3), 2e-3)
    width[1, 2] = 2e-5
    x, z = 0.0185, 0.0135  # fractional position (0.35, 0.85) in the stencil of cells (0..1, 1..2)
    parcels = Parcels.create(np.array([x]), np.array([z]), radius=1e-4, density=2650.0, particles=1.0)
    engine = engine_for(backend_name, frame, width, MppicParams())
    engine.set_parcels(parcels)
    theta = engine.moments().volume_fraction
    fx, fz = 0.35, 0.85
    plain = {(0, 1): (1 - fz) * (1 - fx), (0, 2): (1 - fz) * fx, (1, 1): fz * (1 - fx), (1, 2): fz * fx}
    mean_width = sum(w * width[c] for c, w in plain.items())
    expected = parcels.solid_volume()[0] / (frame.dx * frame.dz * mean_width)
    for cell, share in plain.items():
        assert theta[cell] == pytest.approx(share * expected, rel=1e-12)
    assert np.sum(theta * frame.dx * frame.dz * width) == pytest.approx(parcels.solid_volume()[0], rel=1e-12)


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_bad_fluid_shapes_are_named(backend_name):
    frame, width, parcels, fluid = random_case(n=10)
    engine = engine_for(backend_name, frame, width, MppicParams())
    engine.set_parcels(parcels)
    with pytest.raises(ValueError, match="v: shape"):
        engine.begin_step(fluid["u"], fluid["v"][:-1], fluid["pressure"])
    with pytest.raises(ValueError, match="mppic.backend"):
        make_engine("cuda-python", None, None, RHO_F, MU, G, None)


def test_stencil_flags_match_their_definition():
    """The engine's stencil flags (the cells whose parcels take the kernels' fast paths) against the
    definition in NumPy: INTERIOR = the 3 x 3 cells around are in the grid and open, QUIET = also all below
    theta_cp, LOOSE = INTERIOR and the cell and the one below it below friction_volume_fraction."""
    from hfgpu.kernels.stencil import INTERIOR, LOOSE, QUIET

    rng = np.random.default_rng(7)
    nz, nx = 9, 11
    frame = GridFrame(dx=0.01, dz=0.01, x0=0.005, z0=0.005)
    width = rng.uniform(1e-3, 3e-3, (nz, nx))
    width[rng.random((nz, nx)) < 0.1] = 0.0
    k, i = np.nonzero(width > 0.0)
    load = rng.uniform(0.0, 0.7, k.size)  # theta_p of one parcel at each open cell's centre
    radius = 1e-4
    particles = load * frame.dx * frame.dz * width[k, i] / (4.0 / 3.0 * np.pi * radius ** 3)
    parcels = Parcels.create(frame.x0 + i * frame.dx, frame.z0 + k * frame.dz, radius=radius, density=2650.0,
                             particles=particles)
    engine = engine_for("taichi", frame, width, MppicParams(theta_cp=0.6, friction_volume_fraction=0.5))
    engine.set_parcels(parcels)
    theta = engine.moments().volume_fraction
    flags = engine._flags.to_numpy()
    for k in range(nz):
        for i in range(nx):
            inside = 1 <= k < nz - 1 and 1 <= i < nx - 1
            block = (slice(max(k - 1, 0), k + 2), slice(max(i - 1, 0), i + 2))
            interior = inside and np.all(width[block] > 0.0)
            quiet = interior and np.all(theta[block] < 0.6)
            loose = interior and theta[k, i] < 0.5 and theta[k + 1, i] < 0.5
            assert flags[k, i] == INTERIOR * interior + QUIET * quiet + LOOSE * loose, (k, i)
    assert np.any(flags & QUIET) and np.any(flags & LOOSE) and np.any(flags == INTERIOR)
