"""A request the controller refuses never reads "done" or "sent" (issue 21, "Words that say what
happened": "The command: done." … is never shown for a refusal). Pause, resume and work mode
against the simulator answering their register with a Modbus exception (illegal data address: not
carried out): the result names the command and says it was refused, at the error level, in both
languages; the register was not stored at the simulator."""

from __future__ import annotations

from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app.link.ops import LinkOp, Pause, Resume, SetMode
from app.link.robot_link import RobotLink
from app.link.types import WorkerError
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import WorkMode
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    translator_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.messages import LEVEL_ERROR, error_text, result_level, result_text

pytestmark = pytest.mark.timeout(60)

CASES = [
    (Pause(), registers.REG_PAUSE, "pause"),
    (Resume(), registers.REG_RESUME, "resume"),
    (SetMode(WorkMode.AUTO), registers.REG_WORK_MODE, "work mode"),
]


@pytest.mark.parametrize(("op", "address", "name"), CASES, ids=[c[2] for c in CASES])
def test_a_refused_request_never_reads_done_or_sent_in_both_languages(
    qtbot: Any, sim: Any, link: RobotLink, translator: Any, op: LinkOp, address: int, name: str
) -> None:
    connect(qtbot, link, sim)
    ended: dict[int, CommandResult | WorkerError] = {}
    link.commandFinished.connect(lambda r: ended.setdefault(r.request_id, r))
    link.errorOccurred.connect(lambda e: ended.setdefault(e.request_id, e))
    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, range(address, address + 1))
    since = len(sim.writes)
    request = link.submit(op)
    qtbot.waitUntil(lambda: request in ended, timeout=SIGNAL_TIMEOUT_MS)
    sim.set_exception(None)
    outcome = ended[request]
    assert address not in [w.address for w in sim.writes[since:]]
    if isinstance(outcome, CommandResult):
        assert not outcome.ok, outcome
        text = result_text(outcome)
        assert result_level(outcome) == LEVEL_ERROR
    else:
        text = error_text(outcome)
    assert "done" not in text and "sent" not in text, text
    assert "The command" not in text, text
    assert translator.set_language("zh_CN")
    zh = result_text(outcome) if isinstance(outcome, CommandResult) else error_text(outcome)
    assert_chinese(zh)
    assert "完成" not in zh and "已发送" not in zh, zh
