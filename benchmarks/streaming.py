"""The streaming figures alone, repeated, and where the GUI thread's time goes.

``gui.sim_separate_process.event_loop_stall.streaming`` of :mod:`benchmarks.gui` is one sample
inside a long suite; this runs the same measurement (the main window at its desktop size, the
Monitor tab and the traffic inspector shown, the simulator in its own process running the
100 mm square, polling at 100 Hz) ``--repeat`` times and reports each run and the medians,
with the load average: ``gui_thread_cpu_pct_no_probe`` (the goal's figure: the same stream
measured again right after, without the 1 ms probe timer) and the probe's figures. ``--busy``
adds the busy-neighbour variant after each run, ``--profile FILE`` writes a cProfile of the GUI
thread over the probe-free windows (the worker thread is not profiled: cProfile follows the
thread that enables it), and ``--variants`` measures the stream again with the monitor hidden
and with the traffic inspector hidden.

``--warm SECONDS`` streams that long before measuring (default 1 s): with 31 s the monitor's
30 s plots and its X–Y trace are full, as for an operator watching a program run (the first
seconds draw short curves). ``--events`` counts the Qt events the GUI thread handles per
second over the windows, by type, and the paints and re-layouts per widget class: the
re-layouts of the main window and the paints of widgets no frame changed are what to look for.

``--synthetic`` feeds the same window from a 100 Hz timer in the GUI thread instead (the pose
moving on the simulator's square, a status, a good poll and the four traffic frames per poll,
the way the link delivers them), with no worker and no simulator: the GUI thread's CPU time per
poll, scaled to 100 polls a second, without the closed loop of a real link (on a loaded
machine a starved GUI gets fewer polls and the link flaps to "not answering").

Usage: python -m benchmarks.streaming [--seconds 4] [--repeat 3] [--busy] [--variants]
                                      [--warm 1] [--events] [--synthetic]
                                      [--profile gui.prof] [--top 25]
"""

from __future__ import annotations

import argparse
import collections
import cProfile
import gc
import io
import json
import math
import os
import pstats
import statistics
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEvent, QEventLoop, QObject, Qt, QTimer
from PySide6.QtWidgets import QApplication

from app.connection import ConnectionSettings
from app.link.ops import RunProgram, Stop
from app.link.robot_link import RobotLink
from app.link.types import ConnectionState, LinkState
from app.models import ControllerStatus, Pose
from app.protocol.enums import Alarm, ProgramMotionMode
from benchmarks.gui import show_streaming_layout
from benchmarks.gui_common import (
    POLL_HZ,
    STREAM_PROGRAM,
    RemoteSim,
    _Counters,
    _motion_started,
    _qapp,
    _run_for,
    _wait_until,
)
from benchmarks.gui_stalls import BusyNeighbour, add_no_probe, measure_stalls
from benchmarks.traffic import Feed
from ui.main_window import MainWindow
from ui.settings import AppSettings

_KEYS = (
    "gui_thread_cpu_pct_no_probe",
    "gui_thread_cpu_pct",
    "gui_thread_cpu_pct_per_100hz",
    "process_cpu_pct",
    "p50_ms",
    "p99_ms",
    "max_ms",
    "time_in_gaps_over_16ms_pct",
    "polls_per_s",
    "poses_per_s",
)


class EventCounter(QObject):
    """Counts the events the application delivers (an application-wide filter): per type, and
    the paints and layout requests per receiving class. Installed only while counting."""

    def __init__(self) -> None:
        super().__init__()
        self.types: collections.Counter[str] = collections.Counter()
        self.paints: collections.Counter[str] = collections.Counter()
        self.layouts: collections.Counter[str] = collections.Counter()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        kind = event.type()
        self.types[kind.name] += 1
        if kind == QEvent.Type.Paint:
            self.paints[type(watched).__name__] += 1
        elif kind == QEvent.Type.LayoutRequest:
            self.layouts[type(watched).__name__] += 1
        return False

    def per_second(self, seconds: float, top: int = 12) -> dict[str, dict[str, float]]:
        def rates(counter: collections.Counter[str]) -> dict[str, float]:
            return {k: round(v / seconds, 1) for k, v in counter.most_common(top)}

        return {
            "events_per_s": rates(self.types),
            "paints_per_s": rates(self.paints),
            "layout_requests_per_s": rates(self.layouts),
        }


@contextmanager
def streaming_window(sim: RemoteSim, warm_s: float = 1.0) -> Iterator[tuple[MainWindow, _Counters]]:
    """The main window as :func:`benchmarks.gui.bench_window` shows it, connected, program running."""
    _qapp()
    tmp = tempfile.TemporaryDirectory(prefix="teachpad-bench-")
    link = RobotLink(poll_hz=POLL_HZ)
    window: MainWindow | None = None
    try:
        window = MainWindow(
            link,
            AppSettings.from_file(Path(tmp.name) / "bench.ini"),
            autosave_dir=Path(tmp.name) / "autosave",
        )
        counters = _Counters(link)
        show_streaming_layout(window)
        link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, unit=sim.unit))
        if not _wait_until(lambda: counters.state.state is LinkState.CONNECTED):
            raise RuntimeError(f"could not connect to the simulator: {counters.state.message}")
        start = sim.write_count()
        link.submit(RunProgram(STREAM_PROGRAM, ProgramMotionMode.CYCLE, 0, 100))
        if not _wait_until(lambda: _motion_started(sim, start)):
            raise RuntimeError("the simulator did not start the streaming program")
        _run_for(warm_s)  # the plots' first paints and the stream's start are not the steady state
        yield window, counters
        link.submit(Stop())
        _wait_until(lambda: not sim.busy())
    finally:
        if window is not None:
            window.close_unattended()  # no question (nobody answers): stops what runs
        link.shutdown()
        if window is not None:
            window.deleteLater()
        QApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
        gc.collect()
        tmp.cleanup()


def _stream(
    sim: RemoteSim,
    counters: _Counters,
    seconds: float,
    profiler: cProfile.Profile | None,
    events: EventCounter | None = None,
) -> dict[str, Any]:
    poses0, requests0 = counters.poses, sim.requests()
    app = QApplication.instance()
    if events is not None and app is not None:
        app.installEventFilter(events)
    out = measure_stalls(seconds)
    if events is not None and app is not None:
        app.removeEventFilter(events)
    out["polls_per_s"] = (sim.requests() - requests0) / 2 / out["seconds"]
    out["poses_per_s"] = (counters.poses - poses0) / out["seconds"]
    # the goal's figure: the same stream right after, without the 1 ms probe (and profiled there:
    # the probe's own ~1,000 calls a second are not the GUI's work)
    if profiler is not None:
        profiler.enable()
    add_no_probe(out, seconds)
    if profiler is not None:
        profiler.disable()
    # A loaded machine delivers fewer polls (and so less work) than asked: the same CPU time per
    # poll, scaled to 100 polls a second, compares runs under different load.
    out["gui_thread_cpu_pct_per_100hz"] = out["gui_thread_cpu_pct"] * 100.0 / max(1.0, out["polls_per_s"])
    return {k: round(out[k], 2) for k in _KEYS if k in out}


def run_once(
    seconds: float,
    *,
    busy: bool,
    variants: bool,
    profiler: cProfile.Profile | None,
    warm_s: float = 1.0,
    count_events: bool = False,
) -> dict[str, Any]:
    sim = RemoteSim()
    try:
        with streaming_window(sim, warm_s) as (window, counters):
            out: dict[str, Any] = {"load_avg_1m": os.getloadavg()[0]}
            events = EventCounter() if count_events else None
            out["streaming"] = _stream(sim, counters, seconds, profiler, events)
            if events is not None:
                out["events"] = events.per_second(seconds)
            out["streaming"]["monitor_shown"] = not window.monitor_panel.visibleRegion().isEmpty()
            out["streaming"]["traffic_shown"] = not window.traffic_panel.visibleRegion().isEmpty()
            if busy:
                with BusyNeighbour():
                    _run_for(0.2)
                    out["streaming_busy"] = _stream(sim, counters, seconds, None)
            if variants:
                window.show_tab("points")
                _run_for(0.3)
                out["monitor_hidden"] = _stream(sim, counters, seconds, None)
                window.show_tab("monitor")
                window.event_dock.raise_()
                _run_for(0.3)
                out["traffic_hidden"] = _stream(sim, counters, seconds, None)
                window.traffic_dock.raise_()
            return out
    finally:
        sim.stop()


def run_synthetic(seconds: float, profiler: cProfile.Profile | None) -> dict[str, Any]:
    """The main window shown as in :func:`streaming_window`, fed from a 100 Hz GUI-thread timer."""
    _qapp()
    tmp = tempfile.TemporaryDirectory(prefix="teachpad-bench-")
    link = RobotLink(poll_hz=POLL_HZ)
    window: MainWindow | None = None
    try:
        window = MainWindow(
            link,
            AppSettings.from_file(Path(tmp.name) / "bench.ini"),
            autosave_dir=Path(tmp.name) / "autosave",
        )
        show_streaming_layout(window)
        state = link.state
        state.set_connection(ConnectionState(LinkState.CONNECTED, "", "bench:502"))
        feed = Feed()
        status = ControllerStatus(2, 1, Alarm(0), 0xFF)
        polls = 0

        def poll() -> None:
            nonlocal polls
            polls += 1
            angle = 2.0 * math.pi * polls / 400.0  # a 100 mm circle in 4 s, the orientation turning
            state.set_pose(
                Pose(
                    400.0 + 50.0 * math.cos(angle),
                    50.0 * math.sin(angle),
                    300.0,
                    180.0,
                    0.0,
                    90.0 + 10.0 * math.sin(angle),
                )
            )
            state.set_status(status)
            state.note_good_poll(time.monotonic())
            link.trafficObserved.emit(tuple(feed.batch()))

        timer = QTimer()
        timer.setTimerType(Qt.TimerType.PreciseTimer)
        timer.setInterval(round(1000 / POLL_HZ))
        timer.timeout.connect(poll)
        timer.start()
        _run_for(1.0)  # the plots' first paints are not the steady state
        loop = QEventLoop()
        QTimer.singleShot(round(1000 * seconds), loop.quit)
        polls0, cpu, wall = polls, time.thread_time(), time.perf_counter()
        if profiler is not None:
            profiler.enable()
        loop.exec()
        if profiler is not None:
            profiler.disable()
        cpu, wall, n = time.thread_time() - cpu, time.perf_counter() - wall, polls - polls0
        timer.stop()
        state.set_connection(ConnectionState(LinkState.DISCONNECTED))
        return {
            "load_avg_1m": os.getloadavg()[0],
            "synthetic": {
                "polls_per_s": round(n / wall, 2),
                "gui_thread_cpu_pct": round(100.0 * cpu / wall, 2),
                "gui_thread_cpu_pct_per_100hz": round(100.0 * cpu / max(1, n) * POLL_HZ, 2),
                "gui_cpu_ms_per_poll": round(1000.0 * cpu / max(1, n), 3),
            },
        }
    finally:
        if window is not None:
            window.close_unattended()  # no question (nobody answers): stops what runs
        link.shutdown()
        if window is not None:
            window.deleteLater()
        QApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
        gc.collect()
        tmp.cleanup()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--seconds", type=float, default=4.0, help="length of each streaming window")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--busy", action="store_true", help="also with a busy neighbour on the other core")
    parser.add_argument("--variants", action="store_true", help="also with the monitor / the traffic hidden")
    parser.add_argument(
        "--warm", type=float, default=1.0, help="seconds of streaming before measuring (31: full plots)"
    )
    parser.add_argument("--events", action="store_true", help="count Qt events per second (streaming window)")
    parser.add_argument(
        "--synthetic",
        action="store_true",
        help="feed the window from a GUI-thread timer (no worker, no simulator)",
    )
    parser.add_argument("--profile", help="write a cProfile of the GUI thread's streaming windows here")
    parser.add_argument("--top", type=int, default=30, help="functions printed from the profile")
    args = parser.parse_args(argv)
    profiler = cProfile.Profile() if args.profile else None
    runs = [
        run_synthetic(args.seconds, profiler)
        if args.synthetic
        else run_once(
            args.seconds,
            busy=args.busy,
            variants=args.variants,
            profiler=profiler,
            warm_s=args.warm,
            count_events=args.events,
        )
        for _ in range(args.repeat)
    ]
    medians: dict[str, Any] = {}
    for part in runs[0]:
        if part == "load_avg_1m":
            medians[part] = statistics.median(r[part] for r in runs)
            continue
        if part == "events":  # counts per run, not medians
            continue
        medians[part] = {
            k: round(statistics.median(r[part][k] for r in runs), 2)
            for k in runs[0][part]
            if not isinstance(runs[0][part][k], bool)
        }
    json.dump({"runs": runs, "median": medians}, sys.stdout, indent=2)
    sys.stdout.write("\n")
    if profiler is not None:
        profiler.dump_stats(args.profile)
        text = io.StringIO()
        stats = pstats.Stats(profiler, stream=text)
        stats.sort_stats("tottime").print_stats(args.top)
        stats.sort_stats("cumulative").print_stats(args.top)
        sys.stderr.write(text.getvalue())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
