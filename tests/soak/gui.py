"""The soak's GUI process: ``teachpad --sim`` -- :func:`ui.main.main`, the real window and its
simulator child -- driven by :class:`~tests.soak.operator.Operator`, every failure loud.

    python -m tests.soak.gui --seed S --seconds T --home DIR

Prints its seed, one line per action and a summary (stdout). A failure prints ``SOAK FAILURE:``
on stderr and the process exits 1: an exception in any thread (``sys.excepthook``: PySide reports
an exception raised in a slot there; ``threading.excepthook``; ``sys.unraisablehook``), a Python
warning, a dialog nobody could answer, a window that would not close. A Qt warning (or critical or
fatal message, any thread) aborts at once (``qInstallMessageHandler``): faulthandler prints every
thread's stack and the kernel dumps core (``RLIMIT_CORE`` raised to its hard limit), as for any
crash. ``tests/soak/run.py`` starts this process and judges it (and the simulator child's stderr).
"""

from __future__ import annotations

import argparse
import faulthandler
import os
import random
import resource
import shutil
import sys
import threading
import time
import traceback
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from types import TracebackType
from typing import Any

from PySide6.QtCore import (
    QMessageLogContext,
    QObject,
    QTimer,
    QtMsgType,
    Signal,
    Slot,
    qInstallMessageHandler,
    qWarning,
)
from PySide6.QtWidgets import QApplication

from app.safety.roles import Role
from tests.soak.answers import Answerer
from tests.soak.operator import PASSWORD, Operator
from ui.main_window import MainWindow

__all__ = ["main"]

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "resources" / "samples" / "demo.teachpad.json"
CONNECT_WAIT = 90.0  # s for the simulator to start and the link to come up (a loaded machine)
CLOSE_WAIT = 90.0  # s for the window to close once asked
STATUS_EVERY = 60.0  # s between two status lines
# What the offscreen platform says about its own limits (no window manager): on every shown
# top-level window (pyproject.toml's qt_log_ignore), and when a floating dock is raised.
QT_NOISE = ("This plugin does not support propagateSizeHints", "This plugin does not support raise()")
FAILURE = "SOAK FAILURE:"

_failures: list[str] = []
_session: Session | None = None
_started = time.monotonic()


def say(line: str) -> None:
    print(f"{time.monotonic() - _started:9.3f} s  {line}", flush=True)


def fail(what: str) -> None:
    """A failure: said on stderr at once, the session ends (from any thread)."""
    _failures.append(what)
    sys.stderr.write(f"\n{FAILURE} {what}\n")
    sys.stderr.flush()
    session = _session
    if session is not None:
        session.failed.emit()


# --- the hooks ----------------------------------------------------------------------------------
def _excepthook(kind: type[BaseException], value: BaseException, tb: TracebackType | None) -> None:
    text = "".join(traceback.format_exception(kind, value, tb))
    sys.stderr.write(text)
    fail(f"exception in the GUI thread (a slot): {kind.__name__}: {value}")


def _thread_excepthook(args: threading.ExceptHookArgs) -> None:
    text = "".join(traceback.format_exception(args.exc_type, args.exc_value, args.exc_traceback))
    sys.stderr.write(text)
    name = args.thread.name if args.thread is not None else "?"
    fail(f"exception in thread {name}: {args.exc_type.__name__}: {args.exc_value}")


def _unraisablehook(unraisable: Any) -> None:
    text = "".join(
        traceback.format_exception(type(unraisable.exc_value), unraisable.exc_value, unraisable.exc_traceback)
    )
    sys.stderr.write(f"{unraisable.err_msg or 'Exception ignored in'}: {unraisable.object!r}\n{text}")
    fail(f"unraisable exception: {type(unraisable.exc_value).__name__}: {unraisable.exc_value}")


def _showwarning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))
    fail(f"Python warning: {category.__name__}: {message}")


def _qt_message(kind: QtMsgType, context: QMessageLogContext, message: str) -> None:
    if kind in (QtMsgType.QtDebugMsg, QtMsgType.QtInfoMsg) or any(n in message for n in QT_NOISE):
        return
    where = f" ({context.file}:{context.line}, {context.function})" if context.file else ""
    sys.stderr.write(
        f"\n{FAILURE} Qt {kind.name} in thread {threading.current_thread().name}: {message}{where}\n"
    )
    sys.stderr.flush()
    os.abort()  # faulthandler prints every thread's stack; the kernel dumps core


def install_hooks() -> None:
    faulthandler.enable(file=sys.stderr, all_threads=True)
    _soft, hard = resource.getrlimit(resource.RLIMIT_CORE)
    resource.setrlimit(resource.RLIMIT_CORE, (hard, hard))
    sys.excepthook = _excepthook
    threading.excepthook = _thread_excepthook
    sys.unraisablehook = _unraisablehook
    warnings.simplefilter("always")
    warnings.showwarning = _showwarning
    qInstallMessageHandler(_qt_message)


# --- the session ----------------------------------------------------------------------------------
class Session(QObject):
    """Finds the window ``main()`` built, waits for its link, runs the operator for ``seconds``,
    then closes the window (which ends ``main()``)."""

    failed = Signal()  # from any thread: end now

    def __init__(self, rng: random.Random, seconds: float, folder: Path, inject: str = "") -> None:
        super().__init__()
        self.inject = inject
        self.rng = rng
        self.seconds = seconds
        self.folder = folder
        self.window: MainWindow | None = None
        self.operator: Operator | None = None
        self.answerer = Answerer(rng, folder, lambda line: say(f"       {line}"), self)
        self.ending = False
        self.status_at = time.monotonic() + STATUS_EVERY
        self._deadline = time.monotonic() + CONNECT_WAIT
        self._timer = QTimer(self)
        self._timer.setInterval(200)
        self._timer.timeout.connect(self._tick)
        self._timer.start()
        self.failed.connect(self.end)

    @Slot()
    def _tick(self) -> None:
        if self.answerer.stuck is not None:
            fail(self.answerer.stuck)
            self.answerer.stuck = None
        if self.window is None:
            self._find_window()
        elif self.operator is None and not self.ending:
            self._start_when_connected()
        elif self.ending:
            self._close()
        else:
            self._status()

    def _find_window(self) -> None:
        windows = [w for w in QApplication.topLevelWidgets() if isinstance(w, MainWindow)]
        if windows:
            self.window = windows[0]
            self._set_passwords(self.window)
            say(f"window up; waiting for the simulator and the link (pid {os.getpid()})")

    def _set_passwords(self, window: MainWindow) -> None:
        """Every role gets the soak's password (the first administrator password: anyone)."""
        safety = window.safety_menu.safety
        safety.session.set_password(Role.ADMINISTRATOR, PASSWORD)
        safety.login(Role.ADMINISTRATOR, PASSWORD)
        safety.session.set_password(Role.ENGINEER, PASSWORD)
        safety.logout()

    def _start_when_connected(self) -> None:
        window = self.window
        assert window is not None
        settings = window.link.settings
        if window.link.state.connected and settings is not None:
            say(f"connected to the simulator at {settings.host}:{settings.port}; simulator pid {_children()}")
            self.operator = Operator(window, self.rng, say, settings)
            self.operator.start()
            if self.inject:
                QTimer.singleShot(1000, self, self._inject)
            self._deadline = time.monotonic() + self.seconds
            QTimer.singleShot(round(self.seconds * 1000), self, self.end)
        elif time.monotonic() > self._deadline:
            fail(f"the link did not come up within {CONNECT_WAIT:g} s")

    @Slot()
    def _inject(self) -> None:
        """The soak's self-test (tests/soak/test_soak_smoke.py): the failure asked for, from a
        thread of its own: the hooks must catch it wherever it happens."""
        say(f"injecting: {self.inject}")
        if self.inject == "qt-warning":
            target: Callable[[], object] = lambda: qWarning("soak self-test: a Qt warning")  # noqa: E731
        else:
            target = lambda: 1 / 0  # noqa: E731
        threading.Thread(target=target, name="soak-inject").start()

    def _status(self) -> None:
        if time.monotonic() < self.status_at or self.window is None or self.operator is None:
            return
        self.status_at += STATUS_EVERY
        link = self.window.link
        say(
            f"status: {self.operator.count} actions, {self.answerer.answered} answers, link "
            f"{link.state.connection.state.name.lower()}, {len(link._router)} requests pending, "
            f"RSS {_rss_mb():.0f} MB"
        )

    @Slot()
    def end(self) -> None:
        """Stop acting and close the window (its questions answered so that it closes)."""
        if self.ending:
            return
        self.ending = True
        self._deadline = time.monotonic() + CLOSE_WAIT
        self.answerer.closing = True
        if self.operator is not None:
            self.operator.stop()
        say("ending: closing the window")

    def _close(self) -> None:
        window = self.window
        if window is None or not window.isVisible():
            app = QApplication.instance()
            if window is None and app is not None:
                app.exit(1)  # failed before the window was found
            return
        if time.monotonic() > self._deadline:
            fail(f"the window did not close within {CLOSE_WAIT:g} s")
            self._deadline = float("inf")
            app = QApplication.instance()
            if app is not None:
                app.exit(1)
            return
        if QApplication.activeModalWidget() is None:
            window.close()


def _rss_mb() -> float:
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[1])
    except (OSError, ValueError, IndexError):
        return 0.0
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


def _children() -> str:
    """The pids of this process's children (the simulator), from /proc."""
    me = os.getpid()
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if fields and int(fields[1]) == me:
            found.append(stat.parent.name)
    return ", ".join(found) or "?"


def main(argv: Sequence[str] | None = None) -> int:
    global _session
    parser = argparse.ArgumentParser(prog="python -m tests.soak.gui")
    parser.add_argument("--seed", type=int, required=True)
    parser.add_argument("--seconds", type=float, required=True)
    parser.add_argument("--home", type=Path, required=True, help="settings, project, outputs")
    parser.add_argument("--inject", choices=["qt-warning", "exception"], default="", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    install_hooks()
    home: Path = args.home
    home.mkdir(parents=True, exist_ok=True)
    project = home / "soak.teachpad.json"
    shutil.copyfile(SAMPLE, project)
    say(f"soak session: seed {args.seed}, {args.seconds:g} s, home {home}")
    app = QApplication.instance() or QApplication([sys.argv[0]])
    _session = session = Session(random.Random(args.seed), args.seconds, home, args.inject)
    import ui.main as teachpad

    code = teachpad.main(["--sim", "--settings", str(home / "teachpad.ini"), "--project", str(project)])
    session.answerer.stop()
    operator = session.operator
    actions = operator.count if operator is not None else 0
    kinds = ", ".join(f"{k} {n}" for k, n in sorted(operator.by_kind.items())) if operator else ""
    say(f"soak session done: seed {args.seed}, {actions} actions ({kinds}), main() returned {code}")
    _session = None
    del app
    if _failures:
        say(f"soak session FAILED: {len(_failures)} failure(s): {_failures[0]}")
        return 1
    return code


if __name__ == "__main__":
    sys.exit(main())
