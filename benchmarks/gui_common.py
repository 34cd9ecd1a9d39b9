"""Shared parts of the GUI benchmarks (:mod:`benchmarks.gui`): constants, the Qt event-loop
helpers, the simulator handles (in this process or its own), the counters and sample summaries."""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Protocol

from app.user_dirs import fresh_user_dirs_env

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEvent, QEventLoop, QObject, Qt, QTimer
from PySide6.QtWidgets import QApplication

from app.link.robot_link import RobotLink
from app.link.types import ConnectionState
from app.models import CommandResult, Pose
from app.protocol import registers as R  # noqa: N812
from app.protocol.enums import RunCommand
from app.sim.config import SimConfig, WriteRecord
from app.sim.server import SimController

POLL_HZ = 100.0
STALL_TIMER_MS = 1  # period of the probe timer that measures the GUI event loop's stalls
STALL_THRESHOLD_MS = 50.0
VIEW3D_SETTLE_S = 1.0  # after bringing the 3D tab to the front, before measuring its stalls
STEADY_AFTER_S = 1.0
WARMUP_SAMPLES = 5
WAIT_TIMEOUT_S = 5.0  # for any single condition (connection, motion started, stop seen)
STREAM_PROGRAM = 1  # the simulator's 100 mm square in XY: the plots and the X-Y trace move
STOP_PROGRAM = 3  # J7 shuttle: joint moves without reach checks, so repeated restarts never drift
# out of the workspace (a square restarted after each stop would walk away in X)
INPUT_PHASE_SPREAD_S = 0.034  # posted input: one paint period of the monitor (30 Hz)
STARTUP_TIMEOUT_S = 60.0
REPO = Path(__file__).resolve().parents[1]

_app: QApplication | None = None  # kept alive for the process: Qt wants one QApplication
_user_dirs: tempfile.TemporaryDirectory[str] | None = None  # removed when the process ends


def private_user_dirs() -> None:
    """Point this process's per-user folders (XDG_*) at a temporary folder, once: the windows the
    benchmarks make keep their safety state (roles, envelope, audit trail) in the user's folders,
    never beside their settings file (app/safety/location.py), and must not touch the real ones."""
    global _user_dirs
    if _user_dirs is not None:
        return
    _user_dirs = tempfile.TemporaryDirectory(prefix="teachpad-bench-user-")
    os.environ.update(fresh_user_dirs_env(_user_dirs.name))


def _qapp() -> QApplication:
    global _app
    private_user_dirs()  # every benchmark window is made after this
    existing = QApplication.instance()
    _app = existing if isinstance(existing, QApplication) else QApplication(["teachpad-bench"])
    return _app


# --------------------------------------------------------------------------------------------
# Small helpers
# --------------------------------------------------------------------------------------------


def _pct(values: Sequence[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(len(ordered) * q))]


#: The figures of a sample summary; all None ("not measured") when there was no sample.
SUMMARY_KEYS = ("p50_ms", "p99_ms", "max_ms", "mean_ms")


def not_measured(reason: str, keys: Sequence[str] = SUMMARY_KEYS) -> dict[str, Any]:
    """A figure without samples: each key null, with the reason (the goals say "not measured")."""
    return {"n": 0, **dict.fromkeys(keys), "not_measured": reason}


def ratio(numerator: Any, denominator: Any) -> float | None:
    """``numerator / denominator``, or None when either is missing (not measured) or the
    denominator is not positive: a ratio is never computed from a figure without samples."""
    if not isinstance(numerator, int | float) or not isinstance(denominator, int | float):
        return None
    return numerator / denominator if denominator > 0 else None


def _summary_ms(seconds: Sequence[float], reason: str = "no samples") -> dict[str, Any]:
    """p50/p99/max/mean in ms; with no sample, :func:`not_measured` with ``reason``."""
    if not seconds:
        return not_measured(reason)
    ms = [1000.0 * s for s in seconds]
    return {
        "n": len(ms),
        "p50_ms": statistics.median(ms),
        "p99_ms": _pct(ms, 0.99),
        "max_ms": max(ms),
        "mean_ms": statistics.fmean(ms),
    }


def _wait_until(predicate: Callable[[], bool], timeout: float = WAIT_TIMEOUT_S) -> bool:
    """Run the Qt event loop until ``predicate()`` holds (checked every ms); False on timeout."""
    if predicate():
        return True
    loop = QEventLoop()
    deadline = time.monotonic() + timeout
    met = False

    def check() -> None:
        nonlocal met
        if predicate():
            met = True
            loop.quit()
        elif time.monotonic() >= deadline:
            loop.quit()

    timer = QTimer()
    timer.setTimerType(Qt.TimerType.PreciseTimer)
    timer.setInterval(1)
    timer.timeout.connect(check)
    timer.start()
    loop.exec()
    timer.stop()
    return met


def _run_for(seconds: float) -> None:
    loop = QEventLoop()
    timer = QTimer()
    timer.setSingleShot(True)
    timer.setTimerType(Qt.TimerType.PreciseTimer)  # a coarse timer may end 5 % early
    timer.timeout.connect(loop.quit)
    timer.start(round(1000 * seconds))
    loop.exec()


class SimHandle(Protocol):
    """What the benchmarks need from a simulator, wherever it runs."""

    port: int
    unit: int

    def write_count(self) -> int: ...

    def writes_from(self, start: int) -> list[WriteRecord]: ...

    def busy(self) -> bool: ...

    def requests(self) -> int: ...

    def stop(self) -> None: ...


class LocalSim:
    """A SimController in this process (as ``teachpad --sim`` runs it): shares the GIL with the GUI."""

    placement = "in_process"

    def __init__(self) -> None:
        self.sim = SimController(SimConfig(host="127.0.0.1", port=0))
        self.sim.start()
        self.port = self.sim.port
        self.unit = self.sim.config.unit

    def write_count(self) -> int:
        return len(self.sim.writes)

    def writes_from(self, start: int) -> list[WriteRecord]:
        return self.sim.writes[start:]

    def busy(self) -> bool:
        with self.sim.lock:
            return bool(self.sim.robot.busy)

    def requests(self) -> int:
        return self.sim.requests_count

    def stop(self) -> None:
        self.sim.stop()


# The simulator in its own interpreter, like a controller on the network; queried over a pipe.
_SIM_HOST_CHILD = r"""
import json, sys
from app.sim.config import SimConfig
from app.sim.server import SimController
sim = SimController(SimConfig(host="127.0.0.1", port=0))
sim.start()
print(json.dumps([sim.port, sim.config.unit]), flush=True)
for line in sys.stdin:
    command, _, arg = line.strip().partition(" ")
    if command == "n":
        out = len(sim.writes)
    elif command == "w":
        out = [[w.t, w.function_code, w.address, list(w.values)] for w in sim.writes[int(arg):]]
    elif command == "b":
        with sim.lock:
            out = bool(sim.robot.busy)
    elif command == "r":
        out = sim.requests_count
    else:
        break
    print(json.dumps(out), flush=True)
sim.stop()
"""


class RemoteSim:
    """A SimController in a child process; ``WriteRecord.t`` is CLOCK_MONOTONIC there as here."""

    placement = "separate_process"

    def __init__(self) -> None:
        env = dict(os.environ, PYTHONPATH=str(REPO))
        self._proc = subprocess.Popen(
            [sys.executable, "-c", _SIM_HOST_CHILD],
            cwd=REPO,
            env=env,
            text=True,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            bufsize=1,
        )
        self.port, self.unit = self._read()

    def _read(self) -> Any:
        assert self._proc.stdout is not None
        line = self._proc.stdout.readline()
        if not line:
            raise RuntimeError(f"the simulator process ended (rc={self._proc.poll()})")
        return json.loads(line)

    def _ask(self, command: str) -> Any:
        assert self._proc.stdin is not None
        self._proc.stdin.write(command + "\n")
        self._proc.stdin.flush()
        return self._read()

    def write_count(self) -> int:
        return int(self._ask("n"))

    def writes_from(self, start: int) -> list[WriteRecord]:
        rows = self._ask(f"w {start}")
        return [WriteRecord(t, fc, address, tuple(values)) for t, fc, address, values in rows]

    def busy(self) -> bool:
        return bool(self._ask("b"))

    def requests(self) -> int:
        return int(self._ask("r"))

    def stop(self) -> None:
        if self._proc.poll() is None:
            assert self._proc.stdin is not None
            self._proc.stdin.write("q\n")
            self._proc.stdin.close()
            try:
                self._proc.wait(10)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        if self._proc.stdout is not None:
            self._proc.stdout.close()


def _per_100hz(figures: dict[str, Any]) -> None:
    """Add ``gui_thread_cpu_pct_per_100hz``: the GUI thread's CPU per poll delivered, scaled to
    100 polls a second (a loaded machine delivers fewer polls, and so less work, than asked)."""
    if "gui_thread_cpu_pct" in figures and figures.get("polls_per_s", 0) > 0:
        figures["gui_thread_cpu_pct_per_100hz"] = (
            figures["gui_thread_cpu_pct"] * POLL_HZ / figures["polls_per_s"]
        )


def _stop_write_after(sim: SimHandle, start: int) -> WriteRecord | None:
    """The first 441 <- 1 write the simulator logged at index >= ``start``."""
    for record in sim.writes_from(start):
        offset = R.REG_STOP - record.address
        if 0 <= offset < len(record.values) and record.values[offset] == 1:
            return record
    return None


def _motion_started(sim: SimHandle, start: int) -> bool:
    """A run-program command was written at index >= ``start`` and the simulator is moving."""
    for record in sim.writes_from(start):
        offset = R.REG_RUN_COMMAND - record.address
        if 0 <= offset < len(record.values) and record.values[offset] == int(RunCommand.RUN_PROGRAM):
            return sim.busy()
    return False


class _Counters(QObject):
    """What the link delivered to the GUI thread (slots connected after the window's own)."""

    def __init__(self, link: RobotLink) -> None:
        super().__init__()
        self.poses = 0
        self.traffic_frames = 0
        self.results: list[CommandResult] = []
        self.state = link.connection
        link.state.poseChanged.connect(self._on_pose)
        link.trafficObserved.connect(self._on_traffic)
        link.commandFinished.connect(self._on_result)
        link.connectionChanged.connect(self._on_connection)

    def _on_pose(self, _pose: Pose) -> None:
        self.poses += 1

    def _on_traffic(self, batch: tuple[Any, ...]) -> None:
        self.traffic_frames += len(batch)

    def _on_result(self, result: CommandResult) -> None:
        self.results.append(result)

    def _on_connection(self, state: ConnectionState) -> None:
        self.state = state


def _more_poses(counters: _Counters, before: int) -> bool:
    return counters.poses > before


def _stop_sent(counters: _Counters, first: int) -> bool:
    return any(r.message == "stop: sent" for r in counters.results[first:])


class _PaintCounter(QObject):
    def __init__(self) -> None:
        super().__init__()
        self.paints = 0

    def eventFilter(self, _watched: QObject, event: QEvent) -> bool:
        if event.type() == QEvent.Type.Paint:
            self.paints += 1
        return False
