"""A long move from the window (issue 18): a 15 s step (past the 11 s of the old overflow) arrives
and the window says so."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.types import StepFrame
from app.models import CommandResult
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    register_writes,
    translator_fixture,
    window_fixture,
)

LONG_MOVE_MM = 15.0
LONG_MOVE_SPEED = 1.0  # mm/s: 15 s of the simulator's own time (slow, not far)
LONG_MOVE_WAIT_MS = 90_000  # three times the move: a loaded machine is slow, the move is not

pytestmark = [pytest.mark.timeout(150), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def test_a_15_s_step_from_the_window_arrives_and_says_done(qtbot: Any, sim: Any, window: Any) -> None:
    connect(qtbot, window.link, sim)
    qtbot.waitUntil(lambda: window.control_bar.mode_text() != "", timeout=SIGNAL_TIMEOUT_MS)
    panel = window.step_panel
    window.tabs.setCurrentWidget(panel)
    panel.set_frame(StepFrame.BASE)
    panel.speed_spin.setValue(LONG_MOVE_SPEED)
    panel.set_values([0.0, 0.0, -LONG_MOVE_MM])
    z = sim.state().pose[2]
    with qtbot.waitSignal(
        window.link.commandFinished,
        check_params_cb=lambda r: isinstance(r, CommandResult) and r.command is not None,
        timeout=LONG_MOVE_WAIT_MS,
    ) as blocker:
        qtbot.mouseClick(panel.move_button, Qt.MouseButton.LeftButton)
    result = blocker.args[0]
    assert result.ok, result.message
    assert result.details["elapsed"] >= LONG_MOVE_MM / LONG_MOVE_SPEED * 0.9
    assert sim.state().pose[2] == pytest.approx(z - LONG_MOVE_MM, abs=1e-3)
    assert [v for _, v in register_writes(sim, 440)] == [0x41]
    # the window says it: the status panel's last command and the event log
    qtbot.waitUntil(lambda: "done" in window.status_panel.command_label.text(), timeout=SIGNAL_TIMEOUT_MS)
    assert "incremental move (base)" in window.status_panel.command_label.text()
