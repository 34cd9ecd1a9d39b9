"""RobotLink makes its worker (pymodbus, the envelope's numpy) at the first request, not when it
is built; what it was given before reaches the worker first (app/link/robot_link.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from app.link.ops import Stop
from app.link.robot_link import RobotLink
from app.protocol import registers
from app.safety.audit import AuditLog
from app.safety.audit_read import query
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)


def test_no_worker_until_the_first_request_then_it_has_what_was_set_before(
    qtbot: Any, link: RobotLink, sim: Any, tmp_path: Path
) -> None:
    assert link._made is None and link.is_running  # the thread runs, the worker is not made yet
    link.set_poll_rate(25.0)
    link.set_audit(AuditLog(tmp_path))
    link.set_traffic_capture(True)
    assert link._made is None  # remembered, nothing made
    with qtbot.waitSignal(link.trafficObserved, timeout=SIGNAL_TIMEOUT_MS):  # capture was on
        connect(qtbot, link, sim)
    worker = link._made
    assert worker is not None and worker._poll_hz == 25.0
    with qtbot.waitSignal(link.commandFinished, timeout=SIGNAL_TIMEOUT_MS):
        link.submit(Stop())
    qtbot.waitUntil(lambda: bool(sim.writes_to(registers.REG_STOP)), timeout=SIGNAL_TIMEOUT_MS)
    records = query(tmp_path)  # audited: the log given before the worker existed reached it
    assert ("stop (441 ← 1)", "write") in [(r.command, r.kind) for r in records]


def test_a_link_shut_down_before_any_request_stops_its_thread(qtbot: Any) -> None:
    link = RobotLink(canary_gv=None)
    assert link.is_running and link._made is None
    link.shutdown()
    assert not link.is_running and link._made is None
    assert link.submit(Stop()) == 0  # nothing is made after a shutdown
    assert link._made is None
