"""The GUI's command results say what the controller made of a command, in the same words as the
CLI and the audit trail (app/link/outcome.py, one rule): through RobotLink (the worker thread)
against the simulator, with an audit trail, the result read by ``ui.messages.result_text``.
Issue 18, "Outcomes are the controller's, not the write's"."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, QTranslator

from app import timing
from app.errors import Reason
from app.link.ops import GoZero, RunProgram, Step
from app.link.outcome import Outcome, outcome_of
from app.link.robot_link import RobotLink
from app.link.types import LinkState, Operation, StepFrame
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import Alarm, RunCommand
from app.safety.audit import AuditLog
from app.safety.audit_read import AuditRecord, Result, query, result_label
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
)
from tests.ui.test_messages import QM, assert_chinese
from ui.messages import error_text, result_text

pytestmark = pytest.mark.timeout(60)


@pytest.fixture
def zh(qapp: object) -> Iterator[None]:
    translator = QTranslator()
    assert translator.load(str(QM))
    QCoreApplication.installTranslator(translator)
    yield
    QCoreApplication.removeTranslator(translator)


@pytest.fixture
def audited(link: RobotLink, tmp_path: Path) -> Path:
    """The link's audit trail, in this test's folder."""
    link.set_audit(AuditLog(tmp_path))
    return tmp_path


class Results:
    """Every command result of the link, collected from before the first request."""

    def __init__(self, link: RobotLink) -> None:
        self.seen: list[CommandResult] = []
        link.commandFinished.connect(self.seen.append)

    def of(self, qtbot: Any, request_id: int, timeout: int = SIGNAL_TIMEOUT_MS) -> CommandResult:
        qtbot.waitUntil(lambda: any(r.request_id == request_id for r in self.seen), timeout=timeout)
        return next(r for r in self.seen if r.request_id == request_id)


@pytest.fixture
def results(link: RobotLink) -> Results:
    return Results(link)


def _command_record(audit_dir: Path, address: int) -> AuditRecord:
    found = [r for r in query(audit_dir) if r.kind == "write" and r.args["address"] == address]
    assert len(found) == 1, found
    return found[0]


def test_go_to_zero_during_an_emergency_stop_reads_refused(
    qtbot: Any, sim: Any, link: RobotLink, audited: Path, results: Results
) -> None:
    connect(qtbot, link, sim)
    sim.set_alarm(Alarm.ESTOP, True)
    joints = sim.state().joints
    result = results.of(qtbot, link.submit(GoZero(None)))
    assert not result.ok and outcome_of(result) is Outcome.REFUSED
    assert result_text(result) == "go to zero refused by the controller: emergency stop."
    assert sim.writes_to(registers.REG_GO_ZERO) and sim.state().joints == joints
    qtbot.waitUntil(lambda: _command_record(audited, registers.REG_GO_ZERO).result == Result.REFUSED)


def test_a_step_during_an_emergency_stop_reads_the_controllers_code(
    qtbot: Any, sim: Any, link: RobotLink, audited: Path, results: Results
) -> None:
    connect(qtbot, link, sim)
    sim.set_alarm(Alarm.ESTOP, True)
    result = results.of(qtbot, link.submit(Step(StepFrame.BASE, [10, 0, 0, 0, 0, 0], speed=50.0)))
    assert outcome_of(result) is Outcome.REFUSED
    assert result_text(result) == "incremental move (base) refused by the controller: emergency stop."
    qtbot.waitUntil(lambda: result_label(_command_record(audited, registers.REG_RUN_COMMAND)) == "refused:2")


def test_a_program_that_does_not_start_reads_refused_and_one_that_runs_reads_done(
    qtbot: Any, sim: Any, link: RobotLink, audited: Path, results: Results, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)
    connect(qtbot, link, sim)
    result = results.of(qtbot, link.submit(RunProgram(7)))
    assert outcome_of(result) is Outcome.REFUSED
    assert result_text(result) == "Program 7 did not start: no such program, or the controller refused it."
    result = results.of(qtbot, link.submit(GoZero(1)), timeout=10 * SIGNAL_TIMEOUT_MS)
    assert result.ok and result_text(result) == "go to zero: done."
    assert sim.state().joints[1] == pytest.approx(0.0, abs=0.01)
    outcomes = [r.result for r in query(audited) if r.kind == "write" and r.args.get("judged")]
    assert outcomes == [Result.REFUSED, Result.DONE]


def test_a_link_lost_under_a_go_to_zero_reads_unknown(
    qtbot: Any, sim: Any, link: RobotLink, audited: Path, results: Results, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "NOT_ANSWERING_DOWN_AFTER", 0.3)
    connect(qtbot, link, sim, poll_timeout=0.5)
    zero = link.submit(GoZero(None))
    qtbot.waitUntil(lambda: sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.DOWN), timeout=SIGNAL_TIMEOUT_MS
    ):
        sim.set_silent(True)
    result = results.of(qtbot, zero)
    assert outcome_of(result) is Outcome.UNKNOWN
    assert result_text(result) == (
        "go to zero: the connection was lost while it was under way; the outcome is unknown \u2014 "
        "check the robot before sending it again."
    )
    sim.set_silent(False)
    record = _command_record(audited, registers.REG_GO_ZERO)
    assert record.result == Result.UNKNOWN and "outcome is unknown" in record.detail


def test_the_outcome_words_read_in_chinese(zh: None) -> None:
    """Every reason an outcome ends with (the watch's, the tracker's unknown, the busy refusal)."""
    go_zero = {"operation": Operation.GO_ZERO}
    reasons = [
        Reason("refused_alarm", {**go_zero, "alarms": int(Alarm.ESTOP)}),
        Reason("alarm_while_waiting", {**go_zero, "alarms": int(Alarm.SERVO)}),
        Reason("no_motion", {**go_zero, "seconds": 2.0}),
        Reason("zero_already", go_zero),
        Reason("zero_stopped_short", {**go_zero, "axis": "J2", "value": 20.0}),
        Reason("done", go_zero),
        Reason("outcome_unknown", go_zero),
        Reason("outcome_unknown", {"command": int(RunCommand.STEP_BASE)}),
        Reason("controller_busy", {"operation": Operation.RUN_PROGRAM}),
        Reason("state_not_reached", {"operation": Operation.SET_MODE, "seconds": 2.0}),
        Reason("outcome_unknown_link_lost", {"operation": Operation.MOVE_TO_POINT}),
        Reason("outcome_unknown_link_closed", {"operation": Operation.RUN_PROGRAM}),
    ]
    for reason in reasons:
        assert_chinese(error_text(reason))
    assert (
        error_text(Reason("outcome_unknown", go_zero)) == "回零：已发送，结果未知——再次发送前请先检查机器人。"
    )
