"""The suite's coverage figure counts the code that runs in QThreads (the link's worker, issue 22):
every QThread the tests start runs under the tracer that ``threading.settrace`` gives Python threads
(``tests/conftest.py`` ``_install_trace_hook``), unless ``make test COV_QTHREADS=0``."""

from __future__ import annotations

import sys
import threading
from typing import Any

import pytest
from PySide6.QtCore import QMetaObject, QObject, Qt, QThread, Slot

from tests.conftest import TRACE_QTHREADS


class _Probe(QObject):
    def __init__(self) -> None:
        super().__init__()
        self.tracers: list[object] = []

    @Slot()
    def look(self) -> None:
        self.tracers.append(sys.gettrace())


def test_a_qthread_runs_under_the_coverage_tracer(qtbot: Any) -> None:
    hook = threading.gettrace()
    if hook is None:
        pytest.skip("not measured: no coverage tracer in this run (make test measures)")
    if not TRACE_QTHREADS:
        pytest.skip("make test COV_QTHREADS=0: QThreads are not measured in this run")
    thread = QThread()
    probe = _Probe()
    probe.moveToThread(thread)
    try:
        thread.start()  # as the link's worker thread: an event loop that runs queued jobs
        QMetaObject.invokeMethod(probe, "look", Qt.ConnectionType.QueuedConnection)
        qtbot.waitUntil(lambda: bool(probe.tracers), timeout=10_000)
    finally:
        thread.quit()
        thread.wait()
    [tracer] = probe.tracers
    # the thread's trace function is the one coverage installs in Python threads (its collector's)
    assert tracer is not None and type(tracer) is type(sys.gettrace())
