"""Issue 23, "The cell view (GUI)": File → Open cell… in the real window, against several real
simulators (one of them silenced): the tiles, a silent one greyed while the others keep answering,
Take control (asserted at the simulators: their connections), the history and its CSV, both
languages, and 16 tiles at 1280×800 with no text cut and no tile over another."""

from __future__ import annotations

import itertools
import time
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication

from app.cell.cell_file import Cell, CellController, save_cell
from app.gateway.poller import GatewayTiming
from app.link.types import LinkState
from app.protocol.enums import Alarm
from app.safety.roles import Role
from tests.ui.layout_audit import clipped_texts, overlapping_siblings
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
    log_in,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.panels.cell_panel import CellPanel, CellTile

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

# roomy: the simulators run in the test process on a loaded machine
POLL_TIMEOUT = 0.5  # s
TIMING = GatewayTiming(poll_hz=5.0, poll_timeout=POLL_TIMEOUT, backoff=(0.2, 0.5))
STALE_AFTER = 1.5  # s
WAIT_MS = 10_000


def _cell(sims: list[Any], tmp_path: Path) -> Path:
    controllers = tuple(
        CellController(name=f"R{i + 1}", host="127.0.0.1", port=sim.port) for i, sim in enumerate(sims)
    )
    path = tmp_path / "cell.json"
    save_cell(path, Cell("cell 3", controllers))
    return path


def _open(window: Any, project_dialogs: Any, path: Path) -> CellPanel:
    project_dialogs.open_answer = str(path)
    host = window.cell
    original = host.show_cell
    host.show_cell = lambda cell: original(cell, timing=TIMING, stale_after=STALE_AFTER)
    window.cell.open_action.trigger()
    assert project_dialogs.asked[-1] == "open"
    panel: CellPanel | None = host.panel
    assert panel is not None
    return panel


def _laid_out() -> None:
    """Deliver the posted layout requests (texts just changed), no waiting on anything else."""
    for _ in range(3):
        QCoreApplication.sendPostedEvents()
        QCoreApplication.processEvents()


def _answering(tile: CellTile) -> bool:
    return tile.reading is not None and not tile.silent


@pytest.fixture(name="sims")
def sims_fixture(sim_factory: Any) -> list[Any]:
    return [sim_factory() for _ in range(3)]


@pytest.fixture(name="panel")
def panel_fixture(qtbot: Any, window: Any, project_dialogs: Any, sims: list[Any], tmp_path: Path) -> Any:
    window.resize(1920, 1080)  # room for full tiles
    qtbot.waitUntil(lambda: window.size().toTuple() == (1920, 1080), timeout=WAIT_MS)
    panel = _open(window, project_dialogs, _cell(sims, tmp_path))
    yield panel
    window.cell.close_cell()


def test_open_cell_shows_a_tile_per_controller_each_with_its_own_poller(
    qtbot: Any, window: Any, panel: Any
) -> None:
    assert window.work_tabs.tabText(window.work_tabs.currentIndex()) == "Cell"
    assert list(panel.tiles) == ["R1", "R2", "R3"]
    qtbot.waitUntil(lambda: all(_answering(t) for t in panel.tiles.values()), timeout=WAIT_MS)
    tile = panel.tiles["R1"]
    assert not panel.compact and tile.control_button.isVisible()  # room enough: full tiles
    assert tile.name_label.text() == f"R1  {tile.where}"
    assert tile.link_label.text() == "answering"
    assert tile.state_label.text().startswith("mode ")
    assert tile.alarm_label.text() == "no alarm"
    assert tile.pose_label.text().startswith("X ")
    assert "RTT" in tile.fresh_label.text()
    assert len({poller._client for poller in panel.pollers}) == 3  # one monitor-only client each
    assert all(poller._client.settings.monitor_only for poller in panel.pollers)


def test_a_silent_controller_greys_while_the_others_keep_updating(
    qtbot: Any, window: Any, panel: Any, sims: list[Any], translator: Any
) -> None:
    tiles = panel.tiles
    qtbot.waitUntil(lambda: all(_answering(t) for t in tiles.values()), timeout=WAIT_MS)
    answers: dict[str, list[float]] = {"R1": [], "R3": []}
    panel.feed.answered.connect(lambda name, reading: answers.get(name, []).append(reading.answered_at))
    sims[1].set_silent(True)
    silenced = time.monotonic()
    qtbot.waitUntil(lambda: tiles["R2"].silent, timeout=WAIT_MS)
    greyed_after = time.monotonic() - silenced
    # within its poll timeout (and a poll period, and the queued signal), not the others' business
    assert greyed_after < POLL_TIMEOUT + 1 / TIMING.poll_hz + 1.5
    assert tiles["R2"].property("silent") and not tiles["R2"].state_label.isEnabled()
    qtbot.waitUntil(lambda: tiles["R2"].link_label.text() == "not answering 2 s", timeout=WAIT_MS)
    # the others keep answering: fresh answers, well after the silence began
    since = time.monotonic()
    qtbot.waitUntil(
        lambda: all(tiles[n].reading.answered_at > since + 0.5 for n in ("R1", "R3")), timeout=WAIT_MS
    )
    for name in ("R1", "R3"):
        assert not tiles[name].silent
        assert tiles[name].age() < 1.0
        assert tiles[name].errors_last_minute() == 0
    assert tiles["R2"].errors_last_minute() >= 1
    # a dead one costs the others nothing: their answers keep the poll period while R2 times out
    period = 1 / TIMING.poll_hz
    for name, times in answers.items():
        gaps = [b - a for a, b in itertools.pairwise(times)]
        assert len(gaps) >= 5, name
        assert max(gaps) < 2.5 * period, f"{name}: a gap of {max(gaps):.3f} s (period {period} s)"
    # both languages
    assert translator.set_language("zh_CN")
    window.set_language("zh_CN")
    qtbot.waitUntil(lambda: tiles["R2"].link_label.text().startswith("无应答"), timeout=WAIT_MS)
    assert tiles["R1"].link_label.text() == "正在应答"
    assert tiles["R1"].control_button.text() == "接管控制…"
    assert window.work_tabs.tabText(window.work_tabs.indexOf(panel)) == "单元"
    sims[1].set_silent(False)
    qtbot.waitUntil(lambda: not tiles["R2"].silent, timeout=WAIT_MS)


def test_alarms_most_severe_first_then_oldest_and_history_csv(
    qtbot: Any, window: Any, panel: Any, sims: list[Any], project_dialogs: Any, tmp_path: Path
) -> None:
    tile = panel.tiles["R3"]
    qtbot.waitUntil(lambda: _answering(tile), timeout=WAIT_MS)
    sims[2].set_alarm(Alarm.ENCODER, True)
    qtbot.waitUntil(lambda: tile.alarm_label.text() == "alarms: encoder angle alarm", timeout=WAIT_MS)
    sims[2].set_alarm(Alarm.SERVO, True)
    qtbot.waitUntil(lambda: "servo" in tile.alarm_label.text(), timeout=WAIT_MS)
    assert tile.alarm_label.text().index("servo") < tile.alarm_label.text().index("encoder")
    sims[2].set_alarm(Alarm.SERVO, False)
    sims[2].set_alarm(Alarm.ENCODER, False)
    qtbot.waitUntil(lambda: tile.alarm_label.text() == "no alarm", timeout=WAIT_MS)
    # the detail view
    tile.history_button.click()
    assert panel.pages.currentIndex() == 1
    kinds = [panel.table.item(row, 1).text() for row in range(panel.table.rowCount())]
    assert kinds.count("alarm raised") == 2 and kinds.count("alarm cleared") == 2
    # the CSV: UTF-8 with a BOM, one row per event
    out = tmp_path / "R3-history.csv"
    project_dialogs.save_answer = str(out)
    panel.export_button.click()
    data = out.read_bytes()
    assert data.startswith(b"\xef\xbb\xbf")
    lines = data.decode("utf-8-sig").splitlines()
    assert lines[0] == "time,controller,kind,detail"
    rows = [line.split(",") for line in lines[1:]]
    assert all(row[1] == "R3" for row in rows)
    events = [(row[2], row[3]) for row in rows]
    assert ("link", "answering") in events
    raised = [e for e in events if e[0] == "alarm raised"]
    assert raised == [("alarm raised", "encoder angle alarm"), ("alarm raised", "servo alarm")]
    assert [e for e in events if e[0] == "alarm cleared"] == [
        ("alarm cleared", "servo alarm"),
        ("alarm cleared", "encoder angle alarm"),
    ]
    assert not list(tmp_path.glob("*.tmp*"))


def test_take_control_connects_the_window_to_that_robot_after_a_confirmation(
    qtbot: Any, window: Any, panel: Any, sims: list[Any]
) -> None:
    log_in(window, Role.ADMINISTRATOR)
    qtbot.waitUntil(lambda: all(_answering(t) for t in panel.tiles.values()), timeout=WAIT_MS)
    before = [sim.connections_count for sim in sims]
    assert before == [1, 1, 1]  # the pollers only
    asked: list[tuple[str, str]] = []

    def answer(yes: bool) -> Any:
        def confirm(title: str, text: str) -> bool:
            asked.append((title, text))
            return yes

        return confirm

    window.confirm = answer(False)
    panel.tiles["R2"].control_button.click()
    assert len(asked) == 1 and "R2" in asked[0][1] and f"127.0.0.1:{sims[1].port}" in asked[0][1]
    assert window.link.state.connection.state is LinkState.DISCONNECTED
    window.confirm = answer(True)
    with qtbot.waitSignal(
        window.link.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=WAIT_MS
    ):
        panel.tiles["R2"].control_button.click()
    # its poller and the window's link (which has its own stop connection too)
    qtbot.waitUntil(lambda: sims[1].connections_count > 1, timeout=WAIT_MS)
    assert [sims[0].connections_count, sims[2].connections_count] == [1, 1]
    connection = window.link.state.connection
    assert not connection.monitor_only and connection.endpoint.endswith(f":{sims[1].port}")
    assert connection.controller is not None  # through controller identity
    assert panel.tiles["R2"].controlled and not panel.tiles["R2"].control_button.isEnabled()
    assert "R2" in panel.tiles["R2"].name_label.text() and "in control" in panel.tiles["R2"].name_label.text()
    audit_dir = window.safety_menu.safety.session.audit.directory
    trail = "".join(p.read_text(encoding="utf-8") for p in Path(audit_dir).rglob("*") if p.is_file())
    assert "take control" in trail and "R2" in trail
    # the other: one commandable robot at a time, the link moves to R3
    with qtbot.waitSignal(
        window.link.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=WAIT_MS
    ):
        panel.tiles["R3"].control_button.click()
    qtbot.waitUntil(lambda: sims[1].connections_count == 1 and sims[2].connections_count > 1, timeout=WAIT_MS)
    assert sims[0].connections_count == 1
    assert not panel.tiles["R2"].controlled and panel.tiles["R3"].controlled
    with qtbot.waitSignal(
        window.link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED), timeout=WAIT_MS
    ):
        window.link.disconnect()
    assert not any(tile.controlled for tile in panel.tiles.values())


def test_closing_the_window_ends_every_poller(qtbot: Any, window: Any, panel: Any) -> None:
    qtbot.waitUntil(lambda: all(_answering(t) for t in panel.tiles.values()), timeout=WAIT_MS)
    threads = [poller._thread for poller in panel.pollers]
    assert all(thread.is_alive() for thread in threads)
    window.close()
    assert not any(thread.is_alive() for thread in threads)
    assert window.cell.panel is None and not panel.timer.isActive()


def test_a_bad_cell_file_is_one_line_in_a_dialog(
    qtbot: Any, window: Any, project_dialogs: Any, tmp_path: Path
) -> None:
    path = tmp_path / "bad.json"
    path.write_text(
        '{"format": "teachpad-cell", "version": 1, "name": "c", "controllers": '
        '[{"name": "R2", "host": "h", "port": 70000}]}',
        encoding="utf-8",
    )
    project_dialogs.open_answer = str(path)
    window.cell.open_action.trigger()
    assert window.cell.panel is None
    ((_title, text),) = project_dialogs.errors
    assert "R2" in text and "port" in text and "\n" not in text


def _all_in_sight(qtbot: Any, panel: CellPanel) -> None:
    bars = (panel.area.verticalScrollBar(), panel.area.horizontalScrollBar())
    qtbot.waitUntil(lambda: all(bar.maximum() == 0 for bar in bars), timeout=WAIT_MS)  # layout passes
    grid_host = panel.area.widget()
    assert grid_host is not None and overlapping_siblings(grid_host) == []
    view = panel.area.viewport()
    for tile in panel.tiles.values():
        corner = tile.mapTo(view, tile.rect().bottomRight())
        assert view.rect().contains(corner), f"{tile.name} is out of sight"


def _says_everything(panel: CellPanel, language: str) -> None:
    """Name, link state, mode and program, alarms (most severe first), pose, freshness; the silent
    one greyed and saying so."""
    zh = language != "en"
    r1 = panel.tiles["R1"]
    assert r1.name_label.text() == "R1" and r1.name_label.toolTip() == r1.where
    assert r1.link_label.text() == ("正在应答" if zh else "answering")
    assert r1.state_label.text().startswith("自动" if zh else "auto, ")
    assert r1.alarm_label.text() == ("伺服报警" if zh else "servo alarm")
    assert r1.pose_label.text().startswith("X ") and "\nA " in r1.pose_label.text()
    assert ("往返" if zh else "RTT") in r1.fresh_label.text()
    assert ("/分" if zh else "err/min") in r1.fresh_label.text()
    r6 = panel.tiles["R6"]
    assert r6.silent and r6.property("silent") and not r6.state_label.isEnabled()
    assert r6.link_label.text().startswith("无应答" if zh else "not answering")
    # the actions are in the tile's menu
    assert r1.menu_button.isVisible() and not r1.control_button.isVisible()
    assert [a.text() for a in r1.menu_button.menu().actions()] == [
        r1.control_button.text(),
        r1.history_button.text(),
    ]


@pytest.mark.qt_log_ignore(
    *QT_LOG_IGNORE, "This plugin does not support setParent"
)  # offscreen's, going back
@pytest.mark.parametrize("language", ["en", "zh_CN"])
def test_sixteen_tiles_fit_1280x800(
    qtbot: Any,
    window: Any,
    project_dialogs: Any,
    sim_factory: Any,
    translator: Any,
    tmp_path: Path,
    language: str,
) -> None:
    sims = [sim_factory() for _ in range(16)]
    for sim in sims[::3]:
        sim.set_alarm(Alarm.SERVO, True)
    sims[5].set_silent(True)
    if language != "en":
        assert translator.set_language(language)
        window.set_language(language)
    window.resize(1280, 800)
    qtbot.waitUntil(lambda: window.size().toTuple() == (1280, 800), timeout=WAIT_MS)
    panel = _open(window, project_dialogs, _cell(sims, tmp_path))
    try:
        qtbot.waitUntil(lambda: sum(_answering(t) for t in panel.tiles.values()) == 15, timeout=WAIT_MS * 2)
        qtbot.waitUntil(lambda: panel.tiles["R6"].silent, timeout=WAIT_MS)
        # in the tab beside the pendant's controls (the normal layout): compact tiles, all 16 in sight
        # without scrolling, every field said, nothing cut, no overlap
        panel.refresh()
        _laid_out()
        assert panel.compact and panel.columns == 4
        _all_in_sight(qtbot, panel)
        assert clipped_texts(panel) == []
        assert overlapping_siblings(panel) == []
        _says_everything(panel, language)
        # in a window of its own at 1280×800: all 16 at a glance
        panel.window_button.click()
        assert panel.isWindow() and panel.size().toTuple() == (1280, 800)
        qtbot.waitExposed(panel)
        panel.refresh()
        _laid_out()
        _all_in_sight(qtbot, panel)
        assert clipped_texts(panel) == []
        assert overlapping_siblings(panel) == []
        assert (
            panel.tiles["R6"].link_label.text().startswith("not answering" if language == "en" else "无应答")
        )
        panel.close()  # back in its tab
        assert not panel.isWindow() and window.work_tabs.indexOf(panel) >= 0
    finally:
        window.cell.close_cell()
