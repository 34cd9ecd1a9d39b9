"""Garbage collection in the GUI process runs on the GUI thread only (issue 18, ui/gui_gc.py): a
pass on the link's worker thread frees whatever cycles the GUI thread left, and a parentless Qt
object in one is then destroyed on RobotWorker -- the signature of the segfault the issue saw."""

from __future__ import annotations

import gc
import textwrap
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QObject, Qt, QThread, QTimer, Slot

from tests.cli.ctrl_c import untraced_env
from tests.ui.gui_child import run_gui_child
from ui.gui_gc import GuiThreadCollector, due_generation
from ui.startup_gc import StartupGcPause

# these tests switch collection off and on themselves, and count passes in other threads
pytestmark = pytest.mark.automatic_gc

# ``teachpad --sim`` in a child, collections made due often (a pass would run in any thread that
# allocates past the threshold: the worker allocates at every poll). Every pass is counted by the
# thread it ran in; the window closes after 3 s of polling at 50 Hz.
_PROBE = textwrap.dedent("""
    import gc, json, sys, threading
    from PySide6.QtCore import QTimer
    from PySide6.QtWidgets import QApplication
    import ui.main as teachpad

    gc.set_threshold(20, 5, 5)
    passes = {"gui": 0, "other": 0}

    def counted(phase, info):
        if phase == "start":
            gui = threading.get_ident() == threading.main_thread().ident
            passes["gui" if gui else "other"] += 1

    gc.callbacks.append(counted)

    class Probe(teachpad.MainWindow):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.link.connectionChanged.connect(self._on_connection)

        def _on_connection(self, state):
            if state.connected:  # 3 s of polling (and the monitor's plots) before the window closes
                QTimer.singleShot(3000, self._done)

        def _done(self):
            print("DURING " + json.dumps(gc.isenabled()), flush=True)
            QApplication.instance().exit(0)

    teachpad.MainWindow = Probe
    code = teachpad.main(["--sim", "--settings", sys.argv[1]])
    gc.callbacks.remove(counted)
    print("PASSES " + json.dumps(passes), flush=True)
    print("AFTER " + json.dumps(gc.isenabled()), flush=True)
    sys.exit(code)
""")


def test_the_gui_process_collects_garbage_on_the_gui_thread_only(tmp_path: Path) -> None:
    # coverage's tracer in the child would allocate in every thread
    lines = run_gui_child(_PROBE, tmp_path, env=untraced_env(), expect="PASSES")
    assert lines["DURING"] is False  # no automatic collection while the window lives
    assert lines["PASSES"]["other"] == 0, lines["PASSES"]  # none on the worker (nor any thread)
    assert lines["PASSES"]["gui"] > 0, lines["PASSES"]  # the GUI thread did collect
    assert lines["AFTER"] is True  # automatic collection back when main() ends


def test_the_due_generation_follows_cpythons_thresholds() -> None:
    assert due_generation((700, 0, 0), (700, 10, 10)) is None  # not past the threshold
    assert due_generation((701, 0, 0), (701 - 1, 10, 10)) == 0
    assert due_generation((701, 11, 0), (700, 10, 10)) == 1
    assert due_generation((701, 11, 11), (700, 10, 10)) == 2
    assert due_generation((10**6, 0, 0), (0, 10, 10)) is None  # threshold 0: collection off


def test_a_collector_collects_a_cycle_on_its_own_thread_and_gives_back_the_collector(qapp: Any) -> None:
    was = gc.get_threshold()
    pause = StartupGcPause()
    collector = GuiThreadCollector(pause, check_ms=10_000)
    try:
        collector.start()
        assert collector.running and not gc.isenabled() and gc.get_freeze_count() > 0
        gc.set_threshold(1, 10, 10)
        destroyed: list[str] = []
        orphan = QObject()  # no parent: owned by Python, destroyed by the pass that frees its cycle
        orphan.destroyed.connect(lambda: destroyed.append("gone"))
        cycle: list[Any] = [orphan]
        cycle.append(cycle)
        del orphan, cycle
        assert collector.collect_due() is not None and collector.passes == 1
        assert destroyed == ["gone"]
    finally:
        gc.set_threshold(*was)
        collector.stop()
        pause.resume()
    assert not collector.running and gc.isenabled() and gc.get_freeze_count() == 0
    collector.start()  # not after stop
    assert not collector.running


def test_a_process_without_automatic_collection_gets_none(qapp: Any) -> None:
    gc.disable()
    try:
        pause = StartupGcPause()
        collector = GuiThreadCollector(pause)
        collector.start()
        assert not collector.running and gc.get_freeze_count() == 0
        collector.stop()
        pause.resume()
        assert not gc.isenabled()
    finally:
        gc.enable()


class _Churn(QObject):
    """Allocates in its own thread (as the link's worker does at every poll), cycles included,
    until ``stop`` is set."""

    def __init__(self) -> None:
        super().__init__()
        self.stop = threading.Event()
        self.rounds = 0

    @Slot()
    def run(self) -> None:
        while not self.stop.is_set():
            junk: list[Any] = [[i] for i in range(50)]
            junk.append(junk)
            self.rounds += 1


def _let_allocate(churn: _Churn, rounds: int) -> None:
    """Hand the GIL to the allocating thread until it made ``rounds`` more rounds (bounded)."""
    churn.rounds = 0
    deadline = time.monotonic() + 10.0
    while churn.rounds < rounds:
        assert time.monotonic() < deadline, "the allocating thread does not run"
        time.sleep(0)  # a GIL hand-off, not a wait for time to pass


def test_a_parentless_qt_object_in_a_cycle_dies_on_the_gui_thread_while_a_worker_allocates(
    qtbot: Any,
) -> None:
    """The crash's mechanism: under automatic collection, a pass started by the worker's
    allocations destroyed the GUI thread's garbage there (measured with started QTimers in
    cycles: 293 of 2000 destroyed on the worker, Qt: "Timers cannot be stopped from another
    thread"; a widget dies harder). With the GUI-thread collector, every one dies here."""
    was = gc.get_threshold()
    pause = StartupGcPause()
    collector = GuiThreadCollector(pause, check_ms=5)
    thread = QThread()
    churn = _Churn()
    churn.moveToThread(thread)
    thread.started.connect(churn.run)
    died: list[bool] = []  # destroyed in the GUI thread?
    gui_thread = QThread.currentThread()
    try:
        collector.start()
        gc.set_threshold(50, 10, 10)
        thread.start()
        qtbot.waitUntil(lambda: churn.rounds > 100, timeout=10_000)
        for _ in range(100):
            timer = QTimer()  # no parent, started: its timer is registered in this thread
            timer.start(60_000)
            timer.destroyed.connect(
                lambda *_a: died.append(QThread.currentThread() is gui_thread),
                Qt.ConnectionType.DirectConnection,
            )
            cycle: list[Any] = [timer]
            cycle.append(cycle)
            del timer, cycle
            _let_allocate(churn, 5)
        qtbot.waitUntil(lambda: len(died) == 100, timeout=10_000)  # the collector's ticks free them
    finally:
        churn.stop.set()
        thread.quit()
        thread.wait()
        gc.set_threshold(*was)
        collector.stop()
        pause.resume()
    assert all(died) and collector.passes > 0
