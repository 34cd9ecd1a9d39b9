"""The register profile: the file (named, versioned, atomic, bad files refused in words), only the
administrator changes it (GUI control disabled with the reason, and refused programmatically), the
change is audited, and it really changes how the controller's floats are read."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.safety.audit import AuditLog
from app.safety.audit_read import Result, query
from app.safety.register_profile import (
    RegisterProfile,
    RegisterProfileError,
    active_profile,
    load_register_profile,
    profile_to_json,
    save_register_profile,
)
from app.safety.roles import Role, RoleStore
from app.safety.session import PermissionRefused, SafetySession
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.controllers.safety_menu import SafetyMenu
from ui.dialogs.connection_dialog import ConnectionDialog

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

PASSWORD = "cell-42"
CHEAP_SCRYPT = 2**4
HIGH = RegisterProfile(
    "cell 3 (ABCD)",
    word_order=WordOrder.HIGH_FIRST,
    unit=1,
    completion="observe",
    poll_timeout=0.3,
    datetime_layout=DateTimeLayout.PACKED32,
    point_id_max=9999,
)


# --- the file -------------------------------------------------------------------------------------


def test_saved_atomically_with_a_revision_and_read_back(tmp_path: Path) -> None:
    path = tmp_path / "safety" / "register.profile.json"
    first = save_register_profile(path, HIGH)
    assert first.revision == 1 and first.saved
    again = save_register_profile(path, first)
    assert again.revision == 2 and load_register_profile(path) == again
    assert not [p for p in path.parent.iterdir() if p.name.startswith(".teachpad-tmp")]
    doc = json.loads(path.read_text(encoding="utf-8"))
    assert doc["format"] == "teachpad-registers" and doc["word_order"] == "high-first"


def test_applied_to_the_connection_where_stays_where(tmp_path: Path) -> None:
    where = ConnectionSettings(host="10.0.0.9", port=1502, serial_port=None, timeout=0.7, monitor_only=True)
    applied = HIGH.apply(where)
    assert (applied.host, applied.port, applied.timeout) == ("10.0.0.9", 1502, 0.7) and applied.monitor_only
    assert applied.word_order is WordOrder.HIGH_FIRST and applied.completion == "observe"
    assert applied.poll_timeout == 0.3 and applied.point_id_max == 9999
    assert applied.datetime_layout is DateTimeLayout.PACKED32
    assert RegisterProfile.from_connection(applied, HIGH.name) == HIGH


@pytest.mark.parametrize(
    ("edit", "says"),
    [
        ({"word_order": "middle"}, "word_order must be one of low-first, high-first"),
        ({"unit": 300}, "unit must be a whole number 0..247"),
        ({"completion": "guess"}, "completion must be one of auto, sentinel, observe"),
        ({"poll_timeout": -1}, "poll_timeout must be empty (automatic)"),
        ({"point_id_min": 50, "point_id_max": 10}, "above point_id_max"),
        ({"version": 9}, "newer TeachPad"),
        ({"bogus": 1}, "unknown field 'bogus'"),
        ({"name": ""}, "name must be text"),
    ],
)
def test_a_bad_file_is_refused_naming_the_file_and_field(
    tmp_path: Path, edit: dict[str, Any], says: str
) -> None:
    doc = json.loads(profile_to_json(HIGH))
    doc.update(edit)
    path = tmp_path / "bad.registers.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    with pytest.raises(RegisterProfileError, match=r"register profile bad\.registers\.json") as info:
        load_register_profile(path)
    assert says in str(info.value)


def test_a_damaged_file_in_force_falls_back_and_says_so(tmp_path: Path) -> None:
    path = tmp_path / "register.profile.json"
    assert active_profile(path, HIGH) == (HIGH, "")  # none saved yet: the fallback, no problem
    path.write_text("{not json", encoding="utf-8")
    profile, problem = active_profile(path, HIGH)
    assert profile == HIGH and "not valid JSON" in problem and "administrator" in problem


def test_only_the_administrator_changes_it_and_it_is_audited(tmp_path: Path) -> None:
    store = RoleStore(tmp_path / "roles.json", scrypt_n=CHEAP_SCRYPT)
    store.set_password(Role.ADMINISTRATOR, PASSWORD, by=Role.ADMINISTRATOR)
    session = SafetySession(store, AuditLog(tmp_path / "audit"))
    path = tmp_path / "register.profile.json"
    with pytest.raises(PermissionRefused, match="needs the administrator role"):
        session.set_register_profile(path, HIGH, RegisterProfile())
    assert not path.exists()
    session.login(Role.ADMINISTRATOR, PASSWORD)
    saved = session.set_register_profile(path, HIGH, RegisterProfile())
    assert load_register_profile(path) == saved and saved.revision == 1
    refused, changed = [r for r in query(tmp_path / "audit") if "register profile" in r.command]
    assert refused.result == Result.REFUSED and refused.role == "operator"
    assert changed.role == "administrator" and changed.args["revision"] == 1
    assert changed.args["changes"]["word_order"] == ["low-first", "high-first"]


# --- in the window ----------------------------------------------------------------------------------


@pytest.fixture(name="menu")
def menu_fixture(window: Any) -> SafetyMenu:
    menu: SafetyMenu = window.safety_menu
    store = menu.safety.session.store
    store.scrypt_n = CHEAP_SCRYPT
    store.set_password(Role.ADMINISTRATOR, PASSWORD, by=Role.ADMINISTRATOR)
    return menu


def test_an_operator_cannot_change_the_register_profile(menu: SafetyMenu, window: Any) -> None:
    action = menu.register_profile_action
    assert action in menu.menu.actions() and not action.isEnabled()  # disabled, not hidden
    assert action.toolTip().startswith("Needs the administrator role")
    path = window.settings.register_profile_path()
    why = menu.apply_register_profile(HIGH)  # used anyway (programmatically): refused
    assert why is not None and "administrator" in why and not path.exists()
    dialog = menu.register_profile_dialog()  # opened anyway: every field disabled, with the reason
    assert not dialog.order_combo.isEnabled() and "administrator" in dialog.order_combo.toolTip()
    dialog.close()
    refused = [r for r in query(menu.safety.audit_dir) if r.result == Result.REFUSED]
    assert refused[-1].command == "change register profile"
    menu.safety.login(Role.ADMINISTRATOR, PASSWORD)
    assert action.isEnabled() and action.toolTip().startswith("Word order")  # its own tooltip back


def test_the_connection_dialog_shows_the_profiles_unit_and_word_order(
    menu: SafetyMenu, window: Any, qtbot: Any
) -> None:
    menu.safety.login(Role.ADMINISTRATOR, PASSWORD)
    assert menu.apply_register_profile(HIGH) is None
    saved = window.settings.connection()
    assert saved.word_order is WordOrder.HIGH_FIRST and saved.completion == "observe"
    dialog = ConnectionDialog.for_link(window.link, saved, 50.0)
    qtbot.addWidget(dialog)
    assert not dialog.order_combo.isEnabled() and "register profile" in dialog.order_combo.toolTip()
    dialog.host_edit.setText("10.1.1.1")
    out = dialog.settings()
    assert out.host == "10.1.1.1" and out.word_order is WordOrder.HIGH_FIRST and out.poll_timeout == 0.3


def test_a_changed_word_order_changes_how_the_floats_are_read(
    menu: SafetyMenu, window: Any, qtbot: Any, sim_factory: Any
) -> None:
    """The simulator speaks high word first; the default profile reads its pose as nonsense; an
    administrator saves a high-first profile in the dialog (reconnect now) and the pose is right."""
    sim = sim_factory(word_order=WordOrder.HIGH_FIRST)
    truth = sim.robot.pose
    window.settings.save_connection(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=0.5))
    link = window.link
    with qtbot.waitSignal(link.state.poseChanged, timeout=SIGNAL_TIMEOUT_MS):
        window.connect_with(window.settings.connection())
    assert link.settings.word_order is WordOrder.LOW_FIRST

    def reads_truth() -> bool:
        pose = link.state.pose
        return pose is not None and all(abs(a - b) < 1e-3 for a, b in zip(pose.xyzabc, truth, strict=True))

    assert not reads_truth()  # the words swapped: another number entirely
    menu.safety.login(Role.ADMINISTRATOR, PASSWORD)
    dialog = menu.register_profile_dialog()
    qtbot.addWidget(dialog)
    assert dialog.reconnect_check.isChecked()  # connected: reconnect now is offered
    dialog.name_edit.setText("cell 3")
    dialog.order_combo.setCurrentIndex(dialog.order_combo.findData(WordOrder.HIGH_FIRST.value))
    dialog.accept()
    assert dialog.result() == dialog.DialogCode.Accepted, dialog.error.text()
    qtbot.waitUntil(reads_truth, timeout=SIGNAL_TIMEOUT_MS)
    assert link.settings.word_order.value == "high-first"  # (a value: mypy kept it narrowed above)
    assert load_register_profile(window.settings.register_profile_path()).name == "cell 3"
    assert window.settings.connection().word_order is WordOrder.HIGH_FIRST  # the next start too


def test_load_and_save_as_in_the_dialog(menu: SafetyMenu, qtbot: Any, tmp_path: Path) -> None:
    menu.safety.login(Role.ADMINISTRATOR, PASSWORD)
    dialog = menu.register_profile_dialog()
    qtbot.addWidget(dialog)
    source = tmp_path / "cell3.registers.json"
    source.write_text(profile_to_json(HIGH), encoding="utf-8")
    dialog.open_path = lambda: str(source)
    dialog.load()
    assert dialog.edited().word_order is WordOrder.HIGH_FIRST and dialog.edited().poll_timeout == 0.3
    assert "Save and apply" in dialog.error.text()
    dialog.unconfirmed_spin.setValue(dialog.unconfirmed_spin.minimum())
    assert dialog.edited().unconfirmed_after is None  # the lowest value is "automatic"
    copy = tmp_path / "copy.registers.json"
    dialog.save_path = lambda _suggested: str(copy)
    dialog.save_as()
    assert load_register_profile(copy).name == HIGH.name
    (tmp_path / "junk.json").write_text("[]", encoding="utf-8")
    dialog.open_path = lambda: str(tmp_path / "junk.json")
    dialog.load()
    assert "not a TeachPad register profile" in dialog.error.text()


def test_the_support_bundle_carries_the_register_profile(menu: SafetyMenu, tmp_path: Path) -> None:
    menu.safety.login(Role.ADMINISTRATOR, PASSWORD)
    assert menu.apply_register_profile(HIGH) is None
    out = tmp_path / "bundle.zip"
    menu.save_path = lambda _t, _s: str(out)
    assert menu.write_bundle() == out
    with zipfile.ZipFile(out) as zf:
        doc = json.loads(zf.read("register-profile.json"))
    assert doc["name"] == HIGH.name and doc["word_order"] == "high-first" and doc["revision"] == 1
