"""Roles in the main window: disabled (with the role needed in the tooltip), never hidden; the idle
lock; the envelope dialog, the audit viewer and the support bundle."""

from __future__ import annotations

import csv
import json
import zipfile
from pathlib import Path
from typing import Any

import pytest

from app.safety.audit_read import query
from app.safety.box import Box
from app.safety.envelope import Envelope
from app.safety.profile import load_profile
from app.safety.roles import Action, Role, WrongPassword
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.controllers.safety_menu import SafetyMenu
from ui.panels.audit_viewer import AuditViewer

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

PASSWORD = "cell-42"
SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"
CHEAP_SCRYPT = 2**4  # tests only: the real cost is 2**14


@pytest.fixture(name="menu")
def menu_fixture(window: Any) -> SafetyMenu:
    menu: SafetyMenu = window.safety_menu
    store = menu.safety.session.store
    store.scrypt_n = CHEAP_SCRYPT
    for role in (Role.ADMINISTRATOR, Role.ENGINEER):
        store.set_password(role, PASSWORD, by=Role.ADMINISTRATOR)
    return menu


def test_an_operator_cannot_change_the_connection(menu: SafetyMenu, window: Any) -> None:
    action = window.menus.connect_action
    assert menu.safety.role is Role.OPERATOR
    assert not action.isEnabled() and action in window.menus.file_menu.actions()  # disabled, not hidden
    assert "administrator" in action.toolTip()
    assert not menu.safety.allowed(Action.CONNECTION)  # used anyway (a shortcut): refused and audited
    refused = [r for r in query(menu.safety.audit_dir) if r.result == "refused"]
    assert refused and refused[-1].command == "change connection"
    menu.safety.login(Role.ADMINISTRATOR, PASSWORD)
    assert action.isEnabled() and "administrator" not in action.toolTip()


def test_an_engineer_edits_points_an_operator_does_not(qtbot: Any, menu: SafetyMenu, window: Any) -> None:
    panel = window.points_panel
    assert not panel.action_add.isEnabled() and "engineer" in panel.action_add.toolTip()
    assert not panel.table.editTriggers()
    assert not window.planner_panel.planner_actions["add_plan"].isEnabled()
    with pytest.raises(WrongPassword, match="wrong password"):
        menu.safety.login(Role.ENGINEER, "nope")
    menu.safety.login(Role.ENGINEER, PASSWORD)
    assert panel.action_add.isEnabled() and panel.table.editTriggers()
    assert window.planner_panel.planner_actions["add_plan"].isEnabled()
    n = len(window.project.points_model.ledger)
    panel.action_add.trigger()
    assert len(window.project.points_model.ledger) == n + 1
    assert not window.menus.connect_action.isEnabled()  # still the administrator's


def test_idle_locks_back_to_operator(qtbot: Any, menu: SafetyMenu, window: Any) -> None:
    menu.safety.login(Role.ENGINEER, PASSWORD)
    menu.safety.set_idle_timeout(0.05)
    with qtbot.waitSignal(menu.safety.roleChanged, timeout=5000):
        pass
    assert menu.safety.role is Role.OPERATOR
    assert not window.points_panel.action_add.isEnabled()
    assert any("locked back" in r.command for r in query(menu.safety.audit_dir))


def test_reduced_speed_on_by_anyone_off_by_an_engineer(menu: SafetyMenu) -> None:
    safety = menu.safety
    menu.reduced_action.setChecked(True)
    assert safety.session.reduced and safety.jog_ratio(80) == safety.envelope.reduced_jog_ratio
    menu.reduced_action.setChecked(False)  # an operator may not leave it
    assert safety.session.reduced and menu.reduced_action.isChecked()
    safety.login(Role.ENGINEER, PASSWORD)
    menu.reduced_action.setChecked(False)
    assert not safety.session.reduced and safety.jog_ratio(80) == 80


def test_envelope_dialog_saves_and_draws_the_boxes(qtbot: Any, menu: SafetyMenu, window: Any) -> None:
    from ui.dialogs.envelope_dialog import EnvelopeDialog

    assert not menu.envelope_action.isEnabled() and "engineer" in menu.envelope_action.toolTip()
    menu.safety.login(Role.ENGINEER, PASSWORD)
    assert menu.envelope_action.isEnabled()
    dialog = EnvelopeDialog(menu.safety, window)
    qtbot.addWidget(dialog)
    dialog.keep_in_on.setChecked(True)
    dialog.add_button.click()
    name_cell = dialog.keep_out.item(0, 0)
    assert name_cell is not None
    name_cell.setText("fixture")
    with qtbot.waitSignal(menu.safety.envelopeChanged, timeout=2000):
        dialog.save()
    saved = load_profile(menu.safety.profile_path)
    # revision 1 is the fresh install's (the robot model's defaults), saved at start
    assert saved.revision == 2 and [b.name for b in saved.envelope.keep_out] == ["fixture"]
    top = window.planner_panel.preview.projections["top"]
    assert len(top.keep_out.xData) == 24 and len(top.keep_in.xData) == 24
    view3d = getattr(window, "view3d", None)
    if view3d is not None:
        assert len(view3d.panel.canvas.keep_out_edges) == 24
    x_cell = dialog.keep_out.item(0, 1)
    assert x_cell is not None
    x_cell.setText("abc")  # not a number: refused, the dialog stays
    dialog.save()
    assert "not a number" in dialog.error.text()


def test_a_plan_through_a_keep_out_box_cannot_run(menu: SafetyMenu, window: Any) -> None:
    planner = window.planner_panel
    assert window.project.open_file(SAMPLE)
    planner.plans_box.plan_view.selectRow(0)
    ledger = window.project.points_model.ledger
    assert planner.current_plan() is not None and not any(i.is_error for i in planner.issues)
    xyz = [p.xyz for p in ledger]
    lo = tuple(min(c[i] for c in xyz) - 1000.0 for i in range(3))
    hi = tuple(max(c[i] for c in xyz) + 1000.0 for i in range(3))
    planner.set_envelope(Envelope(keep_out=(Box("everything", lo, hi),)))
    assert any(i.is_error for i in planner.issues)


def test_audit_viewer_filters_and_exports(qtbot: Any, menu: SafetyMenu, tmp_path: Path) -> None:
    safety = menu.safety
    safety.allowed(Action.CONNECTION)  # refused
    safety.login(Role.ENGINEER, PASSWORD)
    viewer = AuditViewer(safety.audit_dir, save_path=lambda _s: str(tmp_path / "out.csv"))
    qtbot.addWidget(viewer)
    assert viewer.model.rowCount() >= 2
    viewer.result_box.setCurrentIndex(viewer.result_box.findData("refused"))
    viewer.refresh()
    assert viewer.model.rowCount() == 1 and viewer.model.records[0].command == "change connection"
    viewer.export()
    assert (tmp_path / "out.csv").read_bytes().startswith(b"\xef\xbb\xbf")  # UTF-8 with a BOM, for Excel
    rows = list(csv.reader((tmp_path / "out.csv").read_text(encoding="utf-8-sig").splitlines()))
    assert rows[0][0] == "host_time" and len(rows) == 2


def test_support_bundle_leaves_passwords_out(menu: SafetyMenu, window: Any, tmp_path: Path) -> None:
    window.settings.store.setValue("connection/password", "secret")
    menu.safety.login(Role.ENGINEER, PASSWORD)  # something in the audit trail
    out = tmp_path / "bundle.zip"
    menu.save_path = lambda _t, _s: str(out)
    assert menu.write_bundle() == out
    with zipfile.ZipFile(out) as zf:
        names = zf.namelist()
        settings = json.loads(zf.read("settings.json"))
        left_out = json.loads(zf.read("manifest.json"))["left_out"]
    assert "versions.json" in names and any(n.startswith("audit/") for n in names)
    # never connected: no traffic, and the manifest says so (issue 21)
    assert "traffic.txt" not in names and any(n.startswith("Modbus traffic: no frames") for n in left_out)
    assert "secret" not in json.dumps(settings)


def test_a_move_to_a_point_outside_the_work_space_is_refused_before_sending(
    qtbot: Any, sim: Any, menu: SafetyMenu, window: Any
) -> None:
    from tests.ui.pendant_support import connect

    assert window.project.open_file(SAMPLE)
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    qtbot.waitUntil(lambda: window.link.state.pose is not None, timeout=5000)
    ledger = window.project.points_model.ledger
    target = max(ledger, key=lambda p: p.xyz[1])  # the point furthest along +Y
    menu.safety.login(Role.ENGINEER, PASSWORD)
    menu.safety.save_envelope(
        Envelope(keep_in=Box("cell", (-5000.0, -5000.0, -5000.0), (5000.0, target.xyz[1] - 10.0, 5000.0)))
    )
    panel = window.points_panel
    panel.select_rows([window.project.points_model.row_of(target.id)])
    writes = len(sim.writes)
    panel.move_to_selected()
    assert "outside the allowed work space" in panel.status.text()
    assert len(sim.writes) == writes  # nothing went out
    refused = [r for r in query(menu.safety.audit_dir) if r.result == "refused"]
    assert refused[-1].command == "move to point"
