"""The GUI's cell view at scale (issue 23): ``cell_view`` in ``make bench``.

``cell_16``: the main window at 1280×800 (the normal layout: the Cell tab beside the pendant's
controls, compact tiles), a cell of 16 simulated controllers polled at 20 Hz each, the simulators
served by one ``teachpad-sim --controllers 16`` process of their own (offscreen platform). Measured,
after the tiles answer and a warm-up:

* ``event_loop``: gaps between the firings of a 1 ms probe timer on the GUI thread (p50/p99/max, as
  ``gui.*.event_loop_stall``), with the GUI thread's and the process's CPU in that window;
* ``gui_thread_cpu_pct_no_probe``: the GUI thread's CPU (% of one core) in a window of the same
  length without the probe (the probe alone costs a few % of a core);
* ``answers_per_s``: polls answered per second, all controllers (16 × 20 = 320 when every poller
  keeps its rate), counted in the pollers' threads (nothing added to the GUI thread).

The machine these figures come from is shared (2 cores, several people's work at once): the
``load_avg_1m`` at the start of the run is beside them.
"""

from __future__ import annotations

import os
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from app.cell.cell_file import Cell, CellController
from app.gateway.metrics import Reading
from app.gateway.poller import GatewayTiming
from app.link.robot_link import RobotLink
from benchmarks.gateway import sim_processes
from benchmarks.gui import _close_window
from benchmarks.gui_common import _qapp, _run_for, _wait_until
from benchmarks.gui_stalls import add_no_probe, measure_stalls
from ui.main_window import MainWindow
from ui.settings import AppSettings

CONTROLLERS = 16
POLL_HZ = 20.0
WINDOW = (1280, 800)
WARM_UP_S = 2.0
POLL_TIMEOUT_S = 0.5  # roomy: the simulators share the machine with the GUI


class _Count:
    """Counts the pollers' answers in their own threads (the cell view's listener's second ear)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.answers = 0
        self.silences = 0

    def answered(self, _device: str, _reading: Reading) -> None:
        with self._lock:
            self.answers += 1

    def silent(self, _device: str, _reason: str) -> None:
        with self._lock:
            self.silences += 1


def measure_cell_view(count: int, seconds: float) -> dict[str, Any]:
    """The cell view of ``count`` controllers at :data:`POLL_HZ` (see the module docstring)."""
    _qapp()
    tmp = tempfile.TemporaryDirectory(prefix="teachpad-bench-cell-")
    link = RobotLink(poll_hz=POLL_HZ)
    window: MainWindow | None = None
    with sim_processes(count, count) as procs:
        try:
            window = MainWindow(
                link,
                AppSettings.from_file(Path(tmp.name) / "bench.ini"),
                autosave_dir=Path(tmp.name) / "auto",
            )
            window.resize(*WINDOW)
            window.show()
            ports = [port for proc in procs for port in proc.ports]
            cell = Cell(
                "bench",
                tuple(CellController(f"R{i + 1}", host="127.0.0.1", port=p) for i, p in enumerate(ports)),
            )
            timing = GatewayTiming(poll_hz=POLL_HZ, poll_timeout=POLL_TIMEOUT_S)
            panel = window.cell.show_cell(cell, timing=timing)
            counter = _Count()
            panel.listener.publisher = counter  # beside the tiles, in the pollers' threads
            if not _wait_until(lambda: all(t.reading is not None for t in panel.tiles.values()), 30.0):
                raise RuntimeError("not every controller of the cell answered within 30 s")
            _run_for(WARM_UP_S)
            answers0, t0 = counter.answers, time.perf_counter()
            stalls = measure_stalls(seconds)
            add_no_probe(stalls, seconds)
            elapsed = time.perf_counter() - t0
            return {
                "controllers": count,
                "poll_hz": POLL_HZ,
                "window": f"{WINDOW[0]}x{WINDOW[1]}",
                "compact_tiles": panel.compact,
                "columns": panel.columns,
                "simulator_processes": len(procs),
                "seconds_each": seconds,
                "answers_per_s": (counter.answers - answers0) / elapsed,
                "answers_per_s_goal": count * POLL_HZ,
                "failed_polls": counter.silences,
                "event_loop": {k: v for k, v in stalls.items() if not k.endswith("_no_probe")},
                "gui_thread_cpu_pct_no_probe": stalls["gui_thread_cpu_pct_no_probe"],
                "process_cpu_pct_no_probe": stalls["process_cpu_pct_no_probe"],
            }
        finally:
            if window is not None:
                window.cell.close_cell()
            _close_window(window, link, tmp)


def run(quick: bool = False) -> dict[str, Any]:
    return {
        "load_avg_1m": os.getloadavg()[0],
        "cpus": os.cpu_count(),
        "note": "a shared machine (2 cores, several engineers' work at once): figures vary with its load",
        "cell_16": measure_cell_view(CONTROLLERS, 3.0 if quick else 10.0),
    }


if __name__ == "__main__":  # python -m benchmarks.cell_view [--quick]
    import json
    import sys

    json.dump(run("--quick" in sys.argv), sys.stdout, indent=2, sort_keys=True)
    sys.stdout.write("\n")
