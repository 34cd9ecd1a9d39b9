"""GUI-thread cost of the traffic inspector at 100 Hz polling (``python -m benchmarks.traffic``).

A shown :class:`ui.panels.traffic_panel.TrafficPanel` (offscreen) gets one batch per poll, as the
worker sends it (pose read + status read, request and answer: 4 frames), from a 100 Hz timer
in the GUI thread, the pose moving every poll; CPU time of the GUI thread over the window,
minus the same timer feeding nothing. Also: the panel hidden (capture on), and the model alone.
"""

from __future__ import annotations

import json
import os
import sys
import time
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEventLoop, Qt, QTimer
from PySide6.QtWidgets import QApplication

from app.link.transport import TrafficRecord
from app.protocol.codec import encode_floats
from app.protocol.framing import encode_request, encode_response
from app.protocol.registers import POSE_BLOCK_COUNT, POSE_BLOCK_START, STATUS_BLOCK_COUNT, STATUS_BLOCK_START
from ui.panels.traffic_panel import TrafficPanel

POLL_HZ = 100


class Feed:
    def __init__(self) -> None:
        self.tid = 0
        self.k = 0

    def batch(self) -> list[Any]:
        out = []
        self.k += 1
        t = time.time()
        pose = encode_floats([400.0 + 0.1 * self.k, -12.5, 300.0, 180.0, 0.0, 90.0])
        for start, count, values in (
            (POSE_BLOCK_START, POSE_BLOCK_COUNT, pose + [0] * (POSE_BLOCK_COUNT - 12)),
            (STATUS_BLOCK_START, STATUS_BLOCK_COUNT, [2, 1, 0] + [0] * (STATUS_BLOCK_COUNT - 3)),
        ):
            self.tid = (self.tid + 1) & 0xFFFF
            request = encode_request(3, start, count=count, transaction_id=self.tid)
            answer = encode_response(3, values=values, transaction_id=self.tid)
            out.append(TrafficRecord(t, "tx", request, "tcp"))
            out.append(TrafficRecord(t + 0.0003, "rx", answer, "tcp"))
        return out


def measure(app: QApplication, sink: Any, seconds: float) -> float:
    """GUI-thread CPU (% of one core) per 100 Hz of traffic: CPU time per delivered batch
    (a loaded machine delivers fewer than 100 a second) x 100, while a PreciseTimer calls
    ``sink(batch)``; the timer's own cost is measured separately (``sink`` doing nothing)."""
    feed = Feed()
    batches = [feed.batch() for _ in range(int(seconds * POLL_HZ) + 50)]
    delivered = 0

    def tick() -> None:
        nonlocal delivered
        sink(batches[delivered])
        delivered += 1

    timer = QTimer()
    timer.setTimerType(Qt.TimerType.PreciseTimer)
    timer.setInterval(1000 // POLL_HZ)
    timer.timeout.connect(tick)
    loop = QEventLoop()
    QTimer.singleShot(int(1000 * seconds), loop.quit)
    cpu = time.thread_time()
    timer.start()
    loop.exec()
    timer.stop()
    app.processEvents()  # the last gathered rows, inserted and painted
    return 100.0 * (time.thread_time() - cpu) / max(1, delivered) * POLL_HZ


def run(seconds: float = 5.0) -> dict[str, Any]:
    app = QApplication.instance() or QApplication([])
    assert isinstance(app, QApplication)
    panel = TrafficPanel()
    panel.resize(900, 500)
    panel.show()
    app.processEvents()
    base = measure(app, lambda b: None, seconds)
    shown = measure(app, panel.on_traffic, seconds)
    rows_shown = panel.model.rowCount()
    panel.hide()
    app.processEvents()
    hidden = measure(app, panel.on_traffic, seconds)
    panel.clear()
    return {
        "poll_hz": POLL_HZ,
        "frames_per_poll": 4,
        "seconds": seconds,
        "what": "GUI-thread CPU, % of one core, per 100 Hz of polling traffic (normalised per batch)",
        "timer_only_pct": round(base, 2),
        "shown_pct": round(shown, 2),
        "shown_cost_pct": round(shown - base, 2),
        "hidden_pct": round(hidden, 2),
        "hidden_cost_pct": round(hidden - base, 2),
        "rows_after_shown": rows_shown,
    }


if __name__ == "__main__":
    json.dump(run(float(sys.argv[1]) if len(sys.argv) > 1 else 5.0), sys.stdout, indent=2)
    sys.stdout.write("\n")
