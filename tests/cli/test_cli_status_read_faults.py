"""Once the controller took a command, a status read that fails does not make it "failed" (issue 19
section 3, first bullet): *busy* (Modbus exception 6) or no answer on the status reads while the
arm moves, the reads are retried within the command's time and the command ends as the controller
then says (done, exit 0); when the status stays unreadable its outcome is *unknown* (exit 4, "sent;
the outcome is unknown -- check the robot before sending it again"), never "failed" (exit 1).
Against the simulator: its pose says the arm did move."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.protocol import registers
from tests.waits import join

UNKNOWN_WORDS = "sent; the outcome is unknown \u2014 check the robot before sending it again"
STATUS_REGS = range(registers.STATUS_BLOCK_START, registers.STATUS_BLOCK_START + registers.STATUS_BLOCK_COUNT)
STEP = ("step", "--frame", "base", "X=40", "--speed", "80")  # 40 mm in 0.5 s


@pytest.fixture(autouse=True)
def audit_home(tmp_path: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))


@pytest.fixture
def faults(sim: Any) -> Iterator[Callable[[Callable[[], None], Callable[[], None]], None]]:
    """``faults(on, off)``: in a thread, ``on()`` once the arm moves, ``off()`` once it stands still
    again (a fault during the move only)."""
    stop = threading.Event()
    threads: list[threading.Thread] = []

    def arm(on: Callable[[], None], off: Callable[[], None]) -> None:
        def watch() -> None:
            while not stop.wait(0.002):
                if sim.state().moving:
                    on()
                    break
            while not stop.wait(0.005):
                if not sim.state().moving:
                    off()
                    return

        thread = threading.Thread(target=watch, daemon=True)
        threads.append(thread)
        thread.start()

    yield arm
    stop.set()
    for thread in threads:
        join(thread, "fault switch")


def _run(sim: Any, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(sim.port), "--timeout", "1", *argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out, err


def test_busy_status_reads_for_the_whole_step_do_not_fail_it(
    sim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    """The field report: *busy* on every status read for 2 s from the step's trigger on (longer
    than the move): the step exits 0 "done" after the move, not 1."""
    x0 = sim.state().pose[0]
    sim.set_exception(ExcCodes.DEVICE_BUSY, STATUS_REGS, after_write=registers.REG_RUN_COMMAND, seconds=2.0)
    code, out, err = _run(sim, capsys, *STEP)
    assert code == ExitCode.OK, err
    assert out.startswith("incremental move (base): done")
    assert sim.state().pose[0] == pytest.approx(x0 + 40.0, abs=0.01)


def test_unanswered_status_reads_during_the_step_do_not_fail_it(
    sim: Any,
    capsys: pytest.CaptureFixture[str],
    faults: Callable[[Callable[[], None], Callable[[], None]], None],
) -> None:
    """The status reads go unanswered (longer than the request timeout) from when the arm moves
    until it stands still again: the step exits 0 "done"."""
    x0 = sim.state().pose[0]
    faults(lambda: sim.set_response_delay(1.5, addresses=STATUS_REGS), lambda: sim.set_response_delay(0.0))
    code, out, err = _run(sim, capsys, *STEP)
    assert code == ExitCode.OK, err
    assert out.startswith("incremental move (base): done")
    assert sim.state().pose[0] == pytest.approx(x0 + 40.0, abs=0.01)


def test_a_status_that_stays_busy_makes_the_step_unknown_not_failed(
    sim: Any, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "OUTCOME_READ_BUDGET", 0.3)
    monkeypatch.setattr(timing, "MOVE_TIMEOUT_MIN", 1.0)
    x0 = sim.state().pose[0]
    sim.set_exception(ExcCodes.DEVICE_BUSY, STATUS_REGS, after_write=registers.REG_RUN_COMMAND)
    code, out, err = _run(sim, capsys, *STEP)
    assert code == ExitCode.UNKNOWN, err
    assert out == "" and UNKNOWN_WORDS in err and "busy" in err
    assert sim.wait_for(lambda s: not s.moving and s.pose[0] > x0 + 39.9, 5.0)  # it did move


@pytest.mark.parametrize(
    "argv",
    [
        ("zero", "J2"),
        ("program", "run", "3", "--speed", "100"),
        ("point", "create", "5", "--xyzabc", "400", "0", "300", "180", "0", "0"),
    ],
    ids=["zero", "program", "create-point"],
)
def test_busy_status_reads_after_the_other_commands_do_not_fail_them(
    sim: Any, capsys: pytest.CaptureFixture[str], argv: tuple[str, ...]
) -> None:
    trigger = registers.REG_GO_ZERO if argv[0] == "zero" else registers.REG_RUN_COMMAND
    sim.set_exception(ExcCodes.DEVICE_BUSY, STATUS_REGS, after_write=trigger, seconds=0.5)
    code, out, err = _run(sim, capsys, *argv)
    assert code == ExitCode.OK, err
    assert ": done" in out or ": success" in out, out
