"""Issue 19 section 2 in the real window on a real link (restart canary on): another TeachPad
writing its own restart token is another master -- said on screen, the points stay on the
controller, never "the controller restarted" -- and a real restart still reads as one.

Asserted at the simulator: its canary register's write log and its stored points."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from app.errors import ForeignMasterRefused
from app.link.robot_link import RobotLink
from app.points.point import SyncState
from app.protocol.enums import RunCommand
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
from ui.main_window import TAB_POINTS, MainWindow
from ui.messages import reason_text

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

TOKENS = 6  # another TeachPad's tokens, each read by our canary poll


@pytest.fixture(name="link")
def foreign_link_fixture(canary_link: RobotLink) -> Iterator[RobotLink]:
    yield canary_link


def _connect_and_teach(qtbot: Any, window: MainWindow, sim: Any) -> None:
    settings = connection_settings(sim)
    with qtbot.waitSignal(
        window.link.state.connectionChanged, check_params_cb=lambda s: s.connected, timeout=SIGNAL_TIMEOUT_MS
    ):
        window.connect_with(settings)
    window.work_tabs.setCurrentIndex(TAB_POINTS)
    with qtbot.waitSignal(window.point_sync.pointTaught, timeout=SIGNAL_TIMEOUT_MS):
        assert window.point_sync.teach() is not None
    assert [p.sync for p in window.project.points_model.ledger] == [SyncState.ON_CONTROLLER]


def test_another_teachpads_token_is_another_master_not_a_restart(
    qtbot: Any, window: MainWindow, sim: Any, make_client: Any
) -> None:
    _connect_and_teach(qtbot, window, sim)
    link = window.link
    other = make_client(sim)
    canary_reg = 2 * CANARY_GV
    ours = len(sim.writes_to(canary_reg))
    with qtbot.assertNotEmitted(link.controllerRestarted):
        for token in range(1, TOKENS + 1):
            with qtbot.waitSignal(
                link.foreignMaster,
                check_params_cb=lambda what, value, t=token: value == 1000.0 + t,
                timeout=SIGNAL_TIMEOUT_MS,
            ):
                other.write_gv(CANARY_GV, [1000.0 + token])
    assert len(sim.writes_to(canary_reg)) - ours == TOKENS  # we never wrote ours back
    assert [p.sync for p in window.project.points_model.ledger] == [SyncState.ON_CONTROLLER]
    banner = window.control_column.foreign_banner
    assert banner.isVisibleTo(window) and "Another Modbus master" in banner.text()
    assert any("Another Modbus master" in e.text for e in window.event_log.model.events())
    # the controller really restarts: GV0..GV99 read 0
    with qtbot.waitSignal(link.controllerRestarted, timeout=SIGNAL_TIMEOUT_MS):
        sim.restart_controller()
    qtbot.waitUntil(
        lambda: [p.sync for p in window.project.points_model.ledger] == [SyncState.UNKNOWN],
        timeout=SIGNAL_TIMEOUT_MS,
    )


def test_another_masters_command_is_said_on_screen(
    qtbot: Any, window: MainWindow, sim: Any, make_client: Any
) -> None:
    _connect_and_teach(qtbot, window, sim)
    other = make_client(sim)
    with qtbot.waitSignal(window.link.foreignMaster, timeout=SIGNAL_TIMEOUT_MS) as seen:
        assert other.create_point(9, pose=[400.0, 0.0, 300.0, 180.0, 0.0, 0.0]).ok
    assert seen.args is not None and seen.args[0] in ("registers", "gv291")
    assert "Another Modbus master" in window.control_column.foreign_banner.text()


def test_the_move_refusal_reads_in_both_languages(translator: Any) -> None:
    error = ForeignMasterRefused("incremental move (base)", 5.0, "another master", int(RunCommand.STEP_BASE))
    english = reason_text(error.as_reason())
    assert english is not None and "another Modbus master" in english and "5 s" in english
    assert translator.set_language("zh_CN")
    chinese = reason_text(error.as_reason())
    assert chinese is not None and "另一个 Modbus 主站" in chinese
