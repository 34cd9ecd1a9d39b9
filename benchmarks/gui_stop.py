"""Stop latency (``stop_latency``): the GUI Stop button and the bare pymodbus floor; see
:mod:`benchmarks.gui`."""

from __future__ import annotations

import functools
import os
import random
import threading
import time
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from pymodbus.client import ModbusTcpClient
from PySide6.QtCore import QCoreApplication, QEvent, QPointF, Qt, QTimer
from PySide6.QtGui import QMouseEvent

from app.link.ops import RunProgram
from app.link.stop_line import StopLine, StopSent
from app.protocol import registers as R  # noqa: N812
from app.protocol.enums import ProgramMotionMode
from app.sim.config import WriteRecord
from benchmarks.gui_common import (
    INPUT_PHASE_SPREAD_S,
    POLL_HZ,
    STOP_PROGRAM,
    WARMUP_SAMPLES,
    SimHandle,
    _Counters,
    _more_poses,
    _motion_started,
    _stop_sent,
    _stop_write_after,
    _summary_ms,
    _wait_until,
)
from ui.main_window import MainWindow

# --------------------------------------------------------------------------------------------
# 1. Stop latency
# --------------------------------------------------------------------------------------------


class _SendClock:
    """Where a stop's time goes: wraps :meth:`StopLine.send_stop` (the stop line's one system call,
    made by the thread that pressed Stop) for the life of the ``with`` block and keeps the
    monotonic time each stop it took was sent. A stop the line could not take (busy with a
    keepalive read, an answer not yet read) went through the worker's queue: no time."""

    def __init__(self) -> None:
        self.sent: list[float | None] = []
        self._original = StopLine.send_stop

    def __enter__(self) -> _SendClock:
        original, sent = self._original, self.sent

        def send_stop(line: StopLine) -> StopSent | None:
            on_line = original(line)
            sent.append(on_line.sent_mono if on_line is not None else None)
            return on_line

        StopLine.send_stop = send_stop  # type: ignore[method-assign, assignment]
        return self

    def __exit__(self, *exc: object) -> None:
        StopLine.send_stop = self._original  # type: ignore[method-assign]


class _GuiStopper:
    """One stop sample after another with the window's Stop button: the motion (re)started and
    seen by a poll, the Stop pressed after a delay, the simulator's 441 <- 1 write found."""

    def __init__(self, window: MainWindow, sim: SimHandle, counters: _Counters, *, posted: bool) -> None:
        self.link = window.link
        self.button = window.control_bar.stop_button
        self.sim = sim
        self.counters = counters
        self.posted = posted
        self.pending: dict[str, float | int] = {}
        self.found: list[WriteRecord] = []
        self.clicker = QTimer()
        self.clicker.setSingleShot(True)
        self.clicker.setTimerType(Qt.TimerType.PreciseTimer)
        self.clicker.timeout.connect(self._click)

    def _click(self) -> None:
        self.pending["t0"] = time.monotonic()
        self.button.click()

    def _post_click(self, local: QPointF, screen: QPointF) -> None:  # runs in a timer thread
        left, none, plain = Qt.MouseButton.LeftButton, Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier
        press = QMouseEvent(QEvent.Type.MouseButtonPress, local, screen, left, left, plain)
        release = QMouseEvent(QEvent.Type.MouseButtonRelease, local, screen, left, none, plain)
        self.pending["t0"] = time.monotonic()
        QCoreApplication.postEvent(self.button, press)
        QCoreApplication.postEvent(self.button, release)

    def _stop_seen(self) -> bool:
        record = _stop_write_after(self.sim, int(self.pending["index"]))
        if record is not None:
            self.found.append(record)
        return record is not None

    def motion_running(self) -> bool:
        """(Re)start the motion; True once the simulator runs it and a poll has seen it."""
        start = self.sim.write_count()
        self.link.submit(RunProgram(STOP_PROGRAM, ProgramMotionMode.CYCLE, 0, 100))
        if not _wait_until(functools.partial(_motion_started, self.sim, start)):
            return False
        poses = self.counters.poses
        return _wait_until(functools.partial(_more_poses, self.counters, poses))

    def press_stop(self, delay: float) -> bool:
        """Press Stop ``delay`` s from now (a GUI-thread timer's ``click()``, or a mouse press and
        release posted from another thread); True once the simulator logged the stop write."""
        self.found.clear()
        self.pending.clear()
        self.pending["index"] = self.sim.write_count()
        self.pending["results"] = len(self.counters.results)
        poster: threading.Timer | None = None
        if self.posted:
            local = QPointF(self.button.rect().center())
            poster = threading.Timer(delay, self._post_click, (local, self.button.mapToGlobal(local)))
            poster.start()
        else:
            self.clicker.start(int(1000.0 * delay))
        seen = _wait_until(lambda: "t0" in self.pending) and _wait_until(self._stop_seen)
        if poster is not None:
            poster.join()
        return seen

    def stop_sent(self) -> bool:
        """Wait for the worker to finish the stop job ("stop: sent")."""
        done = int(self.pending["results"])
        return _wait_until(functools.partial(_stop_sent, self.counters, done))

    def latency(self) -> float:
        """The last stop's: the simulator's write time minus the time just before the press."""
        return self.found[0].t - float(self.pending["t0"])

    def split(self, sent: float | None) -> tuple[float, float] | None:
        """The last stop's two parts around its send on the stop line (``sent``, monotonic): the
        press to the send (this process: the click, the slot, the link), the send to the
        simulator's write (the loopback, the simulator process waking up and answering)."""
        if sent is None:
            return None
        return sent - float(self.pending["t0"]), self.found[0].t - sent


def bench_stop_gui(
    window: MainWindow,
    sim: SimHandle,
    counters: _Counters,
    n: int,
    rng: random.Random,
    *,
    posted: bool = False,
    budget_s: float = float("inf"),
) -> dict[str, Any]:
    """Stop at a random phase of the 100 Hz poll while program STOP_PROGRAM runs.

    ``posted`` False: the Stop button's ``click()`` from a GUI-thread timer, t0 just before it
    (the application's own path, click to wire). ``posted`` True: a mouse press and release
    posted to the Stop button from another thread at a random time, t0 just before posting
    (what an operator's click meets: the event loop has to get to it first).
    Ends early, with fewer samples, after ``budget_s`` (a saturated GUI makes each sample slow).
    """
    stopper = _GuiStopper(window, sim, counters, posted=posted)
    spread = INPUT_PHASE_SPREAD_S if posted else 1.0 / POLL_HZ
    latencies: list[float] = []
    parts: list[tuple[float, float]] = []
    failures = 0
    deadline = time.monotonic() + budget_s
    out: dict[str, Any] = {"budget_exhausted": False}
    with _SendClock() as clock:
        for i in range(n + WARMUP_SAMPLES):
            if time.monotonic() > deadline:
                out["budget_exhausted"] = True
                break
            if not stopper.motion_running():
                failures += 1
                continue
            # Just after a poll: a uniform delay over one poll period (posted input: over one paint
            # period of the monitor, several polls) spreads the stop over the cycle.
            del clock.sent[:]
            if not stopper.press_stop(rng.uniform(0.0, spread)):
                failures += 1
                continue
            # Let the worker finish the stop job ("stop: sent") before the next run request.
            if not stopper.stop_sent():
                failures += 1
            if i >= WARMUP_SAMPLES:
                latencies.append(stopper.latency())
                split = stopper.split(clock.sent[0] if clock.sent else None)
                if split is not None:
                    parts.append(split)
    reason = (
        "the time budget ran out before a stop was measured"
        if out["budget_exhausted"]
        else f"no stop measured ({failures} attempts failed)"
    )
    out.update(_summary_ms(latencies, reason))
    out["failures"] = failures
    # The same stops in two parts (those the stop line carried): what this process spent before
    # the send, and what the loopback and the simulator's process took after it.
    out["press_to_send"] = _summary_ms([p for p, _ in parts], "no stop went on the stop line")
    out["send_to_write"] = _summary_ms([w for _, w in parts], "no stop went on the stop line")
    return out


def bench_stop_bare(sim: SimHandle, n: int, rng: random.Random) -> dict[str, Any]:
    """441 <- 1 from a bare pymodbus client in a plain loop (random pauses, for the phase)."""
    client = ModbusTcpClient("127.0.0.1", port=sim.port, timeout=1.0)
    if not client.connect():
        raise RuntimeError("bare pymodbus client could not connect to the simulator")
    latencies: list[float] = []
    try:
        for i in range(n + WARMUP_SAMPLES):
            time.sleep(rng.uniform(0.0, 1.0 / POLL_HZ))
            index = sim.write_count()
            t0 = time.monotonic()
            client.write_register(R.REG_STOP, 1, device_id=sim.unit)
            record = _stop_write_after(sim, index)
            if record is None:
                raise RuntimeError("the simulator did not log the bare client's stop")
            if i >= WARMUP_SAMPLES:
                latencies.append(record.t - t0)
    finally:
        client.close()
    return _summary_ms(latencies)
