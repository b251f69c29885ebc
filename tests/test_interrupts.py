"""Stop signals (hfgpu.interrupts): SIGTERM and SIGHUP raise Interrupted inside the block, and a raise that
Python dropped (a signal landing in a finalizer or a weakref callback) is raised again at the next check."""

from __future__ import annotations

import gc
import os
import signal
import sys
import weakref

import pytest

from hfgpu.interrupts import Interrupted, signal_number, stop_signals_interrupt

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="SIGTERM cannot be sent to oneself on Windows")


class _Target:
    pass


def test_a_stop_signal_raises_interrupted_with_its_number_and_the_handler_is_restored():
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Interrupted) as caught:
        with stop_signals_interrupt():
            os.kill(os.getpid(), signal.SIGTERM)
            _spin()
    assert signal_number(caught.value) == signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) is before


def test_a_raise_lost_in_a_weakref_callback_is_raised_at_the_next_check():
    """The signal arrives while a weakref callback runs: Python prints "Exception ignored" and goes on; the
    block's check raises it again."""
    unraisable = []
    hook, sys.unraisablehook = sys.unraisablehook, unraisable.append
    try:
        with stop_signals_interrupt() as stop:
            stop.check()   # nothing received yet
            target = _Target()
            ref = weakref.ref(target, lambda _: os.kill(os.getpid(), signal.SIGTERM) or _spin())
            del target
            gc.collect()
            assert ref() is None
            with pytest.raises(Interrupted) as caught:
                stop.check()
    finally:
        sys.unraisablehook = hook
    assert signal_number(caught.value) == signal.SIGTERM
    assert [type(u.exc_value) for u in unraisable] == [Interrupted]


def _spin() -> None:
    """Run bytecode so the pending signal's handler runs here, inside the callback."""
    for _ in range(1000):
        pass


@pytest.mark.skipif(not hasattr(signal, "SIGHUP"), reason="no SIGHUP")
def test_an_ignored_signal_stays_ignored_and_ctrl_c_is_recorded():
    """Under nohup (SIGHUP ignored) closing the terminal does not stop the run; Ctrl-C raises Interrupted with
    SIGINT, recorded like the others."""
    before = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    before_int = signal.signal(signal.SIGINT, signal.default_int_handler)   # as from a terminal
    try:
        with pytest.raises(Interrupted) as caught:
            with stop_signals_interrupt() as stop:
                assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
                os.kill(os.getpid(), signal.SIGHUP)
                _spin()
                stop.check()   # nothing received
                os.kill(os.getpid(), signal.SIGINT)
                _spin()
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGHUP, before)
        signal.signal(signal.SIGINT, before_int)
    assert signal_number(caught.value) == signal.SIGINT and stop.number == signal.SIGINT
