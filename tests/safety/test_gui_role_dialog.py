"""The role dialog: the first administrator password, a wrong password, logging in and out."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from app.safety.location import safety_location
from app.safety.roles import Role
from ui.controllers.safety import SafetyController
from ui.dialogs.role_dialog import RoleDialog


def _safety(qtbot: Any, tmp_path: Path) -> SafetyController:
    safety = SafetyController(None, scrypt_n=2**4)
    safety.set_idle_polling(False)
    return safety


def test_first_admin_password_then_log_in_and_out(qtbot: Any, tmp_path: Path) -> None:
    safety = _safety(qtbot, tmp_path)
    assert safety.audit_dir == safety_location().audit_dir  # the test's own folder (tests/conftest.py)
    dialog = RoleDialog(safety)
    qtbot.addWidget(dialog)
    assert "No administrator password" in dialog.error.text()
    dialog.role_box.setCurrentIndex(dialog.role_box.findData(Role.ADMINISTRATOR))
    assert dialog.set_password_button.isEnabled()  # the first one: anyone
    dialog.password.setText("root-pw")
    dialog.set_password()
    assert safety.session.store.has_password(Role.ADMINISTRATOR)
    assert not dialog.set_password_button.isEnabled()  # now only an administrator
    dialog.password.setText("wrong")
    dialog.log_in()
    refused = safety.role  # a local, so mypy does not keep safety.role narrowed past log_in()
    assert "Wrong password" in dialog.error.text() and refused is Role.OPERATOR
    dialog.password.setText("root-pw")
    dialog.log_in()
    admin = safety.role  # a local again: log_out() below changes the role
    assert admin is Role.ADMINISTRATOR and dialog.result() == RoleDialog.DialogCode.Accepted
    again = RoleDialog(safety)
    qtbot.addWidget(again)
    assert again.set_password_button.isHidden()  # passwords are now the Passwords screen's
    again.log_out()
    assert safety.role is Role.OPERATOR
    stored = safety_location().roles.read_text(encoding="utf-8")
    assert "root-pw" not in stored and "scrypt" in stored.lower()
    safety.close()
