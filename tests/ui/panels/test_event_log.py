"""EventLogPanel: levels and colours, alarm transitions, commands, link changes, bound, export."""

from __future__ import annotations

import datetime as dt
import os
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, Qt, QTranslator

from app.link.types import ConnectionState, LinkState
from app.models import CommandResult
from app.points import atomic
from app.protocol.enums import Alarm, CommandKind, CommandStatus, RunCommand
from ui.palette import COLOR_ERROR_BG, COLOR_WARN_BG
from ui.panels.event_log import (
    COL_LEVEL,
    COL_MESSAGE,
    COL_SOURCE,
    COL_TIME,
    EventLogModel,
    EventLogPanel,
    LogEvent,
)

WHEN = dt.datetime(2025, 6, 1, 8, 30, 15, 250_000)


def cell(panel: EventLogPanel, row: int, column: int, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
    model = panel.model
    return model.data(model.index(row, column), role)


def messages(panel: EventLogPanel) -> list[tuple[str, str]]:
    return [(e.level, e.text) for e in panel.model.events()]


@pytest.fixture
def panel(qtbot: Any) -> Iterator[EventLogPanel]:
    widget = EventLogPanel()
    qtbot.addWidget(widget)
    yield widget


def test_add_event_columns_and_colours(panel: EventLogPanel) -> None:
    panel.add_event("info", "user", "hello", WHEN)
    panel.add_event("warning", "points", "point 3 overwritten", WHEN)
    panel.add_event("error", "link", "link lost", WHEN)
    assert cell(panel, 0, COL_TIME) == "08:30:15.250"
    assert cell(panel, 0, COL_TIME, Qt.ItemDataRole.ToolTipRole) == "2025-06-01 08:30:15.250"
    assert [cell(panel, r, COL_LEVEL) for r in range(3)] == ["Info", "Warning", "Error"]
    assert cell(panel, 1, COL_SOURCE) == "points"
    assert cell(panel, 2, COL_MESSAGE) == "link lost"
    assert cell(panel, 0, COL_MESSAGE, Qt.ItemDataRole.BackgroundRole) is None
    assert cell(panel, 1, COL_MESSAGE, Qt.ItemDataRole.BackgroundRole).color().name() == COLOR_WARN_BG
    assert cell(panel, 2, COL_MESSAGE, Qt.ItemDataRole.BackgroundRole).color().name() == COLOR_ERROR_BG


def test_add_event_defaults_to_now_and_signals(qtbot: Any, panel: EventLogPanel) -> None:
    before = dt.datetime.now()
    with qtbot.waitSignal(panel.eventAdded, check_params_cb=lambda e: e.text == "x") as blocker:
        panel.add_event("info", "s", "x")
    event = blocker.args[0]
    assert isinstance(event, LogEvent)
    assert before <= event.when <= dt.datetime.now()


def test_unknown_level_is_refused(panel: EventLogPanel) -> None:
    with pytest.raises(ValueError):
        panel.add_event("fatal", "s", "x")


def test_alarm_transitions_in_words(panel: EventLogPanel) -> None:
    panel.on_alarms(0)
    assert messages(panel) == []
    panel.on_alarms(int(Alarm.ESTOP | Alarm.SERVO))
    assert messages(panel) == [
        ("error", "Alarm raised: emergency stop"),
        ("error", "Alarm raised: servo alarm"),
    ]
    panel.on_alarms(int(Alarm.ESTOP | Alarm.SERVO))  # no change, nothing logged
    assert len(messages(panel)) == 2
    panel.on_alarms(int(Alarm.SERVO | (1 << 6)))
    assert messages(panel)[2:] == [
        ("info", "Alarm cleared: emergency stop"),
        ("error", "Alarm raised: bit 6"),
    ]
    assert {e.source for e in panel.model.events()} == {"alarm"}


def test_command_results(panel: EventLogPanel) -> None:
    panel.on_command_result(
        CommandResult(RunCommand.STEP_BASE, CommandKind.MOVE, CommandStatus(CommandKind.MOVE, 0xFF), True)
    )
    panel.on_command_result(
        CommandResult(
            RunCommand.CREATE_POINT,
            CommandKind.CREATE_POINT,
            CommandStatus(CommandKind.CREATE_POINT, 1),
            False,
            "point 10001",
        )
    )
    assert messages(panel) == [
        ("info", "incremental move (base): done."),
        ("error", "create temp point refused by the controller: bad point id."),
    ]


def test_connection_changes_are_logged_once(panel: EventLogPanel) -> None:
    panel.on_connection(ConnectionState(LinkState.CONNECTING, "", "127.0.0.1:502"))
    panel.on_connection(ConnectionState(LinkState.CONNECTED, "", "127.0.0.1:502"))
    panel.on_connection(ConnectionState(LinkState.CONNECTED, "", "127.0.0.1:502"))
    panel.on_connection(ConnectionState(LinkState.NOT_ANSWERING, "no answer", "127.0.0.1:502"))
    panel.on_connection(ConnectionState(LinkState.DOWN, "retry in 0.5 s"))
    panel.on_connection(ConnectionState(LinkState.DISCONNECTED))
    assert messages(panel) == [
        ("info", "connecting — 127.0.0.1:502"),
        ("info", "connected — 127.0.0.1:502"),
        ("warning", "not answering — 127.0.0.1:502 — no answer"),
        ("error", "link down — retry in 0.5 s"),
        ("info", "disconnected"),
    ]


def test_bounded(qtbot: Any) -> None:
    panel = EventLogPanel(max_events=50)
    qtbot.addWidget(panel)
    for i in range(120):
        panel.add_event("info", "s", f"event {i}")
        assert panel.model.rowCount() <= 50
    assert cell(panel, panel.model.rowCount() - 1, COL_MESSAGE) == "event 119"


def test_level_filter(panel: EventLogPanel) -> None:
    for level in ("info", "warning", "error", "info"):
        panel.add_event(level, "s", level)
    panel.level_combo.setCurrentIndex(1)
    assert panel.proxy.rowCount() == 2
    panel.level_combo.setCurrentIndex(2)
    assert panel.proxy.rowCount() == 1
    panel.level_combo.setCurrentIndex(0)
    assert panel.proxy.rowCount() == 4


def test_clear(panel: EventLogPanel) -> None:
    panel.add_event("info", "s", "x")
    panel.clear_button.click()
    assert panel.model.rowCount() == 0


def test_export_is_atomic(tmp_path: Path, panel: EventLogPanel) -> None:
    panel.add_event("info", "link", "connected", WHEN)
    panel.add_event("error", "command", "two\nlines", WHEN + dt.timedelta(seconds=1))
    target = tmp_path / "events.txt"
    target.write_text("previous")
    assert panel.export_to(target) == 2
    assert [p.name for p in tmp_path.iterdir()] == ["events.txt"]
    assert target.read_bytes().startswith(b"\xef\xbb\xbf")  # UTF-8 with a BOM, for Excel
    assert target.read_text(encoding="utf-8-sig").splitlines() == [
        "2025-06-01 08:30:15.250\tINFO\tlink\tconnected",
        "2025-06-01 08:30:16.250\tERROR\tcommand\ttwo lines",
    ]
    with pytest.raises(OSError):
        panel.export_to(tmp_path / "nope" / "events.txt")
    assert [p.name for p in tmp_path.iterdir()] == ["events.txt"]


def test_export_is_the_one_atomic_writers(tmp_path: Path, panel: EventLogPanel) -> None:
    """The GUI's exports save as every file of TeachPad does (app/points/atomic.py, issue 22): a
    killed export's leftover temp file is removed by the next one, and the file keeps its mode."""
    panel.add_event("info", "link", "connected", WHEN)
    target = tmp_path / "events.txt"
    target.write_text("previous")
    target.chmod(0o644)
    leftover = tmp_path / f"{atomic.TEMP_PREFIX}events.txt.0123456789ab{atomic.TEMP_SUFFIX}"
    leftover.write_bytes(b"half an export")
    os.utime(leftover, (1_000_000_000.0, 1_000_000_000.0))  # long before: a killed export's
    assert panel.export_to(target) == 1
    assert [p.name for p in tmp_path.iterdir()] == ["events.txt"]
    assert stat.S_IMODE(target.stat().st_mode) == 0o644


def test_model_passes_the_model_tester(qtmodeltester: Any) -> None:
    model = EventLogModel()
    for i, level in enumerate(("info", "warning", "error")):
        model.add(LogEvent(WHEN + dt.timedelta(seconds=i), level, "src", f"text {i}"))
    qtmodeltester.check(model)


def test_proxy_passes_the_model_tester(qtmodeltester: Any, panel: EventLogPanel) -> None:
    for level in ("info", "warning", "error"):
        panel.add_event(level, "s", level)
    panel.level_combo.setCurrentIndex(1)
    qtmodeltester.check(panel.proxy)


class _Prefix(QTranslator):
    def translate(self, context: str, source: str, disambiguation: str | None = None, n: int = -1) -> str:
        return f"中 {source}"

    def isEmpty(self) -> bool:
        return False


def test_language_change_retranslates_levels_and_payload_lines_not_written_texts(
    qtbot: Any, panel: EventLogPanel
) -> None:
    panel.add_event("warning", "s", "as logged", WHEN)
    panel.on_alarms(int(Alarm.SERVO))  # logged from a payload: rendered again after the switch
    translator = _Prefix()
    app = QCoreApplication.instance()
    assert app is not None
    app.installTranslator(translator)
    try:
        qtbot.waitUntil(lambda: cell(panel, 0, COL_LEVEL) == "中 Warning", timeout=2000)
        assert cell(panel, 0, COL_MESSAGE) == "as logged"
        assert cell(panel, 1, COL_MESSAGE) == "中 Alarm raised: 中 servo alarm"
        assert panel.level_combo.itemText(2) == "中 Errors only"
        panel.on_alarms(int(Alarm.ESTOP | Alarm.SERVO))
        assert cell(panel, 2, COL_MESSAGE) == "中 Alarm raised: 中 emergency stop"
    finally:
        app.removeTranslator(translator)
