"""A register profile whose float word order does not match the controller's is told to the
operator once, in words, with what to set (issue 21): the simulator writing high word first read
low word first -> the banner in the motion column, the event log and the status bar, in both
languages; the simulator read in its own word order -> never, at its start pose, during a go to
zero, at the zero pose and during a jog (every pose the link published is judged)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.ops import GoZero
from app.models import Pose
from app.protocol.codec import WordOrder
from app.protocol.word_order_check import judge_pose
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese

pytestmark = [pytest.mark.timeout(90), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def test_the_other_word_order_is_told_once_with_what_to_set(
    qtbot: Any, sim_factory: Any, window: Any
) -> None:
    sim = sim_factory(word_order="high-first")
    banner = window.control_column.word_order_banner
    with qtbot.waitSignal(window.word_order_watch.warned, timeout=SIGNAL_TIMEOUT_MS) as said:
        connect(qtbot, window.link, sim, poll_timeout=1.0, word_order=WordOrder.LOW_FIRST)
    assert said.args[0] is not None and said.args[0].suggested is WordOrder.HIGH_FIRST
    assert banner.isVisible()
    text = banner.text()
    assert "word-swapped" in text and "high word first (ABCD)" in text, text
    assert "X = " in banner.toolTip()  # the pose read both ways
    warnings = [e for e in window.event_log.model.events() if "word-swapped" in e.text]
    assert len(warnings) == 1 and warnings[0].level == "warning"
    window.set_language("zh_CN")
    for text in (banner.text(), banner.toolTip(), warnings[0].rendered().text):  # the log's line too
        assert "高字在前" in text
        assert_chinese(_names_out(text))
    # said once: more poses (the arm moved by the simulator) do not say it again
    emitted: list[Any] = []
    window.word_order_watch.warned.connect(emitted.append)
    sim.set_joint(1, 10.0)
    first = said_pose(said)
    qtbot.waitUntil(lambda: window.link.state.pose != first, timeout=SIGNAL_TIMEOUT_MS)
    assert emitted == []
    # connecting again in the controller's own word order takes the warning away
    with qtbot.waitSignal(window.word_order_watch.warned, timeout=SIGNAL_TIMEOUT_MS) as cleared:
        connect(qtbot, window.link, sim, poll_timeout=1.0, word_order=WordOrder.HIGH_FIRST)
    assert cleared.args[0] is None and not banner.isVisible()


def _names_out(text: str) -> str:
    """The word orders' own names (ABCD, CDAB) stay as they are in Chinese too."""
    return text.replace("ABCD", "").replace("CDAB", "")


def said_pose(said: Any) -> Pose:
    x, y, z, a, b, c, *ext = said.args[0].read
    return Pose(x, y, z, a, b, c, ext=(ext[0], ext[1], ext[2], ext[3], ext[4]), joints=None)


def test_the_right_word_order_is_never_doubted(qtbot: Any, sim_factory: Any, window: Any) -> None:
    sim = sim_factory(watchdog=2.0)
    poses: list[Pose] = []
    window.link.state.poseChanged.connect(poses.append)
    warned: list[Any] = []
    window.word_order_watch.warned.connect(warned.append)
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.link.state.pose is not None, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(window.link.state.lastResultChanged, timeout=30_000) as ended:
        window.link.submit(GoZero(None))  # every axis to zero, and the poses on the way
    assert ended.args[0].ok, ended.args[0]
    assert all(abs(j) < 1e-3 for j in sim.state().joints[:6])  # at the zero pose
    panel = window.jog_panel
    qtbot.waitUntil(lambda: panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    seen = len(poses)
    button = panel.button(0, 0)  # X- from the zero pose
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(lambda: len(poses) > seen + 5, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert len(poses) > 20
    assert warned == [] and window.word_order_watch.verdict is None
    assert not window.control_column.word_order_banner.isVisible()
    assert not any(judge_pose(p, WordOrder.LOW_FIRST).swapped for p in poses)
