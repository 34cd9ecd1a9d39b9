"""The operator's screen against the real simulator: pose on every tab, staleness after silence,
the alarm banner, and an emergency stop that holds motion (asserted at the simulator)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import QEvent, QPoint, QRect, Qt
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import QApplication

from app.protocol import registers
from app.protocol.enums import Alarm
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.main_window import TAB_NAMES, MainWindow

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _live(qtbot: Any, window: MainWindow, sim: Any) -> None:
    connect(qtbot, window.link, sim)
    qtbot.waitUntil(window.pose_strip.is_live, timeout=SIGNAL_TIMEOUT_MS)


def test_the_pose_is_on_every_tab(qtbot: Any, sim: Any, window: MainWindow) -> None:
    _live(qtbot, window, sim)
    x = f"{sim.state().pose[0]:.2f}"
    for name in TAB_NAMES:
        window.show_tab(name)
        strip = window.pose_strip
        assert strip.isVisible() and strip.visibleRegion().boundingRect().width() == strip.width()
        assert strip.value_text("X") == x and strip.freshness_text() == "live"
        assert strip.mode_chip.text() == window.control_bar.mode_text()


def test_stale_after_silence_and_live_again(qtbot: Any, sim: Any, window: MainWindow) -> None:
    _live(qtbot, window, sim)
    window.link.state.set_freshness_limit(0.2)
    strip = window.pose_strip
    sim.set_silent(True)
    qtbot.waitUntil(lambda: not strip.is_live(), timeout=SIGNAL_TIMEOUT_MS)
    assert strip.freshness_text() != "live" and strip.mode_chip.text() == "unknown"
    assert strip.values["X"].property("stale") is True
    assert window.status_panel.mode_label.text() == "unknown"
    assert not window.monitor_panel.readouts["X"].isEnabled()
    sim.set_silent(False)
    qtbot.waitUntil(lambda: strip.freshness_text() == "live", timeout=SIGNAL_TIMEOUT_MS)
    assert strip.values["X"].property("stale") is False and window.monitor_panel.readouts["X"].isEnabled()


def _key(kind: QEvent.Type, key: Qt.Key) -> QKeyEvent:
    return QKeyEvent(kind, key, Qt.KeyboardModifier.NoModifier)


def test_an_emergency_stop_shows_the_banner_and_holds_motion(
    qtbot: Any, sim: Any, window: MainWindow
) -> None:
    _live(qtbot, window, sim)
    banner, jog = window.alarm_banner, window.jog_panel
    assert not banner.isVisible() and jog.axes_box.isEnabled()
    sim.set_alarm(Alarm.ESTOP, True)
    qtbot.waitUntil(banner.isVisible, timeout=SIGNAL_TIMEOUT_MS)
    assert "emergency stop" in banner.text()
    # laid over the window (issue 21): raised above the docks it lies on, STOP not covered
    assert banner.visibleRegion().boundingRect() == banner.rect()
    stop = window.control_bar.stop_button
    assert not banner.geometry().intersects(QRect(stop.mapTo(window, QPoint(0, 0)), stop.size()))
    assert not jog.axes_box.isEnabled() and not window.step_panel.move_button.isEnabled()
    assert not window.program_panel.run_button.isEnabled()
    assert window.control_bar.stop_button.isEnabled()
    assert window.alarm_list.cell(int(Alarm.ESTOP), 4) == "active"
    # a keyboard jog attempt writes nothing: the Stop behind it is the only write that arrives
    before = len(sim.writes)
    jog.setFocus()
    QApplication.sendEvent(jog, _key(QEvent.Type.KeyPress, Qt.Key.Key_Q))
    QApplication.sendEvent(jog, _key(QEvent.Type.KeyRelease, Qt.Key.Key_Q))
    stops = len(sim.writes_to(registers.REG_STOP))
    qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: len(sim.writes_to(registers.REG_STOP)) > stops, timeout=SIGNAL_TIMEOUT_MS)
    after = list(sim.writes)[before:]
    assert after and all(w.address <= registers.REG_STOP < w.address + len(w.values) for w in after)
    assert not sim.state().teach_enabled
    sim.set_alarm(Alarm.ESTOP, False)
    qtbot.waitUntil(lambda: not banner.isVisible(), timeout=SIGNAL_TIMEOUT_MS)
    assert jog.axes_box.isEnabled()
    assert window.alarm_list.cell(int(Alarm.ESTOP), 4) not in ("active", "—")
