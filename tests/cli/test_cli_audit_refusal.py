"""No write without its audit record (issue 19 s5): when the audit trail cannot be written (a full
disk; here a file where the audit folder should be) the CLI refuses the write, with the reason,
and nothing reaches the controller; Stop still goes out, and the CLI says its record was lost."""

from __future__ import annotations

import errno
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.protocol import registers
from app.safety import audit


@pytest.fixture
def blocked_audit(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The CLI's audit folder (its default) is a file: nothing can be written there."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    (tmp_path / "teachpad").mkdir()
    blocker = tmp_path / "teachpad" / "audit"
    blocker.write_text("a file where the audit folder should be")
    return blocker


def run(sim: Any, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["--port", str(sim.port), "--timeout", "5", *argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out, err


def test_the_cli_refuses_a_write_it_cannot_record(
    sim: Any, capsys: pytest.CaptureFixture[str], blocked_audit: Path
) -> None:
    code, _, err = run(sim, capsys, "write", "10", "1.5")
    assert code == ExitCode.FAILED
    assert "not sent" in err and "audit" in err and "cannot be written" in err
    assert not [w for w in sim.writes if w.address == registers.gv_reg(10)]  # at the simulator


def test_a_full_disk_refuses_the_write_too(
    sim: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))

    def full(self: audit.AuditLog, rec: Any, now: Any) -> Any:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(audit.AuditLog, "_append", full)
    code, _, err = run(sim, capsys, "write", "10", "1.5")
    assert code == ExitCode.FAILED and "No space left on device" in err
    assert not [w for w in sim.writes if w.address == registers.gv_reg(10)]


def test_stop_goes_out_without_its_record_and_says_so(
    sim: Any, capsys: pytest.CaptureFixture[str], blocked_audit: Path
) -> None:
    code, _, err = run(sim, capsys, "stop")
    assert [w.values for w in sim.writes if w.address == registers.REG_STOP] == [(1,)]
    assert "warning: the audit trail cannot be written" in err
    assert code == ExitCode.OK
