"""The engines the coupled loop drives take its protocols (hfgpu.engines): FractureRun is a FractureEngine,
ProppantSimulation a ProppantEngine, with the protocols' signatures."""

from __future__ import annotations

import inspect

from hfgpu import load_scene, scene_path
from hfgpu.engines import FractureEngine, ProppantEngine
from hfgpu.fracture.engine_setup import fracture_engine_setup
from hfgpu.fracture.simulator import FractureRun
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation
from hfgpu.records import MemorySink


def _takes_the_protocols_calls(cls: type, protocol: type) -> None:
    """Each method of ``protocol`` is one of ``cls`` that takes its parameters, by name and in order (more only
    with defaults)."""
    for name, member in vars(protocol).items():
        if name.startswith("_") or not inspect.isfunction(member):
            continue
        wanted = list(inspect.signature(member).parameters)
        given = list(inspect.signature(getattr(cls, name)).parameters.values())
        assert [p.name for p in given[:len(wanted)]] == wanted, (cls.__name__, name)
        assert all(p.default is not inspect.Parameter.empty for p in given[len(wanted):]), (cls.__name__, name)


def test_the_fracture_run_is_a_fracture_engine():
    run = FractureRun(fracture_engine_setup(load_scene(scene_path("radial_I.toml"))), MemorySink())
    assert isinstance(run, FractureEngine)
    assert run.time == run.engine.t0 and run.tips_held() == 0
    _takes_the_protocols_calls(FractureRun, FractureEngine)


def test_the_proppant_simulation_is_a_proppant_engine():
    sim = ProppantSimulation(proppant_engine_setup(load_scene(scene_path("settling_stokes.toml"))))
    assert isinstance(sim, ProppantEngine) and sim.time == 0.0
    _takes_the_protocols_calls(ProppantSimulation, ProppantEngine)
