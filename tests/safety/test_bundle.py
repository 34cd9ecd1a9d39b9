"""The support bundle: contents, secrets left out, and ``teachpad-cli support-bundle`` / ``audit``."""

from __future__ import annotations

import datetime as dt
import json
import zipfile
from pathlib import Path

import pytest

from app.cli.main import main
from app.safety.audit import AuditLog
from app.safety.box import Box
from app.safety.bundle import REMOVED, redact, write_support_bundle
from app.safety.envelope import Envelope
from app.safety.profile import SafetyProfile, save_profile
from app.safety.roles import Role, RoleStore

PASSWORD = "s3cret-Pa55"


@pytest.fixture
def files(tmp_path: Path) -> dict[str, Path]:
    project = tmp_path / "demo.teachpad.json"
    project.write_text('{"format": "teachpad-project", "points": []}\n')
    profile = tmp_path / "cell.safety.json"
    save_profile(profile, SafetyProfile("cell", Envelope(keep_in=Box("cell", (-1, -1, -1), (1, 1, 1)))))
    store = RoleStore(tmp_path / "roles.json", scrypt_n=2**8)
    store.set_password(Role.ADMINISTRATOR, PASSWORD, by=Role.ADMINISTRATOR)
    audit_dir = tmp_path / "audit"
    # (written first: a writer never goes back to an older day's file than the newest on disk, and
    # files are pruned by the count of days on disk, not by the clock)
    with AuditLog(audit_dir, now=lambda: dt.datetime(2020, 1, 1, 12, 0).astimezone()) as old:
        old.record("action", "long ago")
    with AuditLog(audit_dir, role="engineer") as log:
        log.record_write(440, [0x80], single=True)
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "teachpad.log").write_text("connected\n")
    (logs / "roles.json").write_bytes((tmp_path / "roles.json").read_bytes())  # a stray copy
    return {
        "project": project,
        "profile": profile,
        "audit": audit_dir,
        "logs": logs,
        "store": tmp_path / "roles.json",
    }


def test_bundle_has_everything_but_secrets(tmp_path: Path, files: dict[str, Path]) -> None:
    settings = {
        "connection": {"host": "10.0.0.5", "port": 502},
        "admin_password": PASSWORD,
        "roles": {"engineer": {"hash": "abcd", "salt": "ef"}},
        "ui": {"language": "zh_CN"},
    }
    out = tmp_path / "bundle.zip"
    manifest = write_support_bundle(
        out,
        settings=settings,
        project=files["project"],
        profile=files["profile"],
        audit_dir=files["audit"],
        events=["03:00 connected"],
        log_dir=files["logs"],
        traffic=["tx 00 01 00 00 00 06 01 03 01 9C 00 0C"],
        days=3,
    )
    with zipfile.ZipFile(out) as zf:
        names = set(zf.namelist())
        blob = b"".join(zf.read(n) for n in names)
        got_settings = json.loads(zf.read("settings.json"))
        versions = json.loads(zf.read("versions.json"))
    assert {
        "versions.json",
        "settings.json",
        "project/demo.teachpad.json",
        "safety-profile.json",
        "events.txt",
        "traffic.txt",
        "logs/teachpad.log",
        "manifest.json",
    } <= names
    today = dt.date.today().isoformat()
    assert [n for n in names if n.startswith("audit/")] == [f"audit/audit-{today}.jsonl"]
    assert "pymodbus" in versions and "python" in versions and "teachpad" in versions
    assert got_settings["connection"] == {"host": "10.0.0.5", "port": 502}
    assert got_settings["admin_password"] == REMOVED and got_settings["roles"]["engineer"]["hash"] == REMOVED
    assert PASSWORD.encode() not in blob
    store = json.loads(files["store"].read_text())["passwords"]["administrator"]
    assert store["hash"].encode() not in blob and store["salt"].encode() not in blob
    assert "logs/roles.json" not in names and any("role store" in n for n in manifest.left_out)


def test_redact_keeps_what_is_not_secret() -> None:
    assert redact({"a": [{"token": 1, "b": 2}], "Password": "x", "port": 5}) == {
        "a": [{"token": REMOVED, "b": 2}],
        "Password": REMOVED,
        "port": 5,
    }


def test_cli_support_bundle_and_audit(
    tmp_path: Path, files: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    settings = tmp_path / "settings.json"
    settings.write_text(json.dumps({"password": PASSWORD, "poll_hz": 50}))
    out = tmp_path / "out.zip"
    code = main(
        [
            "--host",
            "10.1.2.3",
            "support-bundle",
            str(out),
            "--project",
            str(files["project"]),
            "--profile",
            str(files["profile"]),
            "--settings",
            str(settings),
            "--audit-dir",
            str(files["audit"]),
            "--days",
            "2",
        ]
    )
    assert code == 0, capsys.readouterr().err
    assert f"wrote {out}" in capsys.readouterr().out
    with zipfile.ZipFile(out) as zf:
        got = json.loads(zf.read("settings.json"))
        assert PASSWORD.encode() not in b"".join(zf.read(n) for n in zf.namelist())
    assert got["settings file"] == {"password": REMOVED, "poll_hz": 50}
    assert got["cli connection"]["host"] == "10.1.2.3"
    assert main(["support-bundle", str(out), "--project", str(tmp_path / "nope.json")]) == 2
    assert "project file" in capsys.readouterr().err
    csv_out = tmp_path / "audit.csv"
    audit = ["audit", "--audit-dir", str(files["audit"])]
    assert main([*audit, "--role", "engineer", "--csv", str(csv_out)]) == 0
    assert "teach enable (440 ← 0x80)" in csv_out.read_text(encoding="utf-8")
    capsys.readouterr()
    assert main([*audit, "--from", "2019-12-31", "--to", "2020-01-02"]) == 0
    assert "long ago" in capsys.readouterr().out


def test_cli_help_says_how_roles_apply(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "TEACHPAD_ROLE" in out and "TEACHPAD_PASSWORD" in out and "--role" in out


def test_cli_roles(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import io

    store = tmp_path / "roles.json"
    monkeypatch.setattr("sys.stdin", io.StringIO("eng-secret\n"))
    assert main(["roles", "--store", str(store), "set-password", "engineer"]) == 0
    assert "eng-secret" not in store.read_text()
    assert RoleStore(store).verify(Role.ENGINEER, "eng-secret")
    monkeypatch.setattr("sys.stdin", io.StringIO("ab\n"))
    assert main(["roles", "--store", str(store), "set-password", "administrator"]) == 2
    assert "at least 4 characters" in capsys.readouterr().err
    assert main(["roles", "--store", str(store), "show"]) == 0
    assert "engineer      password set" in capsys.readouterr().out
    assert main(["roles", "--store", str(store), "clear-password", "engineer"]) == 0
    assert not RoleStore(store).has_password(Role.ENGINEER)
