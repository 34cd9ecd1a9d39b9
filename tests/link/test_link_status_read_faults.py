"""The GUI's link (RobotLink, worker thread) against the simulator: once the controller took a
command, a status read that fails does not make it "failed" (issue 19 section 3, first bullet).
*Busy* (exception 6) on the status reads right after the trigger, or no answer to them while the
arm moves: the command's result is the controller's ("done") once the reads are answered again,
one result per request. And go to zero / run program that another master wrote under end
*unknown* (issue 19 section 2), in the same words as the moves."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.link.ops import GoZero, RunProgram, Step
from app.link.outcome import Outcome, outcome_of
from app.link.robot_link import RobotLink
from app.link.types import StepFrame
from app.models import CommandResult
from app.protocol import registers
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)
from tests.waits import join
from ui.messages import result_text

pytestmark = pytest.mark.timeout(90)

STATUS_REGS = range(registers.STATUS_BLOCK_START, registers.STATUS_BLOCK_START + registers.STATUS_BLOCK_COUNT)


class Results:
    """Every command result of the link, from before the first request."""

    def __init__(self, link: RobotLink) -> None:
        self.seen: list[CommandResult] = []
        link.commandFinished.connect(self.seen.append)

    def of(self, qtbot: Any, request_id: int) -> list[CommandResult]:
        qtbot.waitUntil(
            lambda: any(r.request_id == request_id for r in self.seen), timeout=10 * SIGNAL_TIMEOUT_MS
        )
        return [r for r in self.seen if r.request_id == request_id]


@pytest.fixture
def results(link: RobotLink) -> Results:
    return Results(link)


def _step_40(link: RobotLink) -> int:
    return link.submit(Step(StepFrame.BASE, [40.0, 0, 0, 0, 0, 0], speed=80.0))


def test_busy_status_reads_right_after_a_step_do_not_fail_it(
    qtbot: Any, sim: Any, link: RobotLink, results: Results
) -> None:
    connect(qtbot, link, sim, poll_timeout=1.0)
    x0 = sim.state().pose[0]
    sim.set_exception(ExcCodes.DEVICE_BUSY, STATUS_REGS, after_write=registers.REG_RUN_COMMAND, seconds=0.5)
    request = _step_40(link)
    qtbot.waitUntil(lambda: any(r.request_id == request and r.ok for r in results.seen), timeout=10_000)
    assert [r.ok for r in results.of(qtbot, request)] == [True]  # no "failed" before the "done"
    assert sim.state().pose[0] == pytest.approx(x0 + 40.0, abs=0.01)


def test_unanswered_status_reads_during_a_step_do_not_fail_it(
    qtbot: Any, sim: Any, link: RobotLink, results: Results
) -> None:
    connect(qtbot, link, sim, poll_timeout=0.3)
    x0 = sim.state().pose[0]
    stop = threading.Event()

    def silence_while_moving() -> None:
        while not stop.wait(0.002):
            if sim.state().moving:
                sim.set_response_delay(0.6, addresses=STATUS_REGS)
                break
        while not stop.wait(0.005):
            if not sim.state().moving:
                sim.set_response_delay(0.0)
                return

    thread = threading.Thread(target=silence_while_moving, daemon=True)
    thread.start()
    try:
        request = _step_40(link)
        found = results.of(qtbot, request)
    finally:
        stop.set()
        join(thread, "fault switch")
    assert [r.ok for r in found] == [True], [r.message for r in found]
    assert sim.state().pose[0] == pytest.approx(x0 + 40.0, abs=0.01)


def test_a_status_that_stays_busy_ends_the_step_unknown_not_failed(
    qtbot: Any, sim: Any, link: RobotLink, results: Results, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The status reads stay *busy* after the step was taken: once they failed for the read budget
    and the step's own time ran out, it ends *unknown*, in words (never "failed", never "under way"
    for ever)."""
    monkeypatch.setattr(timing, "OUTCOME_READ_BUDGET", 0.3)
    monkeypatch.setattr(timing, "MOVE_TIMEOUT_MIN", 1.0)
    connect(qtbot, link, sim, poll_timeout=1.0)
    x0 = sim.state().pose[0]
    sim.set_exception(ExcCodes.DEVICE_BUSY, STATUS_REGS, after_write=registers.REG_RUN_COMMAND)
    request = _step_40(link)
    (result,) = results.of(qtbot, request)
    assert outcome_of(result) is Outcome.UNKNOWN
    assert result_text(result) == (
        "incremental move (base): sent; the outcome is unknown \u2014 check the robot "
        "before sending it again."
    )
    assert sim.wait_for(lambda s: not s.moving and s.pose[0] > x0 + 39.9, 5.0)  # it did move
    sim.set_exception(None)


@pytest.fixture
def another_master(sim: Any, make_client: Any) -> Iterator[threading.Event]:
    """A second client writes GV204 once the arm moves (set the event to arm it)."""
    other = make_client(sim)
    armed, stop = threading.Event(), threading.Event()
    start = sim.state().joints

    def writes_when_moving() -> None:
        while not stop.wait(0.005):
            if armed.is_set() and sim.state().joints != start:
                other.write_gv(204, [15.0])
                return

    thread = threading.Thread(target=writes_when_moving, daemon=True)
    thread.start()
    yield armed
    stop.set()
    join(thread, "another master")


@pytest.mark.parametrize("command", ["zero", "program"])
def test_zero_and_program_another_master_wrote_under_are_unknown(
    qtbot: Any,
    sim: Any,
    link: RobotLink,
    results: Results,
    another_master: threading.Event,
    monkeypatch: pytest.MonkeyPatch,
    command: str,
) -> None:
    monkeypatch.setattr(timing, "CLOCK_POLL_PERIOD", 0.05)  # the shared registers read often
    connect(qtbot, link, sim, poll_timeout=1.0)
    another_master.set()
    request = link.submit(GoZero(None)) if command == "zero" else link.submit(RunProgram(3, speed_ratio=100))
    (result,) = results.of(qtbot, request)
    assert outcome_of(result) is Outcome.UNKNOWN
    assert "another Modbus master" in result.message
    what = "go to zero" if command == "zero" else "run program"
    assert result_text(result) == (
        f"{what}: sent; the outcome is unknown \u2014 check the robot before sending it again."
    )
