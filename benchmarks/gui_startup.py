"""Time to first paint (``startup``) in a fresh interpreter, against a bare QMainWindow; see
:mod:`benchmarks.gui`."""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from app.user_dirs import fresh_user_dirs_env

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


from benchmarks.gui_common import (
    REPO,
    STARTUP_TIMEOUT_S,
    not_measured,
    ratio,
)
from ui.window_geometry import DEFAULT_SIZE

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
            # CPU seconds of this process so far (all threads): less sensitive to a busy machine
            marks.setdefault("cpu_first_paint", time.process_time())
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
    # The simulator must not be imported here (pymodbus, numpy: it would be measured as start-up):
    # SimController.start is wrapped only if the GUI process imports app.sim.server itself (an
    # in-process simulator, which goals.py reports); the child process's start is timed too.
    import importlib.abc, importlib.util
    class SimWatch(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path, target=None):
            if name != "app.sim.server":
                return None
            sys.meta_path.remove(self)
            spec = importlib.util.find_spec(name)
            run_module = spec.loader.exec_module
            def exec_module(module):
                run_module(module)
                sim_start = module.SimController.start
                def timed_start(self):
                    mark("sim_start_begin")
                    sim_start(self)
                    mark("sim_started")
                module.SimController.start = timed_start
            spec.loader.exec_module = exec_module
            return spec
    sys.meta_path.insert(0, SimWatch())
    import ui.main as teachpad
    mark("ui_imported")
    process_start = teachpad.SimProcess.start.__func__
    def timed_process_start(cls, *args, **kwargs):
        mark("sim_process_start_begin")
        try:
            return process_start(cls, *args, **kwargs)
        finally:
            mark("sim_process_started")
    teachpad.SimProcess.start = classmethod(timed_process_start)

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
            self.link.state.poseChanged.connect(self._bench_pose)  # after the window's own slots
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
    env = dict(
        os.environ,
        QT_QPA_PLATFORM="offscreen",
        PYTHONPATH=str(REPO),
        **fresh_user_dirs_env(user),
    )
    args = [kind, str(user / "teachpad.ini"), "{}x{}".format(*DEFAULT_SIZE)]
    t_spawn = time.monotonic()
    proc = subprocess.run(
        [sys.executable, "-c", _STARTUP_CHILD, *args],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=STARTUP_TIMEOUT_S,
        check=False,
    )
    t_exit = time.monotonic()
    line = next((x for x in proc.stdout.splitlines() if x.startswith("BENCH ")), None)
    if proc.returncode != 0 or line is None:
        raise RuntimeError(f"start-up child ({kind}) failed, rc={proc.returncode}: {proc.stderr[-2000:]}")
    marks = json.loads(line[len("BENCH ") :])
    # cpu_* marks are CPU seconds of the child (time.process_time), the others monotonic times
    out = {
        f"{name}_ms": 1000.0 * (t if name.startswith("cpu_") else t - t_spawn) for name, t in marks.items()
    }
    out["process_total_ms"] = 1000.0 * (t_exit - t_spawn)
    return out


def bench_startup(runs: int) -> dict[str, Any]:
    """Median over ``runs`` of each mark, for teachpad --sim and for a bare QMainWindow (alternated).

    A child that fails or times out is left out (``failures``, with the first error); a side
    without any good run is reported as not measured, and so is the ratio."""
    samples: dict[str, list[dict[str, float]]] = {"teachpad_sim": [], "bare_qmainwindow": []}
    errors: list[str] = []
    with tempfile.TemporaryDirectory(prefix="teachpad-bench-") as tmp:
        for i in range(runs):
            for name, kind in (("teachpad_sim", "teachpad"), ("bare_qmainwindow", "bare")):
                try:
                    samples[name].append(_startup_once(kind, Path(tmp), i))
                except (RuntimeError, OSError, subprocess.SubprocessError, ValueError) as exc:
                    errors.append(str(exc)[:300])
    out: dict[str, Any] = {"runs": runs}
    if errors:
        out["failures"] = len(errors)
        out["first_error"] = errors[0]
    for name, runs_marks in samples.items():
        if not runs_marks:
            out[name] = not_measured("every start-up child failed", ("first_paint_ms",))
            continue
        keys = sorted(set.intersection(*(set(m) for m in runs_marks)))
        out[name] = {k: statistics.median(m[k] for m in runs_marks) for k in keys}
    out["ratio_first_paint_cpu_vs_bare"] = ratio(  # the same, in CPU time: steadier under load
        out["teachpad_sim"].get("cpu_first_paint_ms"), out["bare_qmainwindow"].get("cpu_first_paint_ms")
    )
    out["ratio_first_paint_vs_bare"] = ratio(
        out["teachpad_sim"].get("first_paint_ms"), out["bare_qmainwindow"].get("first_paint_ms")
    )
    return out
