"""app/stop_signals.py: the servers' stop signals are noted by a handler that takes no lock, so a
signal that comes while the main thread holds the lock of the Event its loop waits on stops the
server instead of hanging it (``teachpad-sim`` ignored a Ctrl-C beside two busy loops, stop 30)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from app.sim import cli as sim_cli
from app.stop_signals import SignalNote, stop_signals

ROOT = Path(__file__).resolve().parents[1]
HANG_S = 20.0  # a child that has not answered by then hangs (it answers in well under a second)

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals sent to oneself")

# The main loop's moment that hung: inside `done.wait(0.2)`, the Event's lock taken again after the
# wait and not yet given back; the signal is handled at the next bytecode, with the lock held.
_SIGNAL_WITH_THE_LOCK_HELD = textwrap.dedent("""
    import os, signal, sys, threading
    done = threading.Event()
    {install}
    with done._cond:
        os.kill(os.getpid(), signal.SIGTERM)
        handled_here = True  # a bytecode: the handler runs before it
    print("stopping" if {stopping} else "not noted", flush=True)
""")


def _run(install: str, stopping: str) -> subprocess.CompletedProcess[str]:
    code = _SIGNAL_WITH_THE_LOCK_HELD.format(install=install, stopping=stopping)
    return subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=HANG_S, check=False
    )


def test_a_signal_while_the_loop_holds_its_events_lock_is_noted_not_waited_on() -> None:
    result = _run(
        "from app.sim.cli import _stop_on_signals; stop = _stop_on_signals()", "stop.wait(0.01, done)"
    )
    assert result.returncode == 0 and result.stdout.strip() == "stopping", result.stderr


def test_the_handler_it_replaces_waits_for_that_lock_forever() -> None:
    # why: the servers' old handler, `done.set()`, in the same moment. The child says when it is
    # about to signal itself; it is still there, silent, well after that (then killed).
    code = _SIGNAL_WITH_THE_LOCK_HELD.format(
        install="signal.signal(signal.SIGTERM, lambda *_: done.set()); print('signalling', flush=True)",
        stopping="done.is_set()",
    )
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None
        assert child.stdout.readline().strip() == "signalling"
        with pytest.raises(subprocess.TimeoutExpired):
            child.wait(timeout=2.0)  # a handled signal would have printed and ended it in ~1 ms
    finally:
        child.kill()
        child.communicate()  # and its pipe closed


def test_the_simulator_notes_ctrl_c_and_sigterm_and_puts_the_old_handlers_back() -> None:
    before = {sig: signal.getsignal(sig) for sig in stop_signals()}
    stop = sim_cli._stop_on_signals()
    try:
        assert {signal.SIGINT, signal.SIGTERM} <= set(stop_signals())
        for sig in stop_signals():
            assert signal.getsignal(sig) == stop._note
        os.kill(os.getpid(), signal.SIGTERM)
        assert stop.wait(0.01) and stop.signum == signal.SIGTERM and stop.count == 1
    finally:
        stop.restore()
    assert {sig: signal.getsignal(sig) for sig in stop_signals()} == before


def test_wait_ends_on_done_or_on_a_signal_and_lasts_its_period_otherwise() -> None:
    note = SignalNote((signal.SIGUSR1,)).install()
    try:
        done = threading.Event()
        started = time.monotonic()
        assert not note.wait(0.05, done)
        assert not note.wait(0.05)  # no Event: a sleep of the period
        assert time.monotonic() - started >= 0.1
        done.set()
        assert note.wait(5.0, done)  # at once
        os.kill(os.getpid(), signal.SIGUSR1)
        assert note.wait(0.01) and note.came
    finally:
        note.restore()


def test_take_says_each_new_batch_of_a_repeated_signal_once() -> None:
    reload = SignalNote((signal.SIGUSR2,)).install()
    try:
        assert not reload.take()
        os.kill(os.getpid(), signal.SIGUSR2)
        os.kill(os.getpid(), signal.SIGUSR2)
        assert reload.count == 2
        assert reload.take() and not reload.take()  # both acted on by one reload
        os.kill(os.getpid(), signal.SIGUSR2)
        assert reload.take()
    finally:
        reload.restore()


def test_off_the_main_thread_nothing_is_installed() -> None:
    before = signal.getsignal(signal.SIGUSR1)
    notes: list[SignalNote] = []
    thread = threading.Thread(target=lambda: notes.append(SignalNote((signal.SIGUSR1,)).install()))
    thread.start()
    thread.join()
    assert signal.getsignal(signal.SIGUSR1) == before
    notes[0].restore()  # nothing to put back
    assert signal.getsignal(signal.SIGUSR1) == before
