"""The audit viewer's command and detail columns read in the operator's language (issue 21: they
were English inside the Chinese viewer). The trail itself stays English (file, chain, CSV)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt

from app.errors import Reason
from app.link.outcome import outcome_args
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import RunCommand
from app.safety.audit import AuditLog
from app.safety.audit_read import query
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from ui.panels.audit_viewer import AuditModel

# what stays as written: register numbers and names, values, units, the product's name
KEPT = re.compile(r"GV\d+|0x[0-9A-Fa-f]+|\bs\b|TeachPad|\d+")


def _trail(folder: Path) -> None:
    audit = AuditLog(folder)
    audit.record("login", "log in as engineer")
    audit.record("action", "edit envelope")
    audit.record_refused("jog", "jog refused: the TCP would leave the work space")
    with audit.writing(
        registers.REG_RUN_COMMAND, [int(RunCommand.RUN_PROGRAM)], single=True, judged=True
    ) as w:
        pass
    reason = Reason(
        "no_motion", {"operation": "run program", "command": int(RunCommand.RUN_PROGRAM), "seconds": 2}
    )
    result = CommandResult(RunCommand.RUN_PROGRAM, None, None, False, "run program 7: ...", reason=reason)
    audit.record_result(w, "refused", result.message, outcome_args(result))
    audit.close()


def _column(model: AuditModel, name: str) -> list[str]:
    col = AuditModel.COLUMNS.index(name)
    return [model.data(model.index(row, col), Qt.ItemDataRole.DisplayRole) for row in range(model.rowCount())]


def test_the_audit_viewer_words_commands_and_outcomes_in_chinese(
    qapp: Any, translator: Any, tmp_path: Path
) -> None:
    _trail(tmp_path)
    model = AuditModel()
    model.set_records(query(tmp_path))
    english = _column(model, "command")
    assert english[:2] == ["log in as engineer", "edit envelope"]
    assert translator.set_language("zh_CN")
    commands, details = _column(model, "command"), _column(model, "detail")
    assert commands[:3] == ["以工程师身份登录", "编辑安全范围", "点动"]
    assert commands[3].startswith("运行程序（440 ← "), commands
    assert "2 s 内没有运动" in details[3], details
    for text in [*commands, details[3]]:
        assert not re.search(r"[A-Za-z]{3,}", KEPT.sub("", text)), f"English left in {text!r}"
    # the record keeps English
    assert [r.command for r in query(tmp_path)][:2] == ["log in as engineer", "edit envelope"]


def test_the_refusals_details_read_in_chinese(qapp: Any, translator: Any, tmp_path: Path) -> None:
    """A role refusal and an envelope refusal keep their reason's code beside the English; the
    viewer words them (was the English "change connection: needs the administrator role ...")."""
    import pytest

    from app.models import Pose
    from app.safety.box import Box
    from app.safety.envelope import Envelope, EnvelopeRefused
    from app.safety.roles import Action, RoleStore
    from app.safety.session import PermissionRefused, SafetySession

    session = SafetySession(RoleStore(tmp_path / "roles.json", scrypt_n=2**8), AuditLog(tmp_path / "audit"))
    session.envelope = Envelope(keep_in=Box("cell", (-1000, -100, -1000), (1000, 1000, 1000)))
    with pytest.raises(PermissionRefused):
        session.require(Action.CONNECTION, {"host": "10.0.0.9"})
    with pytest.raises(EnvelopeRefused):
        session.check_step(Pose(0.0, 0.0, 500.0, 180.0, 0.0, 90.0), [0, -200, 0, 0, 0, 0], joint=False)
    session.audit.close()
    records = [r for r in query(tmp_path / "audit") if r.kind == "refused"]
    assert records[0].detail.startswith("change connection: needs the administrator role")  # kept
    model = AuditModel()
    model.set_records(records)
    assert translator.set_language("zh_CN")
    details = _column(model, "detail")
    assert details[0] == "需要管理员角色（当时登录的是操作员）", details
    assert "Y = " in details[1] and "工作空间" in details[1], details
    for text in details:
        assert not re.search(r"[A-Za-z]{3,}", KEPT.sub("", text)), f"English left in {text!r}"
