"""One particle sub-step of a particle engine on a given grid, fluid and parcels, for the kernel tests: the
engine's scatter -> grid fields -> gather -> push -> exchange, as a simulator's fluid step runs it. The Taichi
engine runs on HFGPU_ARCH (default cpu: bench/bench_gpu.py --tests runs these tests on CUDA)."""

from __future__ import annotations

import numpy as np

from hfgpu.proppant.engine import make_engine
from hfgpu.proppant.engine_seam import SubLoop
from hfgpu.proppant.grid import StaggeredGrid
from hfgpu.proppant.params import MppicParams
from hfgpu.proppant.parcels import FLOAT_FIELDS, INT_FIELDS, Parcels
from hfgpu.records import GridFrame

RHO_F, MU, G = 1000.0, 1e-3, 9.81
_ENGINES: dict = {}


def engine_for(name: str, frame: GridFrame, width: np.ndarray, params: MppicParams, gravity: float = G,
               outlets: np.ndarray | None = None, private: bool | None = None):
    """An engine on the grid (frame, width), reused by later calls with the same arguments."""
    outlets = np.zeros(width.shape, dtype=bool) if outlets is None else outlets
    key = (name, frame, width.tobytes(), width.shape, params, gravity, outlets.tobytes(), private)
    if key not in _ENGINES:
        grid = StaggeredGrid.from_width(frame, width)
        if name == "taichi":
            from hfgpu.proppant.engine_taichi import TaichiEngine

            engine = TaichiEngine(grid, params, RHO_F, MU, gravity, outlets, private=private)
            engine.stable_sort = True  # the parcels' order as Parcels.sort_by_cell's (the GPU's deposits kept)
        else:
            engine = make_engine(name, grid, params, RHO_F, MU, gravity, outlets)
        _ENGINES.clear()
        _ENGINES[key] = engine
    return _ENGINES[key]


def particle_step(name: str, frame: GridFrame, width: np.ndarray, parcels: Parcels, fluid: dict,
                  params: MppicParams, dt: float = 2e-3, gravity: float = G, substeps: int = 1,
                  private: bool | None = None) -> tuple[SubLoop, object]:
    """``substeps`` sub-steps of dt / substeps of engine ``name`` ("taichi" or "numpy") in the fluid (dict u,
    v, pressure); the parcels are updated in place, in their own order (the engine sorts them by cell).
    Returns the SubLoop and the engine (its moments are those after the step)."""
    engine = engine_for(name, frame, width, params, gravity, private=private)
    engine.set_parcels(parcels)
    order = np.argsort(parcels.cell_keys(frame, width.shape), kind="stable")
    engine.begin_step(fluid["u"], fluid["v"], fluid["pressure"])
    loop = engine.substeps(dt, substeps, 0.0)
    engine.commit()
    moved = engine.parcels()
    assert moved.n == parcels.n
    for name_ in FLOAT_FIELDS + INT_FIELDS:
        getattr(parcels, name_)[order] = getattr(moved, name_)
    return loop, engine

