"""No write without its audit record, on the GUI's link (issue 19 s5): when the audit trail cannot
be written the worker refuses the write with the reason (``audit_unavailable``, in words) and
nothing reaches the simulator; Stop still goes out."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from app.link.robot_link import RobotLink
from app.link.types import WorkerError
from app.protocol import registers
from app.safety.audit import AuditLog
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)
from ui.messages import error_text

pytestmark = pytest.mark.timeout(60)


def test_the_gui_link_refuses_a_write_it_cannot_record(
    qtbot: Any, sim: Any, link: RobotLink, tmp_path: Path
) -> None:
    connect(qtbot, link, sim, poll_timeout=1.0)
    blocker = tmp_path / "audit"
    blocker.write_text("a file where the audit folder should be")
    heard: list[str] = []
    link.set_audit(AuditLog(blocker, on_error=heard.append))
    before = len(sim.writes)
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as refused:
        link.create_point(3001, None)
    error: WorkerError = refused.args[0]
    assert error.reason is not None and error.reason.code == "audit_unavailable"
    assert "not sent" in error.message and "cannot be written" in error.message
    assert "audit" in error_text(error)  # the GUI's sentence (translated)
    assert 3001 not in sim.state().points
    assert sim.writes[before:] == []  # at the simulator: nothing went out
    assert heard and "cannot be written" in heard[0]
    # Stop goes out whatever the disk says
    link.stop()
    qtbot.waitUntil(
        lambda: any(w.address == registers.REG_STOP for w in sim.writes[before:]), timeout=SIGNAL_TIMEOUT_MS
    )
