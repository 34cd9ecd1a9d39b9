"""``teachpad-cli roles`` (issue 19 s5): once the administrator has a password, changing the role
store needs it (asked for in a terminal, or TEACHPAD_ADMIN_PASSWORD for scripts); every change
and refusal is audited, never with a password; the administrator's own cannot be removed."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.safety.audit_read import Result, query
from app.safety.roles import Role, RoleStore

ADMIN = "admin-Pa55"


@pytest.fixture
def store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    path = tmp_path / "roles.json"
    roles = RoleStore(path, scrypt_n=2**8)
    roles.set_password(Role.ADMINISTRATOR, ADMIN, by=Role.ADMINISTRATOR)
    roles.set_password(Role.ENGINEER, "eng-Pa55", by=Role.ADMINISTRATOR)
    monkeypatch.delenv("TEACHPAD_ADMIN_PASSWORD", raising=False)
    monkeypatch.setattr("sys.stdin", io.StringIO(""))  # a script: no terminal to ask in
    return path


def roles(store: Path, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = main(["roles", "--store", str(store), *argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out + err


def test_clearing_a_password_needs_the_administrators(
    store: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, text = roles(store, capsys, "clear-password", "administrator")
    assert code == ExitCode.FAILED and "administrator password is needed" in text
    assert "TEACHPAD_ADMIN_PASSWORD" in text
    code, text = roles(store, capsys, "clear-password", "engineer")
    assert code == ExitCode.FAILED
    monkeypatch.setenv("TEACHPAD_ADMIN_PASSWORD", "guess-1234")
    code, text = roles(store, capsys, "clear-password", "engineer")
    assert code == ExitCode.FAILED and "wrong administrator password" in text
    assert RoleStore(store).has_password(Role.ENGINEER) and RoleStore(store).has_password(Role.ADMINISTRATOR)
    monkeypatch.setenv("TEACHPAD_ADMIN_PASSWORD", ADMIN)
    code, text = roles(store, capsys, "clear-password", "administrator")
    assert code == ExitCode.USAGE and "changed, not removed" in text
    assert RoleStore(store).has_password(Role.ADMINISTRATOR)
    code, _ = roles(store, capsys, "clear-password", "engineer")
    assert code == ExitCode.OK and not RoleStore(store).has_password(Role.ENGINEER)
    records = query(store.parent / "audit")
    assert [(r.command, r.result) for r in records] == [
        ("clear the administrator password", Result.REFUSED),
        ("clear the engineer password", Result.REFUSED),
        ("clear the engineer password", Result.REFUSED),
        ("clear the administrator password", Result.REFUSED),
        ("clear the engineer password", Result.OK),
    ]
    assert all(r.role == "administrator (cli)" for r in records)
    assert ADMIN not in "".join(p.read_text() for p in (store.parent / "audit").iterdir())


def test_setting_a_password_needs_the_administrators_and_is_audited(
    store: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("sys.stdin", io.StringIO("new-eng-Pa55\n"))
    code, _ = roles(store, capsys, "set-password", "engineer")
    assert code == ExitCode.FAILED and not RoleStore(store).verify(Role.ENGINEER, "new-eng-Pa55")
    monkeypatch.setenv("TEACHPAD_ADMIN_PASSWORD", ADMIN)
    monkeypatch.setattr("sys.stdin", io.StringIO("new-eng-Pa55\n"))
    code, _ = roles(store, capsys, "set-password", "engineer")
    assert code == ExitCode.OK and RoleStore(store).verify(Role.ENGINEER, "new-eng-Pa55")
    assert [(r.command, r.result) for r in query(store.parent / "audit")][-1] == (
        "change the engineer password",
        Result.OK,
    )
    trail = "".join(p.read_text() for p in (store.parent / "audit").iterdir())
    assert ADMIN not in trail and "new-eng-Pa55" not in trail


def test_the_first_administrator_password_needs_none(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("TEACHPAD_ADMIN_PASSWORD", raising=False)
    monkeypatch.setattr("sys.stdin", io.StringIO("first-Pa55\n"))
    code, _ = roles(tmp_path / "roles.json", capsys, "set-password", "administrator")
    assert code == ExitCode.OK and RoleStore(tmp_path / "roles.json").verify(Role.ADMINISTRATOR, "first-Pa55")
    assert [r.command for r in query(tmp_path / "audit")] == ["set the administrator password"]


def test_the_help_says_how_a_script_gives_the_password(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["roles", "--help"]) == ExitCode.OK
    assert "TEACHPAD_ADMIN_PASSWORD" in capsys.readouterr().out.replace("\n", " ")
