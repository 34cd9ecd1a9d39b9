"""The CLI says (and the audit records) what the controller made of a command, not that its write
was answered: done (exit 0), refused with the status code's meaning (exit 1), or unknown (exit 4,
"sent; the outcome is unknown -- check the robot before sending it again"). Issue 18, "Outcomes
are the controller's, not the write's"; against the simulator, asserted at its write log and pose.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.protocol import registers
from app.protocol.enums import Alarm, ProgramState
from app.safety.audit_read import AuditRecord, Result, query, result_label

SCAN = 0.02
UNKNOWN_WORDS = "sent; the outcome is unknown \u2014 check the robot before sending it again"
GV291_REGS = range(582, 584)  # the command status: unreadable after the command in some tests


@pytest.fixture
def audit_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The CLI's audit trail (its default folder) in this test's own folder."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    return tmp_path / "teachpad" / "audit"


@pytest.fixture
def csim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=SCAN)


@pytest.fixture
def short_waits(monkeypatch: pytest.MonkeyPatch) -> None:
    """A command told by motion is refused after ACK_TIMEOUT without it; reads retried this long."""
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)
    monkeypatch.setattr(timing, "OUTCOME_READ_BUDGET", 0.3)
    monkeypatch.setattr(timing, "MOVE_TIMEOUT_MIN", 1.0)


def run(sim: Any, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(sim.port), "--timeout", "2", *argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out, err


def error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("teachpad-cli: error: ")
    return lines[0].removeprefix("teachpad-cli: error: ")


def command_record(audit_dir: Path, address: int, value: int | None = None) -> AuditRecord:
    """The one audit record of the write to ``address`` (a command register) the test sent."""
    found = [
        r
        for r in query(audit_dir)
        if r.kind == "write" and r.args["address"] == address and value in (None, r.args["values"][0])
    ]
    assert len(found) == 1, found
    return found[0]


# --- refused: the controller said no, in words -----------------------------------------------


def test_zero_during_an_emergency_stop_is_refused(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path
) -> None:
    csim.set_alarm(Alarm.ESTOP, True)
    joints = csim.state().joints
    code, out, err = run(csim, capsys, "zero", "all")
    assert code == ExitCode.FAILED and out == ""
    assert error_line(err) == "go to zero (all axes) refused by the controller: emergency stop"
    assert csim.writes_to(registers.REG_GO_ZERO)[-1].values == (registers.GO_ZERO_ALL,)  # it was sent
    assert csim.state().joints == joints and not csim.state().moving  # ... and nothing moved
    record = command_record(audit_dir, registers.REG_GO_ZERO)
    assert record.result == Result.REFUSED and "emergency stop" in record.detail


def test_a_step_during_an_emergency_stop_reads_the_controllers_code(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path
) -> None:
    csim.set_alarm(Alarm.ESTOP, True)
    pose = csim.state().pose
    code, _, err = run(csim, capsys, "step", "--frame", "base", "X=10")
    assert code == ExitCode.FAILED
    assert error_line(err) == "incremental move (base) refused: emergency stop (status 2)"
    assert csim.state().pose == pose
    record = command_record(audit_dir, registers.REG_RUN_COMMAND)
    assert record.result == Result.REFUSED and result_label(record) == "refused:2"
    assert record.args["status"] == 2 and "emergency stop" in record.detail


@pytest.mark.usefixtures("open_envelope")  # a move without --project: no keep-in box
def test_move_to_a_missing_point_is_refused_with_status_13_in_words(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path
) -> None:
    code, _, err = run(csim, capsys, "move", "99")
    assert code == ExitCode.FAILED
    assert error_line(err) == "move to temp point refused: bad end point id (status 13)"
    record = command_record(audit_dir, registers.REG_RUN_COMMAND)
    assert record.result == Result.REFUSED and result_label(record) == "refused:13"
    assert record.detail == "move to temp point refused: bad end point id (status 13)"
    # `teachpad-cli audit` shows the controller's word and code, and filters by it
    code, out, _ = run(csim, capsys, "audit", "--audit-dir", str(audit_dir), "--result", "refused")
    assert code == ExitCode.OK and len(out.splitlines()) == 1
    assert " refused:13 " in out and "bad end point id (status 13)" in out


def test_a_program_that_does_not_exist_is_refused(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path, short_waits: None
) -> None:
    code, out, err = run(csim, capsys, "program", "run", "7")
    assert code == ExitCode.FAILED and out == ""
    assert error_line(err) == (
        "run program 7 refused: the program did not start within 0.5 s (no such program, or the "
        "controller refused it)"
    )
    assert not csim.state().moving
    record = command_record(audit_dir, registers.REG_RUN_COMMAND, 0x01)
    assert record.result == Result.REFUSED and "did not start" in record.detail


def test_a_program_run_while_one_runs_is_refused_as_busy(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path
) -> None:
    code, out, _ = run(csim, capsys, "program", "run", "1", "--mode", "cycle", "--cycles", "0", "--no-wait")
    assert code == ExitCode.OK and out == "run program 1: started (under way; its end is not waited for)\n"
    assert csim.state().program_state is ProgramState.RUNNING
    sent = len(csim.writes_to(registers.REG_RUN_COMMAND))
    code, out, err = run(csim, capsys, "program", "run", "2")
    assert code == ExitCode.FAILED and out == ""
    assert error_line(err) == (
        "run program 2 not sent: the controller is busy (program state running); wait for it to end, "
        "or stop it"
    )
    assert len(csim.writes_to(registers.REG_RUN_COMMAND)) == sent  # nothing was sent
    assert csim.state().program_state is ProgramState.RUNNING  # the first one runs on
    refusal = [r for r in query(audit_dir) if r.kind == "refused"]
    assert [(r.command, r.result) for r in refusal] == [("run program 2", Result.REFUSED)]
    # the run that was only seen started reads unknown (its end was not followed), never "ok"
    first = command_record(audit_dir, registers.REG_RUN_COMMAND, 0x01)
    assert first.result == Result.UNKNOWN and "not followed to its end" in first.detail
    code, out, _ = run(csim, capsys, "stop")
    assert code == ExitCode.OK and out == "stop: done (the arm stands still)\n"


# --- unknown: taken, and what it did cannot be told -------------------------------------------


def test_a_step_whose_status_cannot_be_read_is_unknown(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path, short_waits: None
) -> None:
    x0 = csim.state().pose[0]
    csim.set_exception(ExcCodes.DEVICE_FAILURE, GV291_REGS, after_write=registers.REG_RUN_COMMAND)
    code, out, err = run(csim, capsys, "step", "--frame", "base", "X=10", "--speed", "100")
    assert code == ExitCode.UNKNOWN and out == ""
    line = error_line(err)
    assert line.startswith(f"incremental move (base): {UNKNOWN_WORDS} (")
    assert "server device failure" in line
    # the controller did take it: the arm moved (why the operator must check before sending again)
    assert csim.wait_for(lambda s: not s.moving and s.pose[0] > x0 + 9.9, 5.0)
    record = command_record(audit_dir, registers.REG_RUN_COMMAND)
    assert record.result == Result.UNKNOWN and UNKNOWN_WORDS in record.detail


def test_a_zero_whose_status_cannot_be_read_is_unknown(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path, short_waits: None
) -> None:
    csim.set_exception(ExcCodes.DEVICE_FAILURE, GV291_REGS, after_write=registers.REG_GO_ZERO)
    code, _, err = run(csim, capsys, "zero", "J1")
    assert code == ExitCode.UNKNOWN
    assert error_line(err).startswith(f"go to zero (J1): {UNKNOWN_WORDS} (")
    assert command_record(audit_dir, registers.REG_GO_ZERO).result == Result.UNKNOWN


# --- done: the neighbours still succeed -------------------------------------------------------


def test_zero_and_program_run_done_exit_0_and_read_done(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path
) -> None:
    code, out, err = run(csim, capsys, "zero", "J2")
    assert code == ExitCode.OK, err
    assert out == "go to zero (J2): done\n"
    state = csim.state()
    assert not state.moving and state.joints[1] == pytest.approx(0.0, abs=0.01)  # waited until there
    code, out, err = run(csim, capsys, "program", "run", "3", "--speed", "100")
    assert code == ExitCode.OK, err
    assert out == "run program 3: done\n" and not csim.state().moving
    assert command_record(audit_dir, registers.REG_GO_ZERO).result == Result.DONE
    assert command_record(audit_dir, registers.REG_RUN_COMMAND, 0x01).result == Result.DONE
    code, out, _ = run(csim, capsys, "audit", "--audit-dir", str(audit_dir), "--result", "done")
    assert code == ExitCode.OK and len(out.splitlines()) == 2 and " done " in out


def test_plain_commands_read_what_the_controller_shows(
    csim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path, short_waits: None
) -> None:
    code, out, _ = run(csim, capsys, "mode", "manual")
    assert code == ExitCode.OK and out == "work mode manual: done (the controller's mode reads manual)\n"
    run(csim, capsys, "mode", "auto")
    code, out, _ = run(csim, capsys, "pause")  # nothing under way: the arm stands still, as asked
    assert code == ExitCode.OK and out == "pause: done (the program state reads stopped)\n"
    code, _, err = run(csim, capsys, "resume")  # nothing was paused: nothing resumed
    assert code == ExitCode.FAILED
    assert error_line(err) == "resume not taken: the program state reads stopped after 0.5 s"
    code, out, _ = run(csim, capsys, "write", "200", "30", "-1.5")
    assert code == ExitCode.OK and out == "GV200..GV201 written (0000 41F0 0000 BFC0), read back the same\n"
    code, _, err = run(csim, capsys, "write", "291", "30")  # the controller owns GV291
    assert code == ExitCode.FAILED and "the controller did not keep them" in error_line(err)
    results = {(r.args["address"], r.result) for r in query(audit_dir) if r.kind == "write"}
    assert {(444, Result.DONE), (442, Result.DONE), (443, Result.REFUSED)} <= results
    assert {(400, Result.DONE), (582, Result.REFUSED)} <= results
