"""GUI benchmarks: stop latency, event-loop stalls and start-up, against the simulator on loopback.

Each figure comes with a baseline measured the same way in the same run. The main window is
shown at its desktop default size (the offscreen screen would clamp it), Monitor tab in front,
the traffic inspector brought to the front of its dock (it is tabified behind the event log).

* **Stop latency at 100 Hz polling** -- the window connected to the simulator, a program
  running. ``gui_stop_button``: the control bar's Stop button ``click()``-ed from a GUI-thread
  timer at a random phase of the poll cycle; latency = the simulator's ``WriteRecord.t`` of the
  441 <- 1 write minus ``time.monotonic()`` just before the click. ``gui_posted_mouse_click``: a
  mouse press + release posted to the button from another thread at a random time, t0 just
  before posting -- what an operator's click meets, the event loop's own delay included.
  Baselines: a bare pymodbus client writing 441 <- 1 in a plain loop, with nothing else
  connected (the round-trip floor) and while the window's link polls at 100 Hz.
* **Event-loop stalls while streaming** -- a 1 ms ``PreciseTimer`` in the GUI thread records the
  gaps between its firings while the arm runs a program, the link polls at 100 Hz and the
  monitor plots, status panel and traffic inspector update. Baseline: the same window shown,
  disconnected. Attribution: the same stream with the monitor's tab hidden. CPU time of the
  GUI thread and of the process is reported alongside (% of one core).
* **Time to first paint** -- ``teachpad --sim`` in a fresh interpreter (``python -c``; the
  window class is wrapped to note its first paint event, the first pose delivered to the
  window and the first repaint of the X readout after it), timed from just before the
  subprocess is spawned (``CLOCK_MONOTONIC`` is shared between processes), with marks for
  each stage. Baseline: a bare ``QMainWindow`` of the same size in the same way.

* **The 3D view** (``view3d``, :mod:`benchmarks.view3d`) -- frame times of rotating a scene of
  10,000 point markers and a 1,000-segment plan, and ``streaming_view3d_shown`` among the
  stalls: the streaming stall measurement again with the 3D tab in front.
* **Busy neighbour** -- ``sim_separate_process.event_loop_stall.streaming_busy``: the streaming
  figures again while one ``while True: pass`` process per extra core loads the machine.
* **Memory** (``run_memory``, called by ``benchmarks.run`` as ``gui.memory``) -- VmRSS of a
  ``teachpad --sim`` process idle after its first pose, then every few seconds over a soak
  streaming a program with the traffic inspector shown (``--long``: 10 minutes, every 30 s).

The simulator runs in this process (``sim_in_process``, as ``teachpad --sim`` runs it, sharing
the GIL with the GUI) and, as a shorter cross-check, in its own process
(``sim_separate_process``, like a controller on the network).

Usage: python -m benchmarks.gui [--quick]   (``benchmarks.run`` calls :func:`run`)
"""

from __future__ import annotations

import functools
import gc
import itertools
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Protocol

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from pymodbus.client import ModbusTcpClient
from PySide6.QtCore import QCoreApplication, QEvent, QEventLoop, QObject, QPointF, Qt, QTimer
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication

from app.link.client import ConnectionSettings
from app.link.robot_link import RobotLink
from app.link.types import ConnectionState, LinkState
from app.models import CommandResult, Pose
from app.protocol import registers as R  # noqa: N812
from app.protocol.enums import ProgramMotionMode, RunCommand
from app.sim import SimConfig, SimController, WriteRecord
from ui.main_window import DEFAULT_SIZE, MainWindow
from ui.settings import AppSettings

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


def _qapp() -> QApplication:
    global _app
    existing = QApplication.instance()
    _app = existing if isinstance(existing, QApplication) else QApplication(["teachpad-bench"])
    return _app


# --------------------------------------------------------------------------------------------
# Small helpers
# --------------------------------------------------------------------------------------------


def _pct(values: Sequence[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(len(ordered) * q))]


def _summary_ms(seconds: Sequence[float]) -> dict[str, float]:
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
from app.sim import SimConfig, SimController
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
        self._proc = subprocess.Popen([sys.executable, "-c", _SIM_HOST_CHILD], cwd=REPO, env=env, text=True,
                                      stdin=subprocess.PIPE, stdout=subprocess.PIPE, bufsize=1)
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
        figures["gui_thread_cpu_pct_per_100hz"] = (figures["gui_thread_cpu_pct"] * POLL_HZ
                                                   / figures["polls_per_s"])


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
        link.poseChanged.connect(self._on_pose)
        link.trafficObserved.connect(self._on_traffic)
        link.commandFinished.connect(self._on_result)
        link.connectionChanged.connect(self._on_connection)

    def _on_pose(self, _pose: Pose) -> None:
        self.poses += 1

    def _on_traffic(self, batch: list[Any]) -> None:
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


# --------------------------------------------------------------------------------------------
# 1. Stop latency
# --------------------------------------------------------------------------------------------


def bench_stop_gui(window: MainWindow, sim: SimHandle, counters: _Counters, n: int, rng: random.Random,
                   *, posted: bool = False, budget_s: float = float("inf")) -> dict[str, Any]:
    """Stop at a random phase of the 100 Hz poll while program STOP_PROGRAM runs.

    ``posted`` False: the Stop button's ``click()`` from a GUI-thread timer, t0 just before it
    (the application's own path, click to wire). ``posted`` True: a mouse press and release
    posted to the Stop button from another thread at a random time, t0 just before posting
    (what an operator's click meets: the event loop has to get to it first).
    Ends early, with fewer samples, after ``budget_s`` (a saturated GUI makes each sample slow).
    """
    link = window.link
    button = window.control_bar.stop_button
    spread = INPUT_PHASE_SPREAD_S if posted else 1.0 / POLL_HZ
    latencies: list[float] = []
    failures = 0
    pending: dict[str, float | int] = {}
    found: list[WriteRecord] = []
    clicker = QTimer()
    clicker.setSingleShot(True)
    clicker.setTimerType(Qt.TimerType.PreciseTimer)

    def click() -> None:
        pending["t0"] = time.monotonic()
        button.click()

    def post_click(local: QPointF, screen: QPointF) -> None:  # runs in a timer thread
        left, none, plain = Qt.MouseButton.LeftButton, Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier
        press = QMouseEvent(QEvent.Type.MouseButtonPress, local, screen, left, left, plain)
        release = QMouseEvent(QEvent.Type.MouseButtonRelease, local, screen, left, none, plain)
        pending["t0"] = time.monotonic()
        QCoreApplication.postEvent(button, press)
        QCoreApplication.postEvent(button, release)

    def stop_seen() -> bool:
        record = _stop_write_after(sim, int(pending["index"]))
        if record is not None:
            found.append(record)
        return record is not None

    clicker.timeout.connect(click)
    deadline = time.monotonic() + budget_s
    out: dict[str, Any] = {"budget_exhausted": False}
    for i in range(n + WARMUP_SAMPLES):
        if time.monotonic() > deadline:
            out["budget_exhausted"] = True
            break
        # (Re)start the motion and wait until the simulator runs it and a poll has seen it.
        start = sim.write_count()
        link.run_program(STOP_PROGRAM, ProgramMotionMode.CYCLE, 0, 100)
        if not _wait_until(functools.partial(_motion_started, sim, start)):
            failures += 1
            continue
        poses = counters.poses
        if not _wait_until(functools.partial(_more_poses, counters, poses)):
            failures += 1
            continue
        # Just after a poll: a uniform delay over one poll period (posted input: over one paint
        # period of the monitor, several polls) spreads the stop over the cycle.
        found.clear()
        pending.clear()
        pending["index"] = sim.write_count()
        pending["results"] = len(counters.results)
        delay = rng.uniform(0.0, spread)
        poster: threading.Timer | None = None
        if posted:
            local = QPointF(button.rect().center())
            poster = threading.Timer(delay, post_click, (local, button.mapToGlobal(local)))
            poster.start()
        else:
            clicker.start(int(1000.0 * delay))
        seen = _wait_until(lambda: "t0" in pending) and _wait_until(stop_seen)
        if poster is not None:
            poster.join()
        if not seen:
            failures += 1
            continue
        # Let the worker finish the stop job ("stop: sent") before the next run request.
        done = int(pending["results"])
        if not _wait_until(functools.partial(_stop_sent, counters, done)):
            failures += 1
        if i >= WARMUP_SAMPLES:
            latencies.append(found[0].t - float(pending["t0"]))
    out.update(_summary_ms(latencies) if latencies else {"n": 0})
    out["failures"] = failures
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


# --------------------------------------------------------------------------------------------
# 2. Event-loop stalls
# --------------------------------------------------------------------------------------------


def measure_stalls(seconds: float) -> dict[str, Any]:
    """Gaps between the firings of a 1 ms PreciseTimer in the GUI thread, for ``seconds``."""
    stamps: list[float] = []
    clock = time.perf_counter
    timer = QTimer()
    timer.setTimerType(Qt.TimerType.PreciseTimer)
    timer.setInterval(STALL_TIMER_MS)
    timer.timeout.connect(lambda: stamps.append(clock()))
    cpu_gui, cpu_process, wall = time.thread_time(), time.process_time(), time.perf_counter()
    timer.start()
    _run_for(seconds)
    timer.stop()
    wall = time.perf_counter() - wall
    cpu_gui, cpu_process = time.thread_time() - cpu_gui, time.process_time() - cpu_process
    gaps = [b - a for a, b in itertools.pairwise(stamps)]
    if not gaps:
        return {"firings": len(stamps)}
    gaps_ms = [1000.0 * g for g in gaps]
    worst = max(range(len(gaps)), key=gaps.__getitem__)
    # gaps that start after the first second: the steady state, without start-of-stream work
    steady = [g for g, t in zip(gaps_ms, stamps, strict=False) if t - stamps[0] >= STEADY_AFTER_S]
    return {
        "seconds": wall,
        "firings": len(stamps),
        "p50_ms": statistics.median(gaps_ms),
        "p99_ms": _pct(gaps_ms, 0.99),
        "p999_ms": _pct(gaps_ms, 0.999),
        "max_ms": gaps_ms[worst],
        "max_at_s": stamps[worst] - stamps[0],
        f"steady_max_ms_after_{STEADY_AFTER_S:g}s": max(steady, default=0.0),
        f"gaps_over_{STALL_THRESHOLD_MS:g}ms": sum(1 for g in gaps_ms if g > STALL_THRESHOLD_MS),
        "gaps_over_16ms": sum(1 for g in gaps_ms if g > 16.0),
        # share of the window spent inside gaps longer than a 60 Hz frame: a p99 over firings
        # under-weights long gaps (few firings happen during them)
        "time_in_gaps_over_16ms_pct": 100.0 * sum(g for g in gaps_ms if g > 16.0) / (1000.0 * wall),
        # CPU used in the window, % of one core: the GUI thread alone, and the whole process
        # (GUI + worker, + the simulator when it runs in this process)
        "gui_thread_cpu_pct": 100.0 * cpu_gui / wall,
        "process_cpu_pct": 100.0 * cpu_process / wall,
    }


# --------------------------------------------------------------------------------------------
# 3. Start-up (in a fresh interpreter)
# --------------------------------------------------------------------------------------------

# Run with ``python -c``; argv: kind ("teachpad" | "bare"), settings INI path, window size "WxH".
# Prints one line "BENCH {json}" with CLOCK_MONOTONIC marks.
_STARTUP_CHILD = r"""
import time
T0 = time.monotonic()
import json, os, sys
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
marks = {"interpreter_ready": T0}
def mark(name):
    marks.setdefault(name, time.monotonic())
from PySide6.QtCore import QEvent, QObject, QTimer
from PySide6.QtWidgets import QApplication, QLabel, QMainWindow
mark("qt_imported")
kind, settings_path, size = sys.argv[1], sys.argv[2], sys.argv[3]
done = set()
def finish(name, need):
    mark(name)
    done.add(name)
    if need <= done:
        QApplication.instance().exit(0)

class FirstPaint:
    # mixed into the window class: first paint event, then the first return to the event loop
    def paintEvent(self, event):
        if "first_paint" not in marks:
            mark("first_paint")
            QTimer.singleShot(0, lambda: finish("first_frame", self._bench_need))
        super().paintEvent(event)

if kind == "bare":
    class Bare(FirstPaint, QMainWindow):
        _bench_need = {"first_frame"}
    app = QApplication([sys.argv[0]])
    mark("app_created")
    window = Bare()
    window.resize(*(int(v) for v in size.split("x")))
    mark("window_built")
    QTimer.singleShot(30000, app.quit)
    window.show()
    app.exec()
    window.close()
else:
    import ui.main as teachpad
    from app.sim import SimController
    mark("ui_imported")
    sim_start = SimController.start
    def timed_start(self):
        mark("sim_start_begin")
        sim_start(self)
        mark("sim_started")
    SimController.start = timed_start

    class ReadoutPaint(QObject):
        def eventFilter(self, watched, event):
            if event.type() == QEvent.Type.Paint and "first_pose" in marks:
                finish("first_pose_painted", Probe._bench_need)
            return False

    class Probe(FirstPaint, teachpad.MainWindow):
        _bench_need = {"first_frame", "first_pose_painted"}
        def __init__(self, *args, **kwargs):
            mark("window_init_begin")
            super().__init__(*args, **kwargs)
            mark("window_built")
            self.link.poseChanged.connect(self._bench_pose)  # after the window's own slots
            self._bench_filter = ReadoutPaint()
            readout = self.monitor_panel.readouts["X"]
            for widget in (readout, *readout.findChildren(QLabel)):
                widget.installEventFilter(self._bench_filter)
            QTimer.singleShot(30000, QApplication.instance().quit)
        def _bench_pose(self, _pose):
            mark("first_pose")
    teachpad.MainWindow = Probe
    teachpad.main(["--sim", "--settings", settings_path, "--size", size])
print("BENCH " + json.dumps(marks), flush=True)
"""


def _startup_once(kind: str, home: Path, run: int) -> dict[str, float]:
    # A fresh settings file and per-user directories: no saved layout, project or autosave to
    # restore (a recovery question would wait for an answer).
    user = home / f"{kind}{run}"
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", PYTHONPATH=str(REPO),
               **{f"XDG_{d}_HOME": str(user / d.lower()) for d in ("CONFIG", "DATA", "STATE", "CACHE")})
    args = [kind, str(user / "teachpad.ini"), "{}x{}".format(*DEFAULT_SIZE)]
    t_spawn = time.monotonic()
    proc = subprocess.run([sys.executable, "-c", _STARTUP_CHILD, *args], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=STARTUP_TIMEOUT_S, check=False)
    t_exit = time.monotonic()
    line = next((x for x in proc.stdout.splitlines() if x.startswith("BENCH ")), None)
    if proc.returncode != 0 or line is None:
        raise RuntimeError(f"start-up child ({kind}) failed, rc={proc.returncode}: {proc.stderr[-2000:]}")
    marks = json.loads(line[len("BENCH "):])
    out = {f"{name}_ms": 1000.0 * (t - t_spawn) for name, t in marks.items()}
    out["process_total_ms"] = 1000.0 * (t_exit - t_spawn)
    return out


def bench_startup(runs: int) -> dict[str, Any]:
    """Median over ``runs`` of each mark, for teachpad --sim and for a bare QMainWindow (alternated)."""
    samples: dict[str, list[dict[str, float]]] = {"teachpad_sim": [], "bare_qmainwindow": []}
    with tempfile.TemporaryDirectory(prefix="teachpad-bench-") as tmp:
        for i in range(runs):
            samples["teachpad_sim"].append(_startup_once("teachpad", Path(tmp), i))
            samples["bare_qmainwindow"].append(_startup_once("bare", Path(tmp), i))
    out: dict[str, Any] = {"runs": runs}
    for name, runs_marks in samples.items():
        keys = sorted(set.intersection(*(set(m) for m in runs_marks)))
        out[name] = {k: statistics.median(m[k] for m in runs_marks) for k in keys}
    out["ratio_first_paint_vs_bare"] = (out["teachpad_sim"]["first_paint_ms"]
                                        / out["bare_qmainwindow"]["first_paint_ms"])
    return out


# --------------------------------------------------------------------------------------------
# The in-process part: one main window for stalls and stop latency
# --------------------------------------------------------------------------------------------


def bench_window(sim: SimHandle, stall_s: float, n_stop: int, rng: random.Random, *,
                 complete: bool = True, n_posted: int = 0, stop_budget_s: float = float("inf"),
                 posted_budget_s: float = float("inf"), busy_s: float = 0.0) -> dict[str, Any]:
    """Stalls and stop latency with one main window on ``sim`` (see the module docstring).

    ``busy_s`` > 0 adds ``streaming_busy``: the same stream measured for ``busy_s`` while a
    busy neighbour (:class:`BusyNeighbour`) loads every other core.

    ``complete`` False (the cross-check with the simulator in another process) leaves out the
    disconnected stall baseline, the posted-input stops and the bare stops under polling.
    """
    _qapp()
    phases: dict[str, float] = {}
    clock = time.perf_counter()

    def lap(name: str) -> None:
        nonlocal clock
        now = time.perf_counter()
        phases[name] = now - clock
        clock = now

    tmp = tempfile.TemporaryDirectory(prefix="teachpad-bench-")
    link = RobotLink(poll_hz=POLL_HZ)
    window: MainWindow | None = None
    out: dict[str, Any] = {}
    try:
        window = MainWindow(link, AppSettings.from_file(Path(tmp.name) / "bench.ini"),
                            autosave_dir=Path(tmp.name) / "autosave")
        # The offscreen screen is 800x800 and would clamp the window: use the desktop default.
        window.resize(*DEFAULT_SIZE)
        window.show_tab("monitor")
        counters = _Counters(link)
        painted = _PaintCounter()
        window.installEventFilter(painted)
        window.show()
        # Tabified with the event log, which is on top: bring the inspector to the front.
        window.traffic_dock.raise_()
        traffic = window.traffic_panel
        if not _wait_until(lambda: painted.paints > 0 and not traffic.visibleRegion().isEmpty()):
            raise RuntimeError("the main window was never painted with the traffic inspector shown")
        window.removeEventFilter(painted)
        lap("window_shown")

        # --- disconnected: stall baseline and the bare stop floor ----------------------
        stalls: dict[str, Any] = {"probe_timer_ms": STALL_TIMER_MS}
        if complete:
            stalls["disconnected"] = measure_stalls(stall_s)
        floor = bench_stop_bare(sim, n_stop, rng)
        lap("disconnected")

        # --- connected at 100 Hz, program running: streaming stalls -------------------
        link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, unit=sim.unit))
        if not _wait_until(lambda: counters.state.state is LinkState.CONNECTED):
            raise RuntimeError(f"could not connect to the simulator: {counters.state.message}")
        start = sim.write_count()
        link.run_program(STREAM_PROGRAM, ProgramMotionMode.CYCLE, 0, 100)
        if not _wait_until(lambda: _motion_started(sim, start)):
            raise RuntimeError("the simulator did not start the streaming program")
        poses0, frames0, requests0 = counters.poses, counters.traffic_frames, sim.requests()
        t0 = time.perf_counter()
        streaming = measure_stalls(stall_s)
        elapsed = time.perf_counter() - t0
        # a poll is two reads (pose block, status block): the rate the worker really reached
        streaming["polls_per_s"] = (sim.requests() - requests0) / 2 / elapsed
        streaming["poses_per_s"] = (counters.poses - poses0) / elapsed
        streaming["traffic_frames_per_s"] = (counters.traffic_frames - frames0) / elapsed
        _per_100hz(streaming)
        streaming["traffic_shown"] = not traffic.visibleRegion().isEmpty()
        streaming["monitor_shown"] = not window.monitor_panel.visibleRegion().isEmpty()
        stalls["streaming"] = streaming
        if busy_s > 0:
            stalls["streaming_busy"] = _measure_streaming_busy(window, sim, counters, busy_s)
        if complete:
            idle_max = stalls["disconnected"]["max_ms"]
            stalls["ratio_max_streaming_vs_disconnected"] = streaming["max_ms"] / idle_max
            # Attribution: the same stream with the Points tab in front (the monitor's plots and
            # readouts hidden, its paint timer stopped); the traffic inspector stays shown.
            window.show_tab("points")
            requests0, t0 = sim.requests(), time.perf_counter()
            hidden = measure_stalls(stall_s / 2)
            hidden["polls_per_s"] = (sim.requests() - requests0) / 2 / (time.perf_counter() - t0)
            hidden["monitor_shown"] = not window.monitor_panel.visibleRegion().isEmpty()
            stalls["streaming_monitor_hidden"] = hidden
            # The same stream with the 3D view in front: the arm redrawn from every pose.
            view3d = window.view3d.panel
            window.work_tabs.setCurrentWidget(view3d)
            _run_for(VIEW3D_SETTLE_S)  # its first paint and scene build are not the steady state
            requests0, t0 = sim.requests(), time.perf_counter()
            shown3d = measure_stalls(stall_s / 2)
            shown3d["polls_per_s"] = (sim.requests() - requests0) / 2 / (time.perf_counter() - t0)
            shown3d["view3d_shown"] = not view3d.canvas.visibleRegion().isEmpty()
            stalls["streaming_view3d_shown"] = shown3d
            window.show_tab("monitor")
        out["event_loop_stall"] = stalls
        # End the streaming program the ordinary way before the stop-latency runs.
        link.stop()
        if not _wait_until(lambda: not sim.busy()):
            raise RuntimeError("the streaming program did not stop")
        lap("streaming")

        # --- stop latency from the GUI, then the bare floor under the same polling -----
        gui = bench_stop_gui(window, sim, counters, n_stop, rng, budget_s=stop_budget_s)
        stops: dict[str, Any] = {
            "gui_stop_button": gui,
            "bare_pymodbus_idle": floor,
            "ratio_p50_gui_vs_bare_idle": gui["p50_ms"] / floor["p50_ms"],
            "ratio_p99_gui_vs_bare_idle": gui["p99_ms"] / floor["p99_ms"],
        }
        lap("stop_clicks")
        if complete:
            stops["gui_posted_mouse_click"] = bench_stop_gui(window, sim, counters, n_posted, rng,
                                                             posted=True, budget_s=posted_budget_s)
            lap("stop_posted_input")
            stops["bare_pymodbus_while_polling"] = bench_stop_bare(sim, n_stop, rng)
        out["stop_latency"] = stops
        out["traffic_rows_at_end"] = traffic.model.rowCount()
    finally:
        if window is not None:
            window.close()  # saves state and shuts the link down (blocking queued call)
        link.shutdown()
        if window is not None:
            window.deleteLater()
        QApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
        gc.collect()  # pyqtgraph's reference cycles keep ~40 menus alive until collected
        tmp.cleanup()
    if link.is_running:
        raise RuntimeError("the robot worker thread is still running after shutdown")
    lap("rest_and_shutdown")
    out["phase_s"] = phases
    return out


def _with_sim(make: Callable[[], SimHandle], body: Callable[[SimHandle], dict[str, Any]]) -> dict[str, Any]:
    sim = make()
    try:
        return body(sim)
    finally:
        sim.stop()


def run(quick: bool) -> dict[str, Any]:
    rng = random.Random(20240611)
    t0 = time.perf_counter()
    out: dict[str, Any] = {"load_avg_1m_at_start": os.getloadavg()[0], "poll_hz": POLL_HZ}
    # As specified: the simulator in this process (what teachpad --sim does).
    # Sample counts, and time budgets that keep the suite bounded when the GUI is saturated.
    stall_s, n_stop, n_posted = (3.0, 50, 30) if quick else (10.0, 200, 100)
    stop_budget, posted_budget = (4.0, 3.0) if quick else (10.0, 6.0)
    out["sim_in_process"] = _with_sim(LocalSim, lambda sim: bench_window(
        sim, stall_s, n_stop, rng, n_posted=n_posted, stop_budget_s=stop_budget,
        posted_budget_s=posted_budget))
    # The simulator in its own process, as a real controller would be: no GIL shared with it.
    stall_s, n_stop, stop_budget = (2.0, 20, 2.0) if quick else (4.0, 60, 3.0)
    out["sim_separate_process"] = _with_sim(RemoteSim, lambda sim: bench_window(
        sim, stall_s, n_stop, rng, complete=False, stop_budget_s=stop_budget, busy_s=stall_s))
    t1 = time.perf_counter()
    out["startup"] = bench_startup(1 if quick else 3)
    out["startup"]["suite_s"] = time.perf_counter() - t1
    from benchmarks import view3d  # the 3D view's frame times (10,000 markers, 1,000 segments)

    out["view3d"] = view3d.run(quick)
    out["suite_s"] = time.perf_counter() - t0
    return out


# --------------------------------------------------------------------------------------------
# 4. A busy neighbour, and memory (idle RSS after start-up, a soak)
# --------------------------------------------------------------------------------------------


class BusyNeighbour:
    """A parallel CPU load: one ``while True: pass`` child process per core beyond the first
    (at least one), for the life of the ``with`` block -- the operator PC's other work."""

    def __init__(self, procs: int | None = None) -> None:
        self.procs = procs if procs is not None else max(1, (os.cpu_count() or 2) - 1)
        self._children: list[subprocess.Popen[bytes]] = []

    def __enter__(self) -> BusyNeighbour:
        for _ in range(self.procs):
            self._children.append(subprocess.Popen([sys.executable, "-c", "while True: pass"]))
        return self

    def __exit__(self, *exc: object) -> None:
        for child in self._children:  # only the children started here, by their handles
            child.kill()
        for child in self._children:
            child.wait()
        self._children.clear()


def _measure_streaming_busy(window: MainWindow, sim: SimHandle, counters: _Counters,
                            seconds: float) -> dict[str, Any]:
    """The streaming figures again, with :class:`BusyNeighbour` running."""
    with BusyNeighbour() as busy:
        _run_for(0.2)  # let the neighbours reach full speed
        poses0, frames0, requests0 = counters.poses, counters.traffic_frames, sim.requests()
        t0 = time.perf_counter()
        out = measure_stalls(seconds)
        elapsed = time.perf_counter() - t0
        out["polls_per_s"] = (sim.requests() - requests0) / 2 / elapsed
    out["poses_per_s"] = (counters.poses - poses0) / elapsed
    out["traffic_frames_per_s"] = (counters.traffic_frames - frames0) / elapsed
    _per_100hz(out)
    out["busy_neighbour_procs"] = busy.procs
    out["monitor_shown"] = not window.monitor_panel.visibleRegion().isEmpty()
    out["traffic_shown"] = not window.traffic_panel.visibleRegion().isEmpty()
    return out


MEMORY_SETTLE_S = 3.0  # after the first pose, before the idle RSS is read
SOAK_LONG_S, SOAK_LONG_EVERY_S = 600.0, 30.0  # --long: a 10-minute soak, RSS every 30 s

# ``python -c``; argv: settings INI, window size, soak seconds, sample period. ``teachpad --sim``
# with the window's first pose as the start; after MEMORY_SETTLE_S the idle RSS, then a
# streaming program (the 100 mm square, cycled) with RSS every period. Lines "RSS {json}".
_MEMORY_CHILD = r"""
import gc, json, os, sys, time
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication
import ui.main as teachpad
from app.protocol.enums import ProgramMotionMode
settings_path, size, soak_s, every_s, settle_s, program = sys.argv[1:7]
soak_s, every_s, settle_s, program = float(soak_s), float(every_s), float(settle_s), int(program)

def rss_mb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")

def report(kind, **extra):
    print("RSS " + json.dumps(dict(kind=kind, t=time.monotonic(), rss_mb=rss_mb(), **extra)), flush=True)

class Probe(teachpad.MainWindow):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._bench_started = False
        self.link.poseChanged.connect(self._bench_pose)
        QTimer.singleShot(int(1000 * (soak_s + settle_s + 120)), QApplication.instance().quit)
    def _bench_pose(self, _pose):
        if self._bench_started:
            return
        self._bench_started = True
        report("first_pose")
        QTimer.singleShot(int(1000 * settle_s), self._bench_idle)
    def _bench_idle(self):
        gc.collect()
        report("idle")
        self.traffic_dock.raise_()  # the inspector shown too: its capture is part of the soak
        self.link.run_program(program, ProgramMotionMode.CYCLE, 0, 100)
        self._bench_t0 = time.monotonic()
        self._bench_timer = QTimer(self)
        self._bench_timer.timeout.connect(self._bench_sample)
        self._bench_timer.start(int(1000 * every_s))
    def _bench_sample(self):
        report("soak", traffic_rows=self.traffic_panel.model.rowCount())
        if time.monotonic() - self._bench_t0 >= soak_s - 1e-3:
            self.link.stop()
            QApplication.instance().quit()
teachpad.MainWindow = Probe
teachpad.main(["--sim", "--settings", settings_path, "--size", size])
"""


def bench_memory(soak_s: float, every_s: float) -> dict[str, Any]:
    """RSS of a ``teachpad --sim`` process: idle after start-up, then over a streaming soak."""
    with tempfile.TemporaryDirectory(prefix="teachpad-bench-") as tmp:
        user = Path(tmp)
        env = dict(os.environ, QT_QPA_PLATFORM="offscreen", PYTHONPATH=str(REPO),
                   **{f"XDG_{d}_HOME": str(user / d.lower()) for d in ("CONFIG", "DATA", "STATE", "CACHE")})
        args = [str(user / "teachpad.ini"), "{}x{}".format(*DEFAULT_SIZE), str(soak_s), str(every_s),
                str(MEMORY_SETTLE_S), str(STREAM_PROGRAM)]
        proc = subprocess.run([sys.executable, "-c", _MEMORY_CHILD, *args], cwd=REPO, env=env,
                              capture_output=True, text=True, check=False,
                              timeout=STARTUP_TIMEOUT_S + MEMORY_SETTLE_S + soak_s + 120)
    rows = [json.loads(x[4:]) for x in proc.stdout.splitlines() if x.startswith("RSS ")]
    idle = next((r for r in rows if r["kind"] == "idle"), None)
    if proc.returncode != 0 or idle is None:
        raise RuntimeError(f"memory child failed, rc={proc.returncode}: {proc.stderr[-2000:]}")
    soak = [r for r in rows if r["kind"] == "soak"]
    out: dict[str, Any] = {
        "what": "VmRSS of teachpad --sim (the GUI process), idle connected, then streaming program "
                f"{STREAM_PROGRAM} at {POLL_HZ:g} Hz polling",
        "idle_rss_mb": round(idle["rss_mb"], 1),
        "first_pose_rss_mb": round(next(r["rss_mb"] for r in rows if r["kind"] == "first_pose"), 1),
    }
    if soak:
        samples = [round(r["rss_mb"], 1) for r in soak]
        minutes = (soak[-1]["t"] - soak[0]["t"]) / 60.0
        # growth from the first soak sample (plots and traffic buffers filled) to the last
        growth = samples[-1] - samples[0]
        out["soak"] = {
            "seconds": round(soak[-1]["t"] - idle["t"], 1),
            "every_s": every_s,
            "rss_mb": samples,
            "traffic_rows": [r.get("traffic_rows") for r in soak],
            "peak_rss_mb": max(samples),
            "growth_mb": round(growth, 1),
            "growth_mb_per_10min": round(10.0 * growth / minutes, 1) if minutes > 0 else None,
        }
    return out


def run_memory(quick: bool, long: bool) -> dict[str, Any]:
    """``gui.memory``: the idle RSS; a soak of 10 minutes with ``long``, else a short one."""
    if long:
        return bench_memory(SOAK_LONG_S, SOAK_LONG_EVERY_S)
    return bench_memory(10.0, 5.0) if quick else bench_memory(60.0, 10.0)


if __name__ == "__main__":
    json.dump(run("--quick" in sys.argv[1:]), sys.stdout, indent=2, sort_keys=True)
    sys.stdout.write("\n")
