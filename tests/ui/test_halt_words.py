"""A jog's stop the controller has not confirmed is said on screen, in both languages (issue 19,
item 1): "Releasing -- the controller has not confirmed" where the jog is held, until the
controller answered and the arm stands still; the notes of the halt read in Chinese."""

from __future__ import annotations

from typing import Any

import pytest
from pymodbus.constants import ExcCodes
from PySide6.QtCore import Qt

from app.errors import Reason
from app.link.types import HaltKind, Operation, UnconfirmedHalt
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    project_dialogs_fixture,
    ratio_writes,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.messages import error_text
from ui.panels.jog_panel import JogPanel

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

RELEASING = "Releasing — the controller has not confirmed"
RELEASING_ZH = "正在松开 — 控制器尚未确认"
HOLD = "HOLD TO MOVE — release to stop"


@pytest.fixture
def busy_sim(sim_factory: Any) -> Any:
    return sim_factory(watchdog=None)


def test_a_refused_release_is_said_where_the_jog_is_held_until_the_arm_stands_still(
    qtbot: Any, busy_sim: Any, window: Any, translator: Any
) -> None:
    sim = busy_sim
    connect(qtbot, window.link, sim)
    panel = window.jog_panel
    qtbot.waitUntil(lambda: panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    assert panel.hold_label.text() == HOLD
    button = panel.button(2, 1)  # Z+
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    sim.set_exception(ExcCodes.DEVICE_BUSY)
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: panel.hold_label.text() == RELEASING, timeout=SIGNAL_TIMEOUT_MS)
    assert panel.halt is not None and panel.halt.kind is HaltKind.RELEASE
    assert jogging(sim)  # true: the controller still jogs
    assert translator.set_language("zh_CN")
    qtbot.waitUntil(lambda: panel.hold_label.text() == RELEASING_ZH, timeout=SIGNAL_TIMEOUT_MS)
    assert_chinese(panel.hold_label.toolTip())
    sim.set_exception(None)
    qtbot.waitUntil(lambda: panel.halt is None, timeout=SIGNAL_TIMEOUT_MS)
    assert not jogging(sim) and ratio_writes(sim)[-1] == 0.0
    assert panel.hold_label.text() not in (RELEASING, RELEASING_ZH)
    assert translator.set_language("en")
    qtbot.waitUntil(lambda: panel.hold_label.text() == HOLD, timeout=SIGNAL_TIMEOUT_MS)


def test_a_stop_not_confirmed_and_an_escalation_are_said_too(qtbot: Any, translator: Any) -> None:

    panel = JogPanel()
    qtbot.addWidget(panel)
    panel.show_halt(UnconfirmedHalt(HaltKind.STOP, 0.0, True))
    assert panel.hold_label.text() == "Stopping — the controller has not confirmed"
    assert "Stop was sent too." in panel.hold_label.toolTip()
    assert translator.set_language("zh_CN")
    qtbot.waitUntil(lambda: panel.hold_label.text() == "正在停止 — 控制器尚未确认", timeout=SIGNAL_TIMEOUT_MS)
    panel.show_halt(None)
    assert_chinese(panel.hold_label.text())
    assert "控制器尚未确认" not in panel.hold_label.text()


def test_the_notes_of_a_halt_read_in_chinese(translator: Any) -> None:
    assert translator.set_language("zh_CN")
    for reason in (
        Reason("release_unconfirmed", {"seconds": 0.0}),
        Reason("release_escalated", {"seconds": 0.5}),
        Reason("release_confirmed", {"seconds": 2.1}),
        Reason("stop_unconfirmed", {"seconds": 0.0}),
        Reason("stop_confirmed", {"seconds": 1.2}),
        Reason("halt_unconfirmed", {"operation": Operation.JOG}),
        Reason("halt_unconfirmed", {"operation": Operation.STEP}),
    ):
        text = error_text(reason)
        assert text != reason.code
        assert_chinese(text)
    assert "0.5" in error_text(Reason("release_escalated", {"seconds": 0.5}))
