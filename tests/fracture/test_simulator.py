"""The time loop (simulate): sink protocol, volume balance every step, front monotonicity, layered stress,
shut-in, and errors raised before work starts or when a step cannot be solved."""

import dataclasses

import numpy as np
import pytest

from hfgpu.errors import SceneError, SimulationError
from hfgpu.fracture.simulator import initial_time, simulate
from hfgpu.records import MemorySink
from hfgpu.scene import load_scene

from .helpers import SCENES, scene, scene_text

# M-regime-ish small case: E' 3.2e10, Q 1e-3, mu 1 Pa s -> R(100 s) ~ 6 m (the M vertex, Savitski & Detournay 2002)
FAST = dict(end_time="100 s", cell="1 m", every="25 s")


def _run(sc):
    sink = MemorySink()
    times = []
    out = simulate(sc, sink, progress=times.append)
    return out, sink, times


def test_sink_protocol_balance_and_progress():
    out, sink, times = _run(scene(**FAST))
    assert len(sink.fracture_balances) == out["steps"] == len(times)
    assert times == sorted(times) and times[-1] == pytest.approx(100.0)
    assert [s.time for s in sink.fracture_snapshots] == pytest.approx([25.0, 50.0, 75.0, 100.0])
    for rec in sink.fracture_balances:   # injected = stored + leaked within 0.1 % at every step
        assert abs(rec.injected - rec.stored - rec.leaked) <= 1e-3 * rec.injected
        assert rec.injected == pytest.approx(1e-3 * rec.time, rel=1e-12)
    snap = sink.fracture_snapshots[-1]
    nz, nx = snap.width.shape
    for a in (snap.pressure, snap.leakoff_rate, snap.opening_time):
        assert a.shape == (nz, nx)
    open_ = np.isfinite(snap.opening_time)
    # bounding box of the active cells plus a one-cell margin: the border rows/columns are closed
    assert not open_[0].any() and not open_[-1].any() and not open_[:, 0].any() and not open_[:, -1].any()
    assert np.all(snap.width[~open_] == 0.0) and np.all(snap.width[open_] >= 0.0)
    assert snap.width[open_].sum() * snap.frame.dx * snap.frame.dz == pytest.approx(out["stored"], rel=1e-12)
    # injection cell centre at (injection.x, depth)
    x, z = snap.frame.centres(nz, nx)
    k, i = np.unravel_index(np.argmax(snap.width), snap.width.shape)
    assert (x[i], z[k]) == pytest.approx((0.0, 500.0))


def test_front_never_retreats_and_opening_times_are_kept():
    _, sink, _ = _run(scene(**FAST))
    previous = None
    for snap in sink.fracture_snapshots:
        x, z = snap.frame.centres(*snap.width.shape)
        cells = {(round(xx), round(zz)): t for (zz, xx), t in
                 zip(np.array(np.meshgrid(z, x, indexing="ij")).reshape(2, -1).T, snap.opening_time.ravel())
                 if np.isfinite(t)}
        if previous is not None:
            assert set(previous) <= set(cells)
            assert all(cells[c] == previous[c] for c in previous)
        previous = cells


def test_shut_in_keeps_the_injected_volume_and_the_balance():
    sched = '[{ until = "60 s", rate = "1e-3 m**3/s" }, { until = "100 s", rate = "0 m**3/s" }]'
    out, sink, _ = _run(scene(end_time="100 s", cell="1 m", CL="1e-5 m/s**0.5", schedule=sched, every="20 s"))
    assert any(abs(b.time - 60.0) < 1e-9 for b in sink.fracture_balances)          # a step lands on the breakpoint
    after = [b for b in sink.fracture_balances if b.time > 60.0]
    assert after and all(b.injected == pytest.approx(0.06, rel=1e-12) for b in after)
    assert after[-1].leaked > after[0].leaked and after[-1].stored < after[0].stored   # leak-off drains it
    for rec in sink.fracture_balances:
        assert abs(rec.injected - rec.stored - rec.leaked) <= 1e-3 * rec.injected
    assert out["cells"] >= max(np.isfinite(s.opening_time).sum() for s in sink.fracture_snapshots)


def test_fracture_grows_towards_lower_stress():
    # 10 MPa at the injection, 14 MPa above (shallower), 8 MPa below (deeper): z is positive downward
    layers = """
[[rock.layers]]
top = "0 m"
bottom = "497 m"
min_stress = "14 MPa"
[[rock.layers]]
top = "497 m"
bottom = "503 m"
min_stress = "10 MPa"
[[rock.layers]]
top = "503 m"
bottom = "600 m"
min_stress = "8 MPa"
"""
    out, _, _ = _run(scene(**FAST, layers=layers))
    assert out["down"] > 1.3 * out["up"]
    assert out["left"] == pytest.approx(out["right"], rel=1e-9)


def test_bad_input_is_rejected_before_work_starts():
    """A first stage that does not inject is refused by the scene's validation (hfgpu run and hfgpu check validate
    once; the engine checks nothing itself); the starting fracture's size by the engine's start."""
    from hfgpu.scene_checks import validate

    with pytest.raises(SceneError, match=r"injection.schedule\[0\].rate"):
        validate(scene(schedule='[{ until = "10 s", rate = "0 m**3/s" }, { until = "100 s", rate = "1e-3 m**3/s" }]'))
    with pytest.raises(SceneError, match="fracture.tip_asymptote"):
        load_scene(scene_text(fracture='[fracture]\ntip_asymptote = "magic"'))
    with pytest.raises(SceneError, match="fracture.tip_velocity"):
        load_scene(scene_text(fracture='[fracture]\ntip_velocity = "sonic"'))
    with pytest.raises(SceneError, match="fracture.partial_tip_cells"):
        load_scene(scene_text(fracture='[fracture]\npartial_tip_cells = 3'))
    with pytest.raises(SceneError, match="fracture.front_tracking.*subgrid"):
        load_scene(scene_text(fracture='[fracture]\nfront_tracking = "level set"'))
    with pytest.raises(SceneError, match="fracture.ribbon_fit.*two_term"):
        load_scene(scene_text(fracture='[fracture]\nribbon_fit = "quadratic"'))
    with pytest.raises(SceneError, match="fracture.initial_radius_cells"):
        simulate(scene(end_time="0.001 s", cell="1 m"), MemorySink())


def test_start_time_of_an_absurd_rate_is_zero_not_an_overflow():
    """initial_time in float64: Q^3 past 1e308 (a bare-number rate of 5.6e102 m^3/s, found by the CLI fuzz test)
    gives t0 = 0 for the M vertex; an ordinary rate gives the M vertex's closed-form time."""
    t0, power = initial_time(3e10, 12.0, 0.0, 0.0, 5.6e102, 1.0)
    assert t0 == 0.0 and power == pytest.approx(4.0 / 9.0)
    t0, _ = initial_time(3e10, 12.0, 0.0, 0.0, 1e-2, 1.0)
    assert 0.6955 * (3e10 * 1e-6 * t0**4 / 12.0) ** (1.0 / 9.0) == pytest.approx(1.0, rel=1e-12)


def test_start_time_of_an_absurd_radius_is_infinite_not_an_overflow():
    """initial_time in float64: R^9 past 1e308 (cells of 5e33 m, found by the CLI fuzz test) gives t0 = inf."""
    t0, _ = initial_time(3e10, 12.0, 1e6, 1e-6, 1e-2, 1.24e34)
    assert t0 == float("inf")


def test_newton_failure_raises_simulation_error_with_time_cell_and_residual():
    sc = scene(**FAST, fracture="[fracture]\nnewton_max_iterations = 1\nmax_step_retries = 1\n"
                                "newton_tolerance = 1e-12")
    with pytest.raises(SimulationError) as info:
        simulate(sc, MemorySink())
    err = info.value
    assert err.time is not None and err.cell is not None and err.residual is not None
    assert "Newton" in str(err)


def test_a_step_that_cannot_shrink_enough_stops_the_run_with_a_message(monkeypatch):
    """A sub-grid front that moves more than max_front_advance cells however short the step (forced here:
    every step reports twice the limit) halves its steps until they fall below MIN_STEP_FRACTION of the time:
    a SimulationError naming the knob, not a division by zero."""
    from hfgpu.fracture.front_subgrid import SubgridFront

    iterate = SubgridFront.front_iterations

    def too_far(front, eng, dt, start):
        res, _, converged = iterate(front, eng, dt, start)
        return res, 2.0 * eng.num.max_front_advance * min(eng.dx, eng.dz), converged

    monkeypatch.setattr(SubgridFront, "front_iterations", too_far)
    with pytest.raises(SimulationError, match="max_front_advance") as info:
        simulate(scene(**FAST, fracture='[fracture]\nfront_tracking = "subgrid"'), MemorySink())
    assert info.value.time is not None


def test_direct_and_krylov_runs_agree():
    base = scene(end_time="30 s", cell="1 m")
    krylov = base.replace(fracture=dataclasses.replace(base.fracture, linear_solver="krylov"))
    a, b = simulate(base, MemorySink()), simulate(krylov, MemorySink())
    assert a["cells"] == b["cells"]
    assert b["w_inlet"] == pytest.approx(a["w_inlet"], rel=1e-4)


def _five_layer_fracture(end, every):
    sc = load_scene(SCENES / "five_layer_demo.toml")
    return sc.replace(run=dataclasses.replace(sc.run, end_time=end, physics=("fracture",)),
                      output=dataclasses.replace(sc.output, every=every), proppant=None, coupling=None)


def test_results_do_not_depend_on_output_spacing():
    # five-layer demo (stress barriers), fracture only, 100 s: snapshots every 100, 50 or 5 s. Steps are
    # bounded by the front's measured advance (Eq. 35, max_front_advance), not by the output times. Measured:
    # extents within 0.9 %, widest opening within 1 %, same cell count. (The inlet cell sits in the
    # higher-stress perforated layer, pinched nearly shut; its width moves by up to 10 % with the step sequence
    # and is not compared here.)
    def summary(every):
        sink = MemorySink()
        out = simulate(_five_layer_fracture(100.0, every), sink)
        return out, float(sink.fracture_snapshots[-1].width.max())

    fine, fine_wmax = summary(5.0)
    for every in (100.0, 50.0):
        coarse, wmax = summary(every)
        for key in ("left", "right", "up", "down"):
            assert coarse[key] == pytest.approx(fine[key], rel=0.02), (every, key)
        assert wmax == pytest.approx(fine_wmax, rel=0.02), every
        assert coarse["cells"] == pytest.approx(fine["cells"], rel=0.03), every
        assert coarse["stored"] == pytest.approx(fine["stored"], rel=0.02), every


def test_contact_keeps_widths_non_negative_and_volume_exact():
    # the barrier rows beside the front used to reach -0.88 mm at 100 s; closed cells now hold w = 0 (contact)
    sink = MemorySink()
    out = simulate(_five_layer_fracture(60.0, 10.0), sink)
    assert min(float(s.width.min()) for s in sink.fracture_snapshots) >= -1e-9
    assert out["max_balance_error"] < 1e-9
    last = sink.fracture_snapshots[-1]
    closed = np.isfinite(last.opening_time) & (last.width == 0.0)
    assert closed.any()                                   # contact is active somewhere (the perforated layer)


@pytest.mark.parametrize("until, every", [("60 s", "20 s"), ("0.3 s", "0.1 s")])
def test_snapshot_at_an_output_time_that_is_also_a_breakpoint(until, every):
    # 3 x 0.1 s = 0.30000000000000004 s: equal to the 0.3 s breakpoint up to round-off
    end = 100.0 if until == "60 s" else 0.5
    sched = f'[{{ until = "{until}", rate = "1e-3 m**3/s" }}, {{ until = "{end} s", rate = "5e-4 m**3/s" }}]'
    sc = scene(end_time=f"{end} s", cell="1 m" if end == 100.0 else "0.05 m", schedule=sched, every=every)
    out, sink, _ = _run(sc)
    times = [s.time for s in sink.fracture_snapshots]
    assert times == pytest.approx([end * k / 5 for k in range(1, 6)], rel=1e-12)
    assert len(set(times)) == 5
    step_ends = [b.time for b in sink.fracture_balances]
    assert any(abs(t - float(until.split()[0])) < 1e-12 for t in step_ends)     # a step lands on the breakpoint
    assert min(np.diff(step_ends)) > 1e-9
