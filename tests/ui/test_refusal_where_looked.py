"""Safety refusals appear where the operator looks for what became of the command: the status
dock's *Last command*, not only the status bar's 8 s message (issue 21, "Words that say what
happened"). A jog the guard stops before the work space's face and a step out of the work space,
at the simulator (the arm short of the face, the step not sent), in both languages."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.types import StepFrame
from app.safety.box import Box
from app.safety.envelope import Envelope
from tests.ui.controllers.test_gui_motion import _envelope
from tests.ui.controllers.test_gui_roles import menu_fixture  # noqa: F401 - fixture
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.controllers.safety_menu import SafetyMenu
from ui.panels.step_panel import StepRequest

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

MARGIN_MM = 30.0


def _keep_in_below(menu: SafetyMenu, y_limit: float) -> None:
    _envelope(menu, Envelope(keep_in=Box("cell", (-5000.0, -5000.0, -5000.0), (5000.0, y_limit, 5000.0))))


def test_a_jog_the_guard_stops_reads_in_last_command(
    qtbot: Any, sim_factory: Any, menu: SafetyMenu, window: Any
) -> None:
    sim = sim_factory(watchdog=2.0)  # a stalled test process must not stop the jog first
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    y0 = sim.state().pose[1]
    _keep_in_below(menu, y0 + MARGIN_MM)
    panel = window.jog_panel
    qtbot.waitUntil(lambda: panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    label = window.status_panel.command_label
    button = panel.button(1, 1)  # Y+ toward the face
    with qtbot.waitSignal(window.link.jogGuardStopped, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert y0 < sim.state().pose[1] < y0 + MARGIN_MM  # at the simulator: short of the face
    assert label.text().startswith("Jog stopped before the limit: Y = "), label.text()
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)


def test_a_step_out_of_the_work_space_reads_in_last_command_in_both_languages(
    qtbot: Any, sim: Any, menu: SafetyMenu, window: Any
) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.link.state.pose is not None, timeout=SIGNAL_TIMEOUT_MS)
    _keep_in_below(menu, window.link.state.pose.y + 50.0)
    label = window.status_panel.command_label
    writes = len(sim.writes)
    step = StepRequest(StepFrame.BASE, (0.0, 100.0, 0.0, 0.0, 0.0, 0.0), (0.0,) * 5, 50.0)
    with qtbot.waitSignal(menu.safety.message, timeout=SIGNAL_TIMEOUT_MS):
        window.step_panel.stepRequested.emit(step)
    assert len(sim.writes) == writes  # nothing was sent
    assert "mm is outside the allowed work space" in label.text(), label.text()
    window.set_language("zh_CN")
    with qtbot.waitSignal(menu.safety.message, timeout=SIGNAL_TIMEOUT_MS):
        window.step_panel.stepRequested.emit(step)
    assert len(sim.writes) == writes
    assert_chinese(label.text())
