"""The jog guard in the worker: ratio 0 at the simulator before the TCP crosses a boundary,
then jogging back out works and jogging further in is refused. Also: the audit hook records
every write the link sends, exactly once."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from app.link.ops import CreatePoint, JogPress, JogRelease
from app.link.robot_link import RobotLink
from app.link.types import JogRequest, WorkerError
from app.protocol.enums import TeachFrame
from app.safety.audit import AuditLog, FsyncPolicy
from app.safety.box import Box
from app.safety.envelope import Envelope, ViolationCode
from app.safety.jog_guard import JogGuard
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    ratio_writes,
)

pytestmark = pytest.mark.timeout(60)

JOG_RATIO = 20.0  # % of 250 mm/s: 50 mm/s
MARGIN_MM = 30.0  # how far inside the boundary the guarded jog starts


def _guard(link: RobotLink, y_limit: float) -> JogGuard:
    """A keep-in box whose +Y face is ``y_limit`` (wide on every other axis)."""
    box = Box("cell", (-5000.0, -5000.0, -5000.0), (5000.0, y_limit, 5000.0))
    poll_period = 1.0 / 50.0
    return JogGuard(Envelope(keep_in=box), poll_period=poll_period)


def _press(link: RobotLink, direction: int) -> int:
    return link.submit(JogPress(JogRequest(TeachFrame.BASE, 1, direction, JOG_RATIO)))


def test_jog_toward_the_boundary_stops_short_of_it(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim, poll_timeout=1.0)
    y0 = sim.state().pose[1]
    y_limit = y0 + MARGIN_MM
    link.set_jog_guard(_guard(link, y_limit))
    with qtbot.waitSignal(link.jogGuardStopped, timeout=SIGNAL_TIMEOUT_MS) as stopped:
        _press(link, 1)  # Y+ toward the face
    violation = stopped.args[0]
    assert violation.code is ViolationCode.KEEP_IN and violation.approaching
    # At the simulator: a ratio > 0 went out, then ratio 0, and the arm stopped short of the face.
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    ratios = ratio_writes(sim)
    assert max(ratios) == JOG_RATIO and ratios[-1] == 0.0
    y_stop = sim.state().pose[1]
    assert y0 < y_stop < y_limit
    link.submit(JogRelease())

    # Further in: refused before any ratio is written.
    count = len(ratio_writes(sim))
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as refused:
        _press(link, 1)
    error: WorkerError = refused.args[0]
    assert "jog refused" in error.message
    assert [r for r in ratio_writes(sim)[count:] if r > 0] == []
    assert sim.state().pose[1] == pytest.approx(y_stop, abs=0.01)

    # Back out: allowed, the arm moves away from the face.
    _press(link, 0)
    qtbot.waitUntil(lambda: jogging(sim) and sim.state().pose[1] < y_stop - 1.0, timeout=SIGNAL_TIMEOUT_MS)
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert ratio_writes(sim)[-1] == 0.0


@pytest.mark.parametrize(
    ("delay", "every"),
    [
        (0.1, 1),  # a slow controller: every answer 0.1 s (a poll takes 0.2 s, the stop lands 0.1 s late)
        (0.15, 4),  # polls late now and then, as on a loaded PC: every 4th answer held 0.15 s
    ],
    ids=["slow-answers", "late-polls"],
)
def test_a_late_poll_does_not_carry_the_arm_over_the_face(
    qtbot: Any, sim: Any, link: RobotLink, delay: float, every: int
) -> None:
    """The guard's look-ahead is the measured time to the next stop (the pose's age, the longest
    recent gap between two polls, the stop write's trip), not the nominal poll period: with the
    nominal 0.07 s the arm ran up to 15 mm past the face here."""
    connect(qtbot, link, sim, poll_timeout=1.0)
    y0 = sim.state().pose[1]
    y_limit = y0 + MARGIN_MM
    link.set_jog_guard(_guard(link, y_limit))
    if every == 1:
        sim.set_response_delay(delay)
    else:
        sim.set_slow_answers(delay, every)
    with qtbot.waitSignal(link.jogGuardStopped, timeout=SIGNAL_TIMEOUT_MS):
        _press(link, 1)
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert max(ratio_writes(sim)) == JOG_RATIO and ratio_writes(sim)[-1] == 0.0
    y_stop = sim.state().pose[1]
    sim.set_response_delay(0.0)
    sim.set_slow_answers(0.0, 0)
    assert y0 < y_stop < y_limit  # at the simulator: short of the face
    link.submit(JogRelease())


def test_without_a_guard_the_jog_runs(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim, poll_timeout=1.0)
    link.set_jog_guard(None)
    y0 = sim.state().pose[1]
    _press(link, 1)
    qtbot.waitUntil(lambda: jogging(sim) and sim.state().pose[1] > y0 + MARGIN_MM, timeout=SIGNAL_TIMEOUT_MS)
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)


def test_every_write_appears_once_in_the_audit(qtbot: Any, sim: Any, link: RobotLink, tmp_path: Path) -> None:
    audit = AuditLog(tmp_path, role="engineer", fsync=FsyncPolicy.NEVER)
    link.set_audit(audit)
    connect(qtbot, link, sim, poll_timeout=1.0)
    _press(link, 1)
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim) and ratio_writes(sim)[-1] == 0.0, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(link.commandFinished, timeout=SIGNAL_TIMEOUT_MS):
        link.submit(CreatePoint(3001, None))
    qtbot.waitUntil(lambda: 3001 in sim.state().points, timeout=SIGNAL_TIMEOUT_MS)
    link.disconnect()  # ratio 0 / teach disable go out too
    qtbot.waitUntil(lambda: not sim.state().teach_enabled, timeout=SIGNAL_TIMEOUT_MS)

    def audited() -> list[tuple[int, tuple[int, ...]]]:
        out = []
        for file in sorted(tmp_path.glob("audit-*.jsonl")):
            for line in file.read_text(encoding="utf-8").splitlines():
                doc = json.loads(line)
                if doc["kind"] == "write":
                    out.append((doc["args"]["address"], tuple(doc["args"]["values"])))
        return out

    sent = [(w.address, tuple(w.values)) for w in sim.writes]
    qtbot.waitUntil(lambda: len(audited()) == len(sent), timeout=SIGNAL_TIMEOUT_MS)
    assert audited() == sent
    assert all(
        json.loads(line)["role"] == "engineer"
        for f in tmp_path.glob("audit-*.jsonl")
        for line in f.read_text().splitlines()
    )
