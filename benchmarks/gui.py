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

import gc
import json
import os
import random
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEvent
from PySide6.QtWidgets import QApplication

from app.connection import ConnectionSettings
from app.link.ops import RunProgram, Stop
from app.link.robot_link import RobotLink
from app.link.types import LinkState
from app.protocol.enums import ProgramMotionMode
from benchmarks.goals import guarded
from benchmarks.gui_common import (
    POLL_HZ,
    STALL_TIMER_MS,
    STREAM_PROGRAM,
    VIEW3D_SETTLE_S,
    LocalSim,
    RemoteSim,
    SimHandle,
    _Counters,
    _motion_started,
    _PaintCounter,
    _per_100hz,
    _qapp,
    _run_for,
    _wait_until,
    ratio,
)
from benchmarks.gui_stalls import _measure_streaming_busy, add_no_probe, measure_stalls
from benchmarks.gui_startup import bench_startup
from benchmarks.gui_stop import bench_stop_bare, bench_stop_gui
from ui.main_window import MainWindow
from ui.settings import AppSettings
from ui.window_geometry import DEFAULT_SIZE

__all__ = [
    "bench_window",
    "run",
    "show_streaming_layout",
]


# --------------------------------------------------------------------------------------------
# The in-process part: one main window for stalls and stop latency
# --------------------------------------------------------------------------------------------


def show_streaming_layout(window: MainWindow) -> None:
    """Show the window as the streaming figures measure it: desktop size, the Monitor tab and the
    traffic inspector in front, painted once."""
    # The offscreen screen is 800x800 and would clamp the window: use the desktop default.
    window.resize(*DEFAULT_SIZE)
    window.show_tab("monitor")
    painted = _PaintCounter()
    window.installEventFilter(painted)
    window.show()
    # Tabified with the event log, which is on top: bring the inspector to the front.
    window.traffic_dock.raise_()
    traffic = window.traffic_panel
    if not _wait_until(lambda: painted.paints > 0 and not traffic.visibleRegion().isEmpty()):
        raise RuntimeError("the main window was never painted with the traffic inspector shown")
    window.removeEventFilter(painted)


def bench_window(
    sim: SimHandle,
    stall_s: float,
    n_stop: int,
    rng: random.Random,
    *,
    complete: bool = True,
    n_posted: int = 0,
    stop_budget_s: float = float("inf"),
    posted_budget_s: float = float("inf"),
    busy_s: float = 0.0,
) -> dict[str, Any]:
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
        window = MainWindow(
            link,
            AppSettings.from_file(Path(tmp.name) / "bench.ini"),
            autosave_dir=Path(tmp.name) / "autosave",
        )
        counters = _Counters(link)
        show_streaming_layout(window)
        lap("window_shown")

        # --- disconnected: stall baseline and the bare stop floor ----------------------
        stalls: dict[str, Any] = {"probe_timer_ms": STALL_TIMER_MS}
        if complete:
            stalls["disconnected"] = measure_stalls(stall_s)
        floor = bench_stop_bare(sim, n_stop, rng)
        lap("disconnected")

        # --- connected at 100 Hz, program running: streaming stalls -------------------
        _start_streaming(link, sim, counters)
        stalls["streaming"] = _measure_streaming(window, sim, counters, stall_s)
        if busy_s > 0:
            stalls["streaming_busy"] = _measure_streaming_busy(window, sim, counters, busy_s)
        if complete:
            _measure_attribution(window, sim, stalls, stall_s)
        out["event_loop_stall"] = stalls
        # End the streaming program the ordinary way before the stop-latency runs.
        link.submit(Stop())
        if not _wait_until(lambda: not sim.busy()):
            raise RuntimeError("the streaming program did not stop")
        lap("streaming")

        # --- stop latency from the GUI, then the bare floor under the same polling -----
        out["stop_latency"] = _measure_stops(
            window,
            sim,
            counters,
            n_stop,
            rng,
            floor,
            lap,
            posted=(n_posted, posted_budget_s) if complete else None,
            stop_budget_s=stop_budget_s,
        )
        out["traffic_rows_at_end"] = window.traffic_panel.model.rowCount()
    finally:
        _close_window(window, link, tmp)
    if link.is_running:
        raise RuntimeError("the robot worker thread is still running after shutdown")
    lap("rest_and_shutdown")
    out["phase_s"] = phases
    return out


def _start_streaming(link: RobotLink, sim: SimHandle, counters: _Counters) -> None:
    """Connect the window's link and start the streaming program on the simulator."""
    link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, unit=sim.unit))
    if not _wait_until(lambda: counters.state.state is LinkState.CONNECTED):
        raise RuntimeError(f"could not connect to the simulator: {counters.state.message}")
    start = sim.write_count()
    link.submit(RunProgram(STREAM_PROGRAM, ProgramMotionMode.CYCLE, 0, 100))
    if not _wait_until(lambda: _motion_started(sim, start)):
        raise RuntimeError("the simulator did not start the streaming program")


def _measure_streaming(
    window: MainWindow, sim: SimHandle, counters: _Counters, stall_s: float
) -> dict[str, Any]:
    """The streaming stalls with the rates the worker and the views really reached."""
    poses0, frames0, requests0 = counters.poses, counters.traffic_frames, sim.requests()
    t0 = time.perf_counter()
    streaming = measure_stalls(stall_s)
    elapsed = time.perf_counter() - t0
    # a poll is two reads (pose block, status block): the rate the worker really reached
    streaming["polls_per_s"] = (sim.requests() - requests0) / 2 / elapsed
    streaming["poses_per_s"] = (counters.poses - poses0) / elapsed
    streaming["traffic_frames_per_s"] = (counters.traffic_frames - frames0) / elapsed
    _per_100hz(streaming)
    add_no_probe(streaming, stall_s)
    streaming["traffic_shown"] = not window.traffic_panel.visibleRegion().isEmpty()
    streaming["monitor_shown"] = not window.monitor_panel.visibleRegion().isEmpty()
    return streaming


def _stalls_and_polls(sim: SimHandle, seconds: float) -> dict[str, Any]:
    """The stalls over ``seconds`` and the poll rate meanwhile (a poll is two reads)."""
    requests0, t0 = sim.requests(), time.perf_counter()
    stalls = measure_stalls(seconds)
    stalls["polls_per_s"] = (sim.requests() - requests0) / 2 / (time.perf_counter() - t0)
    return stalls


def _measure_attribution(window: MainWindow, sim: SimHandle, stalls: dict[str, Any], stall_s: float) -> None:
    """Into ``stalls``: streaming against disconnected, then the same stream with the Points tab
    in front (the monitor's plots and readouts hidden, its paint timer stopped; the traffic
    inspector stays shown) and with the 3D view in front (the arm redrawn from every pose)."""
    idle_max = stalls["disconnected"].get("max_ms")
    stalls["ratio_max_streaming_vs_disconnected"] = ratio(stalls["streaming"].get("max_ms"), idle_max)
    window.show_tab("points")
    hidden = _stalls_and_polls(sim, stall_s / 2)
    hidden["monitor_shown"] = not window.monitor_panel.visibleRegion().isEmpty()
    stalls["streaming_monitor_hidden"] = hidden
    view3d = window.view3d.panel
    window.work_tabs.setCurrentWidget(view3d)
    _run_for(VIEW3D_SETTLE_S)  # its first paint and scene build are not the steady state
    shown3d = _stalls_and_polls(sim, stall_s / 2)
    shown3d["view3d_shown"] = not view3d.canvas.visibleRegion().isEmpty()
    stalls["streaming_view3d_shown"] = shown3d
    window.show_tab("monitor")


def _measure_stops(
    window: MainWindow,
    sim: SimHandle,
    counters: _Counters,
    n_stop: int,
    rng: random.Random,
    floor: dict[str, Any],
    lap: Callable[[str], None],
    *,
    posted: tuple[int, float] | None,
    stop_budget_s: float,
) -> dict[str, Any]:
    """Stop latency from the GUI's button against the bare floor; with ``posted`` (samples,
    budget) also the posted mouse clicks and the bare stops under the same polling."""
    gui = bench_stop_gui(window, sim, counters, n_stop, rng, budget_s=stop_budget_s)
    stops: dict[str, Any] = {
        "gui_stop_button": gui,
        "bare_pymodbus_idle": floor,
        "ratio_p50_gui_vs_bare_idle": ratio(gui.get("p50_ms"), floor.get("p50_ms")),
        "ratio_p99_gui_vs_bare_idle": ratio(gui.get("p99_ms"), floor.get("p99_ms")),
    }
    lap("stop_clicks")
    if posted is not None:
        n_posted, posted_budget_s = posted
        stops["gui_posted_mouse_click"] = bench_stop_gui(
            window, sim, counters, n_posted, rng, posted=True, budget_s=posted_budget_s
        )
        lap("stop_posted_input")
        stops["bare_pymodbus_while_polling"] = bench_stop_bare(sim, n_stop, rng)
    return stops


def _close_window(window: MainWindow | None, link: RobotLink, tmp: tempfile.TemporaryDirectory[str]) -> None:
    """Close the window unattended (it stops what runs), shut the link down, free what they held."""
    if window is not None:
        window.close_unattended()  # no question: stops what runs, shuts the link down
    link.shutdown()
    if window is not None:
        window.deleteLater()
    QApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    gc.collect()  # pyqtgraph's reference cycles keep ~40 menus alive until collected
    tmp.cleanup()


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
    out["sim_in_process"] = guarded(
        "sim_in_process",
        lambda: _with_sim(
            LocalSim,
            lambda sim: bench_window(
                sim,
                stall_s,
                n_stop,
                rng,
                n_posted=n_posted,
                stop_budget_s=stop_budget,
                posted_budget_s=posted_budget,
            ),
        ),
    )
    # The simulator in its own process, as a real controller would be: no GIL shared with it.
    # 300 stops: the goal's p99 is then the 3rd worst, not the worst of 60 (one late wake-up of a
    # noisy machine was the figure); ~15 s on a quiet machine, the budget bounds a saturated one.
    stall_s, n_stop, stop_budget = (2.0, 20, 2.0) if quick else (4.0, 300, 25.0)
    out["sim_separate_process"] = guarded(
        "sim_separate_process",
        lambda: _with_sim(
            RemoteSim,
            lambda sim: bench_window(
                sim, stall_s, n_stop, rng, complete=False, stop_budget_s=stop_budget, busy_s=stall_s
            ),
        ),
    )
    t1 = time.perf_counter()
    out["startup"] = guarded("startup", lambda: bench_startup(1 if quick else 9))  # 9: a steadier median
    out["startup"]["suite_s"] = time.perf_counter() - t1
    from benchmarks import view3d  # the 3D view's frame times (10,000 markers, 1,000 segments)

    out["view3d"] = guarded("view3d", lambda: view3d.run(quick))
    out["suite_s"] = time.perf_counter() - t0
    return out


if __name__ == "__main__":
    json.dump(run("--quick" in sys.argv[1:]), sys.stdout, indent=2, sort_keys=True)
    sys.stdout.write("\n")
