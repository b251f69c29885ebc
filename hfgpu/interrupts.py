"""Stop signals during a run: SIGTERM (``kill``, batch schedulers at their time limit) and SIGHUP (the terminal
closed) end a run as Ctrl-C (SIGINT) does. The run's ``KeyboardInterrupt`` path then closes the results file
with status "interrupted", its summary and its checkpoint kept, so that ``hfgpu run --resume`` continues it. A
signal the process ignores stays ignored (``nohup`` ignores SIGHUP, a shell's background job SIGINT).

Handlers are installed only in the main thread (Python delivers signals there); elsewhere, e.g. inside a Dask
worker's thread, the context manager changes nothing.

A handler's exception is lost when the signal lands while Python runs a finalizer or a weakref callback (it
prints "Exception ignored in ..." and goes on). The handler therefore also records the signal, and the block's
:class:`StopSignal` raises it again at the caller's next safe point (``check``, called after every step), so a
stop signal always ends the run.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import Iterator

#: Signals that stop a run (SIGHUP does not exist on Windows).
STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


class Interrupted(KeyboardInterrupt):
    """A run stopped by a signal; ``signal_number`` is the signal's number (SIGINT for Ctrl-C)."""

    def __init__(self, signal_number: int):
        self.signal_number = int(signal_number)
        super().__init__(signal.Signals(signal_number).name)


def signal_number(exc: KeyboardInterrupt) -> int:
    """The signal that raised ``exc``: its own for :class:`Interrupted`, SIGINT for a plain Ctrl-C."""
    return exc.signal_number if isinstance(exc, Interrupted) else int(signal.SIGINT)


class StopSignal:
    """The stop signal received inside a :func:`stop_signals_interrupt` block, if any (``number``)."""

    def __init__(self):
        self.number: int | None = None

    def check(self) -> None:
        """Raise :class:`Interrupted` for a stop signal whose own raise was lost (module docstring)."""
        if self.number is not None:
            raise Interrupted(self.number)


@contextmanager
def stop_signals_interrupt() -> Iterator[StopSignal]:
    """Within the block, SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` in the main thread (and are
    recorded in the :class:`StopSignal` it yields), except those the process ignores; the previous handlers
    are restored on leaving it."""
    stop = StopSignal()
    if threading.current_thread() is not threading.main_thread():
        yield stop
        return

    def handler(number: int, frame: object) -> None:
        stop.number = number
        raise Interrupted(number)

    previous = {number: signal.signal(number, handler) for number in STOP_SIGNALS
                if signal.getsignal(number) is not signal.SIG_IGN}
    try:
        yield stop
    finally:
        for number, old in previous.items():
            signal.signal(number, old)
