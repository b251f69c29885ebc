"""Progress over simulated time (a tqdm bar with the wall time left) and the plain summary table of a run.

:class:`Progress` is both the ``progress(t)`` callable the simulators take and an output sink: it
follows the simulated time, counts steps and snapshots, and keeps the last balance records, from which
:meth:`Progress.stats` derives the run's totals.
"""

from __future__ import annotations

import sys
import time as _time
from typing import Any, TextIO

from tqdm import tqdm

from ..records import BalanceRecord, FractureSnapshot, ProppantSnapshot, SolidBalanceRecord


class Progress:
    """A progress bar from 0 to ``end_time`` [s] of simulated time (hidden when ``enabled`` is False)."""

    def __init__(self, end_time: float, *, enabled: bool = True, file: TextIO | None = None):
        self.end_time = float(end_time)
        self.time = 0.0
        self.counts = {"fracture_steps": 0, "fracture_snapshots": 0, "proppant_steps": 0,
                       "proppant_snapshots": 0}
        self.fracture: BalanceRecord | None = None
        self.proppant: SolidBalanceRecord | None = None
        self._started = _time.perf_counter()
        self._bar = tqdm(total=self.end_time, disable=not enabled, file=file or sys.stderr, leave=True,
                         bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s simulated "
                                    "[{elapsed} elapsed, {remaining} left]")

    def __call__(self, t: float) -> None:
        """Advance to simulated time ``t`` [s] (calls with an earlier time are ignored)."""
        t = min(float(t), self.end_time)
        if t > self.time:
            self._bar.update(t - self.time)
            self._bar.n = self.time = t  # no round-off drift: the bar ends at exactly end_time

    def fracture_balance(self, record: BalanceRecord) -> None:
        self.counts["fracture_steps"] += 1
        self.fracture = record
        self(record.time)

    def proppant_balance(self, record: SolidBalanceRecord) -> None:
        self.counts["proppant_steps"] += 1
        self.proppant = record
        self(record.time)

    def fracture_snapshot(self, snap: FractureSnapshot) -> None:
        self.counts["fracture_snapshots"] += 1
        self(snap.time)

    def proppant_snapshot(self, snap: ProppantSnapshot) -> None:
        self.counts["proppant_snapshots"] += 1
        self(snap.time)

    def close(self) -> None:
        self._bar.close()

    def stats(self) -> dict[str, Any]:
        """Simulated and wall time, the non-zero counts, and the last balances; fluid efficiency =
        stored / injected (the fracture volume over the pumped volume)."""
        out: dict[str, Any] = {"sim_time": self.time, "wall_time": _time.perf_counter() - self._started,
                               **{k: n for k, n in self.counts.items() if n}}
        if self.fracture is not None:
            f = self.fracture
            out.update(injected_volume=f.injected, stored_volume=f.stored, leaked_volume=f.leaked,
                       efficiency=f.stored / f.injected if f.injected > 0 else float("nan"),
                       balance_error=abs(f.injected - f.stored - f.leaked) / f.injected
                       if f.injected > 0 else 0.0)
        if self.proppant is not None:
            p = self.proppant
            out.update(proppant_injected=p.injected, proppant_in_domain=p.in_domain,
                       proppant_outflow=p.outflow)
        return out


#: Label and unit of the summary entries shown in the table, in display order.
_ROWS = {
    "status": ("status", ""), "sim_time": ("simulated time", "s"), "wall_time": ("wall time", "s"),
    "fracture_steps": ("fracture steps", ""), "fracture_snapshots": ("fracture snapshots", ""),
    "injected_volume": ("injected volume", "m^3"), "stored_volume": ("stored (fracture) volume", "m^3"),
    "leaked_volume": ("leaked volume", "m^3"), "efficiency": ("fluid efficiency", ""),
    "balance_error": ("relative volume balance error", ""),
    "proppant_steps": ("proppant steps", ""), "proppant_snapshots": ("proppant snapshots", ""),
    "proppant_injected": ("proppant injected", "m^3"), "proppant_in_domain": ("proppant in domain", "m^3"),
    "proppant_outflow": ("proppant outflow", "m^3"), "out": ("results file", ""),
}


def summary_table(summary: dict[str, Any]) -> str:
    """The summary as a plain two-column text table (known entries first, then the others)."""
    keys = [k for k in _ROWS if k in summary] + sorted(k for k in summary if k not in _ROWS)
    rows = []
    for key in keys:
        label, unit = _ROWS.get(key, (key.replace("_", " "), ""))
        value = summary[key]
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        rows.append((label, f"{text} {unit}".rstrip()))
    width = max((len(label) for label, _ in rows), default=0)
    return "\n".join(f"{label:<{width}}  {text}" for label, text in rows)
