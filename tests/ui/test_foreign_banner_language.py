"""The "another master" banner (issue 19 section 2) follows the language: switched while it is
shown, it says the same sign in the new language (the window retranslates it from the sign it
keeps, not from the sentence it was given)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from app.link.robot_link import RobotLink
from app.protocol.registers import CANARY_GV
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    canary_link_fixture,
    connection_settings,
    fast_reconnect_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.controllers.plan_run_reasons import foreign_resume_refused_text
from ui.main_window import MainWindow

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


@pytest.fixture(name="link")
def foreign_link_fixture(canary_link: RobotLink) -> Iterator[RobotLink]:
    yield canary_link


def test_the_banner_retranslates_while_it_is_shown(
    qtbot: Any, window: MainWindow, sim: Any, make_client: Any, translator: Any
) -> None:
    with qtbot.waitSignal(
        window.link.state.connectionChanged, check_params_cb=lambda s: s.connected, timeout=SIGNAL_TIMEOUT_MS
    ):
        window.connect_with(connection_settings(sim))
    other = make_client(sim)
    with qtbot.waitSignal(window.link.foreignMaster, timeout=SIGNAL_TIMEOUT_MS):
        other.write_gv(CANARY_GV, [4242.0])  # another TeachPad's restart token
    banner = window.control_column.foreign_banner
    assert banner.isVisibleTo(window)
    english = banner.text()
    assert english == "Another Modbus master is on this controller (token 4242): check who else is connected."
    assert banner.toolTip().startswith("Seen: it wrote its own restart token (4242). Another master shares")
    window.set_language("zh_CN")
    assert translator.language == "zh_CN"
    chinese = banner.text()
    assert chinese.startswith("此控制器上还有另一个 Modbus 主站（重启标记 4242）"), chinese
    assert banner.toolTip().startswith("迹象：它写入了自己的重启标记（4242）。"), banner.toolTip()
    assert banner.isVisibleTo(window)
    window.set_language("en")
    assert banner.text() == english


def test_a_run_paused_by_another_master_says_so_in_the_run_box_and_the_event_log(
    qtbot: Any, window: MainWindow
) -> None:
    """The window's parts listen to the run's own pause (its behaviour at the simulator:
    tests/ui/controllers/test_plan_run_foreign.py): the run box and the event log say why, in the language in
    force; the pause is recorded in the window's audit trail."""
    runs = window.run_controller
    assert runs.audit is window.safety_menu.safety.session.audit
    panel = window.planner_panel
    runs.pausedByForeign.emit("registers", 409.0)
    text = "Paused: another master wrote to the controller (register 409 changed without a write of TeachPad)"
    assert panel.run_box.run_label.text() == text
    logged = [e for e in window.event_log.model.events() if e.text == text]
    assert len(logged) == 1 and logged[0].level == "warning"
    runs.resumeRefused.emit("Not resumed: because")
    assert panel.run_box.run_label.text() == "Not resumed: because"
    window.set_language("zh_CN")
    chinese = [e.text for e in window.event_log.model.events() if e.text.startswith("已暂停：")]
    assert chinese == ["已暂停：另一个主站写入了控制器（寄存器 409 在 TeachPad 未写入的情况下发生了变化）"]
    refused = foreign_resume_refused_text(5.0, 3.2)
    assert refused.startswith("未继续：另一个主站在不到 5 秒前写入了控制器") and "3.2 秒后" in refused
