"""The administrator's password screen: which role has a password, set / change / clear, the idle
lock time; the operator cannot open it (menu disabled with the reason) nor use it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from app.errors import InvalidInput
from app.safety.audit_read import Result, query
from app.safety.location import safety_location
from app.safety.roles import Role
from app.safety.session import PermissionRefused
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.controllers.safety import SafetyController
from ui.dialogs.password_dialog import PasswordDialog

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

ADMIN_PW = "root-pw"


@pytest.fixture(name="safety")
def safety_fixture(qtbot: Any, tmp_path: Path) -> Any:
    controller = SafetyController(None, scrypt_n=2**4)
    controller.set_idle_polling(False)
    controller.session.set_password(Role.ADMINISTRATOR, ADMIN_PW)  # the first one: anyone
    yield controller
    controller.close()


def _cell(dialog: PasswordDialog, role: Role) -> str:
    item = dialog.table.item(int(role), 1)
    assert item is not None
    return item.text()


def _roles_file(tmp_path: Path) -> str:
    return safety_location().roles.read_text(encoding="utf-8")


def test_an_administrator_sets_changes_and_clears_passwords(qtbot: Any, safety: Any, tmp_path: Path) -> None:
    safety.login(Role.ADMINISTRATOR, ADMIN_PW)
    dialog = PasswordDialog(safety)
    qtbot.addWidget(dialog)
    state = [_cell(dialog, role) for role in Role]
    assert state[0].startswith("not needed") and state[1].startswith("not set") and state[2] == "set"
    dialog.table.selectRow(int(Role.ENGINEER))
    assert not dialog.clear_button.isEnabled()  # nothing to clear yet
    dialog.password.setText("eng-1")
    dialog.repeat.setText("eng-2")
    dialog.set_password()
    assert "differ" in dialog.message.text() and not safety.session.store.has_password(Role.ENGINEER)
    dialog.password.setText("eng-1")
    dialog.repeat.setText("eng-1")
    dialog.set_password()
    assert _cell(dialog, Role.ENGINEER) == "set" and dialog.password.text() == ""
    assert safety.session.store.verify(Role.ENGINEER, "eng-1")
    dialog.password.setText("eng-22")
    dialog.repeat.setText("eng-22")
    dialog.set_password()  # change
    assert safety.session.store.verify(Role.ENGINEER, "eng-22")
    assert "eng-1" not in _roles_file(tmp_path) and "scrypt" in _roles_file(tmp_path)
    dialog.clear_button.click()
    assert not safety.session.store.has_password(Role.ENGINEER)
    assert _cell(dialog, Role.ENGINEER).startswith("not set")
    dialog.table.selectRow(int(Role.ADMINISTRATOR))
    assert not dialog.clear_button.isEnabled()  # changed, never removed (anyone could then set it)
    with pytest.raises(InvalidInput, match="changed, not removed"):
        safety.session.clear_password(Role.ADMINISTRATOR)
    dialog.idle.setValue(3)
    dialog.idle.editingFinished.emit()
    assert safety.session.idle.timeout == 180.0 and '"idle_timeout": 180.0' in _roles_file(tmp_path)
    commands = [r.command for r in query(safety.audit_dir) if r.kind == "action"]
    assert commands[-4:] == [
        "set the engineer password",
        "change the engineer password",
        "clear the engineer password",
        "set the idle lock time",
    ]
    assert not any("eng-" in str(r.args) + r.detail for r in query(safety.audit_dir))


def test_the_operator_cannot_use_it(qtbot: Any, safety: Any) -> None:
    dialog = PasswordDialog(safety)  # opened anyway: everything disabled, with the reason
    qtbot.addWidget(dialog)
    assert not dialog.set_button.isEnabled() and not dialog.idle.isEnabled()
    assert "administrator" in dialog.set_button.toolTip() and "administrator" in dialog.message.text()
    with pytest.raises(PermissionRefused):
        safety.session.set_password(Role.ENGINEER, "sneaky")
    with pytest.raises(PermissionRefused):
        safety.session.set_idle_timeout(9999)
    assert not safety.session.store.has_password(Role.ENGINEER)
    refused = [r for r in query(safety.audit_dir) if r.result == Result.REFUSED]
    assert [r.command for r in refused] == ["manage roles and passwords"] * 2


def test_the_menu_entry_is_the_administrators(window: Any) -> None:
    menu = window.safety_menu
    menu.safety.session.store.scrypt_n = 2**4
    menu.safety.session.set_password(Role.ADMINISTRATOR, ADMIN_PW)
    action = menu.passwords_action
    assert action in menu.menu.actions() and not action.isEnabled()
    assert action.toolTip().startswith("Needs the administrator role")
    menu.open_password_dialog()  # a shortcut anyway: refused, no dialog
    menu.safety.login(Role.ADMINISTRATOR, ADMIN_PW)
    assert action.isEnabled()
