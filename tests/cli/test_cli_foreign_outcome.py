"""Go to zero and run program are told by motion (no GV291 result): when another Modbus master
writes to the controller between our command and its end, what ended cannot be told from what the
other master did, so the outcome is *unknown* (exit 4, the same words as the moves), audited so.
Issue 19 section 2 ("a command's completion is ours only when it can be told from another
master's"); against the simulator, another master being a second client."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from app import timing
from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.protocol import registers
from app.safety.audit_read import Result, query
from tests.waits import join

UNKNOWN_WORDS = "sent; the outcome is unknown \u2014 check the robot before sending it again"


@pytest.fixture
def audit_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    return tmp_path / "teachpad" / "audit"


@pytest.fixture
def fast_watch(monkeypatch: pytest.MonkeyPatch) -> None:
    """The CLI reads the shared registers with every status read (the clock period is not the subject)."""
    monkeypatch.setattr(timing, "CLOCK_POLL_PERIOD", 0.0)


@pytest.fixture
def another_master(sim: Any, make_client: Any) -> Iterator[Callable[[], None]]:
    """Arms a second client that writes GV204 (a step offset of its own) once the arm moves."""
    other = make_client(sim)
    stop = threading.Event()
    threads: list[threading.Thread] = []
    start = sim.state().joints

    def writes_when_moving() -> None:
        while not stop.wait(0.005):
            if sim.state().joints != start:
                other.write_gv(204, [15.0])
                return

    def arm() -> None:
        thread = threading.Thread(target=writes_when_moving, daemon=True)
        threads.append(thread)
        thread.start()

    yield arm
    stop.set()
    for thread in threads:
        join(thread, "another master")


def _run(sim: Any, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(sim.port), "--timeout", "2", *argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out, err


def _judged(audit_dir: Path, address: int) -> list[Any]:
    return [r for r in query(audit_dir) if r.kind == "write" and r.args["address"] == address]


def test_a_go_to_zero_another_master_wrote_under_is_outcome_unknown(
    sim: Any,
    capsys: pytest.CaptureFixture[str],
    audit_dir: Path,
    fast_watch: None,
    another_master: Callable[[], None],
) -> None:
    another_master()
    code, out, err = _run(sim, capsys, "zero", "all")
    assert code == ExitCode.UNKNOWN, err
    assert out == ""
    assert "another Modbus master" in err and UNKNOWN_WORDS in err
    assert sim.state().joints[1] == pytest.approx(0.0, abs=0.05)  # it did move: check the robot
    (record,) = _judged(audit_dir, registers.REG_GO_ZERO)
    assert record.result == Result.UNKNOWN and "another Modbus master" in record.detail


def test_a_program_run_another_master_wrote_under_is_outcome_unknown(
    sim: Any,
    capsys: pytest.CaptureFixture[str],
    audit_dir: Path,
    fast_watch: None,
    another_master: Callable[[], None],
) -> None:
    another_master()
    code, out, err = _run(sim, capsys, "program", "run", "3", "--speed", "100")
    assert code == ExitCode.UNKNOWN, err
    assert out == ""
    assert "another Modbus master" in err and UNKNOWN_WORDS in err
    records = [r for r in _judged(audit_dir, registers.REG_RUN_COMMAND) if r.args["values"] == [0x01]]
    assert [r.result for r in records] == [Result.UNKNOWN]


def test_without_another_master_zero_and_program_read_done(
    sim: Any, capsys: pytest.CaptureFixture[str], audit_dir: Path, fast_watch: None
) -> None:
    """The neighbour: the same commands with the watch reading at every status read end done."""
    code, out, err = _run(sim, capsys, "zero", "all")
    assert code == ExitCode.OK, err
    assert out == "go to zero (all axes): done\n"
    code, out, err = _run(sim, capsys, "program", "run", "3", "--speed", "100")
    assert code == ExitCode.OK, err
    assert out == "run program 3: done\n"
