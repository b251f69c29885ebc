"""Progress over simulated time: one tqdm bar per phase of a run (its name, the simulated time, the wall time
left, what limits the step), and the run's Python warnings held until the bars are done; the summary table of a
run is in :mod:`hfgpu.io.summary`.

:class:`Progress` is both the ``progress(t)`` callable the simulators take and an output sink: it
follows the simulated time, counts steps and snapshots, and keeps the last balance records, from which
:meth:`Progress.stats` derives the run's totals.

The time left is the simulated time left over the recent rate, measured over the last ``WINDOW`` seconds of
wall time up to now (a step still running counts as wall time without simulated time):

    left = (t_end - t) / r,    r = (t - t_0) / (now - w_0)

with (w_0, t_0) the oldest sample at most ``WINDOW`` s old (or the phase's first step, whose wall time, kernel
compilation included, is not counted). On a terminal the bar redraws every ``REFRESH`` s from a daemon thread;
elsewhere (a log file) a phase prints one plain line at its start, at every 10 % of the simulated time, every
``PLAIN_EVERY`` s of wall time and at its end. Engines report through :func:`note` and :func:`limit`, which
do nothing for a plain callable.
"""

from __future__ import annotations

import collections
import contextlib
import math
import sys
import threading
import time as _time
import warnings
from typing import Any, Callable, Iterator, TextIO

from tqdm import tqdm

from ..records import BalanceRecord, FractureSnapshot, ProppantSnapshot, SolidBalanceRecord

WINDOW = 45.0  # [s] of wall time over which the rate is measured
REFRESH = 1.0  # [s] of wall time between redraws of a terminal bar
PLAIN_EVERY = 60.0  # [s] of wall time between plain lines (not a terminal)
_FORMAT = "{desc}: {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} s simulated [{elapsed} elapsed, {left} left{postfix}]"
_PLAIN = "{desc}: {percentage:3.0f}% {n:.4g}/{total:.4g} s simulated [{elapsed} elapsed, {left} left{postfix}]"


class _Bar(tqdm):
    """A tqdm bar whose ``{left}`` and ``{postfix}`` come from ``extra()`` (no tqdm monitor thread)."""

    monitor_interval = 0

    def __init__(self, *args: Any, extra: Callable[[], dict[str, str]], **kwargs: Any):
        self._extra = extra
        super().__init__(*args, **kwargs)

    @property
    def format_dict(self) -> dict[str, Any]:
        return {**super().format_dict, **self._extra()}


class Progress:
    """One progress bar per phase of a run over simulated time [s] (hidden when ``enabled`` is False).

    The first phase, ``phase`` (a name such as "fracture"), runs from 0 to ``end_time``; :meth:`phase` closes
    the bar and opens the next phase's (a coupled run: "fracture" over the whole schedule, then "proppant" from
    the proppant start). Each bar shows its phase, the simulated time, an estimate of the wall time left (module
    docstring), a note (:meth:`note`) and what limits the step (:meth:`limit`). ``terminal`` (default: whether
    the output is a TTY) chooses a redrawn bar or plain lines; ``clock`` [s] is the wall clock.
    """

    def __init__(self, end_time: float, *, enabled: bool = True, file: TextIO | None = None,
                 phase: str | None = None, terminal: bool | None = None,
                 clock: Callable[[], float] = _time.monotonic):
        self.end_time = float(end_time)
        self.time = 0.0
        self.counts = {"fracture_steps": 0, "fracture_snapshots": 0, "proppant_steps": 0,
                       "proppant_snapshots": 0}
        self.fracture: BalanceRecord | None = None
        self.proppant: SolidBalanceRecord | None = None
        self.phases: list[str] = []
        self.warnings: list[str] = []  # held by holding_warnings, printed by close
        self._enabled, self._file, self._clock = enabled, file, clock
        out = file or sys.stderr
        self._terminal = bool(getattr(out, "isatty", lambda: False)()) if terminal is None else terminal
        self._started = _time.perf_counter()
        self._lock = threading.RLock()  # the state and the output, shared with the refresh thread
        self._bar: _Bar | None = None
        self._note: str | None = None
        self._limit: str | None = None
        self._samples: collections.deque[tuple[float, float]] = collections.deque()
        self._printed: tuple[float, float] | None = None  # (wall, simulated) of the last plain line
        self.phase(phase or "run", 0.0)
        self._stop = threading.Event()
        self._thread = None
        if enabled:
            self._thread = threading.Thread(target=self._refresh, name="hfgpu-progress", daemon=True)
            self._thread.start()

    def phase(self, name: str, start: float, end: float | None = None) -> None:
        """Close the current phase's bar and start phase ``name``'s, from simulated time ``start`` to ``end``
        (default ``end_time``) [s]."""
        with self._lock:
            self._end_phase()
            self.phases.append(name)
            end = self.end_time if end is None else float(end)
            self.time = min(float(start), end)
            self._end, self._phase_start = end, self._clock()
            self._note = self._limit = None
            self._samples.clear()
            if self._enabled and self._terminal:
                self._bar = _Bar(total=end, initial=self.time, desc=name, file=self._file or sys.stderr,
                                 leave=True, bar_format=_FORMAT, extra=self._extra)
            elif self._enabled:
                self._print()

    def __call__(self, t: float) -> None:
        """Advance to simulated time ``t`` [s] (calls with an earlier time are ignored); a step has returned,
        which ends a :meth:`note`."""
        with self._lock:
            now, self._note = self._clock(), None
            t = min(float(t), self._end)
            if t > self.time:
                if self._bar is not None:
                    self._bar.update(t - self.time)
                    self._bar.n = t  # no round-off drift: the bar ends at exactly its phase's end
                self.time = t
            if not self._samples or now - self._samples[-1][0] >= WINDOW / 45:
                self._samples.append((now, self.time))
            while len(self._samples) > 2 and self._samples[1][0] <= now - WINDOW:
                self._samples.popleft()
            if self._bar is None and self._enabled and self._printed is not None and (
                    self._tenth(self.time) > self._tenth(self._printed[1]) or now - self._printed[0] >= PLAIN_EVERY):
                self._print()

    def note(self, text: str | None) -> None:
        """Show ``text`` (e.g. "compiling kernels") on the phase's bar until the next step returns."""
        with self._lock:
            self._note = text
            self._show()

    def limit(self, dt: float, reason: str) -> None:
        """Show the step ``dt`` [s] and what limits it (e.g. "dt_max", "Courant 0.5", "front advance",
        "coupling interval") on the phase's bar, as ``dt 0.05 s (dt_max)``, until the next limit or phase."""
        with self._lock:
            self._limit = f"dt {dt:.3g} s ({reason})"

    def seconds_left(self) -> float | None:
        """The phase's wall time left [s] at the recent rate (module docstring); None before a rate is known."""
        with self._lock:
            if not self._samples:
                return None
            wall, sim = self._samples[0]
            rate = (self.time - sim) / max(self._clock() - wall, 1e-9)
            return (self._end - self.time) / rate if rate > 0 else None

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
        """Stop the refresh thread, close the bar, then print the held warnings as ``hfgpu: warning: <message>``
        lines (no source paths)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        with self._lock:
            self._end_phase()
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


    def _extra(self) -> dict[str, str]:
        """The ``{left}`` and ``{postfix}`` fields of a line: the time left, the note and the step's limit."""
        left = self.seconds_left()
        postfix = ", ".join(part for part in (self._note, self._limit) if part)
        return {"left": "?" if left is None else tqdm.format_interval(left),
                "postfix": postfix}  # tqdm writes ", <postfix>" when not empty

    def _tenth(self, t: float) -> int:
        return math.floor(10 * t / self._end) if self._end > 0 else 10

    def _print(self) -> None:
        """One plain line of the phase (not a terminal)."""
        now = self._clock()
        line = tqdm.format_meter(self.time, self._end, now - self._phase_start, prefix=self.phases[-1],
                                 bar_format=_PLAIN, **self._extra())
        print(line, file=self._file or sys.stderr, flush=True)
        self._printed = (now, self.time)

    def _show(self) -> None:
        """Redraw the bar now (a terminal) or print a line (else)."""
        if self._bar is not None:
            self._bar.refresh()
        elif self._enabled:
            self._print()

    def _end_phase(self) -> None:
        """Close the phase's bar, or print its last plain line when the time moved since the one before."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self._enabled and self._printed is not None and self._printed[1] != self.time:
            self._print()

    def _refresh(self) -> None:
        """The refresh thread: every ``REFRESH`` s, redraw the bar, or print a plain line when ``PLAIN_EVERY`` s
        passed since the last one."""
        while not self._stop.wait(REFRESH):
            with self._lock:
                if self._bar is not None:
                    self._bar.refresh()
                elif self._printed is not None and self._clock() - self._printed[0] >= PLAIN_EVERY:
                    self._print()


def note(progress: Any, text: str | None) -> None:
    """``progress.note(text)`` when the engine's ``progress`` callable has it (:meth:`Progress.note`)."""
    if hasattr(progress, "note"):
        progress.note(text)


def limit(progress: Any, dt: float, reason: str) -> None:
    """``progress.limit(dt, reason)`` when the engine's ``progress`` callable has it (:meth:`Progress.limit`)."""
    if hasattr(progress, "limit"):
        progress.limit(dt, reason)
