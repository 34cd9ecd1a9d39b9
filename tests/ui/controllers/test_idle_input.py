"""The idle lock notices operator input where the window system delivers it (each window:
child widgets, dialogs, popups) and nothing else reaches its Python filter: paints, timers and
queued calls of a streaming window stay in C++."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QEvent, QObject, QPoint, QPointF, Qt, QTimer
from PySide6.QtGui import QGuiApplication, QWheelEvent, QWindow
from PySide6.QtTest import QTest
from PySide6.QtWidgets import (
    QApplication,
    QDialog,
    QLabel,
    QLineEdit,
    QMenu,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from app.safety.roles import IDLE_TIMEOUT_DEFAULT, Role
from ui.controllers import safety as safety_module
from ui.controllers.safety import SafetyController

pytestmark = pytest.mark.timeout(60)

PASSWORD = "cell-42"
# The offscreen platform can neither raise a new window nor grab the keyboard for a popup (and says so).
OFFSCREEN_LIMITS = ("This plugin does not support raise", "This plugin does not support grabbing")
INPUT_TYPES = {QEvent.Type.KeyPress, QEvent.Type.MouseButtonPress, QEvent.Type.Wheel, QEvent.Type.TouchBegin}


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class WheelTarget(QLabel):
    def __init__(self) -> None:
        super().__init__("wheel here")
        self.setMinimumSize(80, 40)
        self.turns = 0

    def wheelEvent(self, event: QWheelEvent) -> None:
        self.turns += 1
        event.accept()


class Panel(QWidget):
    """A window with the children input goes to: a line edit, a button, a wheel target."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        layout = QVBoxLayout(self)
        self.edit, self.button, self.wheel = QLineEdit(), QPushButton("Go"), WheelTarget()
        for child in (self.edit, self.button, self.wheel):
            layout.addWidget(child)
        self.clicks = 0
        self.button.clicked.connect(self._clicked)

    def _clicked(self) -> None:
        self.clicks += 1


class Dialog(QDialog):
    def __init__(self, parent: QWidget) -> None:
        super().__init__(parent)
        self.panel = Panel(self)
        QVBoxLayout(self).addWidget(self.panel)


@pytest.fixture(name="clock")
def clock_fixture() -> Clock:
    return Clock()


def _controller(tmp_path: Path, clock: Clock, monkeypatch: pytest.MonkeyPatch) -> SafetyController:
    """A controller with an engineer logged in, its idle lock on ``clock``."""
    safety = SafetyController(None, scrypt_n=2**4)
    monkeypatch.setattr(safety.session.idle, "_clock", clock)
    roles = safety.session.store
    roles.set_password(Role.ADMINISTRATOR, PASSWORD, by=Role.ADMINISTRATOR)
    roles.set_password(Role.ENGINEER, PASSWORD, by=Role.ADMINISTRATOR)
    safety.login(Role.ENGINEER, PASSWORD)
    return safety


@pytest.fixture(name="safety")
def safety_fixture(
    qapp: Any, tmp_path: Path, clock: Clock, monkeypatch: pytest.MonkeyPatch
) -> Iterator[SafetyController]:
    safety = _controller(tmp_path, clock, monkeypatch)
    safety.set_idle_polling(False)  # the test polls, on its own clock
    yield safety
    safety.close()


def _shown(qtbot: Any, widget: QWidget) -> QWindow:
    """Show ``widget`` and wait until its window has the focus (as it has before anyone can
    reach it: the window system activates it first)."""
    qtbot.addWidget(widget)
    widget.show()
    assert QTest.qWaitForWindowExposed(widget)
    handle = widget.windowHandle()
    assert handle is not None
    qtbot.waitUntil(lambda: QGuiApplication.focusWindow() is handle)
    return handle


def _at(panel: Panel, child: QWidget) -> QPoint:
    """``child``'s centre in its window's coordinates."""
    return child.mapTo(panel.window(), child.rect().center())


def _key(qtbot: Any, window: QWindow, panel: Panel) -> None:
    panel.edit.clear()
    panel.edit.setFocus()
    QTest.keyClick(window, Qt.Key.Key_A)
    assert panel.edit.text() == "a"


def _mouse(qtbot: Any, window: QWindow, panel: Panel) -> None:
    at = _at(panel, panel.button)
    QTest.mouseClick(window, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, at)
    assert panel.clicks == 1


def _wheel(qtbot: Any, window: QWindow, panel: Panel) -> None:
    # What the window system hands the window (QGuiApplication's processWheelEvent); the window
    # passes it on to the widget under the cursor.
    at = QPointF(_at(panel, panel.wheel))
    event = QWheelEvent(
        at,
        window.mapToGlobal(at),
        QPoint(),
        QPoint(0, 120),
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    QApplication.sendEvent(window, event)
    assert panel.wheel.turns == 1


def _touch(qtbot: Any, window: QWindow, panel: Panel) -> None:
    device = QTest.createTouchDevice()
    at = _at(panel, panel.button)
    QTest.touchEvent(window, device).press(0, at, window)
    QTest.touchEvent(window, device).release(0, at, window)
    qtbot.waitUntil(lambda: panel.clicks == 1)  # the button got it (as a synthesized click)


INPUTS: dict[str, Callable[[Any, QWindow, Panel], None]] = {
    "key": _key,
    "mouse": _mouse,
    "wheel": _wheel,
    "touch": _touch,
}


def _still_engineer_after(safety: SafetyController, clock: Clock, act: Callable[[], None]) -> bool:
    """Idle for most of the timeout, ``act``, idle for most of it again: does the role hold?"""
    clock.now += 0.8 * IDLE_TIMEOUT_DEFAULT
    act()
    clock.now += 0.8 * IDLE_TIMEOUT_DEFAULT
    safety.session.poll_idle()
    return safety.role is Role.ENGINEER


def test_without_input_the_lock_falls(safety: SafetyController, clock: Clock) -> None:
    assert not _still_engineer_after(safety, clock, lambda: None)


@pytest.mark.parametrize("kind", sorted(INPUTS))
def test_input_in_a_child_widget_keeps_the_role(
    qtbot: Any, safety: SafetyController, clock: Clock, kind: str
) -> None:
    panel = Panel()
    window = _shown(qtbot, panel)
    assert _still_engineer_after(safety, clock, lambda: INPUTS[kind](qtbot, window, panel))


@pytest.mark.parametrize("kind", sorted(INPUTS))
def test_input_in_a_dialog_opened_later_keeps_the_role(
    qtbot: Any, safety: SafetyController, clock: Clock, kind: str
) -> None:
    main = Panel()
    _shown(qtbot, main)
    dialog = Dialog(main)
    window = _shown(qtbot, dialog)  # a new window: picked up when it takes the focus
    assert _still_engineer_after(safety, clock, lambda: INPUTS[kind](qtbot, window, dialog.panel))


@pytest.mark.qt_log_ignore(*OFFSCREEN_LIMITS)
def test_a_click_in_a_popup_menu_keeps_the_role(qtbot: Any, safety: SafetyController, clock: Clock) -> None:
    main = Panel()
    _shown(qtbot, main)
    menu = QMenu(main)
    action = menu.addAction("Teach")
    triggered: list[bool] = []
    action.triggered.connect(lambda: triggered.append(True))

    def click() -> None:
        menu.popup(main.mapToGlobal(QPoint(10, 10)))
        assert QTest.qWaitForWindowExposed(menu)
        popup = menu.windowHandle()
        assert popup is not None
        QTest.mouseClick(
            popup,
            Qt.MouseButton.LeftButton,
            Qt.KeyboardModifier.NoModifier,
            menu.actionGeometry(action).center(),
        )
        assert triggered

    assert _still_engineer_after(safety, clock, click)


@pytest.mark.qt_log_ignore(*OFFSCREEN_LIMITS)
def test_a_window_that_never_takes_the_focus_is_watched_from_the_next_poll(
    qtbot: Any, tmp_path: Path, clock: Clock, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(safety_module, "IDLE_POLL_MS", 20)
    safety = _controller(tmp_path, clock, monkeypatch)  # polling (every 20 ms)
    main = Panel()
    _shown(qtbot, main)
    tool = Panel()
    tool.setWindowFlags(Qt.WindowType.Tool | Qt.WindowType.WindowDoesNotAcceptFocus)
    tool.setAttribute(Qt.WidgetAttribute.WA_ShowWithoutActivating)
    qtbot.addWidget(tool)
    tool.show()
    assert QTest.qWaitForWindowExposed(tool)
    window = tool.windowHandle()
    assert window is not None
    clock.now = 100.0

    def click_is_noticed() -> bool:
        QTest.mouseClick(
            window, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, _at(tool, tool.button)
        )
        return safety.session.idle.remaining() == IDLE_TIMEOUT_DEFAULT  # touched at 100 s

    qtbot.waitUntil(click_is_noticed, timeout=5000)
    assert tool.clicks >= 1 and safety.role is Role.ENGINEER
    safety.close()


class _Recording:
    """Records the event types that reach :meth:`SafetyController.eventFilter` (Python)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.types: list[QEvent.Type] = []
        original = SafetyController.eventFilter

        def recording(controller: SafetyController, watched: QObject, event: QEvent) -> bool:
            self.types.append(event.type())
            return original(controller, watched, event)

        monkeypatch.setattr(SafetyController, "eventFilter", recording)


def test_paints_timers_and_queued_calls_never_reach_the_filter(
    qtbot: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen = _Recording(monkeypatch)
    safety = SafetyController(None, scrypt_n=2**4)
    safety.set_idle_polling(False)
    panel = Panel()
    window = _shown(qtbot, panel)
    qtbot.wait(50)  # the first paints, the window settling
    seen.types.clear()

    # A streaming window: repaints, a fast timer, queued calls and posted events, for a while.
    ticks: list[int] = []
    timer = QTimer()
    timer.setInterval(1)

    def tick() -> None:
        ticks.append(1)
        panel.edit.setText(str(len(ticks)))
        panel.wheel.setText(f"tick {len(ticks)}")
        panel.update()
        QTimer.singleShot(0, panel.button.update)  # a queued call
        QApplication.postEvent(panel, QEvent(QEvent.Type.User))

    timer.timeout.connect(tick)
    timer.start()
    qtbot.waitUntil(lambda: len(ticks) >= 100, timeout=20000)
    timer.stop()
    panel.repaint()
    busy = {
        QEvent.Type.Paint,
        QEvent.Type.Timer,
        QEvent.Type.MetaCall,
        QEvent.Type.User,
        QEvent.Type.UpdateRequest,
        QEvent.Type.LayoutRequest,
    }
    assert not busy.intersection(seen.types), seen.types
    assert len(seen.types) < 10  # a few window events at most (against thousands app-wide)

    _key(qtbot, window, panel)  # and the filter is there for input
    assert QEvent.Type.KeyPress in seen.types
    safety.close()
    seen.types.clear()
    QTest.keyClick(window, Qt.Key.Key_B)
    assert panel.edit.text().endswith("b") and not seen.types  # closed: no longer watching


def test_input_types_are_the_ones_that_count() -> None:
    assert set(safety_module._TOUCH_EVENTS) == INPUT_TYPES
