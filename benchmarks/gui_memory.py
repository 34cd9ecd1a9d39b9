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

from app.user_dirs import fresh_user_dirs_env

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


from benchmarks.gui_common import (
    POLL_HZ,
    REPO,
    STARTUP_TIMEOUT_S,
    STREAM_PROGRAM,
)
from ui.window_geometry import DEFAULT_SIZE

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
from app.link.ops import RunProgram, Stop
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

TRACE_AT = float(os.environ.get("TEACHPAD_BENCH_TRACE_AT", "0") or 0)  # seconds into the soak
if TRACE_AT:
    import tracemalloc
    tracemalloc.start(int(os.environ.get("TEACHPAD_BENCH_TRACE_FRAMES", "1")))
_trace_first = None

def malloc_stats():
    # glibc's view: bytes in use by malloc vs. held in its arenas (free but not returned)
    import ctypes
    class MallInfo2(ctypes.Structure):
        _fields_ = [(n, ctypes.c_size_t) for n in (
            "arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks",
            "uordblks", "fordblks", "keepcost")]
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.mallinfo2.restype = MallInfo2
        m = libc.mallinfo2()
    except (OSError, AttributeError):
        return {}
    mb = 1024.0 * 1024.0
    return dict(heap_mb=round((m.arena + m.hblkhd) / mb, 2), used_mb=round((m.uordblks + m.hblkhd) / mb, 2),
                free_mb=round(m.fordblks / mb, 2))

def pymalloc_stats():
    # CPython's small-object allocator: bytes in its arenas vs. in live blocks (fragmentation)
    import re, tempfile
    with tempfile.TemporaryFile() as tmp:
        sys.stderr.flush()
        saved = os.dup(2)
        os.dup2(tmp.fileno(), 2)
        try:
            sys._debugmallocstats()
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        tmp.seek(0)
        text = tmp.read().decode("ascii", "replace")
    def field(name):
        m = re.search(r"^# " + re.escape(name) + r"\s*=\s*([\d,]+)", text, re.M)
        return int(m.group(1).replace(",", "")) if m else 0
    mb = 1024.0 * 1024.0
    kinds = ("bytes in allocated blocks", "bytes in available blocks", "bytes in unused pools")
    held = sum(field(k) for k in kinds)
    return dict(py_held_mb=round(held / mb, 2),
                py_used_mb=round(field("bytes in allocated blocks") / mb, 2),
                py_objects=len(gc.get_objects()))

def type_counts():
    counts = {}
    for o in gc.get_objects():
        name = type(o).__name__
        counts[name] = counts.get(name, 0) + 1
    return counts

def trace(label, top=25):
    # tracemalloc: the first call takes the reference snapshot, later ones print the top growth
    global _trace_first
    gc.collect()
    snap = tracemalloc.take_snapshot().filter_traces([
        tracemalloc.Filter(False, tracemalloc.__file__),
        tracemalloc.Filter(False, "<frozen importlib._bootstrap>"),
    ])
    types = type_counts()
    if _trace_first is None:
        _trace_first = (snap, types)
        traced = tracemalloc.get_traced_memory()[0] / 1e6
        print(f"TRACE {label}: reference snapshot, traced {traced:.1f} MB", flush=True)
        return
    first, first_types = _trace_first
    stats = snap.compare_to(first, "lineno")
    total = sum(s.size_diff for s in stats)
    print(f"TRACE {label}: python heap {total / 1e6:+.2f} MB since the reference", flush=True)
    for s in stats[:top]:
        print(f"TRACE   {s.size_diff / 1024:+9.1f} KiB {s.count_diff:+7d} blocks  {s.traceback}", flush=True)
    grown = sorted(((n - first_types.get(k, 0), k) for k, n in types.items()), reverse=True)[:15]
    print("TRACE   objects: " + ", ".join(f"{k} {d:+d}" for d, k in grown), flush=True)

def qt_counts(win):
    from PySide6.QtCore import QObject
    app = QApplication.instance()
    widgets = len(QApplication.allWidgets())
    objects = len(win.findChildren(QObject))
    return dict(widgets=widgets, qobjects=objects)

class Probe(teachpad.MainWindow):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._bench_started = False
        self.link.state.poseChanged.connect(self._bench_pose)
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
        self.link.submit(RunProgram(program, ProgramMotionMode.CYCLE, 0, 100))
        self._bench_t0 = time.monotonic()
        self._bench_timer = QTimer(self)
        self._bench_timer.timeout.connect(self._bench_sample)
        self._bench_timer.start(int(1000 * every_s))
    def _bench_sample(self):
        elapsed = time.monotonic() - self._bench_t0
        extra = dict(malloc_stats(), **pymalloc_stats(), **qt_counts(self))
        report("soak", traffic_rows=self.traffic_panel.model.rowCount(), **extra)
        if TRACE_AT and (_trace_first is None and elapsed >= TRACE_AT - 1e-3
                         or elapsed >= soak_s - 1e-3):
            trace(f"{elapsed:.0f} s")
        if time.monotonic() - self._bench_t0 >= soak_s - 1e-3:
            self.link.submit(Stop())
            QApplication.instance().quit()
teachpad.MainWindow = Probe
teachpad.main(["--sim", "--settings", settings_path, "--size", size])
"""


def bench_memory(
    soak_s: float, every_s: float, *, trace_at: float = 0.0, detail: bool = False
) -> dict[str, Any]:
    """RSS of a ``teachpad --sim`` process: idle after start-up, then over a streaming soak.

    ``trace_at`` > 0 (diagnosis, not a benchmark: tracing slows the child and costs memory):
    ``tracemalloc`` runs in the child, the first sample at or after ``trace_at`` seconds into the
    soak is the reference snapshot and the last sample prints the top growth by line, the Python
    object types that grew, and glibc's heap (in use / free) and Qt object counts with every
    sample; the printed lines come back in ``out["trace"]``.
    """
    with tempfile.TemporaryDirectory(prefix="teachpad-bench-") as tmp:
        user = Path(tmp)
        env = dict(
            os.environ,
            QT_QPA_PLATFORM="offscreen",
            PYTHONPATH=str(REPO),
            **fresh_user_dirs_env(user),
        )
        env["TEACHPAD_BENCH_TRACE_AT"] = str(trace_at) if trace_at > 0 else ""
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
            "t_s": [round(r["t"] - idle["t"], 1) for r in soak],
            "peak_rss_mb": max(samples),
            "growth_mb": round(growth, 1),
            "growth_mb_per_10min": round(10.0 * growth / minutes, 1) if minutes > 0 else None,
        }
    if trace_at > 0:
        out["trace"] = [x[6:] for x in proc.stdout.splitlines() if x.startswith("TRACE ")]
    if trace_at > 0 or detail:
        out["samples"] = [{k: v for k, v in r.items() if k not in ("kind", "t")} for r in soak]
    return out


def run_memory(quick: bool, long: bool) -> dict[str, Any]:
    """``gui.memory``: the idle RSS; a soak of 10 minutes with ``long``, else a short one."""
    if long:
        return bench_memory(SOAK_LONG_S, SOAK_LONG_EVERY_S)
    return bench_memory(10.0, 5.0) if quick else bench_memory(60.0, 10.0)


def main(argv: list[str] | None = None) -> int:
    """``python -m benchmarks.gui_memory [--soak S] [--every S] [--trace AT]``: one run, as JSON."""
    import argparse

    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--soak", type=float, default=SOAK_LONG_S, help="soak seconds")
    parser.add_argument("--every", type=float, default=SOAK_LONG_EVERY_S, help="RSS sample period")
    parser.add_argument(
        "--trace",
        type=float,
        default=0.0,
        metavar="AT",
        help="tracemalloc: reference at AT s into the soak, the growth at the end",
    )
    parser.add_argument("--detail", action="store_true", help="heap figures with every sample")
    args = parser.parse_args(argv)
    result = bench_memory(args.soak, args.every, trace_at=args.trace, detail=args.detail)
    for line in result.pop("trace", []):
        print(line)
    print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
