"""The safety state does not follow ``teachpad --settings FILE`` (issue 19 s5): the role store, the
envelope, the register profile and the audit trail are where :func:`app.safety.location.
safety_location` says -- machine-wide when an administrator made that folder, else the user's --
for the GUI and the CLI alike, whatever settings file the GUI was started with."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import Any

import pytest

from app.cli.main import main as cli_main
from app.safety import location
from app.safety.audit_read import Result, query, read_records
from app.safety.box import Box
from app.safety.envelope import Envelope
from app.safety.location import Scope, safety_location
from app.safety.profile import SafetyProfile, load_profile, save_profile
from app.safety.register_profile import RegisterProfile, save_register_profile
from app.safety.roles import Role, RoleStore, WrongPassword, default_store_path
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.dialogs.role_dialog import RoleDialog

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

ADMIN_PW = "site-admin-1"
BOX = Box("cell", (100.0, -300.0, 0.0), (700.0, 300.0, 620.0))


@pytest.fixture(name="real_state")
def real_state_fixture() -> SafetyProfile:
    """The site's safety state, set up before TeachPad starts: an administrator password, an
    envelope at revision 3 with a keep-in box (the test's own per-user folders, tests/conftest.py)."""
    where = safety_location()
    RoleStore(where.roles, scrypt_n=2**4).set_password(Role.ADMINISTRATOR, ADMIN_PW, by=Role.ADMINISTRATOR)
    where.config_dir.mkdir(parents=True, exist_ok=True)
    profile = SafetyProfile("cell 3", Envelope(keep_in=BOX), revision=2)
    return save_profile(where.envelope, profile)


def test_a_settings_file_in_a_fresh_folder_does_not_move_the_safety_state(
    real_state: SafetyProfile, window: Any, app_settings: Any, tmp_path: Path, qtbot: Any
) -> None:
    # ``window`` is TeachPad started with ``--settings <tmp_path>/teachpad.ini``: a fresh folder
    assert Path(app_settings.store.fileName()).parent == tmp_path
    safety = window.safety_menu.safety
    where = safety_location()
    assert safety.location == where and where.scope is Scope.USER
    # the roles: the administrator password set in the real store is asked for
    dialog = RoleDialog(safety)
    qtbot.addWidget(dialog)
    assert "No administrator password" not in dialog.error.text()
    dialog.role_box.setCurrentIndex(dialog.role_box.findData(Role.ADMINISTRATOR))
    assert not dialog.set_password_button.isEnabled()  # not "the first one: anyone"
    dialog.password.setText("anything")
    dialog.log_in()
    refused_role = safety.role
    assert refused_role is Role.OPERATOR and "Wrong password" in dialog.error.text()
    dialog.password.setText(ADMIN_PW)
    dialog.log_in()
    admin_role = safety.role
    assert admin_role is Role.ADMINISTRATOR
    # the envelope: the real one, its revision and its keep-in box
    assert safety.profile.revision == real_state.revision == 3
    assert safety.envelope.keep_in == BOX
    assert load_profile(where.envelope).revision == 3  # not replaced by a fresh install's
    # the audit: the records land in the real audit folder
    logins = [r for r in read_records(where.audit_dir) if r.kind == "login"]
    assert [r.result for r in logins][-2:] == [Result.REFUSED, Result.OK]
    assert not (tmp_path / "safety").exists()  # nothing beside the settings file
    # the register profile: the one in force is the real one
    assert app_settings.register_profile_path() == where.register_profile
    # Help -> About says where it all lives
    about = window._safety_state_text()
    assert str(where.config_dir) in about and str(where.audit_dir) in about


def test_the_cli_finds_the_store_and_the_audit_the_gui_uses(
    real_state: SafetyProfile, window: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    safety = window.safety_menu.safety
    with pytest.raises(WrongPassword):
        safety.login(Role.ADMINISTRATOR, "guess")
    assert default_store_path() == safety.session.store.path  # one role store for both
    assert cli_main(["roles", "show"]) == 0
    out = capsys.readouterr().out
    assert "administrator password set" in " ".join(out.split())
    refused = [r for r in query(safety.audit_dir) if r.kind == "login" and r.result == Result.REFUSED]
    assert refused, "the GUI's refused login is not where the CLI reads the audit trail"


def test_a_machine_wide_folder_is_used_when_an_administrator_made_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    machine = tmp_path / "machine"
    monkeypatch.setattr(location, "machine_dir", lambda: machine)
    assert safety_location().scope is Scope.USER  # no folder: TeachPad never creates it
    machine.mkdir()
    where = safety_location()
    assert where.scope is Scope.MACHINE and where.roles == machine / "roles.json"
    assert where.audit_dir == machine / "audit" and where.envelope == machine / "envelope.safety.json"
    assert default_store_path() == machine / "roles.json"
    saved = save_register_profile(where.register_profile, RegisterProfile("unit 7", unit=7))
    assert saved.revision == 1 and where.register_profile.parent == machine
    assert str(machine) in where.describe() and "machine-wide" in where.describe()


def test_the_support_bundle_says_where_the_safety_state_lives(window: Any, tmp_path: Path) -> None:
    menu = window.safety_menu
    out = tmp_path / "bundle.zip"
    menu.save_path = lambda _title, _suggested: str(out)
    assert menu.write_bundle() == out
    with zipfile.ZipFile(out) as zf:
        settings = json.loads(zf.read("settings.json"))
    where = safety_location()
    assert settings["safety_state"] == where.describe() and str(where.audit_dir) in settings["safety_state"]
