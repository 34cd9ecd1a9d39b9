"""A jog cut short by a silent controller is said in the operator's language (issue 9): the
real worker and simulator; the note carries its code, the English stays beside it."""

from __future__ import annotations

from typing import Any

import pytest

from app.link.ops import JogPress
from app.link.types import JogRequest, LinkState, WorkerError
from app.protocol.enums import TeachFrame
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    ratio_writes,
    translator_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.messages import error_text

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def test_a_jog_stopped_by_a_silent_controller_reads_in_chinese(
    qtbot: Any, sim: Any, link: Any, translator: Any
) -> None:
    assert translator.set_language("zh_CN")
    connect(qtbot, link, sim)
    link.submit(JogPress(JogRequest(TeachFrame.BASE, 0, 1, 40.0)))
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    errors: list[WorkerError] = []
    link.errorOccurred.connect(errors.append)
    sim.set_silent(True)
    try:
        qtbot.waitUntil(
            lambda: any(e.reason is not None and e.reason.code == "jog_stopped_silent" for e in errors),
            timeout=SIGNAL_TIMEOUT_MS,
        )
    finally:
        sim.set_silent(False)
    note = next(e for e in errors if e.reason is not None and e.reason.code == "jog_stopped_silent")
    assert "not answering" in note.message  # English for logs and the CLI
    assert_chinese(error_text(note))
    # the dead-man on its return: speed 0 before anything else
    qtbot.waitUntil(lambda: link.state.connection.state is LinkState.CONNECTED, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(
        lambda: bool(ratio_writes(sim)) and ratio_writes(sim)[-1] == 0.0, timeout=SIGNAL_TIMEOUT_MS
    )
