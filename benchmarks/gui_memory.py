"""Memory (``gui.memory``): idle RSS of ``teachpad --sim`` and a streaming soak; see
:mod:`benchmarks.gui`."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


from benchmarks.gui_common import (
    POLL_HZ,
    REPO,
    STARTUP_TIMEOUT_S,
    STREAM_PROGRAM,
)
from ui.main_window import DEFAULT_SIZE

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
        env = dict(
            os.environ,
            QT_QPA_PLATFORM="offscreen",
            PYTHONPATH=str(REPO),
            **{f"XDG_{d}_HOME": str(user / d.lower()) for d in ("CONFIG", "DATA", "STATE", "CACHE")},
        )
        args = [
            str(user / "teachpad.ini"),
            "{}x{}".format(*DEFAULT_SIZE),
            str(soak_s),
            str(every_s),
            str(MEMORY_SETTLE_S),
            str(STREAM_PROGRAM),
        ]
        proc = subprocess.run(
            [sys.executable, "-c", _MEMORY_CHILD, *args],
            cwd=REPO,
            env=env,
            capture_output=True,
            text=True,
            check=False,
            timeout=STARTUP_TIMEOUT_S + MEMORY_SETTLE_S + soak_s + 120,
        )
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
