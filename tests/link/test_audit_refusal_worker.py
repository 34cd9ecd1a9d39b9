"""No write without its audit record, on the GUI's link (issue 19 s5): when the audit trail cannot
be written the worker refuses the write with the reason (``audit_unavailable``, in words) and
nothing reaches the simulator; Stop still goes out. The full disk: the audit's writer raises
ENOSPC."""

from __future__ import annotations

import datetime as dt
import errno
from pathlib import Path
from typing import Any

import pytest

from app.link.ops import CreatePoint, Stop
from app.link.robot_link import RobotLink
from app.link.types import WorkerError
from app.protocol import registers
from app.safety.audit import AuditLog
from app.safety.audit_read import AuditRecord
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
    heard: list[str] = []
    audit = AuditLog(tmp_path / "audit", on_error=heard.append)
    link.set_audit(audit)  # (before connecting: the worker has it for every write that follows)
    connect(qtbot, link, sim, poll_timeout=1.0)

    def full(rec: AuditRecord, now: dt.datetime) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    audit._append = full  # type: ignore[method-assign]  # the disk is full from now on
    before = len(sim.writes)
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as refused:
        link.submit(CreatePoint(3001, None))
    error: WorkerError = refused.args[0]
    assert error.reason is not None and error.reason.code == "audit_unavailable"
    assert "not sent" in error.message and "No space left on device" in error.message
    assert "audit" in error_text(error)  # the GUI's sentence (translated)
    assert 3001 not in sim.state().points
    assert sim.writes[before:] == []  # at the simulator: nothing went out
    assert heard and "cannot be written" in heard[0]
    # Stop goes out whatever the disk says
    link.submit(Stop())
    qtbot.waitUntil(
        lambda: any(w.address == registers.REG_STOP for w in sim.writes[before:]), timeout=SIGNAL_TIMEOUT_MS
    )
