"""How an ended plan run reads (ui/controllers/plan_run_reasons.py): the controller's reason or
the runner's message, the segment counted from 1, in both languages; a silent controller is not
a lost link."""

from __future__ import annotations

from typing import Any

import pytest

from app.errors import LinkError, ResponseTimeout
from app.link.types import ConnectionState, LinkState
from app.plan.runner import RunOutcome, RunState
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from ui.controllers.plan_run_reasons import connection_error, outcome_text, stopped_by_operator
from ui.messages import error_text


def _outcome(state: RunState, resume_from: int | None, message: str = "the runner's words") -> RunOutcome:
    return RunOutcome(state, message, resume_from, 1 if resume_from is not None else None, 0)


@pytest.mark.parametrize(
    ("state", "resume_from", "reason", "expected"),
    [
        (RunState.FAILED, 2, "the point is gone", "Failed at segment 3: the point is gone"),
        (RunState.STOPPED, 0, "", "Stopped at segment 1: the runner's words"),
        (RunState.FAILED, None, "", "Failed: the runner's words"),
        (RunState.STOPPED, None, "enough", "Stopped: enough"),
    ],
)
def test_the_reason_wins_over_the_runners_message(
    qapp: Any, state: RunState, resume_from: int | None, reason: str, expected: str
) -> None:
    assert outcome_text(_outcome(state, resume_from), reason) == expected


def test_the_run_ends_in_chinese(translator: Any) -> None:
    assert translator.set_language("zh_CN")
    assert stopped_by_operator() == "已由操作员停止"
    stopped = outcome_text(_outcome(RunState.STOPPED, 1), stopped_by_operator())
    assert stopped == "在第 2 段停止：已由操作员停止"
    assert outcome_text(_outcome(RunState.FAILED, None), "x") == "失败：x"


def test_a_silent_controller_is_not_a_lost_link(qapp: Any) -> None:
    silent = connection_error(ConnectionState(LinkState.NOT_ANSWERING, "no answer", "fake:502"))
    assert isinstance(silent, ResponseTimeout) and silent.code == "run_not_answering"
    assert "not answering" in error_text(silent) and "fake:502" in error_text(silent)
    lost = connection_error(ConnectionState(LinkState.DOWN, "", "fake:502"))
    assert isinstance(lost, LinkError) and not isinstance(lost, ResponseTimeout)
    assert error_text(lost) == "Lost the connection to the controller at fake:502."
    assert "link lost" in str(connection_error(ConnectionState(LinkState.DOWN)))
