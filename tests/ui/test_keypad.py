"""Touch mode: the on-screen keypad (range, decimals, sign) and bigger motion buttons."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDoubleSpinBox, QSpinBox, QWidget

from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.keypad import KeypadDialog, keypad_opener
from ui.main_window import MainWindow
from ui.touch import MOTION_MIN_HEIGHT, TOUCH_MOTION_HEIGHT

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _type(dialog: KeypadDialog, keys: str) -> None:
    for key in keys.split():
        dialog.press(key)


def test_keypad_keeps_the_fields_decimals_and_range(qtbot: Any) -> None:
    parent = QWidget()
    qtbot.addWidget(parent)
    field = QDoubleSpinBox(parent)
    field.setRange(-10.0, 100.0)
    field.setDecimals(1)
    field.setValue(5.0)
    dialog = KeypadDialog(field, parent)
    assert dialog.text() == "5"
    _type(dialog, "1 2 . 3 4")  # the first key replaces the old value; one decimal only
    assert dialog.text() == "12.3" and dialog.value() == pytest.approx(12.3)
    _type(dialog, "sign")
    assert dialog.display.text() == "−12.3" and dialog.value() is None  # below -10
    assert not dialog.ok_button.isEnabled()
    _type(dialog, "back back back")
    assert dialog.text() == "-1" and dialog.ok_button.isEnabled()
    _type(dialog, "0 0 0")
    assert dialog.value() is None  # -1000: out of range, OK stays off
    dialog.press("ok")
    assert dialog.isVisible() is False and dialog.result() == 0


def test_keypad_for_an_integer_field_has_no_point_or_sign(qtbot: Any) -> None:
    parent = QWidget()
    qtbot.addWidget(parent)
    field = QSpinBox(parent)
    field.setRange(0, 100)
    dialog = KeypadDialog(field, parent)
    assert not dialog.keys["."].isEnabled() and not dialog.keys["sign"].isEnabled()
    _type(dialog, "1 . 5 0 sign")
    assert dialog.text() == "150" and not dialog.ok_button.isEnabled()
    _type(dialog, "back")
    assert dialog.value() == 15


def test_touch_mode_enlarges_motion_buttons_and_opens_the_keypad(
    qtbot: Any, window: MainWindow, app_settings: Any
) -> None:
    jog_button = window.jog_panel.button(0, 1)
    assert jog_button.height() >= MOTION_MIN_HEIGHT and jog_button.property("motion")
    assert window.control_bar.stop_button.property("motion")
    window.menus.touch_action.trigger()
    assert app_settings.touch_mode
    qtbot.waitUntil(lambda: jog_button.height() >= TOUCH_MOTION_HEIGHT, timeout=SIGNAL_TIMEOUT_MS)

    window.tabs.setCurrentWidget(window.step_panel)
    field = window.step_panel.speed_spin
    opener = keypad_opener(field)
    assert opener is not None
    with qtbot.waitSignal(opener.opened, timeout=SIGNAL_TIMEOUT_MS) as opened:
        qtbot.mouseClick(field.lineEdit(), Qt.MouseButton.LeftButton)
    dialog = opened.args[0]
    assert isinstance(dialog, KeypadDialog) and dialog.isVisible()
    for key in ("1", "2", ".", "5"):
        qtbot.mouseClick(dialog.keys[key], Qt.MouseButton.LeftButton)
    qtbot.mouseClick(dialog.ok_button, Qt.MouseButton.LeftButton)
    assert field.value() == pytest.approx(12.5)

    window.menus.touch_action.trigger()  # off again: a tap edits the field as usual
    assert not app_settings.touch_mode and not opener.enabled
    window.tabs.setCurrentWidget(window.jog_panel)  # a hidden tab is laid out when shown
    qtbot.waitUntil(lambda: jog_button.height() < TOUCH_MOTION_HEIGHT, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.assertNotEmitted(opener.opened):
        qtbot.mouseClick(field.lineEdit(), Qt.MouseButton.LeftButton)


def test_touch_mode_is_remembered(
    qtbot: Any, link: Any, app_settings: Any, translator: Any, project_dialogs: Any, tmp_path: Any
) -> None:
    app_settings.touch_mode = True
    window = MainWindow(
        link, app_settings, translator, project_dialogs=project_dialogs, autosave_dir=tmp_path / "autosave"
    )
    qtbot.addWidget(window)
    assert window.menus.touch_action.isChecked()
    assert window.jog_panel.button(0, 0).minimumHeight() == TOUCH_MOTION_HEIGHT
    assert keypad_opener(window.program_panel.id_spin) is not None
