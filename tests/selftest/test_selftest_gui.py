"""The register-map self-test in the window (issue 24): it runs by itself after every connect,
through the link's worker, writing nothing at the simulator; quiet when the map matches, a warning
line in the event log and the status bar when it does not; the dialog (Help menu) shows the lines
in both languages (screenshots at 1280×800: into $TEACHPAD_SCREENSHOTS when set -- the README's in
docs/screenshots were made so -- else into the test's own folder)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QPoint
from PySide6.QtGui import QPainter, QPixmap

from app.protocol.codec import WordOrder
from app.selftest.checks import CheckVerdict, SelfTestReport
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese

# the offscreen platform cannot raise a window (the dialog is raised when asked for again)
pytestmark = [
    pytest.mark.timeout(120),
    pytest.mark.qt_log_ignore(*QT_LOG_IGNORE, "This plugin does not support raise"),
]

CANARY_REGISTERS = {198}  # the restart canary GV99, written by every connect (not by the self-test)


def register_map_warnings(window: Any) -> list[Any]:
    return [e for e in window.event_log.model.events() if e.level == "warning" and "register map" in e.text]


def test_after_a_connect_the_other_word_order_is_reported_and_fixed_by_the_profile(
    qtbot: Any, sim_factory: Any, window: Any
) -> None:
    sim = sim_factory(word_order="high-first")
    check = window.register_map_check
    with qtbot.waitSignal(check.reported, timeout=SIGNAL_TIMEOUT_MS) as got:
        connect(qtbot, window.link, sim, poll_timeout=1.0, word_order=WordOrder.LOW_FIRST)
    report: SelfTestReport = got.args[0]
    assert not report.passed
    assert report.settings_to_change == {"word_order": "high-first"}
    assert {line.check for line in report.mismatches} == {"pose", "model"}
    # nothing but the connect's restart canary was written: the self-test only reads
    assert {w.address for w in sim.writes} <= CANARY_REGISTERS
    warnings = register_map_warnings(window)
    assert len(warnings) == 1
    assert "word order" in warnings[0].text and "high word first" in warnings[0].text

    # run on demand: not one write during it
    before = len(sim.writes)
    with qtbot.waitSignal(check.reported, timeout=SIGNAL_TIMEOUT_MS) as again:
        assert check.run()
    assert not again.args[0].passed
    assert len(sim.writes) == before

    # the profile set to the controller's word order: the next connect's self-test passes, quietly
    with qtbot.waitSignal(check.reported, timeout=SIGNAL_TIMEOUT_MS) as fixed:
        connect(qtbot, window.link, sim, poll_timeout=1.0, word_order=WordOrder.HIGH_FIRST)
    assert fixed.args[0].passed, [line.line for line in fixed.args[0].lines]
    assert {line.verdict for line in fixed.args[0].lines} == {CheckVerdict.MATCH}
    assert len(register_map_warnings(window)) == 1  # nothing new said


def test_a_matching_map_is_quiet(qtbot: Any, sim_factory: Any, window: Any) -> None:
    sim = sim_factory()
    with qtbot.waitSignal(window.register_map_check.reported, timeout=SIGNAL_TIMEOUT_MS) as got:
        connect(qtbot, window.link, sim, poll_timeout=1.0)
    assert got.args[0].passed
    assert register_map_warnings(window) == []


def _shot(window: Any, dialog: Any, path: Path) -> None:
    """The window at 1280×800 with the dialog over its middle, as the operator sees it."""
    canvas = QPixmap(window.grab())
    over = dialog.grab()
    painter = QPainter(canvas)
    painter.drawPixmap(
        QPoint((canvas.width() - over.width()) // 2, (canvas.height() - over.height()) // 2), over
    )
    painter.end()
    canvas.save(str(path))


def test_the_dialog_shows_each_line_in_both_languages(
    qtbot: Any, sim_factory: Any, window: Any, tmp_path: Path
) -> None:
    shots = Path(os.environ.get("TEACHPAD_SCREENSHOTS") or tmp_path)
    sim = sim_factory(word_order="high-first", clock_offset=-365 * 86400.0)
    window.resize(1280, 800)
    window.show()
    qtbot.waitExposed(window)
    with qtbot.waitSignal(window.register_map_check.reported, timeout=SIGNAL_TIMEOUT_MS):
        connect(qtbot, window.link, sim, poll_timeout=1.0, word_order=WordOrder.LOW_FIRST)
    action = window.register_map_ui.action
    assert action in window.menus.help_menu.actions()
    action.trigger()
    dialog = window.register_map_ui.dialog
    qtbot.waitExposed(dialog)
    table = dialog.table
    report = window.register_map_check.report
    assert table.rowCount() == len(report.lines)
    rows = {
        table.item(r, 0).text(): [table.item(r, c).text() for c in range(4)] for r in range(table.rowCount())
    }
    clock = rows["Date and time (576–579)"]
    assert clock[1] == "does not match" and "365 days behind" in clock[2] and "clock" in clock[3]
    pose = rows["Pose X Y Z A B C (word order)"]
    assert pose[1] == "does not match" and "high word first (ABCD)" in pose[3]
    assert "does not match" in dialog.summary_label.text()
    shots.mkdir(parents=True, exist_ok=True)
    _shot(window, dialog, shots / "selftest_en_1280x800.png")
    window.set_language("zh_CN")
    rows_zh = [[table.item(r, c).text() for c in range(4)] for r in range(table.rowCount())]
    model = window.view3d.robot.profile.name  # a name, as the profile file gives it
    for row in rows_zh:
        for text in row:
            if text:
                assert_chinese(text.replace("ABCD", "").replace("CDAB", "").replace(model, ""))
    assert_chinese(dialog.summary_label.text())
    assert_chinese(window.register_map_ui.action.text().replace("(&R)", ""))  # the accelerator key
    _shot(window, dialog, shots / "selftest_zh_1280x800.png")
    assert (shots / "selftest_zh_1280x800.png").stat().st_size > 10_000
    dialog.close()
