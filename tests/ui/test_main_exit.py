"""``teachpad`` (ui/main.py) always leaves its event loop: when the simulator fails to start (for
any reason), when that is decided before the loop runs, when saving the screenshot fails, and when
the simulator is slow to start. An exit asked after the loop is never passed on to the next loop.

These tests run ``main()`` in this process. A SIGALRM (pytest-timeout) cannot end a Qt event loop
(its exception is raised in a slot and swallowed), so each run is also bounded by
:func:`tests.waits.loop_deadline`: a main() whose own exits were lost returns anyway, and the test says so."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QTimer
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QApplication

from tests.ui.pendant_support import QT_LOG_IGNORE
from tests.waits import loop_deadline
from ui import main as teachpad
from ui.main_window import MainWindow

pytestmark = [pytest.mark.timeout(90), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _args(tmp_path: Path, *extra: str) -> list[str]:
    return ["--sim", "--settings", str(tmp_path / "teachpad.ini"), "--lang", "en", *extra]


def main_run(tmp_path: Path, *extra: str) -> int:
    return teachpad.main(_args(tmp_path, *extra))


def _failing_start(exc: BaseException) -> Any:
    def start(*_args: Any, **_kwargs: Any) -> teachpad.SimProcess:
        raise exc

    return start


@pytest.mark.parametrize(
    "exc",
    [RuntimeError("the simulator did not start"), OSError(24, "Too many open files"), ValueError("odd")],
    ids=["runtime", "os", "unexpected"],
)
def test_main_returns_when_the_simulator_fails_to_start(
    qtbot: Any,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    exc: Exception,
) -> None:
    # no --screenshot: nothing but the failure itself can end this run
    monkeypatch.setattr(teachpad.SimProcess, "start", _failing_start(exc))
    started = time.monotonic()
    with loop_deadline("main()"):
        code = main_run(tmp_path)
    assert code == 1
    assert "could not start the simulator" in capsys.readouterr().err
    assert time.monotonic() - started < teachpad.SIM_START_TIMEOUT  # not ended by a timeout


def test_an_exit_asked_before_the_loop_runs_still_ends_it(
    qtbot: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Start-up work that turns the event loop before ``app.exec()`` (here: the window's show)
    lets the simulator's failure arrive early; Qt would drop that exit and run forever."""
    monkeypatch.setattr(teachpad.SimProcess, "start", _failing_start(RuntimeError("no port")))
    asked: list[int] = []
    real_call = teachpad._LoopExit.__call__

    def recording_call(self: Any, code: int) -> None:
        asked.append(code)
        real_call(self, code)

    monkeypatch.setattr(teachpad._LoopExit, "__call__", recording_call)
    real_show = MainWindow.show

    def show_and_turn_the_loop(window: MainWindow) -> None:
        real_show(window)
        deadline = time.monotonic() + 15.0
        while not asked:  # paint, start the simulator (it fails), deliver the failure
            assert time.monotonic() < deadline, "the simulator's failure never arrived"
            QApplication.processEvents()
            time.sleep(0.005)

    monkeypatch.setattr(MainWindow, "show", show_and_turn_the_loop)
    with loop_deadline("main()"):
        code = main_run(tmp_path)
    assert asked == [1] and code == 1
    assert "could not start the simulator: no port" in capsys.readouterr().err


def test_an_exit_asked_after_the_loop_does_not_end_the_next_loop(qtbot: Any, qapp: QApplication) -> None:
    loop_exit = teachpad._LoopExit(qapp)
    QTimer.singleShot(0, lambda: loop_exit(3))
    with loop_deadline("the loop", 10.0):
        assert loop_exit.exec() == 3
    assert loop_exit.ended
    loop_exit(5)  # late (a signal queued before the window closed): ignored
    # Passed on to Qt, it would make every later event loop return at once (its "quit now" stays
    # set outside app.exec): this wait would time out immediately instead of seeing the timer.
    timer = QTimer()
    timer.setSingleShot(True)
    started = time.monotonic()
    with qtbot.waitSignal(timer.timeout, timeout=5000):
        timer.start(100)
    assert time.monotonic() - started >= 0.09
    with pytest.raises(RuntimeError, match="already ran"):
        loop_exit.exec()


def test_a_screenshot_that_cannot_be_saved_still_ends_the_run(
    qtbot: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(teachpad, "SCREENSHOT_SETTLE_MS", 50)

    def broken_grab(_window: MainWindow) -> Any:
        raise MemoryError("no memory for 1400x900")

    monkeypatch.setattr(MainWindow, "grab", broken_grab)
    with loop_deadline("main()"), qtbot.captureExceptions() as raised:
        code = main_run(tmp_path, "--screenshot", str(tmp_path / "shot.png"))
    assert code == 1
    assert [type(e[1]) for e in raised] == [MemoryError]  # the failure is not hidden either
    assert not (tmp_path / "shot.png").exists()


def test_a_slow_simulator_start_gets_the_full_wait_for_a_pose(
    qtbot: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The wait for a pose counts from the simulator being up, not from the window being built."""
    timeout_ms = 3000
    monkeypatch.setattr(teachpad, "SCREENSHOT_TIMEOUT_MS", timeout_ms)
    monkeypatch.setattr(teachpad, "SCREENSHOT_SETTLE_MS", 50)
    real_start = teachpad.SimProcess.start
    built = time.monotonic()

    def slow_start(*args: Any, **kwargs: Any) -> teachpad.SimProcess:
        sim = real_start(*args, **kwargs)
        time.sleep(max(0.0, built + timeout_ms / 1000 + 0.5 - time.monotonic()))  # past the first wait
        return sim

    monkeypatch.setattr(teachpad.SimProcess, "start", slow_start)
    png = tmp_path / "shot.png"
    with loop_deadline("main()"):
        code = main_run(tmp_path, "--screenshot", str(png), "--size", "800x600")
    assert code == 0
    assert not QImage(str(png)).isNull()
