"""The two-way coupled run (hfgpu/coupled.py ``simulate_two_way``, ``[coupling] mode``): the tiny layered scene in
both modes (volume balances at every step, the slurry's pressure), the slurry fields the proppant hands the
fracture (hfgpu/slurry_feedback.py), and the bad input of the mode key."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hfgpu import load_scene, open_results, run
from hfgpu.closure.permeability import kozeny_carman
from hfgpu.errors import SceneError
from hfgpu.proppant.params import MppicParams
from hfgpu.records import GridFrame, ProppantSnapshot
from hfgpu.scene_checks import describe
from hfgpu.slurry_feedback import slurry_of

TINY = (Path(__file__).parent / "scenes" / "tiny_coupled.toml").read_text()


def tiny(mode: str | None, extra: str = "") -> str:
    line = f'\nmode = "{mode}"' if mode is not None else ""
    return TINY.replace('fracture_every = "5 s"', f'fracture_every = "5 s"{line}{extra}')


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    folder = tmp_path_factory.mktemp("two_way")
    out = {}
    for mode in ("one-way", "two-way"):
        path = folder / f"{mode}.h5"
        out[mode] = (run(load_scene(tiny(mode)), path, progress=False), open_results(path))
    return out


@pytest.mark.parametrize("mode", ["one-way", "two-way"])
def test_fluid_and_solid_balances_hold_at_every_step(both, mode):
    summary, r = both[mode]
    b = r.fracture_balance
    fluid = np.abs(b["injected"] - b["stored"] - b["leaked"]) / b["injected"]
    # each accepted step balances its volume to round-off (hfgpu.fracture.newton._volume_conserving): measured
    # 3e-16 one-way, 8e-13 two-way before it (the leak-off ramp's curvature over Newton's last update)
    assert fluid.max() < 1e-13 and summary["fracture_max_balance_error"] < 1e-13
    s = r.proppant_balance
    solid = np.abs(s["injected"] - s["in_domain"] - s["outflow"] - s["screened_out"])
    assert np.all(solid <= 1e-10 * np.maximum(s["injected"], 1e-300))


def test_two_way_fracture_feels_the_slurry(both):
    one, _ = both["one-way"]
    two, r = both["two-way"]
    # the 10 % slurry is ~1.4x as viscous (Eq. 10): measured net pressure at the end +6.9 %, area -0.4 %
    assert two["net_pressure_end"] > 1.03 * one["net_pressure_end"]
    assert two["fracture_area"] <= one["fracture_area"]
    assert len(r.proppant_snapshots) == 3 and r.status == "complete"
    np.testing.assert_allclose(r.proppant_snapshots.times, [20.0, 30.0, 40.0], rtol=1e-9)
    for key in ("tip_screen_out_time", "net_pressure_rise", "packed_length", "time_footprint", "time_feedback"):
        assert key in two
    assert "tip_screen_out_time" not in one


def snapshot(theta: np.ndarray, width: np.ndarray, radius: float, frame=GridFrame(1.0, 1.0, 0.0, 0.0)):
    """A proppant snapshot with one parcel of one particle of ``radius`` in every cell where theta > 0."""
    k, i = np.nonzero(theta > 0.0)
    n = k.size
    parcels = dict(x=frame.x0 + frame.dx * i.astype(float), z=frame.z0 + frame.dz * k.astype(float),
                   radius=np.full(n, radius), particles=np.ones(n))
    return ProppantSnapshot(time=0.0, frame=frame, parcels=parcels,
                            grid=dict(volume_fraction=theta, width=width))


def test_slurry_fields_follow_the_viscosity_law_the_pack_and_the_bridges():
    params = MppicParams()
    theta = np.array([[0.0, 0.2, 0.59, 0.1]])
    width = np.array([[2e-3, 2e-3, 2e-3, 0.5e-3]])
    d = 0.4e-3
    fields = slurry_of(snapshot(theta, width, 0.5 * d), params)
    assert fields.ratio[0, 0] == 1.0
    assert fields.ratio[0, 1] == pytest.approx((1.0 - 0.2 / 0.6) ** -1.82)     # Eq. 10
    # packed: Darcy through the pack, w^2 / (12 k) with Kozeny-Carman k (d, porosity 1 - theta_cp)
    assert fields.ratio[0, 2] == pytest.approx(2e-3**2 / (12.0 * float(kozeny_carman(d, 0.4))))
    assert fields.ratio[0, 2] > 1e3
    # blocked: the pack, and the cell narrower than bridging_factor (2) x its grain
    assert fields.blocked.tolist() == [[False, False, True, True]]


def test_a_bad_mode_is_one_line_naming_the_key():
    with pytest.raises(SceneError) as err:
        load_scene(tiny("both"))
    assert err.value.path == "coupling.mode" and "\n" not in str(err.value) and "two-way" in str(err.value)


def test_two_way_needs_the_whole_cell_front():
    with pytest.raises(SceneError) as err:
        load_scene(tiny("two-way").replace("[coupling]", '[fracture]\nfront_tracking = "subgrid"\n[coupling]'))
    assert err.value.path == "coupling.mode"


def test_two_way_needs_both_physics():
    text = tiny("two-way").replace('physics = ["fracture", "proppant"]', 'physics = ["fracture"]')
    with pytest.raises(SceneError) as err:
        load_scene(text)
    assert "coupling" in str(err.value) and "proppant" in str(err.value)


def test_check_says_which_coupling_runs():
    assert "coupling: one-way (the default" in describe(load_scene(tiny(None)), "tiny")
    assert "coupling: two-way ([coupling] mode)" in describe(load_scene(tiny("two-way")), "tiny")


@pytest.mark.slow
def test_the_frac_pack_scene_screens_out(tmp_path):
    """hfgpu/scenes/frac_pack_tso.toml on 20 x 5 ft cells (a quarter of its cost): the slurry bridges at the tip
    while pumping, the net pressure climbs after it, the walls close onto the pack after shut-in."""
    from hfgpu import scene_path
    from hfgpu.scene_text import edit_scene

    scene = edit_scene(load_scene(scene_path("frac_pack_tso.toml")),
                       {"mesh.cell_size": ["20 ft", "5 ft"], "mppic.parcels_per_cell": 4})
    s = run(scene, tmp_path / "tso.h5", progress=False)
    # measured: screen-out at 200 s (slurry from 120 s, shut-in at 600 s), net pressure +3.58 MPa after it,
    # 61 m packed; the fracture does not close (its walls rest on the pack)
    assert 120.0 < s["tip_screen_out_time"] < 600.0
    assert s["net_pressure_rise"] > 2e6 and s["packed_length"] > 0.0
    assert np.isnan(s["fracture_closed_at"]) and s["fracture_max_balance_error"] < 1e-13
    b = open_results(tmp_path / "tso.h5").fracture_balance
    w0 = np.interp([s["tip_screen_out_time"], 600.0], b["time"], b["inlet_width"])
    assert w0[1] > 1.5 * w0[0]                                 # widening behind the bridged tip (measured 3x)
