"""Jogging from the main window: hold to move, and every way of letting go writes ratio 0."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import QEvent, Qt
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import QApplication, QLineEdit

from app import timing
from app.link.types import LinkState
from app.protocol.enums import ControllerMode, TeachFrame
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    gv_writes,
    is_state,
    jogging,
    link_fixture,
    project_dialogs_fixture,
    ratio_writes,
    translator_fixture,
    window_fixture,
)

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


# Polls with a roomy timeout: the simulator shares the GIL in tests and a loaded machine must not
# show "not answering" (which drops the held jog); the link-loss test sets its own.
POLL_TIMEOUT = 1.0


def _start_jog(qtbot: Any, window: Any, sim: Any, axis: int = 0, direction: int = 1, **settings: Any) -> Any:
    """Press and hold a jog button until the simulator moves; returns the button."""
    settings.setdefault("poll_timeout", POLL_TIMEOUT)
    connect(qtbot, window.link, sim, **settings)
    qtbot.waitUntil(lambda: window.jog_panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    button = window.jog_panel.button(axis, direction)
    x0 = sim.state().pose[axis]
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(
        lambda: jogging(sim) and abs(sim.state().pose[axis] - x0) > 1.0, timeout=SIGNAL_TIMEOUT_MS
    )
    assert window.jog_panel.is_jogging
    assert max(ratio_writes(sim)) > 0
    return button


def _stopped_by_ratio_zero(sim: Any) -> bool:
    ratios = ratio_writes(sim)
    return not sim.state().jogging and bool(ratios) and ratios[-1] == 0.0 and max(ratios) > 0


def test_held_button_moves_and_release_writes_ratio_zero(qtbot: Any, sim: Any, window: Any) -> None:
    button = _start_jog(qtbot, window, sim, axis=0, direction=1)
    qtbot.waitUntil(lambda: window.control_bar.mode_text() == "Modbus teach", timeout=SIGNAL_TIMEOUT_MS)
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: _stopped_by_ratio_zero(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert not window.jog_panel.is_jogging
    x, t = sim.state().pose[0], sim.state().t
    qtbot.waitUntil(lambda: sim.state().t > t + 0.1, timeout=SIGNAL_TIMEOUT_MS)  # 10 simulator ticks
    assert sim.state().pose[0] == pytest.approx(x)


def test_speed_slider_changes_the_ratio_while_moving(qtbot: Any, sim: Any, window: Any) -> None:
    button = _start_jog(qtbot, window, sim, axis=2, direction=0)
    window.jog_panel.speed_slider.setValue(90)
    qtbot.waitUntil(lambda: sim.state().teach_ratio == 90.0, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: _stopped_by_ratio_zero(sim), timeout=SIGNAL_TIMEOUT_MS)


def test_window_deactivation_stops_the_jog(qtbot: Any, sim: Any, window: Any) -> None:
    button = _start_jog(qtbot, window, sim)
    QApplication.sendEvent(window, QEvent(QEvent.Type.WindowDeactivate))
    qtbot.waitUntil(lambda: _stopped_by_ratio_zero(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert not window.jog_panel.is_jogging and not button.isDown()
    # Still holding the mouse and sliding back does not restart: it needs a new press.
    qtbot.mouseMove(button)
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    assert not sim.state().jogging


def test_focus_moving_to_another_window_stops_the_jog(qtbot: Any, sim: Any, window: Any) -> None:
    _start_jog(qtbot, window, sim, axis=1, direction=1)
    other = QLineEdit()
    qtbot.addWidget(other)
    other.show()
    qtbot.waitExposed(other)
    other.activateWindow()
    other.setFocus()
    qtbot.waitUntil(lambda: _stopped_by_ratio_zero(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert not window.jog_panel.is_jogging


def test_application_inactive_stops_the_jog(qtbot: Any, sim: Any, window: Any) -> None:
    _start_jog(qtbot, window, sim)
    window._on_application_state(Qt.ApplicationState.ApplicationInactive)
    qtbot.waitUntil(lambda: _stopped_by_ratio_zero(sim), timeout=SIGNAL_TIMEOUT_MS)


def test_closing_the_window_stops_the_jog_and_teach(qtbot: Any, sim: Any, window: Any) -> None:
    _start_jog(qtbot, window, sim)
    window.close()  # blocks until the worker has written ratio 0 and teach disable
    state = sim.state()
    assert not state.jogging and not state.teach_enabled
    assert ratio_writes(sim)[-1] == 0.0
    assert not window.link.is_running


def test_link_loss_releases_and_reconnect_makes_safe(
    qtbot: Any, sim: Any, window: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "NOT_ANSWERING_DOWN_AFTER", 0.3)
    sim.set_watchdog(None)  # a controller without a communication watchdog
    _start_jog(qtbot, window, sim, poll_timeout=0.5)
    with qtbot.waitSignal(
        window.link.connectionChanged, check_params_cb=is_state(LinkState.DOWN), timeout=SIGNAL_TIMEOUT_MS
    ):
        sim.set_silent(True)
    assert not window.jog_panel.is_jogging
    assert not window.jog_panel.axes_box.isEnabled()
    assert jogging(sim)  # the controller itself keeps moving while its master is gone
    writes_before = len(sim.writes)
    with qtbot.waitSignal(window.link.controllerReconnected, timeout=SIGNAL_TIMEOUT_MS):
        sim.set_silent(False)
    assert sim.writes[writes_before].address == 406  # the first write after the return: ratio ...
    assert gv_writes(sim, 203)[-1][1] == 0.0  # ... 0
    assert not sim.state().jogging and not sim.state().teach_enabled
    qtbot.waitUntil(lambda: window.jog_panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)


def _key(kind: QEvent.Type, key: Qt.Key, autorepeat: bool = False) -> QKeyEvent:
    return QKeyEvent(kind, key, Qt.KeyboardModifier.NoModifier, "", autorepeat)


def test_keyboard_jog_with_dead_man(qtbot: Any, sim: Any, window: Any) -> None:
    connect(qtbot, window.link, sim)
    panel = window.jog_panel
    qtbot.waitUntil(lambda: panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    panel.setFocus()
    qtbot.waitUntil(lambda: panel.hasFocus(), timeout=SIGNAL_TIMEOUT_MS)
    QApplication.sendEvent(panel, _key(QEvent.Type.KeyPress, Qt.Key.Key_W))  # Y +
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    # Auto-repeat sends release/press pairs while the key is held: the jog goes on.
    for _ in range(3):
        QApplication.sendEvent(panel, _key(QEvent.Type.KeyRelease, Qt.Key.Key_W, autorepeat=True))
        QApplication.sendEvent(panel, _key(QEvent.Type.KeyPress, Qt.Key.Key_W, autorepeat=True))
    assert panel.is_jogging and ratio_writes(sim)[-1] > 0
    QApplication.sendEvent(panel, _key(QEvent.Type.KeyRelease, Qt.Key.Key_W))
    qtbot.waitUntil(lambda: _stopped_by_ratio_zero(sim), timeout=SIGNAL_TIMEOUT_MS)


def test_keyboard_jog_lights_up_the_button_it_presses(qtbot: Any, sim: Any, window: Any) -> None:
    connect(qtbot, window.link, sim)
    panel = window.jog_panel
    qtbot.waitUntil(lambda: panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    panel.setFocus()
    qtbot.waitUntil(lambda: panel.hasFocus(), timeout=SIGNAL_TIMEOUT_MS)
    y_plus, z_minus = panel.button(1, 1), panel.button(2, 0)
    QApplication.sendEvent(panel, _key(QEvent.Type.KeyPress, Qt.Key.Key_W))  # Y +
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert y_plus.isDown() and not z_minus.isDown()
    QApplication.sendEvent(panel, _key(QEvent.Type.KeyPress, Qt.Key.Key_D))  # Z − takes over
    assert z_minus.isDown() and not y_plus.isDown()
    QApplication.sendEvent(panel, _key(QEvent.Type.KeyRelease, Qt.Key.Key_W))  # the older key: Z goes on
    assert z_minus.isDown()
    QApplication.sendEvent(panel, _key(QEvent.Type.KeyRelease, Qt.Key.Key_D))
    qtbot.waitUntil(lambda: _stopped_by_ratio_zero(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert not any(b.isDown() for b in (*panel.plus_buttons, *panel.minus_buttons))
    QApplication.sendEvent(panel, _key(QEvent.Type.KeyPress, Qt.Key.Key_Q))  # X +, then the link drops
    assert panel.button(0, 1).isDown()
    window.link.disconnect()
    qtbot.waitUntil(lambda: not panel.button(0, 1).isDown(), timeout=SIGNAL_TIMEOUT_MS)
    assert not panel.is_jogging


def test_joint_frame_shows_external_axes_and_jogs_them(qtbot: Any, sim: Any, window: Any) -> None:
    panel = window.jog_panel
    assert not panel.button(6, 1).isVisibleTo(panel)
    panel.set_frame(TeachFrame.JOINT)
    assert panel.button(10, 1).isVisibleTo(panel)
    assert [label.text() for label in panel.axis_labels][6:] == ["J7", "J8", "J9", "J10", "J11"]
    connect(qtbot, window.link, sim)
    qtbot.waitUntil(lambda: panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    j7 = sim.state().joints[6]
    qtbot.mousePress(panel.button(6, 1), Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: sim.state().joints[6] > j7 + 0.5, timeout=SIGNAL_TIMEOUT_MS)
    assert sim.state().mode == ControllerMode.MODBUS_TEACH
    qtbot.mouseRelease(panel.button(6, 1), Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: _stopped_by_ratio_zero(sim), timeout=SIGNAL_TIMEOUT_MS)
