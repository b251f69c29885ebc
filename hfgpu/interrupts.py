"""Stop signals during a run: SIGTERM (``kill``, batch schedulers at their time limit) and SIGHUP (the terminal
closed) end a run as Ctrl-C does. The run's ``KeyboardInterrupt`` path then closes the results file with status
"interrupted", its summary and its checkpoint kept, so that ``hfgpu run --resume`` continues it.

Handlers are installed only in the main thread (Python delivers signals there); elsewhere, e.g. inside a Dask
worker's thread, the context manager changes nothing.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import Iterator

#: Signals handled as Ctrl-C (SIGHUP does not exist on Windows).
STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))


class Interrupted(KeyboardInterrupt):
    """A run stopped by a signal; ``signal_number`` is the signal's number (SIGINT for Ctrl-C)."""

    def __init__(self, signal_number: int):
        self.signal_number = int(signal_number)
        super().__init__(signal.Signals(signal_number).name)


def signal_number(exc: KeyboardInterrupt) -> int:
    """The signal that raised ``exc``: its own for :class:`Interrupted`, SIGINT for a plain Ctrl-C."""
    return exc.signal_number if isinstance(exc, Interrupted) else int(signal.SIGINT)


@contextmanager
def stop_signals_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise :class:`Interrupted` in the main thread; the previous
    handlers are restored on leaving it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(number: int, frame: object) -> None:
        raise Interrupted(number)

    previous = {number: signal.signal(number, handler) for number in STOP_SIGNALS}
    try:
        yield
    finally:
        for number, old in previous.items():
            signal.signal(number, old)
