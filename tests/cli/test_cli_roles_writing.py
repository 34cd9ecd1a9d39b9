"""Issue 19 §5: where passwords are set, teachpad-cli's writing commands act as a role
(``--role`` / TEACHPAD_ROLE, its password from a terminal or TEACHPAD_PASSWORD) and the GUI's
permission table says what it may do; audit records carry the role (app/cli/guard.py)."""

from __future__ import annotations

import io
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.protocol import registers
from app.safety.audit import default_audit_dir
from app.safety.audit_read import Result, query
from app.safety.roles import Role, RoleStore, default_store_path

ADMIN = "admin-Pa55"
ENGINEER = "eng-Pa55"


def run(sim: Any, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = main(["--port", str(sim.port), "--timeout", "3", *argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out + err


@pytest.fixture(autouse=True)
def own_audit(tmp_path: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))  # this test's audit trail only


@pytest.fixture
def passwords(monkeypatch: pytest.MonkeyPatch) -> None:
    roles = RoleStore(default_store_path(), scrypt_n=2**8)
    roles.set_password(Role.ADMINISTRATOR, ADMIN, by=Role.ADMINISTRATOR)
    roles.set_password(Role.ENGINEER, ENGINEER, by=Role.ADMINISTRATOR)
    monkeypatch.setattr("sys.stdin", io.StringIO(""))  # a script: no terminal to ask in


def gv150_writes(sim: Any) -> int:
    return len(sim.writes_to(registers.gv_reg(150)))


@pytest.mark.usefixtures("passwords")
def test_a_writing_command_acts_as_a_role_with_its_password(
    sim: Any, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # operator (the default): may step, may not write raw registers
    code, text = run(sim, capsys, "step", "--frame", "base", "X=5")
    assert code == ExitCode.OK, text
    code, text = run(sim, capsys, "write", "150", "1.5")
    assert code == ExitCode.FAILED
    assert "write controller registers directly: needs the administrator role (logged in as operator)" in text
    assert gv150_writes(sim) == 0
    # another role needs its password: none in a script without the variable
    code, text = run(sim, capsys, "--role", "administrator", "write", "150", "1.5")
    assert code == ExitCode.FAILED and "needs its password" in text and "TEACHPAD_PASSWORD" in text
    monkeypatch.setenv("TEACHPAD_ROLE", "administrator")
    monkeypatch.setenv("TEACHPAD_PASSWORD", "guess-1234")
    code, text = run(sim, capsys, "write", "150", "1.5")
    assert code == ExitCode.FAILED and "wrong password for the administrator role" in text
    assert gv150_writes(sim) == 0
    monkeypatch.setenv("TEACHPAD_PASSWORD", ENGINEER)  # the engineer's: still not enough
    code, text = run(sim, capsys, "--role", "engineer", "write", "150", "1.5")
    assert code == ExitCode.FAILED and "needs the administrator role (logged in as engineer)" in text
    assert gv150_writes(sim) == 0
    monkeypatch.setenv("TEACHPAD_PASSWORD", ADMIN)
    code, text = run(sim, capsys, "write", "150", "1.5")
    assert code == ExitCode.OK, text
    assert gv150_writes(sim) > 0
    records = query(default_audit_dir())
    step = next(r for r in records if r.kind == "write")
    assert step.role == "operator (cli)"
    refused = [(r.command, r.role) for r in records if r.result == Result.REFUSED]
    assert refused == [
        ("write controller registers directly", "operator (cli)"),
        ("log in as administrator", "operator (cli)"),
        ("log in as administrator", "operator (cli)"),
        ("write controller registers directly", "engineer (cli)"),
    ]
    writes = [r for r in records if r.kind == "write" and r.args.get("address") == registers.gv_reg(150)]
    assert writes and all(r.role == "administrator (cli)" for r in writes)
    assert ADMIN not in "".join(p.read_text() for p in default_audit_dir().rglob("*.jsonl"))


def test_reads_need_no_role(sim: Any, capsys: pytest.CaptureFixture[str], passwords: None) -> None:
    code, text = run(sim, capsys, "--poll-timeout", "1", "status")
    assert code == ExitCode.OK, text


def test_without_passwords_the_cli_acts_as_administrator_as_before(
    sim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    code, text = run(sim, capsys, "write", "150", "1.5")
    assert code == ExitCode.OK, text
    writes = [r for r in query(default_audit_dir()) if r.kind == "write"]
    assert writes and all(r.role == "administrator (cli)" for r in writes)


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_in_a_terminal_the_password_is_asked_for(
    sim: Any, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, passwords: None
) -> None:
    asked: list[str] = []

    def ask(prompt: str = "") -> str:
        asked.append(prompt)
        return ENGINEER

    monkeypatch.setattr("sys.stdin", _Terminal(""))
    monkeypatch.setattr("getpass.getpass", ask)
    code, text = run(sim, capsys, "--role", "engineer", "step", "--frame", "base", "X=5")
    assert code == ExitCode.OK, text
    assert asked == ["engineer password: "]
    records = query(default_audit_dir())
    assert ("log in as engineer", "engineer (cli)") in [(r.command, r.role) for r in records]
    assert next(r for r in records if r.kind == "write").role == "engineer (cli)"
