"""A stage of several clusters: N parallel planar fractures on one in-plane grid, coupled by the stress shadow
and the wellbore node (``[completion]``, hfgpu.completion).

Cluster i is a fracture plane at the normal position y_i (its position along the well) with its own engine
(simulator._Engine: Newton step, front, leak-off, contact) on the shared grid: the same cells dx x dz and the
injection cell at the same (x, z) on every plane, so the planes' cell indices are those of one grid. Plane i's
system has the minimum stress

    sigma_i(x, z) = sigma_0(z) + offset_i + sum_{l != i} C(i <- l) w_l    (shadow.PlanesOperator.shadow_fields)

and takes the rate q_i of the wellbore node (hfgpu.perforations): p_w = p_i(q_i) + a_i q_i^2, sum_i q_i = Q(t),
p_i the fluid pressure in plane i's perforated cell.

The coupled step is a Jacobi iteration inside each time step. From the planes' states at t, every plane solves
[t, t + dt] with its rate q_i^k and the shadow of the other planes' widths of the last iterate (their widths at t
on the first); its inlet pressure p_i^k gives the linearisation p_i(q) = p_i^k + s_i (q - q_i^k), s_i the secant
of the last two iterates (else the previous step's; at the first step (p_i - sigma_i) / (3 q_i), the viscosity
vertex's p_net ~ q^(1/3)), and the node gives q^(k+1). The iteration stops when the wellbore pressures the
clusters taking fluid ask for, p_i^k + a_i (q_i^k)^2, agree within STAGE_TOLERANCE of their mean net pressure and
the shadow the new widths cast differs from the one the step used by less than STAGE_TOLERANCE of each plane's net
pressure at its inlet: iterate k is kept, p_w the mean of those pressures. It is not one block Newton because
each plane's step keeps its own front, retries and contact set (front_strategy.py): the engines run unchanged
behind one hook (_Engine.stress_shift); the shadow is a smooth far-field load, and the measured iterations per
step are in the summary (``stage_iterations``, ``unconverged_steps``) and docs/validation.md.

Time steps: the stage's step is the smallest of the planes' next steps (Eq. 35); when a plane takes a shorter
step (a retry, a long front advance) every plane redoes the step at that length. After the pumps stop each
cluster keeps its fluid (no cross-flow through the wellbore). One cluster without friction, offset or neighbour
runs the single-plane engine's steps unchanged. Checkpoints hold every plane's engine state and the node's split
(:meth:`StageEngine.state`).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import TYPE_CHECKING, Callable

import numpy as np

from ..perforations import Entry, split_rate
from ..records import BalanceRecord, StageRecord, StageSnapshot
from .engine_setup import FractureEngineSetup, fracture_engine_setup
from .shadow import PlanesOperator
from .simulator import _Engine, _landed, _step_times, MIN_STEP_FRACTION
from .views import front_extents, geometry, snapshot

if TYPE_CHECKING:
    from ..completion import Completion

#: Relative tolerance of the stage iteration (module docstring).
STAGE_TOLERANCE = 1e-3
#: Iterations of one step before it is taken as it is (counted in ``unconverged_steps``).
STAGE_ITERATIONS = 12


class ClusterInlet:
    """The pump schedule as one cluster's engine sees it: the pump rate times this cluster's ``share``, constant
    over a step and set by the wellbore node before it; ``commit(t)`` books the volume to t."""

    def __init__(self, pump, share: float):
        self.pump, self.share = pump, share
        self.t_c, self.v_c = 0.0, 0.0

    @property
    def stages(self):
        return tuple(dataclasses.replace(s, rate=s.rate * self.share) for s in self.pump.stages)

    @property
    def end(self) -> float:
        return self.pump.end

    def volume(self, t: float) -> float:
        """The volume injected into this cluster to t [m^3] (t in the current step, or at its start)."""
        return self.v_c + self.share * (self.pump.volume(t) - self.pump.volume(self.t_c))

    def mean_rate(self, t0: float, t1: float) -> float:
        return self.share * self.pump.mean_rate(t0, t1)

    def rate(self, t: float) -> float:
        return self.share * self.pump.rate(t)

    def commit(self, t: float) -> None:
        self.v_c, self.t_c = self.volume(t), t


class StageEngine:
    """The planes of a stage and the coupled step (module docstring)."""

    def __init__(self, setup: FractureEngineSetup, completion: Completion, density: float):
        n = completion.clusters
        self.pump = setup.schedule
        self.inlets = [ClusterInlet(self.pump, 1.0 / n) for _ in range(n)]
        self.planes = [_Engine(dataclasses.replace(setup, schedule=inlet)) for inlet in self.inlets]
        first = self.planes[0]
        self.t0 = self.t = first.t0
        for inlet in self.inlets:   # the starting fractures hold Q t0 / N each
            inlet.commit(self.t0)
        self.coefficients = completion.entry_coefficients(density)
        self.offsets = completion.offsets()
        self.operator = PlanesOperator(first.dx, first.dz, first.e_prime, completion.positions)
        self.sources = [self._widths(plane) for plane in self.planes]
        self._shadow_fields()
        self.rates = np.full(n, self.pump.rate(self.t0) / n)   # the last pumping step's split
        self.step_rates = self.rates.copy()                      # the rates over the last step
        self.slopes: np.ndarray | None = None
        self.p_wellbore = math.nan
        self.iterations = self.unconverged = self.steps = 0
        self.max_balance_error = np.zeros(n)
        if n > 1 or self.offsets.any():
            for k, plane in enumerate(self.planes):
                plane.stress_shift = functools.partial(self._shift, k)

    @staticmethod
    def _widths(plane: _Engine) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(ix, iz, w) of a plane's active cells: a source of the shadow."""
        return plane.ix.copy(), plane.iz.copy(), plane.grid["w"][plane.rows, plane.cols].copy()

    def _shadow(self, k: int, ix: np.ndarray, iz: np.ndarray, sources) -> np.ndarray:
        cells = [(s[0], s[1]) for s in sources]
        return self.operator.on_plane(k, (ix, iz), cells, [s[2] for s in sources])

    def _shadow_fields(self) -> None:
        """The shadow of the sources on every cell of the box that holds all planes' grids (``box``, ``fields``:
        PlanesOperator.shadow_fields, N forward FFTs for all planes)."""
        boxes = [(p.grid.ix0, p.grid.iz0, p.grid.shape[1], p.grid.shape[0]) for p in self.planes]
        ix0, iz0 = min(b[0] for b in boxes), min(b[1] for b in boxes)
        self.box = (ix0, iz0, max(b[0] + b[2] for b in boxes) - ix0, max(b[1] + b[3] for b in boxes) - iz0)
        self.fields = self.operator.shadow_fields(self.box, [(s[0], s[1]) for s in self.sources],
                                                  [s[2] for s in self.sources])

    def _shift(self, k: int, ix: np.ndarray, iz: np.ndarray) -> np.ndarray:
        """_Engine.stress_shift of plane k: its offset and the shadow of the other planes' last iterate (read from
        ``fields``; on a cell a plane's grid has grown past ``box`` to during the step, computed there)."""
        ix0, iz0, nx, nz = self.box
        if np.all((ix >= ix0) & (ix < ix0 + nx) & (iz >= iz0) & (iz < iz0 + nz)):
            return self.offsets[k] + self.fields[k][iz - iz0, ix - ix0]
        return self.offsets[k] + self._shadow(k, ix, iz, self.sources)

    def inlet_pressures(self) -> np.ndarray:
        return np.array([float(p.grid["p"][p.rows[p.inj], p.cols[p.inj]]) for p in self.planes])

    def net_pressures(self) -> np.ndarray:
        """Each plane's inlet pressure less its rock stress and offset there (the shadow not taken off) [Pa]."""
        return self.inlet_pressures() - np.array([float(p.sigma_a[p.inj]) for p in self.planes]) - self.offsets

    def step(self, dt: float, keep_ends: bool = False) -> float:
        """The coupled step [t, t + dt] (module docstring); returns the step taken."""
        n = len(self.planes)
        states = [p.state() for p in self.planes] if n > 1 else None
        q_total = self.pump.mean_rate(self.t, self.t + dt)
        rates = self.rates * (q_total / self.rates.sum()) if self.rates.sum() > 0.0 else np.full(n, q_total / n)
        before: tuple[np.ndarray, np.ndarray] | None = None
        k, fresh = 0, True
        while True:
            k += 1
            if not fresh:
                for plane, state in zip(self.planes, states):
                    plane.restore(state)
            fresh = False
            for inlet, q in zip(self.inlets, rates):
                inlet.share = q / q_total if q_total > 0.0 else 1.0 / n
            taken = min(plane.step(dt, keep_ends) for plane in self.planes)
            if n > 1 and taken < dt * (1.0 - 1e-12):   # a plane shortened the step: all redo it at that length
                dt, k, before = taken, 0, None
                continue
            self.iterations += 1
            if n == 1:
                self.p_wellbore = float(self.inlet_pressures()[0] + self.coefficients[0] * rates[0] ** 2)
                break
            new_rates, done = self._update(rates, q_total, before)
            before = (rates, self.inlet_pressures())
            if done or k >= STAGE_ITERATIONS:
                self.unconverged += not done
                break
            rates = new_rates
        self.step_rates = rates
        if q_total > 0.0:   # the split a later pumping step starts from
            self.rates = rates
        for inlet in self.inlets:
            inlet.commit(self.t + dt)
        self.t += dt
        self.steps += 1
        return dt

    def _update(self, rates: np.ndarray, q_total: float, before) -> tuple[np.ndarray, bool]:
        """The node's next rates from the planes' inlet pressures after an iterate, and whether the iterate is
        converged (module docstring); the iterate's widths become the shadow's sources."""
        pressures, net = self.inlet_pressures(), self.net_pressures()
        used = [self._shift(k, p.ix, p.iz) for k, p in enumerate(self.planes)]
        self.sources = [self._widths(plane) for plane in self.planes]
        self._shadow_fields()
        change = max(float(np.max(np.abs(self._shift(k, p.ix, p.iz) - used[k]), initial=0.0))
                     / max(abs(float(net[k])), 1.0) for k, p in enumerate(self.planes))
        if q_total <= 0.0:
            self.p_wellbore = math.nan
            return rates, change <= STAGE_TOLERANCE
        slopes = self._slopes(rates, pressures, net, q_total, before)
        entries = [Entry(float(p), float(s), float(q)) for p, s, q in zip(pressures, slopes, rates)]
        new_rates, _ = split_rate(q_total, entries, self.coefficients)
        heads = pressures + self.coefficients * rates**2   # the wellbore pressure each cluster asks for
        taking = rates > 0.0
        self.p_wellbore = float(heads[taking].mean())
        spread = float(np.max(np.abs(heads[taking] - self.p_wellbore)))
        done = spread <= STAGE_TOLERANCE * float(np.mean(net)) and change <= STAGE_TOLERANCE
        return new_rates, done

    def _slopes(self, rates, pressures, net, q_total, before) -> np.ndarray:
        """dp_i/dq_i: the secant of the last two iterates where the rate moved and it is positive, else the
        previous step's, else (p_i - sigma_i) / (3 q_i) (module docstring)."""
        if self.slopes is None:
            self.slopes = np.maximum(net, 1e-3 * np.abs(pressures)) / (3.0 * np.maximum(rates, 1e-6 * q_total))
        if before is not None:
            dq, dp = rates - before[0], pressures - before[1]
            moved = np.abs(dq) > 1e-9 * q_total
            secant = np.divide(dp, dq, out=np.zeros_like(dp), where=moved)
            self.slopes = np.where(moved & (secant > 0.0), secant, self.slopes)
        return self.slopes

    def next_dt(self, dt_prev: float) -> float:
        return min(plane.next_dt(dt_prev) for plane in self.planes)

    def state(self) -> dict:
        """Everything needed to continue from now (a checkpoint): each plane's engine state, each inlet's booked
        volume, the split and the counters. The shadow's sources are the planes' widths, cast again on restore."""
        return {"planes": {f"plane_{k}": p.state() for k, p in enumerate(self.planes)},
                "inlets": np.array([[i.t_c, i.v_c, i.share] for i in self.inlets]),
                "t": self.t, "rates": self.rates.copy(), "step_rates": self.step_rates.copy(),
                "slopes": np.array([]) if self.slopes is None else self.slopes.copy(),
                "p_wellbore": self.p_wellbore, "iterations": self.iterations, "unconverged": self.unconverged,
                "steps": self.steps, "max_balance_error": self.max_balance_error.copy()}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state` of a stage of the same scene."""
        for k, plane in enumerate(self.planes):
            plane.restore(state["planes"][f"plane_{k}"])
        for inlet, (t_c, v_c, share) in zip(self.inlets, np.asarray(state["inlets"])):
            inlet.t_c, inlet.v_c, inlet.share = float(t_c), float(v_c), float(share)
        self.t = float(state["t"])
        self.rates, self.step_rates = np.array(state["rates"]), np.array(state["step_rates"])
        self.slopes = np.array(state["slopes"]) if np.size(state["slopes"]) else None
        self.p_wellbore = float(state["p_wellbore"])
        self.iterations, self.unconverged = int(state["iterations"]), int(state["unconverged"])
        self.steps, self.max_balance_error = int(state["steps"]), np.array(state["max_balance_error"])
        self.sources = [self._widths(plane) for plane in self.planes]
        self._shadow_fields()

    def record(self) -> StageRecord:
        """The stage at the current time: each cluster's balance record, rate and the wellbore pressure."""
        return StageRecord(time=self.t, wellbore_pressure=self.p_wellbore, rates=self.step_rates.copy(),
                           clusters=tuple(plane.balance() for plane in self.planes))


def stage_balance(record: StageRecord) -> BalanceRecord:
    """The stage's balance as one fracture's: volumes and areas summed, the wellbore pressure as the injection
    pressure (while the pumps stop, when no wellbore pressure joins the clusters: the inlet pressure of the cluster
    that has taken the most fluid), the net pressure, inlet width, length and height those of that cluster."""
    c = record.clusters
    lead = c[int(np.argmax([r.injected for r in c]))]
    injected, stored = sum(r.injected for r in c), sum(r.stored for r in c)
    pressure = record.wellbore_pressure if math.isfinite(record.wellbore_pressure) else lead.injection_pressure
    return BalanceRecord(time=record.time, injected=injected, stored=stored, leaked=sum(r.leaked for r in c),
                         injection_pressure=pressure, net_pressure=lead.net_pressure,
                         efficiency=stored / injected if injected > 0.0 else math.nan,
                         area=sum(r.area for r in c), length=lead.length, height=lead.height,
                         inlet_width=lead.inlet_width)


def simulate(scene, sink, progress: Callable[[float], None] | None = None, checkpoint=None,
             resume: dict | None = None) -> dict:
    """Run the stage of ``scene`` (module docstring) to ``run.end_time`` as simulator.simulate runs one fracture:
    ``sink.fracture_balance`` gets the stage's balance (:func:`stage_balance`) after every step,
    ``sink.stage_record`` (where the sink has it) each step's :class:`hfgpu.records.StageRecord`,
    ``sink.fracture_snapshot`` the snapshots of the first cluster and ``sink.stage_snapshot`` (where the sink has
    it) every cluster's (:class:`hfgpu.records.StageSnapshot`). Returns simulator.simulate's summary of the
    stage (summed volumes and area) with ``clusters`` (one summary per cluster: its volumes, footprint, rate,
    inlet pressure, front extents), ``wellbore_pressure``, ``stage_iterations`` and ``unconverged_steps``.
    Checkpoints as simulator.simulate's: ``checkpoint.save(t, {"stage": StageEngine.state(), "dt": next step,
    "target": index of the step target})`` after the first step past each interval; ``resume`` continues from
    such a state."""
    return run(fracture_engine_setup(scene), scene.completion, scene.fluid.density, sink, progress, checkpoint,
               resume)


def run(setup: FractureEngineSetup, completion: Completion, density: float, sink,
        progress: Callable[[float], None] | None = None, checkpoint=None, resume: dict | None = None) -> dict:
    """:func:`simulate` of a stage given as its planes' engine setup (``schedule`` the pump's), its completion and
    the fluid density [kg/m^3] (the perforation friction's)."""
    stage = StageEngine(setup, completion, density)
    first = stage.planes[0]
    targets, outputs = _step_times(setup, stage.t0)
    dt = setup.numerics.time_step_relaxation * min(first.dx, first.dz) / first.v_front
    index = 0
    if resume is not None:
        stage.restore(resume["stage"])
        dt, index = float(resume["dt"]), int(resume["target"])
    k = sum(1 for t in outputs if t < stage.t or _landed(t, stage.t)) if resume is not None else 0
    stage_record = getattr(sink, "stage_record", None)
    stage_snapshot = getattr(sink, "stage_snapshot", None)
    for index in range(index, len(targets)):
        target = targets[index]
        while stage.t < target * (1 - 1e-12):
            remaining = target - stage.t
            step = min(dt, remaining)
            if remaining - step < 1e-3 * step:
                step = remaining
            if step < MIN_STEP_FRACTION * stage.t:
                from ..errors import SimulationError

                raise SimulationError(f"the time step fell to {step:.3g} s (below {MIN_STEP_FRACTION:g} of the "
                                      "time)", time=stage.t)
            taken = stage.step(step, keep_ends=k < len(outputs) and outputs[k] < stage.t + step)
            if abs(stage.t - target) < 1e-9 * target:
                stage.t = target
                for plane in stage.planes:
                    plane.t = target
            record = stage.record()
            for i, r in enumerate(record.clusters):
                if r.injected > 0.0:
                    stage.max_balance_error[i] = max(stage.max_balance_error[i],
                                                     abs(r.injected - r.stored - r.leaked) / r.injected)
            sink.fracture_balance(stage_balance(record))
            if stage_record is not None:
                stage_record(record)
            if progress is not None:
                progress(stage.t)
            while k < len(outputs) and (outputs[k] < stage.t or _landed(outputs[k], stage.t)):
                for i, plane in enumerate(stage.planes):
                    view = plane.now() if _landed(outputs[k], stage.t) else plane.between(outputs[k])
                    snap = snapshot(plane, view, outputs[k])
                    if i == 0:
                        sink.fracture_snapshot(snap)
                    if stage_snapshot is not None:
                        stage_snapshot(StageSnapshot(i, snap))
                k += 1
            dt = stage.next_dt(dt if taken == step else taken)
            if checkpoint is not None and checkpoint.due(stage.t):
                checkpoint.save(stage.t, {"stage": stage.state(), "dt": dt, "target": index})
    return summary(stage)


#: The per-cluster values the summary also gives as scalars ``cluster_<i>_<key>`` (the results file's /summary).
CLUSTER_SUMMARY = ("rate", "injected", "stored", "p_inlet", "area", "length", "height")


def summary(stage: StageEngine) -> dict:
    """The stage's summary (:func:`simulate`), with each cluster's CLUSTER_SUMMARY values as scalars."""
    record = stage.record()
    total = stage_balance(record)
    clusters = []
    for i, plane in enumerate(stage.planes):
        r = record.clusters[i]
        clusters.append(dict(injected=r.injected, stored=r.stored, leaked=r.leaked, rate=float(stage.step_rates[i]),
                             p_inlet=r.injection_pressure, w_inlet=r.inlet_width,
                             max_balance_error=float(stage.max_balance_error[i]), cells=int(plane.grid["active"].sum()),
                             steps=plane.steps, newton_iterations=plane.newton_iterations,
                             **front_extents(plane, plane.now()), **geometry(plane, plane.now())))
    flat = {f"cluster_{i}_{key}": c[key] for i, c in enumerate(clusters) for key in CLUSTER_SUMMARY}
    return dict(time=stage.t, t0=stage.t0, steps=stage.steps, stage_iterations=stage.iterations,
                unconverged_steps=stage.unconverged, dx=stage.planes[0].dx, dz=stage.planes[0].dz,
                injected=total.injected, stored=total.stored, leaked=total.leaked, area=total.area,
                wellbore_pressure=record.wellbore_pressure,
                max_balance_error=float(stage.max_balance_error.max()), clusters=clusters, **flat)
