"""Progress over simulated time: one tqdm bar per phase of a run (its name, the simulated time, the wall time
left), and the run's Python warnings held until the bars are done; the summary table of a run is in
:mod:`hfgpu.io.summary`.

:class:`Progress` is both the ``progress(t)`` callable the simulators take and an output sink: it
follows the simulated time, counts steps and snapshots, and keeps the last balance records, from which
:meth:`Progress.stats` derives the run's totals.
"""

from __future__ import annotations

import contextlib
import math
import sys
import time as _time
import warnings
from typing import Any, Iterator, TextIO

from tqdm import tqdm

from ..records import BalanceRecord, FractureSnapshot, ProppantSnapshot, SolidBalanceRecord


class Progress:
    """One progress bar per phase of a run over simulated time [s] (hidden when ``enabled`` is False).

    The first phase, ``phase`` (a name such as "fracture"), runs from 0 to ``end_time``; :meth:`phase` closes
    the bar and opens the next phase's (a coupled run: "fracture" over the whole schedule, then "proppant" from
    the proppant start). Each bar shows its phase, the simulated time and an estimate of the wall time left.
    """

    def __init__(self, end_time: float, *, enabled: bool = True, file: TextIO | None = None,
                 phase: str | None = None):
        self.end_time = float(end_time)
        self.time = 0.0
        self.counts = {"fracture_steps": 0, "fracture_snapshots": 0, "proppant_steps": 0,
                       "proppant_snapshots": 0}
        self.fracture: BalanceRecord | None = None
        self.proppant: SolidBalanceRecord | None = None
        self.phases: list[str] = []
        self.warnings: list[str] = []  # held by holding_warnings, printed by close
        self._enabled, self._file = enabled, file
        self._started = _time.perf_counter()
        self._bar = None
        self.phase(phase or "run", 0.0)

    def phase(self, name: str, start: float, end: float | None = None) -> None:
        """Close the current phase's bar and start phase ``name``'s, from simulated time ``start`` to ``end``
        (default ``end_time``) [s]."""
        if self._bar is not None:
            self._bar.close()
        self.phases.append(name)
        end = self.end_time if end is None else float(end)
        self.time = min(float(start), end)
        self._bar = tqdm(total=end, initial=self.time, desc=name, disable=not self._enabled,
                         file=self._file or sys.stderr, leave=True,
                         bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} s simulated "
                                    "[{elapsed} elapsed, {remaining} left]")
        self._end = end

    def __call__(self, t: float) -> None:
        """Advance to simulated time ``t`` [s] (calls with an earlier time are ignored)."""
        t = min(float(t), self._end)
        if t > self.time:
            self._bar.update(t - self.time)
            self._bar.n = self.time = t  # no round-off drift: the bar ends at exactly its phase's end

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

    @contextlib.contextmanager
    def holding_warnings(self) -> Iterator[None]:
        """Keep the Python warnings raised inside (when the bar is shown) instead of letting them print into
        the bar; :meth:`close` prints them after it, one line each."""
        if not self._enabled:
            yield
            return
        with warnings.catch_warnings(record=True) as caught:
            try:
                yield
            finally:
                for w in caught:
                    line = " ".join(str(w.message).split())
                    if line not in self.warnings:
                        self.warnings.append(line)

    def close(self) -> None:
        """Close the bar, then print the held warnings as ``hfgpu: warning: <message>`` lines (no source
        paths)."""
        self._bar.close()
        out = self._file or sys.stderr
        for line in self.warnings:
            print(f"hfgpu: warning: {line}", file=out, flush=True)
        self.warnings.clear()

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
            if math.isfinite(f.net_pressure):  # the last step's pressure (at shut-in, an ISIP-like value)
                out.update(injection_pressure_end=f.injection_pressure, net_pressure_end=f.net_pressure)
        if self.proppant is not None:
            p = self.proppant
            out.update(proppant_injected=p.injected, proppant_in_domain=p.in_domain,
                       proppant_outflow=p.outflow)
        return out

