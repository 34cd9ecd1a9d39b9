"""Point provenance in the window (the points table's tooltip) and *File → Compare with…*."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.points.ledger_import import ImportMode
from app.points.point import make_point
from app.points.project import load_project, save_project, write_points_csv
from app.points.provenance import Origin
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    FakeProjectDialogs,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.models.point_columns import COL_NAME, COL_X

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _tip(window: Any, row: int, column: int = COL_NAME) -> str:
    model = window.project.points_model
    return str(model.data(model.index(row, column), Qt.ItemDataRole.ToolTipRole))


def test_taught_typed_and_edited_points_say_how_where_and_when(qtbot: Any, sim: Any, window: Any) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    with qtbot.waitSignal(window.point_sync.pointTaught, timeout=SIGNAL_TIMEOUT_MS):
        assert window.point_sync.teach() is not None
    model = window.project.points_model
    taught = model.ledger[0].made
    assert taught.origin is Origin.TAUGHT and taught.controller == f"127.0.0.1:{sim.port} unit 1"
    assert taught.time.endswith("Z") and taught.software.startswith("TeachPad")
    tip = _tip(window, 0)
    assert (
        tip.startswith("Made: taught from the pose\n") and f"Controller: 127.0.0.1:{sim.port} unit 1" in tip
    )
    assert _tip(window, 0, COL_X) == tip  # the pose cells say it too

    row = model.add_point(name="typed")
    assert model.ledger[row].made.origin is Origin.TYPED
    assert _tip(window, row).startswith("Made: typed\n")
    model.edit_field(row, "x", 12.5)
    made = model.ledger[row].made
    assert made.origin is Origin.TYPED and made.edited and made.edited_controller.endswith("unit 1")
    assert "Last edited: " in _tip(window, row)
    window.project.action_undo.trigger()
    assert not model.ledger[row].made.edited  # the undo puts the history back too


def test_provenance_is_saved_and_an_import_records_its_file(
    qtbot: Any, window: Any, tmp_path: Path, project_dialogs: FakeProjectDialogs
) -> None:
    csv_path = tmp_path / "line 4.csv"
    write_points_csv(csv_path, [make_point(3, "a", (1.0, 2.0, 3.0, 0.0, 0.0, 0.0))])
    assert window.project.import_csv(csv_path, ImportMode.REPLACE)
    assert _tip(window, 0).startswith("Made: imported\nFile: line 4.csv\n")
    target = tmp_path / "saved.teachpad.json"
    project_dialogs.save_answer = str(target)
    assert window.project.save_as()
    made = load_project(target).ledger[0].made
    assert (made.origin, made.file) == (Origin.IMPORTED, "line 4.csv")


def test_an_old_project_says_made_unknown(window: Any, tmp_path: Path) -> None:
    sample = Path(__file__).resolve().parents[2] / "resources" / "samples" / "demo.teachpad.json"
    copy = tmp_path / "demo.teachpad.json"
    copy.write_bytes(sample.read_bytes())
    assert window.project.open_file(copy)
    assert _tip(window, 0) == "Made: unknown (saved before TeachPad recorded how points are made)"


def test_compare_with_shows_what_the_cli_lists(
    qtbot: Any, window: Any, tmp_path: Path, project_dialogs: FakeProjectDialogs
) -> None:
    model = window.project.points_model
    for x in (0.0, 100.0, 200.0):
        model.add_point(pose=(x, 0.0, 300.0, 180.0, 0.0, 0.0))
    mine = list(model.ledger)
    moved = make_point(2, "", (100.2, 0.0, 300.0, -179.95, 0.0, 0.0))  # 0.2 mm, 0.05 deg across the wrap
    other = [mine[0], moved, make_point(9, "new", (5.0, 5.0, 5.0, 0.0, 0.0, 0.0))]  # P3 removed, P9 added
    csv_path = tmp_path / "other.csv"
    write_points_csv(csv_path, other)
    actions = window.menus.file_menu.actions()
    action = window.compare.action
    assert action in actions and actions.index(action) == actions.index(window.project.action_export_csv) + 1
    project_dialogs.open_answer = str(csv_path)
    action.trigger()
    dialog = window.compare.dialog
    assert dialog is not None and dialog.isVisible()
    kinds = [(c.kind.value, c.point_id) for c in dialog.diff.changes]
    assert kinds == [("moved", 2), ("removed", 3), ("added", 9)]
    assert dialog.table.rowCount() == 3 and dialog.table.item(0, 2).text() == "0.200"
    assert dialog.table.item(0, 3).text() == "0.05"
    dialog.tol_mm.setValue(0.3)  # over the move now: listed no more
    assert [c.point_id for c in dialog.diff.changes] == [3, 9] and dialog.table.rowCount() == 2
    # a row's tooltip says how the point was made: P3 in A (typed here), P9 in B (the CSV)
    assert dialog.table.item(0, 0).toolTip().startswith("In A:\nMade: typed\n")
    assert dialog.table.item(1, 0).toolTip().startswith("In B:\nMade: imported\nFile: other.csv\n")
    dialog.close()


def test_compare_with_a_malformed_file_says_one_clear_message(
    window: Any, tmp_path: Path, project_dialogs: FakeProjectDialogs
) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("id,x,y,z,a,b,c\n1,abc,0,0,0,0,0\n", encoding="utf-8")
    assert window.compare.compare_with(bad) is None
    [(title, text)] = project_dialogs.errors
    assert title == "Cannot compare" and "\n" not in text and "abc" in text
    assert window.compare.dialog is None


def test_save_keeps_a_taught_point_history(tmp_path: Path) -> None:
    # (the file side of the window's points: app/points tests cover the format in full)
    from app.points.ledger import PointLedger
    from app.points.point import with_provenance
    from app.points.project_model import Project
    from app.points.provenance import stamp

    point = with_provenance(make_point(1), stamp(Origin.TAUGHT, controller="c unit 1"))
    save_project(Project(ledger=PointLedger([point])), tmp_path / "p.teachpad.json")
    assert load_project(tmp_path / "p.teachpad.json").ledger[0].made.controller == "c unit 1"
