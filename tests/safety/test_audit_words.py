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
