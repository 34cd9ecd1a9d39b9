"""The envelope in the motion panels, asserted at the simulator: the jog ratio is capped, a step
leaving the work space is refused before it is sent, the connection dialog is the administrator's."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QApplication

from app.link.types import StepFrame
from app.safety.audit_read import query
from app.safety.box import Box
from app.safety.envelope import Envelope
from app.safety.roles import Role
from tests.ui.controllers.test_gui_roles import PASSWORD, menu_fixture  # noqa: F401 - fixture
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
from ui.controllers.safety_menu import SafetyMenu
from ui.panels.step_panel import StepRequest

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _envelope(menu: SafetyMenu, envelope: Envelope) -> None:
    menu.safety.login(Role.ENGINEER, PASSWORD)
    menu.safety.save_envelope(envelope)
    menu.safety.logout()


def test_the_jog_ratio_is_capped_by_the_envelope(
    qtbot: Any, sim_factory: Any, menu: SafetyMenu, window: Any
) -> None:
    # The simulator shares this process (and its GIL) with the GUI and the worker: a stall of the
    # process longer than the simulator's 0.3 s communication watchdog stopped this jog before the
    # test saw it (once, in a full run beside two busy loops). The cap is what is tested here.
    sim = sim_factory(watchdog=2.0)
    _envelope(menu, Envelope(max_jog_ratio=30.0))
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    panel = window.jog_panel
    qtbot.waitUntil(lambda: panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    panel.speed_slider.setValue(80)
    button = panel.button(0, 1)
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert max(ratio_writes(sim)) == 30.0 and ratio_writes(sim)[-1] == 0.0


def test_a_step_out_of_the_work_space_is_refused_before_sending(
    qtbot: Any, sim: Any, menu: SafetyMenu, window: Any
) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.link.state.pose is not None, timeout=SIGNAL_TIMEOUT_MS)
    y = window.link.state.pose.y
    _envelope(menu, Envelope(keep_in=Box("cell", (-5000.0, -5000.0, -5000.0), (5000.0, y + 50.0, 5000.0))))
    writes = len(sim.writes)
    with qtbot.waitSignal(menu.safety.message, timeout=SIGNAL_TIMEOUT_MS) as said:
        window.step_panel.stepRequested.emit(
            StepRequest(StepFrame.BASE, (0.0, 100.0, 0.0, 0.0, 0.0, 0.0), (0.0,) * 5, 50.0)
        )
    assert "outside the allowed work space" in said.args[0]
    assert len(sim.writes) == writes  # nothing was sent
    assert query(menu.safety.audit_dir)[-1].command == "step"
    t = sim.state().t
    qtbot.waitUntil(lambda: sim.state().t > t + 0.1, timeout=SIGNAL_TIMEOUT_MS)
    assert len(sim.writes) == writes


def test_an_operator_cannot_open_the_connection_dialog(qtbot: Any, menu: SafetyMenu, window: Any) -> None:
    seen: list[object] = []

    def close_modal() -> None:  # if a dialog opened anyway, note it and close it (no hang)
        modal = QApplication.activeModalWidget()
        if modal is not None:
            seen.append(modal)
            modal.close()

    QTimer.singleShot(300, close_modal)
    window.open_connection_dialog()
    assert not window.menus.connect_action.isEnabled()
    qtbot.wait(400)  # the watchdog above had its turn
    assert seen == []
    assert query(menu.safety.audit_dir)[-1].command == "change connection"
