"""Fluid phase (grid, momentum predictor, SIMPLE loop) against closed forms and conservation.

References: plane Poiseuille / Hele-Shaw flow between parallel plates, mean velocity u = -w^2/(12 mu) dp/dx
(Poiseuille 1840s; e.g. Munson et al. 2006, the paper's source for Eq. 9; Batchelor 1967 section 4.2);
slots in series: resistances 12 mu L/(H w^3) add. Conservation: Eq. 25 integrated over the domain.
"""

import numpy as np
import pytest

from hfgpu.errors import SceneError
from hfgpu.proppant.fluid import CourantLimitExceeded, FluidNumerics, FluidSolver
from hfgpu.proppant.grid import StaggeredGrid
from hfgpu.proppant.params import MppicParams
from hfgpu.records import GridFrame

RHO, MU = 1000.0, 0.05


def slot_flow(grid, rate, steps=30, dt=0.05, solver=None, theta_p=None):
    """Inflow ``rate`` [m^3/s] spread over column 0, outlet (p = 0) in the last column; returns the
    solver, state and last StepInfo."""
    solver = solver or FluidSolver(grid, RHO, MU)
    state = solver.initial_state(theta_p)
    sources = np.zeros(grid.shape)
    sources[:, 0] = rate / grid.nz
    outlets = np.zeros(grid.shape, dtype=bool)
    outlets[:, -1] = True
    for _ in range(steps):
        info = solver.step(state, dt, theta_p=theta_p, sources=sources, outlets=outlets)
    return solver, state, info


def test_hele_shaw_mean_velocity_uniform_slot():
    """Steady flow through a uniform slot: u = -w^2/(12 mu) dp/dx (plane Poiseuille) within 1 %."""
    length, height, gap = 1.0, 0.2, 1.5e-3
    grid = StaggeredGrid.slot(length, height, gap, nx=40, nz=8)
    rate = 2e-6
    _, state, _ = slot_flow(grid, rate)
    dx = grid.frame.dx
    dpdx = (state.p[:, 30] - state.p[:, 10]) / (20 * dx)
    expected = -gap ** 2 / (12.0 * MU) * dpdx
    mean_u = rate / (height * gap)
    np.testing.assert_allclose(expected, mean_u, rtol=1e-2)
    np.testing.assert_allclose(state.u[:, 5:35], mean_u, rtol=1e-2)
    assert np.max(np.abs(state.v)) < 1e-9 * mean_u


def test_hele_shaw_with_slurry_viscosity_and_fluid_fraction():
    """Uniform suspension: Eq. 10 viscosity mu_0 (1 - theta_p/theta_cp)^-1.82 and a fluid flux theta_f w u;
    Darcy-Poiseuille: fluid rate = theta_f H w (-w^2/(12 mu_f) dp/dx)."""
    params = MppicParams()
    grid = StaggeredGrid.slot(0.5, 0.1, 1e-3, nx=25, nz=5)
    theta_p = np.full(grid.shape, 0.2)
    solver = FluidSolver(grid, RHO, MU, params=params)
    rate = 5e-7
    _, state, _ = slot_flow(grid, rate, solver=solver, theta_p=theta_p)
    mu_f = MU * (1.0 - 0.2 / params.theta_cp) ** -1.82
    dpdx = (state.p[:, 20] - state.p[:, 5]) / (15 * grid.frame.dx)
    predicted = 0.8 * 0.1 * 1e-3 * (-(1e-3) ** 2 / (12.0 * mu_f) * dpdx)
    np.testing.assert_allclose(predicted, rate, rtol=1e-2)


def test_two_widths_in_series():
    """Two slots in series: rate = dp H / (12 mu (L1/w1^3 + L2/w2^3)) within 1 %."""
    nx, nz, length, height = 120, 4, 1.2, 0.1
    w1, w2 = 2e-3, 1e-3
    frame = GridFrame(dx=length / nx, dz=height / nz, x0=0.5 * length / nx, z0=0.5 * height / nz)
    width = np.full((nz, nx), w1)
    width[:, nx // 2:] = w2
    grid = StaggeredGrid.from_width(frame, width)
    rate = 1e-6
    _, state, _ = slot_flow(grid, rate)
    drop = np.mean(state.p[:, 0] - state.p[:, -1])
    l1 = (nx // 2 - 0.5) * frame.dx  # centre of cell 0 to the step
    l2 = (nx - nx // 2 - 0.5) * frame.dx  # the step to the centre of the outlet cell
    predicted = drop * height / (12.0 * MU * (l1 / w1 ** 3 + l2 / w2 ** 3))
    np.testing.assert_allclose(predicted, rate, rtol=1e-2)


def test_start_up_of_slot_flow_under_a_pressure_drop():
    """Impulsively applied pressure drop between two fixed-pressure ends of a uniform slot: the mean velocity
    obeys theta_f du/dt = -(1/rho) dp/dx - 12 mu u/(rho w^2) (Eq. 8-9), u = U (1 - exp(-t/tau)),
    U = -w^2/(12 mu) dp/dx, tau = rho theta_f w^2/(12 mu); checked over two time constants within 1 %."""
    gap, length, drop, theta_p = 2e-3, 0.5, 50.0, 0.25
    grid = StaggeredGrid.slot(length, 0.05, gap, nx=25, nz=2)
    solver = FluidSolver(grid, RHO, MU)
    theta = np.full(grid.shape, theta_p)
    state = solver.initial_state(theta)
    outlets = np.zeros(grid.shape, dtype=bool)
    outlets[:, [0, -1]] = True
    pressure = np.zeros(grid.shape)
    pressure[:, 0] = drop
    tau = RHO * (1.0 - theta_p) * gap ** 2 / (12.0 * MU)
    gradient = -drop / ((grid.nx - 1) * grid.frame.dx)
    terminal = -gap ** 2 / (12.0 * MU) * gradient
    dt = tau / 200.0
    for n in range(1, 401):
        solver.step(state, dt, theta_p=theta, outlets=outlets, outlet_pressure=pressure)
        if n % 100 == 0:
            expected = terminal * (1.0 - np.exp(-n * dt / tau))
            np.testing.assert_allclose(state.u[:, 1:-1], expected, rtol=1e-2)


def test_radial_hele_shaw_source_flow():
    """2-D check: a point source Q in a uniform gap drains to a ring of outlet cells; the steady pressure
    is the radial Hele-Shaw solution p(r1) - p(r2) = 6 mu Q/(pi w^3) ln(r2/r1) (from q = -w^3/(12 mu)
    grad p and Q = 2 pi r q), checked along an axis and a diagonal within 1 %."""
    n, size, gap, rate = 81, 0.8, 1e-3, 1e-6
    grid = StaggeredGrid.box(size, size, gap, n, n)
    x, z = grid.centres()
    r = np.hypot(*np.meshgrid(x - size / 2, z - size / 2))
    sources = np.zeros(grid.shape)
    sources[n // 2, n // 2] = rate
    solver = FluidSolver(grid, RHO, MU)
    state = solver.initial_state()
    for _ in range(20):
        solver.step(state, 0.05, sources=sources, outlets=r >= 0.35)
    c = 6.0 * MU * rate / (np.pi * gap ** 3)
    axis = (n // 2, n // 2 + 5), (n // 2, n // 2 + 25)
    diagonal = (n // 2 + 4, n // 2 + 4), (n // 2 + 18, n // 2 + 18)
    for a, b in (axis, diagonal):
        np.testing.assert_allclose(state.p[a] - state.p[b], c * np.log(r[b] / r[a]), rtol=1e-2)


def test_linearised_drag_of_a_fixed_suspension():
    """Flow through a slot held back by a resting suspension with drag F = beta u (given as F^o = beta u^o plus
    the implicit coefficient beta): steady momentum balance dp/dx = -(beta + 12 mu/w^2) u (Eq. 8-9), with a
    beta that would make an explicit drag unstable (dt beta / rho = 50)."""
    gap, beta, rate = 1e-3, 5e6, 1e-6
    grid = StaggeredGrid.slot(0.5, 0.1, gap, nx=25, nz=4)
    solver = FluidSolver(grid, RHO, MU)
    state = solver.initial_state()
    sources = np.zeros(grid.shape)
    sources[:, 0] = rate / grid.nz
    outlets = np.zeros(grid.shape, dtype=bool)
    outlets[:, -1] = True
    drag_x, drag_z = np.full((4, 26), beta), np.full((5, 25), beta)
    for _ in range(10):
        solver.step(state, 0.01, sources=sources, outlets=outlets, force_x=beta * state.u,
                    force_z=beta * state.v, drag_x=drag_x, drag_z=drag_z)
    mean_u = rate / (0.1 * gap)
    dpdx = (state.p[:, 20] - state.p[:, 5]) / (15 * grid.frame.dx)
    np.testing.assert_allclose(dpdx, -(beta + 12.0 * MU / gap ** 2) * mean_u, rtol=1e-6)


def test_start_up_reaches_poiseuille_and_loop_converges_fast():
    """From rest, a few steps reach the steady state; Algorithm 1 stops after at most two passes (the
    correction is exact because the predictor couples each face to its own pressure difference only)."""
    grid = StaggeredGrid.slot(1.0, 0.2, 1e-3, nx=20, nz=4)
    solver, state, info = slot_flow(grid, 1e-6, steps=3)
    assert info.iterations <= 2
    assert info.pressure_correction <= 1e-5
    np.testing.assert_allclose(state.u[:, 10], 1e-6 / (0.2 * 1e-3), rtol=1e-6)


def test_balance_with_leakoff_growth_and_outlet():
    """Every step: continuity residual at round-off, injected = stored + leaked + outflow, leaked = s_l dA dt
    exactly; the width grows (w^o != w) and closed cells open."""
    rng = np.random.default_rng(7)
    nz, nx = 10, 16
    frame = GridFrame(dx=0.02, dz=0.02, x0=0.01, z0=0.01)
    width = rng.uniform(1e-3, 3e-3, (nz, nx))
    width[:, 12:] = 0.0  # a closed region that opens later
    solver = FluidSolver(StaggeredGrid.from_width(frame, width), RHO, MU, params=MppicParams())
    state = solver.initial_state()
    sources = np.zeros((nz, nx))
    sources[4:6, 0] = 2e-6
    outlets = np.zeros((nz, nx), dtype=bool)
    outlets[0, 8] = True
    for n in range(12):
        width = width * 1.01
        if n == 5:
            width[:, 12:] = 1e-3
        grid = StaggeredGrid.from_width(frame, width)
        solver.set_grid(grid)
        leakoff = np.where(grid.active, 1e-5, 0.0)
        theta_p = np.where(grid.active, rng.uniform(0.0, 0.3, (nz, nx)), 0.0)
        fz = rng.normal(0.0, 10.0, (nz + 1, nx))
        dt = min(0.02, 0.9 * solver.stable_dt(state))
        info = solver.step(state, dt, theta_p=theta_p, force_z=fz, sources=sources, leakoff=leakoff,
                           outlets=outlets)
        scale = max(info.injected, abs(info.stored), abs(info.outflow))
        assert info.continuity_residual < 1e-12 * scale / dt
        assert info.leaked == pytest.approx(1e-5 * frame.dx * frame.dz * np.count_nonzero(grid.active) * dt,
                                            rel=1e-14)
        assert info.injected == pytest.approx(4e-6 * dt, rel=1e-14)
        balance = info.injected + info.opened - info.stored - info.leaked - info.outflow
        assert abs(balance) < 1e-12 * scale
        assert info.dropped == 0.0
        # the cells that open are filled as a storage source (their fluid is not drawn through their faces)
        opened = np.sum((1.0 - theta_p[:, 12:]) * 1e-3) * frame.dx * frame.dz  # theta_f w dA of the new cells
        assert info.opened == (pytest.approx(opened, rel=1e-12) if n == 5 else 0.0)


def test_reused_factorisation_gives_the_direct_solution():
    """Preconditioned CG with an earlier step's LU factors gives the fields of a fresh factorisation every
    step (to the linear tolerance), with fewer factorisations."""
    grid = StaggeredGrid.slot(0.6, 0.2, 2e-3, nx=30, nz=10)
    runs = []
    for reuse in (0, 8):
        solver = FluidSolver(grid, RHO, 1e-3, FluidNumerics(reuse_iterations=reuse), params=MppicParams())
        state = solver.initial_state()
        sources = np.zeros(grid.shape)
        sources[3:6, 0] = 1e-5
        outlets = np.zeros(grid.shape, dtype=bool)
        outlets[7:9, -1] = True
        theta_p = np.random.default_rng(9).uniform(0.0, 0.3, grid.shape)
        for n in range(15):
            theta_p = theta_p * (1.0 + 0.01 * np.cos(n + theta_p))  # a slowly changing suspension
            dt = min(0.01, 0.9 * solver.stable_dt(state))
            solver.step(state, dt, theta_p=theta_p, sources=sources, outlets=outlets)
        runs.append((state, solver.factorisations))
    (direct, n_direct), (reused, n_reused) = runs
    assert n_reused < n_direct
    np.testing.assert_allclose(reused.p, direct.p, rtol=1e-9, atol=1e-9 * np.max(np.abs(direct.p)))
    np.testing.assert_allclose(reused.u, direct.u, rtol=0, atol=1e-9 * np.max(np.abs(direct.u)))
    np.testing.assert_allclose(reused.v, direct.v, rtol=0, atol=1e-9 * np.max(np.abs(direct.u)))


def test_closing_cells_drop_their_fluid():
    """Cells whose width goes to 0 leave the fluid grid: their fluid theta_f^o w^o dA is reported as dropped
    and the balance over the open cells still closes."""
    grid = StaggeredGrid.slot(0.4, 0.2, 2e-3, nx=8, nz=4)
    solver = FluidSolver(grid, RHO, MU)
    state = solver.initial_state()
    outlets = np.zeros(grid.shape, dtype=bool)
    outlets[:, 0] = True
    width = grid.width.copy()
    width[:, -2:] = 0.0
    solver.set_grid(grid.with_width(width))
    info = solver.step(state, 0.01, outlets=outlets)
    assert info.dropped == pytest.approx(2e-3 * grid.cell_area * 8, rel=1e-14)
    assert info.stored == 0.0 and info.outflow == pytest.approx(0.0, abs=1e-18)
    assert np.all(state.u[:, -3:] == 0.0)


def test_closed_box_leakoff_removes_exactly_the_sink():
    """A closed box whose only inflow feeds the leak-off: no outlet, so the inflow must equal s_l A; the
    solved fluid balances it to round-off and the box stays consistent (pinned pressure level)."""
    grid = StaggeredGrid.box(0.3, 0.3, 2e-3, nx=12, nz=12)
    solver = FluidSolver(grid, RHO, MU)
    state = solver.initial_state()
    s_l = 2e-6
    area = 0.3 * 0.3
    sources = np.zeros(grid.shape)
    sources[6, 6] = s_l * area
    for _ in range(5):
        info = solver.step(state, 0.1, sources=sources, leakoff=np.full(grid.shape, s_l))
        assert info.continuity_residual < 1e-12 * s_l * area
        assert info.leaked == pytest.approx(s_l * area * 0.1, rel=1e-13)
        assert info.outflow == 0.0 and abs(info.stored) < 1e-18
    # radial Hele-Shaw flow away from the source: fluid moves outward on both sides of it
    assert state.u[6, 8] > 0.0 > state.u[6, 5]


@pytest.mark.parametrize("backend", ["numpy", "taichi"])
def test_closed_box_body_force_stays_at_rest(backend):
    """A uniform force on the fluid in a closed box (non-uniform width and fluid fraction): the pressure
    balances it, dp/dx = -F_x, dp/dz = -F_z, and the fluid stays at rest (no spurious currents)."""
    rng = np.random.default_rng(11)
    nz, nx = 14, 9
    frame = GridFrame(dx=0.01, dz=0.015, x0=0.005, z0=0.0075)
    width = rng.uniform(0.5e-3, 4e-3, (nz, nx))
    width[3, 4] = 0.0  # an island
    grid = StaggeredGrid.from_width(frame, width)
    solver = FluidSolver(grid, RHO, MU, backend=backend, params=MppicParams())
    theta_p = np.where(grid.active, rng.uniform(0.0, 0.4, (nz, nx)), 0.0)
    state = solver.initial_state(theta_p)
    fx, fz = 300.0, -9.81 * 800.0
    for _ in range(4):
        info = solver.step(state, 0.05, theta_p=theta_p, force_x=np.full((nz, nx + 1), fx),
                           force_z=np.full((nz + 1, nx), fz))
    assert np.max(np.abs(state.u)) < 1e-14 and np.max(np.abs(state.v)) < 1e-14
    p = state.p
    gx = (p[:, 1:] - p[:, :-1])[grid.active_u[:, 1:-1]] / frame.dx
    gz = (p[1:] - p[:-1])[grid.active_v[1:-1]] / frame.dz
    np.testing.assert_allclose(gx, -fx, rtol=1e-9)
    np.testing.assert_allclose(gz, -fz, rtol=1e-9)
    assert info.continuity_residual < 1e-18


def test_courant_limit_is_detected():
    """Eq. 42: a dt above c_max / max(|u|/dx + |v|/dz) raises before any work and leaves the state as it
    was; the stable dt passes; StepInfo reports the Courant number of the new velocities."""
    grid = StaggeredGrid.slot(1.0, 0.2, 1e-3, nx=20, nz=4)
    solver, state, _ = slot_flow(grid, 1e-4, steps=20, dt=1e-3)
    speed = 1e-4 / (0.2 * 1e-3)
    dt_stable = solver.stable_dt(state)
    assert dt_stable == pytest.approx(0.5 * grid.frame.dx / speed, rel=1e-6)
    before = solver.copy_state(state)
    with pytest.raises(CourantLimitExceeded) as caught:
        solver.step(state, 1.5 * dt_stable)
    assert caught.value.stable_dt == pytest.approx(dt_stable)
    np.testing.assert_array_equal(state.u, before.u)
    np.testing.assert_array_equal(state.p, before.p)
    sources = np.zeros(grid.shape)
    sources[:, 0] = 1e-4 / 4
    outlets = np.zeros(grid.shape, dtype=bool)
    outlets[:, -1] = True
    info = solver.step(state, 0.99 * dt_stable, sources=sources, outlets=outlets)
    assert info.courant == pytest.approx(0.99 * 0.5, rel=1e-6)


def test_bad_input_names_the_field():
    grid = StaggeredGrid.box(0.1, 0.1, 1e-3, nx=4, nz=4)
    solver = FluidSolver(grid, RHO, MU)
    state = solver.initial_state()
    with pytest.raises(SceneError, match="fluid.theta_p"):
        solver.step(state, 0.01, theta_p=np.full((4, 4), 1.2))
    with pytest.raises(SceneError, match="fluid.leakoff"):
        solver.step(state, 0.01, leakoff=np.full((4, 4), -1.0))
    with pytest.raises(SceneError, match="fluid.force_x"):
        solver.step(state, 0.01, force_x=np.zeros((4, 4)))
    with pytest.raises(SceneError, match="fluid.dt"):
        solver.step(state, -1.0)
    with pytest.raises(SceneError, match="grid.width"):
        StaggeredGrid.from_width(grid.frame, np.full((3, 3), -1e-3))
    with pytest.raises(SceneError, match="mppic.c_max"):
        FluidNumerics(c_max=1.5)
    closed = StaggeredGrid.from_width(grid.frame, np.where(np.eye(4) > 0, 0.0, 1e-3))
    with pytest.raises(SceneError, match="fluid.sources"):
        FluidSolver(closed, RHO, MU).step(FluidSolver(closed, RHO, MU).initial_state(), 0.01,
                                          sources=np.eye(4) * 1e-6)


def test_grid_faces_and_volumes():
    width = np.array([[1.0, 2.0, 0.0], [3.0, 4.0, 5.0]]) * 1e-3
    grid = StaggeredGrid.from_width(GridFrame(0.1, 0.2, 0.05, 0.1), width)
    np.testing.assert_allclose(grid.width_u, [[0, 1.5e-3, 0, 0], [0, 3.5e-3, 4.5e-3, 0]])
    np.testing.assert_allclose(grid.width_v, [[0, 0, 0], [2e-3, 3e-3, 0], [0, 0, 0]])
    np.testing.assert_allclose(grid.volume_u, 0.02 * grid.width_u)
    assert grid.cell_volume.sum() == pytest.approx(0.02 * width.sum())
    assert grid.with_width(width * 2).width_u[1, 1] == pytest.approx(7e-3)


def test_jet_momentum_replaces_the_pressure_it_would_take():
    """Momentum balance of the jet's face (Eq. 26): a source carrying momentum flux rho Q U into a channel
    leaves the velocities of a straight one-row channel unchanged (continuity fixes them) and lowers the
    pressure drop across the jet's face by exactly rho Q U / (w_f dz), the jet's thrust over the face area."""
    grid = StaggeredGrid.slot(1.0, 0.05, 2e-3, nx=20, nz=1)
    rate, jet_speed = 1e-5, 0.3
    sources = np.zeros(grid.shape)
    sources[0, 0] = rate
    outlets = np.zeros(grid.shape, dtype=bool)
    outlets[0, -1] = True
    momentum = np.zeros((1, 21))
    momentum[0, 1] = rate * jet_speed
    results = []
    for m in (None, momentum):
        solver = FluidSolver(grid, RHO, MU)
        state = solver.initial_state()
        for _ in range(5):
            solver.step(state, 0.05, sources=sources, outlets=outlets, momentum_x=m)
        results.append(state)
    plain, jet = results
    np.testing.assert_allclose(jet.u, plain.u, rtol=1e-10, atol=1e-15)
    drop = lambda s: s.p[0, 0] - s.p[0, 1]  # noqa: E731
    thrust = RHO * rate * jet_speed / (2e-3 * grid.frame.dz)
    assert drop(plain) - drop(jet) == pytest.approx(thrust, rel=1e-8)
    np.testing.assert_allclose(np.diff(jet.p[0, 1:]), np.diff(plain.p[0, 1:]), rtol=1e-8)


def test_width_history_inconsistent_with_the_injection_is_spread_not_jetted():
    """A closed region whose prescribed width grows faster than its sources fill it (a one-way coupled width
    history that is not mass-consistent): the missing fluid is supplied in proportion to each cell's growth
    (StepInfo.supplied = growth volume - injected volume, exactly), so a uniformly growing slot stays at rest
    instead of jetting the whole deficit out of its pinned cell; the balance injected + opened + supplied =
    stored + leaked + outflow holds."""
    w0, rate = 1e-3, 1e-5  # growth [m/s]
    grid = StaggeredGrid.slot(1.0, 0.5, w0, nx=20, nz=10)
    solver = FluidSolver(grid, RHO, MU)
    state = solver.initial_state()
    dt, t = 0.05, 0.0
    for _ in range(5):
        t += dt
        solver.set_grid(grid.with_width(np.full(grid.shape, w0 + rate * t)))
        info = solver.step(state, dt)
    assert max(np.abs(state.u).max(), np.abs(state.v).max()) < 1e-12
    assert info.supplied == pytest.approx(rate * dt * 0.5, rel=1e-10)
    # with a source of half the growth at the centre: the other half is supplied, the flow is the source's
    sources = np.zeros(grid.shape)
    sources[5, 10] = 0.5 * rate * 0.5
    for _ in range(5):
        t += dt
        solver.set_grid(grid.with_width(np.full(grid.shape, w0 + rate * t)))
        info = solver.step(state, dt, sources=sources)
        balance = info.injected + info.opened + info.supplied - info.stored - info.leaked - info.outflow
        assert abs(balance) < 1e-12 * info.stored
    assert info.supplied == pytest.approx(0.5 * rate * dt * 0.5, rel=1e-10)
    corner = max(abs(state.u[0, 1]), abs(state.v[1, 0]))
    assert corner < 0.05 * max(np.abs(state.u).max(), np.abs(state.v).max())
