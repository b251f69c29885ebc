"""Honest progress (issue 30 item 6): the time left follows the recent rate (a fake clock), the bar redraws from a
thread that stops at close, a note ("compiling kernels") lasts until the step returns, the step's limit is shown,
and a log that is not a terminal gets plain lines, not bar frames."""

from __future__ import annotations

import io
import threading
import time

import pytest
from hfgpu.io.progress import PLAIN_EVERY, Progress, limit, note


class Clock:
    """A wall clock moved by hand [s]."""

    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def _steps(bar: Progress, clock: Clock, wall: float, sim_per_wall: float, dt_wall: float = 0.5) -> None:
    """Advance ``wall`` seconds of the clock, stepping the simulation at ``sim_per_wall`` [s/s]."""
    for _ in range(round(wall / dt_wall)):
        clock.now += dt_wall
        bar(bar.time + sim_per_wall * dt_wall)


def test_a_slowing_phase_raises_the_estimate():
    clock = Clock()
    bar = Progress(1000.0, enabled=False, clock=clock)
    assert bar.seconds_left() is None  # no step yet
    bar(0.0)  # the first step returns: the rate's baseline (kernel compilation not counted)
    _steps(bar, clock, 100.0, 1.0)  # 1 s simulated per wall second
    assert bar.seconds_left() == pytest.approx(900.0, rel=0.02)
    _steps(bar, clock, 60.0, 0.1)  # the step shrinks tenfold: 894 s left at 0.1 s/s
    assert bar.seconds_left() == pytest.approx(8940.0, rel=0.05)  # the mean since the start would say 1349 s
    clock.now += 30.0  # one step runs 30 s: the rate falls further while it runs
    assert bar.seconds_left() > 1.4 * 8940.0
    _steps(bar, clock, 100.0, 1.0)  # and recovers
    assert bar.seconds_left() == pytest.approx((1000.0 - bar.time) / 1.0, rel=0.05)


def test_terminal_bar_redraws_while_a_step_runs_and_its_thread_stops_at_close():
    out = io.StringIO()
    before = set(threading.enumerate())
    bar = Progress(100.0, file=out, phase="proppant", terminal=True)
    bar(1.0)
    bar.note("compiling kernels")
    frames = out.getvalue().count("\r")
    time.sleep(2.6)  # a long step: no call
    assert out.getvalue().count("\r") >= frames + 2  # redrawn about every second
    assert "compiling kernels" in out.getvalue().split("\r")[-1]
    bar.limit(0.05, "dt_max")
    bar(2.0)  # the step returned: the note is gone, the limit shown
    bar._bar.refresh()
    last = out.getvalue().split("\r")[-1]
    assert "compiling kernels" not in last and "dt 0.05 s (dt_max)]" in last and "s simulated" in last
    bar.close()
    assert set(threading.enumerate()) == before
    assert not any(t.name == "hfgpu-progress" for t in threading.enumerate())


def test_a_log_gets_one_plain_line_per_tenth_not_bar_frames():
    out, clock = io.StringIO(), Clock()
    bar = Progress(100.0, file=out, phase="fracture", clock=clock)  # a StringIO is not a terminal
    bar.limit(0.25, "front advance")
    for k in range(1, 401):
        clock.now += 0.125  # exact in binary
        bar(k * 0.25)
    bar.phase("proppant", 40.0)
    bar.note("compiling kernels")
    bar(40.0)
    bar.limit(1.5e-4, "Courant 0.5")
    clock.now += 2 * PLAIN_EVERY  # slow: a line every PLAIN_EVERY s besides the tenths
    bar(41.0)
    bar.close()
    text = out.getvalue()
    lines = text.splitlines()
    assert "\r" not in text and "|" not in text
    fracture = [line for line in lines if line.startswith("fracture:")]
    assert len(fracture) == 11  # 0 %, 10 %, ..., 100 %
    assert fracture[5].startswith("fracture:  50% 50/100 s simulated [00:25 elapsed, 00:25 left, "
                                  "dt 0.25 s (front advance)]")
    assert lines[11:] == [
        "proppant:  40% 40/100 s simulated [00:00 elapsed, ? left]",
        "proppant:  40% 40/100 s simulated [00:00 elapsed, ? left, compiling kernels]",
        "proppant:  41% 41/100 s simulated [02:00 elapsed, 1:58:00 left, dt 0.00015 s (Courant 0.5)]"]


def test_engines_report_through_any_progress_callable():
    calls = []
    note(calls.append, "compiling kernels")  # a plain callable: nothing happens
    limit(None, 0.1, "dt_max")
    bar = Progress(100.0, enabled=False, clock=Clock())
    bar.phase("proppant", 20.0)   # the proppant engine's clock is the run's: its phase starts at 20 s
    note(bar, "compiling kernels")
    assert bar._extra()["postfix"] == "compiling kernels"
    limit(bar, 5.0, "coupling interval")
    bar(25.0)
    assert bar.time == 25.0 and bar._extra()["postfix"] == "dt 5 s (coupling interval)"
    bar.close()
    assert calls == []
