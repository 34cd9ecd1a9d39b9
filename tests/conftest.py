"""Shared fixtures: the simulator on a free loopback port, and a strict Qt leak check."""

from __future__ import annotations

import ctypes
import os
import sys
import threading
import weakref
from collections.abc import Iterator
from typing import Any

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


@pytest.fixture(autouse=True, scope="session")
def _private_data_dir(tmp_path_factory: pytest.TempPathFactory) -> None:
    """The audit trail (CLI clients write one) goes to a temporary data directory, not $HOME."""
    os.environ["XDG_DATA_HOME"] = str(tmp_path_factory.mktemp("xdg-data"))


@pytest.fixture
def sim() -> Iterator[Any]:
    """A running simulated controller on 127.0.0.1:<free port>, stopped after the test."""
    from app.sim import SimConfig, SimController

    controller = SimController(SimConfig(host="127.0.0.1", port=0))
    controller.start()
    try:
        yield controller
    finally:
        controller.stop()


@pytest.fixture
def sim_factory() -> Iterator[Any]:
    """Build simulators with custom settings; all are stopped after the test."""
    from app.sim import SimConfig, SimController

    made: list[Any] = []

    def make(**kwargs: Any) -> Any:
        kwargs.setdefault("host", "127.0.0.1")
        kwargs.setdefault("port", 0)
        controller = SimController(SimConfig(**kwargs))
        controller.start()
        made.append(controller)
        return controller

    try:
        yield make
    finally:
        for controller in made:
            controller.stop()


@pytest.fixture
def make_client() -> Iterator[Any]:
    """RobotClients for a simulator (its port, framer and word order) or any ``port=``;
    connected unless ``connect=False``; every one is closed after the test."""
    from app.link.client import ConnectionSettings, RobotClient

    made: list[Any] = []

    def make(sim: Any = None, *, connect: bool = True, **kwargs: Any) -> Any:
        kwargs.setdefault("host", "127.0.0.1")
        if sim is not None:
            kwargs.setdefault("port", sim.port)
            kwargs.setdefault("framer", sim.config.framer)
            kwargs.setdefault("word_order", sim.config.word_order)
        client = RobotClient(ConnectionSettings(**kwargs))
        made.append(client)
        if connect:
            client.connect()
        return client

    try:
        yield make
    finally:
        for client in made:
            client.close()


# --- Qt leak check (napari-style): a test must not leave a QThread running or a QTimer active.
_threads: weakref.WeakSet[Any] = weakref.WeakSet()
_timers: weakref.WeakSet[Any] = weakref.WeakSet()
_trace_hooked: weakref.WeakSet[Any] = weakref.WeakSet()
#: ``make test COV_QTHREADS=1``: measure the code that runs in QThreads (the link's worker) too;
#: off by default: tracing every poll of the worker costs the suite ~15 % more time for ~1 point.
TRACE_QTHREADS = os.environ.get("TEACHPAD_COV_QTHREADS", "") not in ("", "0")


def _install_trace_hook() -> None:
    """Run in a QThread as it starts: give it the tracer ``threading.settrace`` gives Python
    threads, so coverage (pytest-cov) measures the worker's code too. Nothing without a tracer.

    PySide6 enters Python from a QThread with PyGILState_Ensure/Release, which makes and drops
    a thread state per call (and the trace function with it): one extra Ensure, released when
    the thread finishes, keeps a single thread state (and the tracer) for the thread's life."""
    hook = threading.gettrace()
    if hook is None:
        return
    from PySide6.QtCore import Qt, QThread

    state = ctypes.pythonapi.PyGILState_Ensure()
    thread = QThread.currentThread()
    thread.finished.connect(
        lambda: ctypes.pythonapi.PyGILState_Release(state), Qt.ConnectionType.DirectConnection
    )
    sys.settrace(hook)


_patched = False


def _patch_qt() -> None:
    global _patched
    if _patched:
        return
    from PySide6.QtCore import Qt, QThread, QTimer

    thread_start = QThread.start
    timer_start = QTimer.start

    def tracked_thread_start(self: Any, *args: Any) -> None:
        _threads.add(self)
        if TRACE_QTHREADS and self not in _trace_hooked:
            _trace_hooked.add(self)
            self.started.connect(_install_trace_hook, Qt.ConnectionType.DirectConnection)
        thread_start(self, *args)

    def tracked_timer_start(self: Any, *args: Any) -> None:
        _timers.add(self)
        timer_start(self, *args)

    # patching Qt's methods: the stubs' overloads are not a replacement's concern
    QThread.start = tracked_thread_start  # type: ignore[method-assign,assignment]
    QTimer.start = tracked_timer_start  # type: ignore[method-assign]
    _patched = True


@pytest.fixture(autouse=True)
def _qt_leak_check(request: pytest.FixtureRequest) -> Iterator[None]:
    if "qtbot" not in request.fixturenames and "qapp" not in request.fixturenames:
        yield
        return
    _patch_qt()
    import shiboken6

    before_threads = set(map(id, _threads))
    before_timers = set(map(id, _timers))
    yield
    leaked_threads = [
        t for t in list(_threads) if id(t) not in before_threads and shiboken6.isValid(t) and t.isRunning()
    ]
    leaked_timers = [
        t for t in list(_timers) if id(t) not in before_timers and shiboken6.isValid(t) and t.isActive()
    ]
    _threads.clear()
    _timers.clear()
    if leaked_threads or leaked_timers:
        pytest.fail(
            f"test leaked {len(leaked_threads)} running QThread(s) and {len(leaked_timers)} active QTimer(s)",
            pytrace=False,
        )
