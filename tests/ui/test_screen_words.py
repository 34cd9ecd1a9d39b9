"""Every message in the operator's language (issue 9): the link's state from a real silent
simulator, the event log after a language switch, and the plan checks and the ledger's
refusals worded from their codes and arguments."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.types import ConnectionState, LinkState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    translator_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.panels.event_log import COL_MESSAGE, COL_SOURCE, EventLogPanel
from ui.panels.status_panel import StatusPanel

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _cell(panel: EventLogPanel, row: int, column: int) -> str:
    return str(panel.model.data(panel.model.index(row, column), Qt.ItemDataRole.DisplayRole))


def test_a_silent_controller_is_explained_in_chinese(
    qtbot: Any, sim: Any, link: Any, translator: Any
) -> None:
    assert translator.set_language("zh_CN")
    status, log = StatusPanel(), EventLogPanel()
    for panel in (status, log):
        qtbot.addWidget(panel)
        panel.bind(link.state)
    connect(qtbot, link, sim)
    sim.set_silent(True)
    try:
        qtbot.waitUntil(
            lambda: link.state.connection.state is LinkState.NOT_ANSWERING, timeout=SIGNAL_TIMEOUT_MS
        )
        connection: ConnectionState = link.state.connection
        assert connection.reason is not None and connection.reason.code == "no_answer"
        assert "did not answer" in connection.message  # the English stays for logs and the CLI
        assert_chinese(status.link_message.text())
        last = log.model.rowCount() - 1
        assert_chinese(_cell(log, last, COL_MESSAGE))
        assert_chinese(_cell(log, last, COL_SOURCE))
    finally:
        sim.set_silent(False)
    qtbot.waitUntil(lambda: link.state.connection.connected, timeout=SIGNAL_TIMEOUT_MS)


def test_the_event_log_speaks_the_new_language_after_a_switch(
    qtbot: Any, sim: Any, link: Any, translator: Any
) -> None:
    log = EventLogPanel()
    qtbot.addWidget(log)
    log.bind(link.state)
    connect(qtbot, link, sim)
    # the first status (alarms 0) first: arriving after the injected bit it would log "cleared"
    qtbot.waitUntil(lambda: link.state.alarms is not None, timeout=SIGNAL_TIMEOUT_MS)
    log.on_alarms(1)  # an emergency stop raised
    log.add_event("info", "safety", "written as it was")  # a text logged as written stays so
    english = [_cell(log, row, COL_MESSAGE) for row in range(log.model.rowCount())]
    assert any("connected" in text for text in english) and "Alarm raised: emergency stop" in english
    assert translator.set_language("zh_CN")

    def messages() -> list[str]:
        return [_cell(log, r, COL_MESSAGE) for r in range(log.model.rowCount())]

    qtbot.waitUntil(lambda: "报警触发：急停" in messages(), timeout=SIGNAL_TIMEOUT_MS)
    rows = range(log.model.rowCount())
    for row in rows[:-1]:
        assert_chinese(_cell(log, row, COL_MESSAGE))
        assert_chinese(_cell(log, row, COL_SOURCE))
    assert _cell(log, rows[-1], COL_MESSAGE) == "written as it was"
    assert translator.set_language("en")
    qtbot.waitUntil(lambda: _cell(log, 0, COL_MESSAGE) == english[0], timeout=SIGNAL_TIMEOUT_MS)
    assert [_cell(log, row, COL_MESSAGE) for row in rows] == english
