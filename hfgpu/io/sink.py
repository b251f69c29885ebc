"""What a simulator calls on its output sink, as protocols: the records of hfgpu.records go to
``fracture_snapshot`` / ``fracture_balance`` (the fracture simulator) and ``proppant_snapshot`` /
``proppant_balance`` (the proppant run loop). The HDF5 writer (hfgpu.io.results.ResultsWriter), the Rerun
recorder, the progress bar and hfgpu.records.MemorySink take all four; the coupled run's phase sinks
(hfgpu.coupled) take their phase's two; hfgpu.runner.FanOut hands each record to those of its sinks that take it.
"""

from __future__ import annotations

from typing import Protocol

from ..records import (BalanceRecord, FractureSnapshot, ProppantSnapshot, SolidBalanceRecord, StageRecord,
                       StageSnapshot)


class FractureSink(Protocol):
    """Takes the fracture simulator's records: a snapshot every output interval and at the end, a balance
    record every accepted time step."""

    def fracture_snapshot(self, snap: FractureSnapshot) -> None: ...

    def fracture_balance(self, record: BalanceRecord) -> None: ...


class ProppantSink(Protocol):
    """Takes the proppant run loop's records: a snapshot every output interval and at the end, a solid balance
    record every fluid step."""

    def proppant_snapshot(self, snap: ProppantSnapshot) -> None: ...

    def proppant_balance(self, record: SolidBalanceRecord) -> None: ...


class StageSink(Protocol):
    """Takes a stage's records (hfgpu.fracture.stage, several clusters): one every accepted time step, beside the
    stage's fracture balance record, and each cluster's snapshot at every output time."""

    def stage_record(self, record: StageRecord) -> None: ...

    def stage_snapshot(self, record: StageSnapshot) -> None: ...


class ResultsSink(FractureSink, ProppantSink, Protocol):
    """Takes the records of either simulator (a coupled run's)."""


#: the methods of a ResultsSink, in the order of hfgpu.records
METHODS = tuple(name for proto in (FractureSink, ProppantSink, StageSink) for name in vars(proto)
                if not name.startswith("_"))
