"""Output-independent time stepping (simulator.simulate, interpolate.py): the steps land on schedule
breakpoints and the end time only, snapshots between steps are interpolated, so the number of snapshots does
not change the solution, and an interpolated snapshot balances its volumes as well as its two steps do."""

import dataclasses

import numpy as np
import pytest

from hfgpu.fracture.simulator import simulate
from hfgpu.records import MemorySink
from hfgpu.scene import load_scene

from .helpers import SCENES, scene


def _run(sc, snapshots: int):
    sc = sc.replace(output=dataclasses.replace(sc.output, every=sc.run.end_time / snapshots))
    sink = MemorySink()
    return simulate(sc, sink), sink


def _assert_same_final_state(sc):
    (few, few_sink), (many, many_sink) = _run(sc, 5), _run(sc, 100)
    t0 = few["t0"]   # no snapshot before the starting fracture forms
    assert len(few_sink.fracture_snapshots) == sum(sc.run.end_time * k / 5 > t0 for k in range(1, 6))
    assert len(many_sink.fracture_snapshots) == sum(sc.run.end_time * k / 100 > t0 for k in range(1, 101))
    assert few["steps"] == many["steps"]
    assert [b.time for b in few_sink.fracture_balances] == [b.time for b in many_sink.fracture_balances]
    assert few == many                                   # every summary value, bit for bit
    a, b = few_sink.fracture_snapshots[-1], many_sink.fracture_snapshots[-1]
    assert a.time == b.time == sc.run.end_time and a.frame == b.frame
    for name in ("width", "pressure", "leakoff_rate", "opening_time"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.extras.keys() == b.extras.keys()
    for name in a.extras:
        np.testing.assert_array_equal(a.extras[name], b.extras[name], err_msg=name)
    return many, many_sink


@pytest.mark.parametrize("front", ["cells", "subgrid"])
def test_five_and_a_hundred_snapshots_give_the_same_run(front):
    # radial case I (storage-viscosity, 5 m cells), both fronts; with a leak-off scene for the cells front
    sc = load_scene(SCENES / "radial_I.toml")
    _assert_same_final_state(sc.replace(fracture=dataclasses.replace(sc.fracture, front_tracking=front)))


def test_same_run_with_leakoff_shut_in_and_coarsening():
    sched = '[{ until = "60 s", rate = "1e-3 m**3/s" }, { until = "100 s", rate = "0 m**3/s" }]'
    sc = scene(end_time="100 s", cell="0.5 m", CL="1e-5 m/s**0.5", schedule=sched)
    sc = sc.replace(mesh=dataclasses.replace(sc.mesh, max_cells_across=12))
    out, sink = _assert_same_final_state(sc)
    assert out["coarsenings"] >= 1
    assert any(b.time == 60.0 for b in sink.fracture_balances)      # the breakpoint is a step target


def test_interpolated_snapshots_balance_their_volumes():
    """Snapshots inside a step: stamped with the output time, injected = stored + leaked as well as at the
    steps around them (to round-off beyond the steps' own Newton residual), stored = the sum of the widths,
    the widths between the two steps' widths and the leaked volume between theirs."""
    sc = scene(end_time="100 s", cell="0.5 m", CL="1e-5 m/s**0.5")
    out, sink = _run(sc, 100)
    steps = sink.fracture_balances
    step_times = np.array([b.time for b in steps])
    step_error = max(abs(b.injected - b.stored - b.leaked) for b in steps)
    inside = 0
    for snap in sink.fracture_snapshots:
        e = {k: float(v) for k, v in snap.extras.items()}
        assert e["injected_volume"] == pytest.approx(1e-3 * snap.time, rel=1e-14)
        assert abs(e["injected_volume"] - e["stored_volume"] - e["leaked_volume"]) <= step_error + 1e-14 * e[
            "injected_volume"]
        assert e["stored_volume"] == pytest.approx(snap.width.sum() * snap.frame.dx * snap.frame.dz, rel=1e-14)
        j = int(np.searchsorted(step_times, snap.time))
        if step_times[j] != snap.time and j > 0:     # (j = 0: inside the first step, from the start)
            inside += 1
            before, after = steps[j - 1], steps[j]
            assert before.leaked <= e["leaked_volume"] <= after.leaked
            assert before.stored <= e["stored_volume"] <= after.stored
    assert inside > 50                       # most output times fall inside steps
    assert sink.fracture_snapshots[-1].time == step_times[-1] == 100.0
