"""The role dialog: the first administrator password, a wrong password, logging in and out."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from app.safety.location import safety_location
from app.safety.roles import Role
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
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
    dialog.repeat.setText("root-pw")
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


def _first_admin(qtbot: Any, tmp_path: Path) -> tuple[SafetyController, RoleDialog]:
    safety = _safety(qtbot, tmp_path)
    dialog = RoleDialog(safety)
    qtbot.addWidget(dialog)
    dialog.role_box.setCurrentIndex(dialog.role_box.findData(Role.ADMINISTRATOR))
    return safety, dialog


def test_the_first_administrator_password_is_typed_twice_and_confirmed(qtbot: Any, tmp_path: Path) -> None:
    """Issue 21: one typo in the first administrator password locked the administrator out."""
    safety, dialog = _first_admin(qtbot, tmp_path)
    assert not dialog.repeat.isHidden()
    dialog.password.setText("root-pw")
    dialog.repeat.setText("root-pq")
    dialog.set_password()
    assert not safety.session.store.has_password(Role.ADMINISTRATOR)
    assert "differ" in dialog.error.text() and "nothing was set" in dialog.error.text()
    assert dialog.password.text() == dialog.repeat.text() == ""
    dialog.password.setText("root-pw")
    dialog.repeat.setText("root-pw")
    dialog.set_password()
    assert safety.session.store.verify(Role.ADMINISTRATOR, "root-pw")
    assert dialog.error.text() == "Password set for the administrator role"  # stays, not a red hint
    assert "c62828" not in dialog.error.styleSheet()
    assert dialog.repeat.isHidden()  # the Passwords screen's from now on
    safety.close()


def test_the_first_password_reads_in_chinese(qtbot: Any, tmp_path: Path, translator: Any) -> None:
    assert translator.set_language("zh_CN")
    safety, dialog = _first_admin(qtbot, tmp_path)
    assert "两次" in dialog.error.text()  # the hint: type it twice
    dialog.password.setText("a-Pa55")
    dialog.repeat.setText("b-Pa55")
    dialog.set_password()
    assert dialog.error.text().startswith("两次输入的密码不一致")
    dialog.password.setText("a-Pa55")
    dialog.repeat.setText("a-Pa55")
    dialog.set_password()
    assert dialog.error.text().startswith("已设置") and not any("a" <= c <= "z" for c in dialog.error.text())
    safety.close()
