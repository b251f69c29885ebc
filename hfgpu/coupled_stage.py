"""The coupled run of a stage: the clusters' fractures (hfgpu.fracture.stage), then each cluster's proppant in its
own fracture history, all clusters in one MP-PIC engine (``[completion]`` with ``physics = ["fracture",
"proppant"]``; one-way coupling, as :func:`hfgpu.coupled.simulate`).

1. The stage's fracture over the whole schedule: every cluster's snapshots every ``[coupling] fracture_every``
   and the wellbore node's split of the fluid at every step go to the sink and to memory.
2. The proppant grid: one plane's grid covering the union of the clusters' largest footprints plus ``[coupling]
   margin`` cells (:func:`hfgpu.coupling.proppant_frame` per cluster, the planes sharing cells and injection
   point), repeated once per cluster side by side (:class:`hfgpu.stage_blocks.Blocks`); block i follows cluster
   i's width and leak-off history, its inlet is the annulus around cluster i's perforation, and the slurry rate
   splits among the inlets as the fluid did (:class:`hfgpu.stage_blocks.ClusterSplit`): each cluster gets the
   proppant its fluid carries.
3. The MP-PIC run from the proppant start, as the single fracture's; its snapshots carry ``bridging_risk`` and
   ``cluster`` (hfgpu.stage_blocks) and go to ``/proppant`` (the stage's grid, clusters side by side).

Summary: the stage fracture's values prefixed ``fracture_`` (its ``cluster_<i>_*`` values unprefixed), the
proppant's prefixed ``proppant_``, and per cluster ``cluster_<i>_solid`` (proppant in the cluster at the end
[m^3]), ``cluster_<i>_solid_share`` (its share of the proppant in the stage), ``cluster_<i>_propped_area``
(cells whose proppant would cover the width when closed, hfgpu.propped.propped_cells) and
``cluster_<i>_created_area`` (open cells of its block). The closure after the run adds each cluster's
conductivity values (hfgpu.runner). Checkpoints as the single fracture's one-way coupled run; no two-way mode.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable

import numpy as np

from .coupled import (Timings, _BridgingRisk, _FractureTee, late_start, proppant_geometry, proppant_phase,
                      proppant_start_time)
from .coupling import FractureHistory, proppant_frame
from .fracture import stage
from .fracture.engine_setup import fracture_engine_setup
from .fracture.mesh import injection_cell_centre
from .io.sink import ResultsSink
from .propped import created_area, propped_cells
from .proppant.engine_setup import proppant_engine_setup
from .proppant.injection import batch_solid_volume
from .proppant.simulator import ProppantSimulation
from .records import GridFrame, ProppantSnapshot, StageRecord, StageSnapshot
from .scene import Scene
from .stage_blocks import Blocks, ClusterSplit, cluster_view


class _StageTee(_FractureTee):
    """Sink of the stage's fracture phase: records go on to ``sink``; every cluster's snapshots are kept in
    ``clusters``, the clusters' injected volumes at every step in ``times`` / ``injected``."""

    def __init__(self, sink: ResultsSink, timings: Timings, clusters: int):
        super().__init__(sink, timings)
        self.clusters: list[list] = [[] for _ in range(clusters)]
        self.times: list[float] = []
        self.injected: list[list[float]] = []

    def stage_record(self, record: StageRecord) -> None:
        self.times.append(record.time)
        self.injected.append([r.injected for r in record.clusters])
        forward = getattr(self.sink, "stage_record", None)
        if forward is not None:
            with self.timings.measure("io"):
                forward(record)

    def stage_snapshot(self, record: StageSnapshot) -> None:
        self.clusters[record.cluster].append(record.snapshot)
        forward = getattr(self.sink, "stage_snapshot", None)
        if forward is not None:
            with self.timings.measure("io"):
                forward(record)


class _Labelled(_BridgingRisk):
    """The proppant phase's sink (hfgpu.coupled._BridgingRisk) adding the grid field ``cluster``."""

    def __init__(self, sink, factor: float, timings: Timings, labels: np.ndarray):
        super().__init__(sink, factor, timings)
        self.labels = labels

    def proppant_snapshot(self, snap: ProppantSnapshot) -> None:
        super().proppant_snapshot(dataclasses.replace(snap, grid={**snap.grid, "cluster": self.labels}))


def union_frame(frames: list[tuple[GridFrame, tuple[int, int]]]) -> tuple[GridFrame, tuple[int, int]]:
    """The grid covering every cluster's proppant grid; they share cells (the same dx, dz, and the injection cell
    on a cell centre), so the union is a grid of the same cells."""
    f0 = frames[0][0]
    x0 = min(f.x0 for f, _ in frames)
    z0 = min(f.z0 for f, _ in frames)
    x1 = max(f.x0 + s[1] * f.dx for f, s in frames)
    z1 = max(f.z0 + s[0] * f.dz for f, s in frames)
    frame = GridFrame(dx=f0.dx, dz=f0.dz, x0=x0, z0=z0)
    return frame, (int(round((z1 - z0) / f0.dz)), int(round((x1 - x0) / f0.dx)))


def simulate(scene: Scene, sink: ResultsSink, progress: Callable[[float], None] | None = None,
             timings: Timings | None = None, checkpoint=None, resume: dict | None = None) -> dict:
    """Run the coupled stage (module docstring); ``sink`` gets the stage's fracture records and the proppant
    records (on the scene's clock).

    Checkpoints as :func:`hfgpu.coupled.simulate`'s: {"phase": "fracture", "fracture": <the stage's>}, then
    {"phase": "proppant", "clock": "scene", "fracture_summary" (its scalars), "screen_out", "proppant"};
    ``resume`` is such a state plus what the results file kept before it: "stage_snapshots" (each cluster's
    fracture snapshots) and "stage_balance" (``/stage/balance``, the clusters' injected volumes)."""
    timings = timings if timings is not None else Timings()
    cfg = scene.coupling
    n = scene.completion.clusters
    tee = _StageTee(sink, timings, n)
    setup = fracture_engine_setup(scene, every=cfg.fracture_every)
    phase = resume["phase"] if resume is not None else "fracture"
    if resume is not None:
        tee.clusters = [list(snaps) for snaps in resume["stage_snapshots"]]
        kept = resume["stage_balance"]
        if kept:
            tee.times, tee.injected = list(kept["time"]), [list(row) for row in kept["injected"]]
    if phase == "fracture":
        with timings.measure("fracture"):
            fracture = stage.run(setup, scene.completion, scene.fluid.density, tee, progress,
                                 checkpoint=checkpoint and checkpoint.within(
                                     0.0, lambda state: {"phase": "fracture", "fracture": state}),
                                 resume=resume and resume["fracture"])
    else:
        fracture = resume["fracture_summary"]
    histories = [FractureHistory(snaps) for snaps in tee.clusters]
    start = late_start(scene, proppant_start_time(scene), min(float(h.times[0]) for h in histories))
    source = injection_cell_centre(scene)
    frame, shape = union_frame([proppant_frame(h, cfg.cell_size, cfg.margin, source=source) for h in histories])
    blocks = Blocks(frame, shape, n)
    fields = [h.width_field(frame, shape, cfg.min_width) for h in histories]

    def width_at(t: float) -> tuple[np.ndarray, np.ndarray]:
        pairs = [f(t) for f in fields]
        return blocks.tile([p[0] for p in pairs]), blocks.tile([p[1] for p in pairs])

    geometry = proppant_geometry(scene, frame, blocks.tiled_shape, width_at(start)[0])
    (port,) = geometry.inlets
    geometry = dataclasses.replace(geometry, inlets=tuple(dataclasses.replace(port, x=port.x + blocks.shift(i))
                                                          for i in range(n)))
    sim = ProppantSimulation(proppant_engine_setup(scene, geometry=geometry, start=start), width_field=width_at,
                             inlet_split=ClusterSplit(np.array(tee.times), np.array(tee.injected)))
    sim.watch.stride = blocks.stride
    risk = _Labelled(sink, scene.proppant.params.bridging_factor, timings, blocks.labels())
    scalars = {k: v for k, v in fracture.items() if isinstance(v, (int, float, str))}   # a checkpoint's
    proppant = proppant_phase(sim, risk, start, scalars, scene.proppant.params.theta_cp, timings, progress,
                              checkpoint, resume)
    last = sim.snapshot()
    last = dataclasses.replace(last, grid={**last.grid, "cluster": blocks.labels()})
    summary = {(k if k.startswith("cluster_") else f"fracture_{k}"): v for k, v in fracture.items()}
    summary.update({f"proppant_{k}": v for k, v in proppant.items()})
    summary.update(proppant_start=start, proppant_nx=blocks.tiled_shape[1], proppant_nz=shape[0],
                   proppant_dx=frame.dx, proppant_dz=frame.dz, proppant_cluster_nx=shape[1],
                   screen_out_cells=risk.flagged, screen_out_cells_max=risk.flagged_max,
                   screen_out_first_time=risk.first_time, time=scene.run.end_time)
    summary.update(cluster_values(last, n, scene.proppant.params.theta_cp))
    summary.update({f"time_{k}": v for k, v in timings.seconds.items()})
    return summary


def cluster_values(snap: ProppantSnapshot, clusters: int, theta_cp: float) -> dict[str, float]:
    """Per cluster of a stage's proppant snapshot: ``cluster_<i>_solid`` [m^3], ``cluster_<i>_solid_share``,
    ``cluster_<i>_propped_area`` and ``cluster_<i>_created_area`` [m^2] (module docstring)."""
    views = [cluster_view(snap, i) for i in range(clusters)]
    solids = [batch_solid_volume(v.parcels) for v in views]
    total = sum(solids)
    area = snap.frame.dx * snap.frame.dz
    out: dict[str, float] = {}
    for i, (view, solid) in enumerate(zip(views, solids)):
        out.update({f"cluster_{i}_solid": solid, f"cluster_{i}_solid_share": solid / total if total > 0 else math.nan,
                    f"cluster_{i}_propped_area": float(propped_cells(view, theta_cp).sum()) * area,
                    f"cluster_{i}_created_area": created_area(view)})
    return out
