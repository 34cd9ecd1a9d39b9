"""Requests whose outcome the controller does not report (pause, resume, work mode) read as
*sent*, named ("pause: sent."), never a nameless "The command: done."; a command refused because
another is under way keeps the core's own sentence ("run program is still under way: wait for it
or press Stop."), not "Invalid value: nothing was sent.". Through RobotLink against the
simulator, in both languages (issue 21, "Words that say what happened")."""

from __future__ import annotations

from typing import Any

import pytest

from app.link.ops import Pause, Resume, RunProgram, Stop
from app.link.robot_link import RobotLink
from app.link.types import WorkerError
from app.protocol import registers
from app.protocol.enums import ProgramState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    translator_fixture,
)
from tests.ui.test_messages import assert_chinese
from tests.ui.test_outcome_words import Results
from ui.messages import error_text, result_level, result_text

pytestmark = pytest.mark.timeout(60)


def test_pause_and_resume_read_sent_and_named_in_both_languages(
    qtbot: Any, sim: Any, link: RobotLink, translator: Any
) -> None:
    connect(qtbot, link, sim)
    results = Results(link)
    since = len(sim.writes)
    pause = results.of(qtbot, link.submit(Pause()))
    resume = results.of(qtbot, link.submit(Resume()))
    addresses = [write.address for write in sim.writes[since:]]
    assert registers.REG_PAUSE in addresses and registers.REG_RESUME in addresses
    assert (result_text(pause), result_text(resume)) == ("pause: sent.", "resume: sent.")
    assert result_level(pause) == "info"
    assert translator.set_language("zh_CN")
    for result in (pause, resume):
        assert_chinese(result_text(result))
        assert "命令" not in result_text(result)  # not the nameless "the command"


def test_a_program_while_one_runs_keeps_the_cores_sentence_in_both_languages(
    qtbot: Any, sim: Any, link: RobotLink, translator: Any
) -> None:
    connect(qtbot, link, sim)
    errors: list[WorkerError] = []
    link.errorOccurred.connect(errors.append)
    link.submit(RunProgram(1))
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    since = len(sim.writes)
    second = link.submit(RunProgram(2))
    qtbot.waitUntil(lambda: any(e.request_id == second for e in errors), timeout=SIGNAL_TIMEOUT_MS)
    error = next(e for e in errors if e.request_id == second)
    assert error_text(error) == "run program is still under way: wait for it or press Stop."
    assert registers.REG_RUN_COMMAND not in [write.address for write in sim.writes[since:]]
    assert translator.set_language("zh_CN")
    assert_chinese(error_text(error))
    link.submit(Stop())
