"""An operator's Stop of a running program is not a red failure (issue 21, "Words that say what
happened": "Failed: run program 2 stopped by the host", "失败：run program 1 stopped by the host"):
a program run at the simulator, stopped by the window's Stop on the link; the arm stands still at the
simulator; the result reads "stopped by the operator", at the info level, without "Failed", and in
Chinese without English inside; the status dock's *Last command* is not red."""

from __future__ import annotations

from typing import Any

import pytest

from app.link.ops import RunProgram, Stop
from app.link.robot_link import RobotLink
from app.models import CommandResult
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    translator_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.messages import LEVEL_INFO, result_level, result_text
from ui.palette import COLOR_ERROR
from ui.panels.status_panel import StatusPanel

pytestmark = pytest.mark.timeout(60)


def test_a_stopped_program_reads_stopped_by_the_operator_in_both_languages(
    qtbot: Any, sim: Any, link: RobotLink, translator: Any
) -> None:
    connect(qtbot, link, sim)
    seen: list[CommandResult] = []
    link.commandFinished.connect(seen.append)
    run = link.submit(RunProgram(1, speed_ratio=10))  # the 100 mm square, slowly
    qtbot.waitUntil(lambda: sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    link.submit(Stop())
    qtbot.waitUntil(lambda: any(r.request_id == run for r in seen), timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    result = next(r for r in seen if r.request_id == run)
    assert result.stopped_by_operator, result.message
    text = result_text(result)
    assert "stopped by the operator" in text and "Failed" not in text and "host" not in text, text
    assert result_level(result) == LEVEL_INFO
    panel = StatusPanel()
    qtbot.addWidget(panel)
    panel.on_command_result(result)
    assert "stopped by the operator" in panel.command_label.text()
    assert COLOR_ERROR not in panel.command_label.styleSheet()
    assert translator.set_language("zh_CN")
    zh = result_text(result)
    assert_chinese(zh)
    assert "失败" not in zh, zh
    panel.on_command_result(result)
    assert_chinese(panel.command_label.text())
    assert "失败" not in panel.command_label.text()
