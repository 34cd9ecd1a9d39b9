"""Shared fixtures: the simulator on a free loopback port, and a strict Qt leak check."""

from __future__ import annotations

import ctypes
import faulthandler
import gc
import os
import shutil
import sys
import tempfile
import threading
import traceback
import weakref
from collections.abc import Iterator
from typing import Any

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


# --- A hung test ends the run in minutes, saying which test and where. pytest-timeout (120 s,
# pyproject) fails a test stuck in Python code and the run goes on; a test stuck where its
# SIGALRM cannot end it (a Qt event loop or wait in C++: the exception raised in a slot is
# swallowed) would otherwise hold the run until CI's limit. The watchdog below dumps every
# thread's stack, names the test in the last lines printed, and exits the process. It is a
# Python thread: a main thread stuck in C++ *holding the GIL* would keep it from running, so
# faulthandler's own timer (a C thread, no GIL needed) dumps every stack and exits (code 1) a
# little later as a last resort; the progress line above the dump names the test's file.
HUNG_AFTER = float(os.environ.get("TEACHPAD_TEST_HUNG_AFTER", "180"))  # s for setup, call, teardown
HUNG_EXIT_CODE = 70
HUNG_BACKSTOP = float(os.environ.get("TEACHPAD_TEST_HUNG_BACKSTOP", "30"))  # s after HUNG_AFTER (see above)
_stderr_copy = -1
_PRIVATE_DIR = pytest.StashKey[str]()


def pytest_report_header(config: pytest.Config) -> str:
    """Which fonts this run lays the window out with (the layout checks depend on them): a font
    set of ``tests/fonts`` (``make test-fonts``) or what this machine's fontconfig finds."""
    from tests.fonts.fontsets import describe_fonts

    config_file = os.environ.get("FONTCONFIG_FILE", "")
    which = os.environ.get("TEACHPAD_FONTSET") or (config_file and f"FONTCONFIG_FILE={config_file}")
    return f"fonts ({which or 'this machine'}): {describe_fonts()}"


def pytest_configure(config: pytest.Config) -> None:
    global _stderr_copy
    _stderr_copy = os.dup(2)  # the terminal's stderr, before tests capture fd 2
    # The settings and data of the user running the tests are never read nor written: the audit
    # trail, QSettings (XDG_CONFIG_HOME on Linux), autosaves (XDG_STATE_HOME) and projects go to a
    # fresh directory.
    private = tempfile.mkdtemp(prefix="teachpad-tests-")
    os.environ["XDG_DATA_HOME"] = os.path.join(private, "data")
    os.environ["XDG_CONFIG_HOME"] = os.path.join(private, "config")
    os.environ["XDG_STATE_HOME"] = os.path.join(private, "state")
    config.stash[_PRIVATE_DIR] = private
    from app.safety.location import machine_dir

    if machine_dir().is_dir():  # the tests (and the programs they start) would write there
        pytest.exit(
            f"{machine_dir()} exists: on this PC TeachPad keeps its safety state (roles, envelope, "
            "audit) there for every account, and the tests would change it. Run them elsewhere.",
            returncode=4,
        )


def pytest_unconfigure(config: pytest.Config) -> None:
    private = config.stash.get(_PRIVATE_DIR, "")
    if private:
        shutil.rmtree(private, ignore_errors=True)


def _hung(nodeid: str) -> None:
    fd = _stderr_copy if _stderr_copy >= 0 else 2
    faulthandler.dump_traceback(file=fd, all_threads=True)
    frame = sys._current_frames().get(threading.main_thread().ident or 0)
    where = "".join(traceback.format_stack(frame)[-8:]) if frame is not None else "  (no main thread)\n"
    os.write(
        fd,
        (
            f"\nHUNG: {nodeid} did not end within {HUNG_AFTER:.0f} s; the main thread was at:\n"
            f"{where}HUNG: {nodeid}\n"
        ).encode(errors="replace"),
    )
    os._exit(HUNG_EXIT_CODE)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    watchdog = threading.Timer(HUNG_AFTER, _hung, args=(item.nodeid,))
    watchdog.daemon = True
    watchdog.start()
    fd = _stderr_copy if _stderr_copy >= 0 else 2
    faulthandler.dump_traceback_later(HUNG_AFTER + HUNG_BACKSTOP, exit=True, file=fd)
    try:
        yield
    finally:
        faulthandler.cancel_dump_traceback_later()
        watchdog.cancel()


@pytest.fixture
def sim() -> Iterator[Any]:
    """A running simulated controller on 127.0.0.1:<free port>, stopped after the test."""
    from app.sim.config import SimConfig
    from app.sim.server import SimController

    controller = SimController(SimConfig(host="127.0.0.1", port=0))
    controller.start()
    try:
        yield controller
    finally:
        controller.stop()


@pytest.fixture
def sim_factory() -> Iterator[Any]:
    """Build simulators with custom settings; all are stopped after the test."""
    from app.sim.config import SimConfig
    from app.sim.server import SimController

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
    from app.connection import ConnectionSettings
    from app.link.client import RobotClient

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
#: Measure the code that runs in QThreads (the link's worker) too, as ``make test`` does (issue 22:
#: the figure without it said the worker's Stop path was 26 % covered); ``COV_QTHREADS=0`` leaves
#: them out. Nothing is traced when the run measures nothing.
TRACE_QTHREADS = os.environ.get("TEACHPAD_COV_QTHREADS", "1") != "0"


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
    _forbid_modal_dialogs()
    _patched = True


# --- No modal dialog in a test. Offscreen, nobody answers one: its event loop would never end (and
# no timeout can end a loop in C++). A test that expects a question answers it with its own fake
# (``monkeypatch`` over these); any other opens nothing, gets "cancel" and fails, naming the dialog.
_modals: list[str] = []


def _forbid_modal_dialogs() -> None:
    from PySide6.QtWidgets import QDialog, QFileDialog, QInputDialog, QMenu, QMessageBox

    def refuse(what: str, answer: Any) -> Any:
        def opened(*args: Any, **_kwargs: Any) -> Any:
            texts = [a for a in args if isinstance(a, str)][:2]
            name = type(args[0]).__name__ if args and isinstance(args[0], QDialog | QMenu) else what
            _modals.append(f"{name}: {' / '.join(texts)}" if texts else name)
            return answer

        return opened

    cancel = QMessageBox.StandardButton.Cancel
    QDialog.exec = refuse("QDialog.exec", 0)  # type: ignore[method-assign]
    QMenu.exec = refuse("QMenu.exec", None)  # type: ignore[method-assign]
    for name in ("question", "warning", "critical", "information"):
        setattr(QMessageBox, name, staticmethod(refuse(f"QMessageBox.{name}", cancel)))
    QMessageBox.about = staticmethod(refuse("QMessageBox.about", None))  # type: ignore[method-assign]
    for name in ("getOpenFileName", "getSaveFileName"):
        setattr(QFileDialog, name, staticmethod(refuse(f"QFileDialog.{name}", ("", ""))))
    QFileDialog.getOpenFileNames = staticmethod(refuse("QFileDialog.getOpenFileNames", ([], "")))  # type: ignore[method-assign]
    QFileDialog.getExistingDirectory = staticmethod(refuse("QFileDialog.getExistingDirectory", ""))  # type: ignore[method-assign]
    for name, answer in (("getItem", ""), ("getText", ""), ("getInt", 0), ("getDouble", 0.0)):
        setattr(QInputDialog, name, staticmethod(refuse(f"QInputDialog.{name}", (answer, False))))


@pytest.fixture(autouse=True)
def _qt_leak_check(request: pytest.FixtureRequest) -> Iterator[None]:
    if "qtbot" not in request.fixturenames and "qapp" not in request.fixturenames:
        yield
        return
    _patch_qt()
    import shiboken6

    _modals.clear()
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
    modals, _modals[:] = list(_modals), []
    if modals:
        opened = "; ".join(modals)
        pytest.fail(f"a modal dialog opened in the test (nobody answers it): {opened}", pytrace=False)
    if leaked_threads or leaked_timers:
        pytest.fail(
            f"test leaked {len(leaked_threads)} running QThread(s) and {len(leaked_timers)} active QTimer(s)",
            pytrace=False,
        )


@pytest.fixture(autouse=True)
def _gc_on_the_gui_thread(request: pytest.FixtureRequest) -> Iterator[None]:
    """A Qt test collects garbage on the GUI (main) thread only, as the GUI process does
    (``ui/gui_gc.py``): automatic collection is off while it runs, and what CPython would have
    collected is collected at its end, here. With automatic collection on, a pass started by an
    allocation in the link's worker or the simulator's threads freed the cycles of pyqtgraph items
    a plot had dropped (labels, curves) on that thread while the GUI thread painted: a segfault in
    ``GraphicsView.paintEvent`` (seen once in ~2,400 tests run on two cores). Tests of the
    collection itself (marker ``automatic_gc``) keep CPython's automatic collection."""
    if "automatic_gc" in request.keywords or (
        "qtbot" not in request.fixturenames and "qapp" not in request.fixturenames
    ):
        yield
        return
    from ui.gui_gc import due_generation

    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        generation = due_generation(gc.get_count(), gc.get_threshold())
        if generation is not None:
            gc.collect(generation)
        if was_enabled:
            gc.enable()


_SAMPLES = os.path.realpath(os.path.join(os.path.dirname(__file__), os.pardir, "resources", "samples"))


@pytest.fixture(autouse=True)
def _sample_project_locks_per_test(
    monkeypatch: pytest.MonkeyPatch, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """A test that opens a shipped sample project (``resources/samples``) takes its lock in a folder
    of its own, not beside the sample: the suite runs in several processes (``make test -n``), and
    two of them opening ``demo.teachpad.json`` at once are two TeachPads on one project -- the
    second is refused, as it must be (``app/points/lock.py``), and its test failed (seen with the
    suite beside two busy loops). A test of the lock itself uses a project of its own."""
    import app.points.lock as lock

    folder = tmp_path_factory.mktemp("sample-locks")
    original = lock.lock_path

    def lock_path(project_path: str | os.PathLike[str]) -> Any:
        path = original(project_path)
        if os.path.dirname(os.path.realpath(project_path)) == _SAMPLES:
            return folder / path.name
        return path

    monkeypatch.setattr(lock, "lock_path", lock_path)


@pytest.fixture(autouse=True)
def _private_safety_state(monkeypatch: pytest.MonkeyPatch, tmp_path_factory: pytest.TempPathFactory) -> None:
    """Each test its own per-user folders (``app.safety.location``): the role store, the envelope,
    the register profile and the audit trail of one test are never another's (they do not follow
    a settings file, so a test's INI file does not separate them)."""
    home = tmp_path_factory.mktemp("xdg")
    monkeypatch.setenv("XDG_CONFIG_HOME", str(home / "config"))
    monkeypatch.setenv("XDG_DATA_HOME", str(home / "data"))


@pytest.fixture(autouse=True)
def _no_foreign_move_hold(monkeypatch: pytest.MonkeyPatch) -> None:
    """Many tests move the simulated arm with a helper client (``make_client``) between the
    product's own moves: for the product that is another master, and it holds every move for
    ``timing.FOREIGN_MOVE_HOLD`` after one (issue 19). The hold is not those tests' subject: it is
    off here; the tests about it (tests/link/test_foreign_master.py) set it themselves."""
    from app import timing

    monkeypatch.setattr(timing, "FOREIGN_MOVE_HOLD", 0.0)
