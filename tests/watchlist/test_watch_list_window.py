"""View → Watch list in the main window, against the simulator: live values, the project, the
engineer's write (confirmed, audited, at the simulator), the operator's and monitor-only's
refusals (nothing written at the simulator), the CSV export."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.safety.audit_read import query
from app.safety.roles import Role
from app.watchlist.entry import Source, ValueType, WatchEntry
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    log_in,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.models.watch_list_model import COL_AGE, COL_VALUE

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

GV10 = WatchEntry.make(Source.GV, 10, name="tool length")
REG40 = WatchEntry.make(Source.REGISTER, 40, ValueType.INT16)


def _hold(sim: Any) -> None:
    with RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port)) as client:
        client.write_gv(10, [12.5])
        client.write_registers(40, [(-1234) & 0xFFFF])


def _open(qtbot: Any, window: Any) -> Any:
    host = window.watch_list
    action = window.menus.view_menu.findChild(object, "WatchListAction") or host.dock.toggleViewAction()
    assert action in window.menus.view_menu.actions()
    action.trigger()
    qtbot.waitUntil(lambda: host.panel is not None and host.panel.isVisible(), timeout=SIGNAL_TIMEOUT_MS)
    return host


def _add(host: Any, source: Source, number: int, name: str = "", kind: ValueType | None = None) -> None:
    panel = host.panel
    panel.source_box.setCurrentIndex(panel.source_box.findData(source))
    panel.number_box.setValue(number)
    if kind is not None:
        panel.type_box.setCurrentIndex(panel.type_box.findData(kind))
    panel.name_edit.setText(name)
    panel.add_button.click()


def _writes_after(sim: Any, count: int) -> list[Any]:
    return list(sim.writes)[count:]


def test_live_values_and_the_project(qtbot: Any, sim: Any, window: Any) -> None:
    _hold(sim)
    host = _open(qtbot, window)
    connect(qtbot, window.link, sim)
    _add(host, Source.GV, 10, "tool length")
    _add(host, Source.REGISTER, 40)
    assert window.project.project.watch_list == (GV10, REG40)
    assert window.project.is_dirty  # a change of the project, saved with it
    model = host.panel.model
    qtbot.waitUntil(lambda: model.index(1, COL_VALUE).data() == "-1234", timeout=SIGNAL_TIMEOUT_MS)
    assert model.index(0, COL_VALUE).data() == "12.5"
    qtbot.waitUntil(lambda: not model.index(0, COL_AGE).data().startswith("stale"), timeout=SIGNAL_TIMEOUT_MS)
    window.link.disconnect()  # not fresh: the values read stale
    qtbot.waitUntil(lambda: model.index(0, COL_AGE).data().startswith("stale"), timeout=SIGNAL_TIMEOUT_MS)


def test_closing_the_dock_stops_the_reads(qtbot: Any, sim: Any, window: Any) -> None:
    host = _open(qtbot, window)
    connect(qtbot, window.link, sim)
    _add(host, Source.GV, 10)
    qtbot.waitUntil(lambda: bool(host.history.last), timeout=SIGNAL_TIMEOUT_MS)
    host.dock.toggleViewAction().trigger()
    assert host.dock.isHidden()
    qtbot.waitUntil(lambda: host._sent == (), timeout=SIGNAL_TIMEOUT_MS)
    stamp = max(v.read_at for v in host.history.last.values())
    requests = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count > requests + 20, timeout=SIGNAL_TIMEOUT_MS)
    assert max(v.read_at for v in host.history.last.values()) == stamp


def test_a_project_brings_its_watch_list(qtbot: Any, window: Any, tmp_path: Path) -> None:
    doc = {
        "format": "teachpad-project",
        "version": 1,
        "name": "cell",
        "watch_list": [{"source": "reg", "number": 562, "type": "bits", "name": "alarms"}],
    }
    path = tmp_path / "cell.teachpad.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    assert window.project.open_file(str(path))
    host = _open(qtbot, window)
    assert host.panel.model.entries == (WatchEntry.make(Source.REGISTER, 562, ValueType.BITS, "alarms"),)


def test_the_operator_may_not_write(qtbot: Any, sim: Any, window: Any) -> None:
    host = _open(qtbot, window)
    connect(qtbot, window.link, sim)
    _add(host, Source.GV, 10)
    host.panel.select_row(0)
    assert not host.panel.write_button.isEnabled()
    assert "engineer" in host.panel.write_button.toolTip()
    before = len(sim.writes)
    host.ask_value = lambda *_args: pytest.fail("the operator is not asked for a value")
    assert not host.write_value(GV10)
    safety = window.safety_menu.safety
    safety.session.audit.close()
    refused = [r for r in query(safety.audit_dir) if r.kind == "refused"]
    assert refused and "write a watched value" in refused[-1].command
    assert _writes_after(sim, before) == []


def test_the_engineer_writes_confirmed_and_audited(qtbot: Any, sim: Any, window: Any) -> None:
    asked: list[str] = []

    def confirm(_title: str, text: str) -> bool:
        asked.append(text)
        return True

    window.confirm = confirm
    host = _open(qtbot, window)
    connect(qtbot, window.link, sim)
    log_in(window, Role.ENGINEER)
    _add(host, Source.GV, 10, "tool length")
    host.panel.select_row(0)
    assert host.panel.write_button.isEnabled()
    host.ask_value = lambda *_args: "7.5"
    before = len(sim.writes)
    with qtbot.waitSignal(window.link.commandFinished, timeout=SIGNAL_TIMEOUT_MS):
        assert host.write_value(GV10)
    assert "7.5" in asked[-1] and "GV10" in asked[-1]
    writes = _writes_after(sim, before)
    assert [(w.function_code, w.address, w.values) for w in writes] == [(0x10, 20, (0, 0x40F0))]
    qtbot.waitUntil(lambda: host.panel.model.index(0, COL_VALUE).data() == "7.5", timeout=SIGNAL_TIMEOUT_MS)
    safety = window.safety_menu.safety
    safety.session.audit.close()
    records = list(query(safety.audit_dir))
    action = [r for r in records if r.kind == "action" and r.command == "write watched value"]
    assert action and action[-1].args["value"] == "7.5" and action[-1].role == "engineer"
    assert any(r.kind == "write" and r.args["address"] == 20 for r in records)


def test_a_bad_value_is_said_and_nothing_is_written(qtbot: Any, sim: Any, window: Any) -> None:
    host = _open(qtbot, window)
    connect(qtbot, window.link, sim)
    log_in(window, Role.ENGINEER)
    _add(host, Source.GV, 10)
    before = len(sim.writes)
    for text, words in (("nan", "finite"), ("abc", "not a number")):
        host.ask_value = lambda *_args, t=text: t
        assert not host.write_value(GV10)
        assert words in host.panel.message.text()
    _add(host, Source.REGISTER, 40)
    host.ask_value = lambda *_args: "40000"
    assert not host.write_value(REG40)
    assert "out of range (-32768..32767)" in host.panel.message.text()
    assert _writes_after(sim, before) == []


def test_monitor_only_refuses_the_engineers_write(qtbot: Any, sim: Any, window: Any) -> None:
    host = _open(qtbot, window)
    connect(qtbot, window.link, sim, monitor_only=True)
    log_in(window, Role.ENGINEER)
    _add(host, Source.GV, 10)
    host.panel.select_row(0)
    assert not host.panel.write_button.isEnabled()
    host.ask_value = lambda *_args: "7.5"
    assert not host.write_value(GV10)
    assert "monitor-only" in host.panel.message.text()
    assert sim.writes == []


def test_csv_export(qtbot: Any, sim: Any, window: Any, tmp_path: Path) -> None:
    _hold(sim)
    host = _open(qtbot, window)
    connect(qtbot, window.link, sim)
    _add(host, Source.GV, 10, "工具 tool")
    _add(host, Source.REGISTER, 40)
    qtbot.waitUntil(lambda: host.history.count() >= 6, timeout=SIGNAL_TIMEOUT_MS)
    path = tmp_path / "watch.csv"
    assert host.export_csv(str(path))
    text = path.read_text(encoding="utf-8-sig")
    rows = list(csv.DictReader(text.splitlines()))
    assert {r["key"] for r in rows} == {"GV10", "reg40"}
    assert {r["value"] for r in rows if r["key"] == "GV10"} == {"12.5"}
    assert {r["value"] for r in rows if r["key"] == "reg40"} == {"-1234"}
    assert rows[0]["name"] == "工具 tool" and rows[0]["time"].endswith("Z")
    assert not list(tmp_path.glob("*.tmp"))  # the atomic writer left nothing behind


def test_the_table_model_is_sound(qtmodeltester: Any, qtbot: Any, window: Any) -> None:
    host = _open(qtbot, window)
    host.set_entries((GV10, REG40))
    qtmodeltester.check(host.panel.model)


def test_the_same_value_twice_is_said_and_remove_takes_one_out(qtbot: Any, window: Any) -> None:
    host = _open(qtbot, window)
    _add(host, Source.GV, 10, "tool length")
    _add(host, Source.GV, 10, "again")
    assert "GV10 is in the list already" in host.panel.message.text()
    assert window.project.project.watch_list == (GV10,)
    host.panel.select_row(0)
    host.panel.remove_button.click()
    assert window.project.project.watch_list == () and host.panel.model.entries == ()
