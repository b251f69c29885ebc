"""The fracture and the proppant engine as the coupled loop drives them (hfgpu.coupled), as protocols: each is built
from its own typed frozen setup (hfgpu.fracture.engine_setup, hfgpu.proppant.engine_setup), keeps its own clock on
the scene's time and steps to a time it is given; the loop hands the fracture the slurry between intervals.
:class:`hfgpu.fracture.simulator.FractureRun` and :class:`hfgpu.proppant.simulator.ProppantSimulation` take them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

if TYPE_CHECKING:
    from .fracture.slurry import Slurry
    from .io.sink import ProppantSink
    from .records import ProppantSnapshot


@runtime_checkable
class FractureEngine(Protocol):
    """A fracture run, its records going to the sink it was built with."""

    @property
    def time(self) -> float:
        """Its clock [s] (the scene's)."""

    def advance(self, until: float) -> None:
        """Step to ``until`` [s, the scene's clock], a step landing on it."""

    def use_slurry(self, slurry: Slurry) -> None:
        """Step on in this slurry (viscosity ratios, blocked cells, the width floor after shut-in)."""

    def tips_held(self) -> int:
        """Cells where the slurry holds the front's lateral tip now (a tip screen-out when > 0)."""

    def summary(self) -> dict[str, Any]:
        """The run's summary so far."""

    def state(self) -> dict[str, Any]:
        """A checkpoint: what a run built with it as ``resume`` continues from."""


@runtime_checkable
class ProppantEngine(Protocol):
    """A proppant (MP-PIC) run on a fixed grid, its records going to the sink each call is given."""

    @property
    def time(self) -> float:
        """Its clock [s] (the scene's: its setup's ``start`` before the first step)."""

    @property
    def seconds(self) -> dict[str, float]:
        """Wall time [s] of its own phases: "fluid" (the fluid steps) and "parcels" (the parcel sub-loops)."""

    def advance(self, until: float, sink: ProppantSink) -> None:
        """Step to ``until`` [s, the scene's clock], a step landing on it, writing the snapshots due and a balance
        record a step."""

    def snapshot(self) -> ProppantSnapshot:
        """Parcels and grid fields now."""

    def finish(self, sink: ProppantSink) -> dict[str, Any]:
        """The last snapshot (unless one was just written) and the run's summary."""

    def checkpoint_state(self) -> dict[str, Any]:
        """A checkpoint: what :meth:`resume` continues from."""

    def resume(self, state: dict[str, Any]) -> None:
        """Continue from a :meth:`checkpoint_state` (the run freshly built from the same setup)."""
