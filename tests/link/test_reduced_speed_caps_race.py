"""Reduced-speed caps apply to every request made after them, even one the worker takes from its
queue before the queued caps call arrives (RobotLink.set_motion_caps sets them on the worker at
once as well). RobotLink + worker against the real simulator, no widgets; asserted at the simulator.

The race made certain: the worker is held inside a poll (the simulator holds the poll's read);
meanwhile a request is queued (any: the watch list's), then the caps, then a motion. When the read
is answered, the worker's job loop takes the first request and, in the same turn, the motion -- the
queued caps call comes after both, whichever event Qt delivers first. The old code (caps only by
the queued call) let the motion go out uncapped."""

from __future__ import annotations

from typing import Any

import pytest

from app.link.ops import GoZero, LinkOp, RunProgram, SetWatchList
from app.link.robot_link import RobotLink
from app.link.types import WorkerError
from app.protocol import registers
from app.safety.caps import MotionCaps
from tests.ui.pendant_support import SIGNAL_TIMEOUT_MS, connect

pytestmark = pytest.mark.timeout(60)

CAPS = MotionCaps(ratio=25.0, speed=250.0, reach=1000.0)
# The poll's read is held this long (s): the three requests are queued meanwhile (microseconds on
# an idle machine). Well within the roomy timeouts below: the held poll is answered, no silence.
HOLD = 1.0
ROOMY = 10.0  # s: request and poll timeouts (timing is not the subject)


def _race(qtbot: Any, sim: Any, link: RobotLink, motion: LinkOp) -> tuple[int, list[WorkerError]]:
    """Hold the worker inside a poll, queue a request, switch reduced speed on, queue ``motion``;
    returns its ticket and the link's errors (collected from before the hold)."""
    connect(qtbot, link, sim, timeout=ROOMY, poll_timeout=ROOMY)
    errors: list[WorkerError] = []
    link.errorOccurred.connect(errors.append)
    sim.set_response_delay(HOLD)
    seen = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count > seen, timeout=SIGNAL_TIMEOUT_MS)  # a poll's read held
    link.submit(SetWatchList(()))  # queued before the caps: its wake comes first
    link.set_motion_caps(CAPS)
    ticket = link.submit(motion)
    sim.set_response_delay(0.0)  # the held read keeps its delay; nothing after it is held
    return ticket, errors


def test_a_go_to_zero_queued_right_after_reduced_speed_is_refused_before_the_wire(
    qtbot: Any, sim: Any, main_only_link: RobotLink
) -> None:
    """Go to zero has no speed to cap: refused in reduced-speed mode. The old code sent it (445)."""
    ticket, errors = _race(qtbot, sim, main_only_link, GoZero(None, switch_to_auto=True))
    qtbot.waitUntil(
        lambda: any(e.request_id == ticket for e in errors) or bool(sim.writes_to(registers.REG_GO_ZERO)),
        timeout=SIGNAL_TIMEOUT_MS + HOLD * 1000,
    )
    assert sim.writes_to(registers.REG_GO_ZERO) == [], "go to zero reached the controller in reduced speed"
    assert sim.writes_to(registers.REG_WORK_MODE) == []  # not even the switch to auto before it
    [refusal] = [e for e in errors if e.request_id == ticket]
    assert refusal.reason is not None and refusal.reason.code == "reduced_speed_refused"


def test_a_program_run_queued_right_after_reduced_speed_gets_the_capped_ratio(
    qtbot: Any, sim: Any, main_only_link: RobotLink
) -> None:
    """A program run at 100 %: the controller receives the cap (25 %) in 449. The old code: 100."""
    ticket, errors = _race(qtbot, sim, main_only_link, RunProgram(1, speed_ratio=100, switch_to_auto=True))
    qtbot.waitUntil(
        lambda: (
            bool(sim.writes_to(registers.REG_PROGRAM_SPEED)) or any(e.request_id == ticket for e in errors)
        ),
        timeout=SIGNAL_TIMEOUT_MS + HOLD * 1000,
    )
    assert [e for e in errors if e.request_id == ticket] == []
    assert [w.values for w in sim.writes_to(registers.REG_PROGRAM_SPEED)] == [(CAPS.program_ratio_cap,)]
