"""Audit details recorded without a reason code read in Chinese in the viewer (issue 21: a wrong
password, the CLI's refusals, the link's refusals before the wire, the jog guard's stop, another
master seen, a write's error were shown as recorded English inside the Chinese viewer). The trail
stays English: each record is made by its real producer where one can run here, and the file keeps
what it wrote. Also: an unreadable robot profile's cause is worded by its errno, not the OS's English."""

from __future__ import annotations

import errno
import re
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.errors import ModbusExceptionError, ProfileError, ReducedSpeedRefused
from app.link.foreign import ForeignSighting, audit_sighting
from app.protocol import registers
from app.safety.audit import AuditLog
from app.safety.audit_read import query
from app.safety.caps import MotionCaps
from app.safety.envelope import EnvelopeViolation, ViolationCode
from app.safety.roles import Role, RoleStore, WrongPassword
from app.safety.session import SafetySession
from app.view3d.profile import load_profile
from tests.ui.pendant_support import app_settings_fixture, translator_fixture  # noqa: F401 - fixtures
from tests.ui.test_messages import assert_chinese
from ui.messages import error_text
from ui.panels.audit_viewer import AuditModel

pytestmark = pytest.mark.timeout(60)

# names that stay as written in Chinese: an environment variable, a CLI option, a zone's name
NAMES = re.compile(r"TEACHPAD_\w+|--project|'cell'|cell")


def _trail(folder: Path, sim: Any, make_client: Any) -> None:
    audit = AuditLog(folder)
    store = RoleStore(folder / "roles.json", scrypt_n=2**4)
    store.set_password(Role.ADMINISTRATOR, "admin-1", by=Role.ADMINISTRATOR)
    store.set_password(Role.ENGINEER, "eng-1", by=Role.ADMINISTRATOR)
    session = SafetySession(store, audit)
    with pytest.raises(WrongPassword):
        session.login(Role.ENGINEER, "wrong")  # "wrong password for the engineer role"
    session.login(Role.ADMINISTRATOR, "admin-1")
    with pytest.raises(Exception, match="changed, not removed"):
        session.clear_password(Role.ADMINISTRATOR)
    # the CLI's refusals (app/cli/guard.py, app/cli/support.py), as they are written
    audit.record_refused(
        "log in as operator",
        "the operator role needs its password: run it in a terminal, or set TEACHPAD_PASSWORD",
    )
    audit.record_refused("set the engineer password", "wrong administrator password")
    audit.record_refused(
        "move to point",
        "P7 cannot be checked against the safety envelope: the host has no copy of it "
        "(give the project holding the point with --project)",
        {"end": 7},
    )
    too_fast = EnvelopeViolation(ViolationCode.SPEED, 400.0, 100.0)
    audit.record_refused("move to point", too_fast.message, {"speed": 400.0})
    near = EnvelopeViolation(ViolationCode.KEEP_IN, 538.4, 540.0, "Z", approaching=True)
    audit.record("action", "jog stopped before the limit", result="stopped", detail=near.message)
    outside = EnvelopeViolation(ViolationCode.KEEP_OUT, 560.2, 550.0, "X", box="cell")
    audit.record_refused("step", outside.message)
    # the link's refusal before the wire: go to zero in reduced-speed mode, at a real client
    client = make_client(sim, poll_timeout=1.0)
    client.audit = audit
    client.caps = MotionCaps(10.0, 50.0, 900.0)
    with pytest.raises(ReducedSpeedRefused):
        client.go_zero(None)
    audit.record_refused(
        "run program 3",
        "run program 3 not sent: the controller is busy (program state running); "
        "wait for it to end, or stop it",
        {"program_state": 1},
    )
    audit_sighting(audit, ForeignSighting("registers", 446.0, 0.0))
    # a write the controller answered with an exception
    with pytest.raises(ModbusExceptionError), audit.writing(registers.REG_RUN_COMMAND, [0x41], single=True):
        raise ModbusExceptionError(6, 2, "exception 2 (illegal data address) for the write of 440")
    audit.close()


def _details(model: AuditModel) -> list[str]:
    col = AuditModel.COLUMNS.index("detail")
    return [model.data(model.index(row, col), Qt.ItemDataRole.DisplayRole) for row in range(model.rowCount())]


def test_details_without_a_reason_code_read_in_chinese(
    qapp: Any, translator: Any, tmp_path: Path, sim: Any, make_client: Any
) -> None:
    _trail(tmp_path / "audit", sim, make_client)
    records = query(tmp_path / "audit")
    model = AuditModel()
    model.set_records(records)
    english = [d for d in _details(model) if d]
    assert "wrong password for the engineer role" in english
    assert any("reduced-speed mode" in d for d in english), english
    assert translator.set_language("zh_CN")
    shown = [d for d in _details(model) if d]
    assert len(shown) >= 12, shown
    for text in shown:
        assert_chinese(NAMES.sub("", text))
    # the records themselves stay English (the file, the chain, the CSV)
    assert {r.detail for r in query(tmp_path / "audit") if r.detail} >= {
        "wrong password for the engineer role"
    }


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (lambda tmp: tmp / "missing.json", "文件不存在"),
        (lambda tmp: tmp, "这是文件夹，不是文件"),
    ],
)
def test_an_unreadable_robot_profile_says_why_in_words(
    qapp: Any, translator: Any, tmp_path: Path, make: Any, words: str
) -> None:
    with pytest.raises(ProfileError) as caught:
        load_profile(make(tmp_path))
    assert translator.set_language("zh_CN")
    text = error_text(caught.value)
    assert words in text, text
    assert_chinese(text.replace(str(tmp_path), "").replace("/missing.json", ""))


def test_a_refused_robot_profile_by_errno_in_both_languages(qapp: Any, translator: Any) -> None:
    denied = ProfileError(
        "robot.json: cannot read the robot profile (Permission denied)",
        code="profile_unreadable",
        params={"file": "robot.json", "cause": "Permission denied", "errno": errno.EACCES},
    )
    assert "permission denied" in error_text(denied)
    odd = ProfileError(
        "x", code="profile_unreadable", params={"file": "r.json", "cause": "Bad", "errno": 200}
    )
    assert translator.set_language("zh_CN")
    assert "没有访问权限" in error_text(denied)
    assert_chinese(error_text(denied).replace("robot.json", ""))
    assert_chinese(error_text(odd).replace("r.json", ""))


@pytest.mark.parametrize(
    ("damage", "words"),
    [
        (lambda path: path.mkdir(), "这是文件夹，不是文件"),
        (lambda path: path.write_text("{not json", encoding="utf-8"), "不是有效的 JSON"),
        (lambda path: path.write_bytes(b"\xff\xfe\x00"), "不是 UTF-8 文本"),
    ],
)
def test_the_register_profile_in_force_says_why_it_is_not_used_in_words(
    qapp: Any, translator: Any, app_settings: Any, damage: Any, words: str
) -> None:
    path = app_settings.register_profile_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    damage(path)
    assert "remembered connection settings are used" in app_settings.register_profile()[1]
    assert translator.set_language("zh_CN")
    problem = app_settings.register_profile()[1]
    assert words in problem and "使用记住的连接设置" in problem, problem
    assert_chinese(problem.replace(path.name, "").replace("JSON", "").replace("UTF-8", ""))


def test_loading_a_missing_register_profile_says_so_in_words(
    qapp: Any, translator: Any, tmp_path: Path
) -> None:
    from app.safety.register_profile import RegisterProfile
    from ui.dialogs.register_profile_dialog import RegisterProfileDialog

    def apply(_profile: RegisterProfile, _reconnect: bool = False) -> str | None:
        return None

    dialog = RegisterProfileDialog(RegisterProfile(), apply, None)
    dialog.open_path = lambda: str(tmp_path / "gone.registers.json")
    assert translator.set_language("zh_CN")
    dialog.load()
    text = dialog.error.text()
    assert "文件不存在" in text, text
    assert_chinese(text.replace("gone.registers.json", ""))
    dialog.deleteLater()
