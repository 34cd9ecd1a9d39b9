"""Event-loop stalls (``event_loop_stall``): the 1 ms probe timer and the busy neighbour; see
:mod:`benchmarks.gui`."""

from __future__ import annotations

import itertools
import os
import statistics
import subprocess
import sys
import time
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import Qt, QTimer

from benchmarks.gui_common import (
    STALL_THRESHOLD_MS,
    STALL_TIMER_MS,
    STEADY_AFTER_S,
    SimHandle,
    _Counters,
    _pct,
    _per_100hz,
    _run_for,
    not_measured,
)
from ui.main_window import MainWindow

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
        return {
            **not_measured(
                "the probe timer fired less than twice (event loop starved)",
                ("p50_ms", "p99_ms", "p999_ms", "max_ms"),
            ),
            "firings": len(stamps),
            "seconds": wall,
            "gui_thread_cpu_pct": 100.0 * cpu_gui / wall,
            "process_cpu_pct": 100.0 * cpu_process / wall,
        }
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


def measure_cpu(seconds: float) -> dict[str, float]:
    """CPU of the GUI thread and of the process over ``seconds`` of the event loop, with no probe.

    The 1 ms probe of :func:`measure_stalls` is itself work for the GUI thread (~1,000 timer
    events and Python calls a second: 4-5 % of a core in an empty application on this machine),
    so the GUI's own cost is measured in a window of its own, next to the probe's."""
    cpu_gui, cpu_process, wall = time.thread_time(), time.process_time(), time.perf_counter()
    _run_for(seconds)
    wall = time.perf_counter() - wall
    cpu_gui, cpu_process = time.thread_time() - cpu_gui, time.process_time() - cpu_process
    return {"gui_thread_cpu_pct": 100.0 * cpu_gui / wall, "process_cpu_pct": 100.0 * cpu_process / wall}


def add_no_probe(figures: dict[str, Any], seconds: float) -> None:
    """Add ``gui_thread_cpu_pct_no_probe`` / ``process_cpu_pct_no_probe``: the same stream measured
    right after, for ``seconds``, without the probe timer."""
    quiet = measure_cpu(seconds)
    figures["gui_thread_cpu_pct_no_probe"] = quiet["gui_thread_cpu_pct"]
    figures["process_cpu_pct_no_probe"] = quiet["process_cpu_pct"]
    if "gui_thread_cpu_pct" in figures:
        figures["probe_cpu_pct"] = figures["gui_thread_cpu_pct"] - quiet["gui_thread_cpu_pct"]


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


def _measure_streaming_busy(
    window: MainWindow, sim: SimHandle, counters: _Counters, seconds: float
) -> dict[str, Any]:
    """The streaming figures again, with :class:`BusyNeighbour` running."""
    with BusyNeighbour() as busy:
        _run_for(0.2)  # let the neighbours reach full speed
        poses0, frames0, requests0 = counters.poses, counters.traffic_frames, sim.requests()
        t0 = time.perf_counter()
        out = measure_stalls(seconds)
        elapsed = time.perf_counter() - t0
        out["polls_per_s"] = (sim.requests() - requests0) / 2 / elapsed
        # the rates of the probe's window (they were counted through the no-probe window too)
        out["poses_per_s"] = (counters.poses - poses0) / elapsed
        out["traffic_frames_per_s"] = (counters.traffic_frames - frames0) / elapsed
        add_no_probe(out, seconds)
    _per_100hz(out)
    out["busy_neighbour_procs"] = busy.procs
    out["monitor_shown"] = not window.monitor_panel.visibleRegion().isEmpty()
    out["traffic_shown"] = not window.traffic_panel.visibleRegion().isEmpty()
    return out
