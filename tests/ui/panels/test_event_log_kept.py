"""The event log is kept across restarts (issue 21): appended to a bounded pair of files in the
data folder, shown again at the next start (so the support bundle has the last days), a torn
line skipped; its export honours the level filter ("Errors only") and carries a BOM."""

from __future__ import annotations

import datetime as dt
from pathlib import Path
from typing import Any

from app.event_store import CURRENT, PREVIOUS, EventStore, StoredEvent, default_events_dir
from app.safety.audit import default_data_dir
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from ui.panels.event_log import EventLogPanel


def new_panel(qtbot: Any) -> EventLogPanel:
    panel = EventLogPanel()
    qtbot.addWidget(panel)
    return panel


def texts(panel: EventLogPanel) -> list[tuple[str, str]]:
    return [(e.level, e.text) for e in panel.model.events()]


def test_events_of_the_last_session_come_back(qtbot: Any, tmp_path: Path) -> None:
    first = new_panel(qtbot)
    first.add_event("info", "user", "before the store")  # logged before the first paint
    assert first.keep_across_restarts(tmp_path) == 0
    first.add_event("error", "link", "link lost")
    first.add_event("info", "link", "connected — 127.0.0.1:1502 中文")
    second = new_panel(qtbot)  # the next start
    second.add_event("info", "user", "this session")
    assert second.keep_across_restarts(tmp_path) == 3
    assert texts(second) == [
        ("info", "before the store"),
        ("error", "link lost"),
        ("info", "connected — 127.0.0.1:1502 中文"),
        ("info", "this session"),
    ]
    out = tmp_path / "bundle-events.txt"  # what the support bundle takes
    assert second.export_to(out) == 4
    assert "link lost" in out.read_text(encoding="utf-8-sig")


def test_old_and_torn_lines_are_left_out(tmp_path: Path) -> None:
    store = EventStore(tmp_path)
    now = dt.datetime.now()
    store.append(StoredEvent(now - dt.timedelta(days=30), "error", "link", "a month ago"))
    store.append(StoredEvent(now - dt.timedelta(hours=1), "warning", "points", "an hour ago"))
    with open(tmp_path / CURRENT, "a", encoding="utf-8") as handle:
        handle.write('{"when": "2026-')  # the process died mid-line
    assert [e.text for e in store.recent(now)] == ["an hour ago"]


def test_the_files_are_bounded(tmp_path: Path) -> None:
    store = EventStore(tmp_path, max_bytes=4096)
    now = dt.datetime.now()
    for n in range(500):
        assert store.append(StoredEvent(now, "info", "test", f"event {n} " + "x" * 40))
    sizes = [(tmp_path / name).stat().st_size for name in (CURRENT, PREVIOUS)]
    assert all(size <= 4096 for size in sizes) and sum(sizes) > 4096
    recent = store.recent(now + dt.timedelta(seconds=1))
    assert recent[-1].text.startswith("event 499 ") and len(recent) < 500


def test_the_default_folder_is_the_data_folder() -> None:
    assert default_events_dir().parent == default_data_dir()


def test_a_folder_that_cannot_be_written_says_so_once(qtbot: Any, tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    panel = new_panel(qtbot)
    panel.keep_across_restarts(blocker / "events")
    panel.add_event("info", "user", "one")
    panel.add_event("info", "user", "two")
    warnings = [t for level, t in texts(panel) if level == "warning"]
    assert len(warnings) == 1 and "not saved for the next start" in warnings[0]


def test_export_honours_errors_only(qtbot: Any, tmp_path: Path) -> None:
    panel = new_panel(qtbot)
    panel.add_event("info", "link", "connected")
    panel.add_event("warning", "points", "point 3 overwritten")
    panel.add_event("error", "link", "link lost")
    panel.level_combo.setCurrentIndex(2)  # Errors only
    target = tmp_path / "events.txt"
    assert panel.export_to(target, shown_only=True) == 1
    data = target.read_bytes()
    assert data.startswith(b"\xef\xbb\xbf")
    lines = data.decode("utf-8-sig").splitlines()
    assert len(lines) == 1 and lines[0].endswith("\tERROR\tlink\tlink lost")
    panel.level_combo.setCurrentIndex(1)  # warnings and errors
    assert panel.export_to(target, shown_only=True) == 2
    assert panel.export_to(target) == 3  # the support bundle's: every event


def test_the_warning_reads_in_chinese(qtbot: Any, tmp_path: Path, translator: Any) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert translator.set_language("zh_CN")
    panel = new_panel(qtbot)
    panel.keep_across_restarts(blocker / "events")
    panel.add_event("info", "user", "one")
    (warning,) = [e for e in panel.model.events() if e.level == "warning"]
    assert warning.source == "事件日志" and warning.text.startswith("事件日志无法保存到下次启动：")
