"""PointsModel: Qt model checks, validated cell edits, undo / redo of every edit, sync states."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoStack

from app.models import Pose
from app.plan.segments import Plan, Segment
from app.points.point import SyncState, TempPoint, make_point
from app.points.project import load_project
from app.points.project_model import Project
from app.points.upload import UploadOutcome, UploadReport
from ui.models.point_columns import COL_ID, COL_NAME, COL_SYNC, COL_TOOL, COL_X, COLUMNS
from ui.models.point_filter import PointFilterProxy
from ui.models.points_model import PointsModel

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"
COL_Y = COLUMNS.index("y")


def on_controller(point: TempPoint) -> TempPoint:
    return make_point(
        point.id, point.name, point.xyzabc, point.ext, point.tool, point.note, sync=SyncState.ON_CONTROLLER
    )


@pytest.fixture
def model(qtbot: Any) -> PointsModel:
    project = load_project(SAMPLE)
    # P1..P3 on the controller, the rest as in the file
    project.ledger.replace_all([on_controller(p) if p.id <= 3 else p for p in project.ledger])
    return PointsModel(project, QUndoStack())


def cell(model: PointsModel, row: int, column: int, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
    return model.data(model.index(row, column), role)


def test_model_passes_qt_model_tester_through_edits(qtmodeltester: Any, model: PointsModel) -> None:
    qtmodeltester.check(model, force_py=False)
    stack = model.undo_stack
    model.add_point(2)
    model.duplicate_rows([0, 4])
    model.remove_rows([1, 5, 6])
    model.move_rows([0, 1], 1)
    model.move_rows([3], -1)
    model.setData(model.index(0, COL_X), "12.5")
    model.import_points([make_point(40, "", (1, 2, 3, 4, 5, 6))])
    while stack.canUndo():
        stack.undo()
    while stack.canRedo():
        stack.redo()
    qtmodeltester.check(model, force_py=False)


def test_display_edit_and_decoration_roles(model: PointsModel) -> None:
    assert model.columnCount() == 16 and model.rowCount() == 8
    assert cell(model, 0, COL_ID) == "1"
    assert cell(model, 0, COL_X) == "400.000"
    assert cell(model, 0, COL_X, Qt.ItemDataRole.EditRole) == "400.0"
    assert cell(model, 0, COL_TOOL) == "none"
    assert cell(model, 0, COL_SYNC) == "on controller"
    assert cell(model, 5, COL_SYNC) == "unknown"
    assert cell(model, 0, COL_SYNC, Qt.ItemDataRole.BackgroundRole) is not None
    assert not model.flags(model.index(0, COL_SYNC)) & Qt.ItemFlag.ItemIsEditable
    assert model.flags(model.index(0, COL_X)) & Qt.ItemFlag.ItemIsEditable


@pytest.mark.parametrize(
    ("column", "text", "reason"),
    [
        ("x", "nan", "not a finite number"),
        ("y", "inf", "not a finite number"),
        ("z", "abc", "'abc' is not a number"),
        ("id", "10001", "outside 0..10000"),
        ("id", "-3", "outside 0..10000"),
        ("id", "2", "already used by P2"),
        ("id", "2.5", "not an integer"),
        ("tool", "201", "is not 0..199"),
        ("x", "", "empty"),
    ],
)
def test_bad_cell_input_is_refused_with_a_message(
    qtbot: Any, model: PointsModel, column: str, text: str, reason: str
) -> None:
    before = model.ledger.snapshot()
    with qtbot.waitSignal(model.editRejected) as blocker:
        ok = model.setData(model.index(0, COLUMNS.index(column)), text)
    assert ok is False
    message = blocker.args[0]
    assert reason in message and "P1" in message
    assert model.ledger.snapshot() == before
    assert model.undo_stack.count() == 0


def test_editing_a_pose_marks_changed_name_does_not(model: PointsModel) -> None:
    assert model.setData(model.index(0, COL_NAME), "home 2")
    assert model.point_at(0).sync is SyncState.ON_CONTROLLER
    assert model.setData(model.index(0, COL_Y), "5")
    assert model.point_at(0).sync is SyncState.CHANGED
    assert model.point_at(0).y == 5.0
    # editing back to what the controller holds: on the controller again
    assert model.setData(model.index(0, COL_Y), "0")
    assert model.point_at(0).sync is SyncState.ON_CONTROLLER
    # unchanged value: no undo step
    count = model.undo_stack.count()
    assert model.setData(model.index(0, COL_Y), "0.0")
    assert model.undo_stack.count() == count


def test_tool_accepts_none_words(model: PointsModel) -> None:
    assert model.setData(model.index(0, COL_TOOL), "3")
    assert model.point_at(0).tool == 3
    assert model.setData(model.index(0, COL_TOOL), "none")
    assert model.point_at(0).tool == 200


def test_undo_redo_edit(model: PointsModel) -> None:
    model.setData(model.index(1, COL_X), "451.5")
    assert model.point_at(1).x == 451.5 and model.point_at(1).sync is SyncState.CHANGED
    model.undo_stack.undo()
    assert model.point_at(1).x == 450.0 and model.point_at(1).sync is SyncState.ON_CONTROLLER
    model.undo_stack.redo()
    assert model.point_at(1).x == 451.5


def test_undo_redo_add_duplicate_delete(model: PointsModel) -> None:
    stack = model.undo_stack
    ids = model.ledger.ids()
    row = model.add_point(1)
    assert row == 1 and model.point_at(1).id == 9 and model.point_at(1).sync is SyncState.CHANGED
    stack.undo()
    assert model.ledger.ids() == ids
    stack.redo()
    assert model.ledger.ids() == [1, 9, 2, 3, 4, 5, 6, 7, 8]
    stack.undo()
    rows = model.duplicate_rows([0, 2])
    assert rows == [1, 4]
    assert model.ledger.ids() == [1, 9, 2, 3, 10, 4, 5, 6, 7, 8]
    assert model.point_at(1).name == model.point_at(0).name
    assert model.point_at(1).sync is SyncState.CHANGED
    stack.undo()
    assert model.ledger.ids() == ids
    # delete several: one undo step brings them back where they were, with their state
    before = model.ledger.snapshot()
    assert model.remove_rows([0, 3, 7]) == 3
    assert model.ledger.ids() == [2, 3, 5, 6, 7]
    stack.undo()
    assert model.ledger.snapshot() == before
    stack.redo()
    assert model.ledger.ids() == [2, 3, 5, 6, 7]


def test_undo_redo_reorder(model: PointsModel) -> None:
    ids = model.ledger.ids()
    assert model.move_rows([1, 2], 1) == [2, 3]
    assert model.ledger.ids() == [1, 4, 2, 3, 5, 6, 7, 8]
    assert model.move_rows([0, 7], -1) == [0, 7]  # at the top: refused, nothing pushed
    assert model.move_rows([7], -1) == [6]
    assert model.ledger.ids() == [1, 4, 2, 3, 5, 6, 8, 7]
    model.undo_stack.undo()
    model.undo_stack.undo()
    assert model.ledger.ids() == ids
    model.undo_stack.redo()
    assert model.ledger.ids() == [1, 4, 2, 3, 5, 6, 7, 8]


def test_undo_redo_teach(model: PointsModel) -> None:
    row = model.add_taught_point(9, Pose(1.0, 2.0, 3.0, 180.0, 0.0, 90.0))
    point = model.point_at(row)
    assert (point.id, point.sync) == (9, SyncState.ON_CONTROLLER)
    assert point.xyzabc == (1.0, 2.0, 3.0, 180.0, 0.0, 90.0)
    assert model.undo_stack.undoText() == "Teach P9"
    model.undo_stack.undo()
    assert 9 not in model.ledger
    model.undo_stack.redo()
    assert model.ledger.point(9).sync is SyncState.ON_CONTROLLER


def test_id_edit_follows_the_plans_and_undo_restores_them(model: PointsModel) -> None:
    plan = model.project.plans[1]  # circle: uses P5 twice
    before = list(plan.segments)
    assert model.setData(model.index(4, COL_ID), "50")
    assert model.point_at(4).id == 50
    assert plan[0].end_id == 50 and plan[2].end_id == 50
    model.undo_stack.undo()
    assert model.point_at(4).id == 5 and plan.segments == before


def test_undo_after_an_upload_does_not_claim_the_old_values_are_on_the_controller(model: PointsModel) -> None:
    model.setData(model.index(0, COL_X), "401")
    edited = model.point_at(0)
    model.apply_upload(UploadReport([UploadOutcome(1, True, sent=edited)]))
    assert model.point_at(0).sync is SyncState.ON_CONTROLLER
    model.undo_stack.undo()  # back to x = 400 on the host; the controller holds 401
    assert model.point_at(0).x == 400.0 and model.point_at(0).sync is SyncState.CHANGED
    model.undo_stack.redo()
    assert model.point_at(0).sync is SyncState.ON_CONTROLLER


def test_failed_upload_and_reconnect(model: PointsModel) -> None:
    model.apply_upload(UploadReport([UploadOutcome(5, False, "bad point id")]))
    assert model.point_at(4).sync is SyncState.FAILED
    assert "bad point id" in cell(model, 4, COL_SYNC, Qt.ItemDataRole.ToolTipRole)
    model.setData(model.index(5, COL_X), "1")  # P6 changed on host
    assert model.mark_all_unknown() == 4  # P1..P3 and the failed P5
    states = [p.sync for p in model.ledger]
    assert states[:5] == [SyncState.UNKNOWN] * 5 and states[5] is SyncState.CHANGED
    # a restored (undone) delete of a point that was on the controller is unknown now
    model.remove_rows([0])
    model.undo_stack.undo()
    assert model.point_at(0).sync is SyncState.UNKNOWN


def test_import_is_one_undo_step(model: PointsModel) -> None:
    before = model.ledger.snapshot()
    report = model.import_points([make_point(1, "home", (400, 0, 450, 180, 0, 0)), make_point(30, "new")])
    assert (report.added, report.removed) == (1, 7)
    assert model.ledger.ids() == [1, 30]
    assert model.point_at(0).sync is SyncState.ON_CONTROLLER  # same on the controller side: kept
    model.undo_stack.undo()
    assert model.ledger.snapshot() == before


def test_filter_by_id_or_name(model: PointsModel) -> None:
    proxy = PointFilterProxy()
    proxy.setSourceModel(model)
    proxy.set_filter_text("circle")
    assert proxy.rowCount() == 4
    proxy.set_filter_text("3")
    assert [proxy.data(proxy.index(r, COL_ID)) for r in range(proxy.rowCount())] == ["3"]
    proxy.set_filter_text("PICK")
    assert proxy.rowCount() == 1
    proxy.set_filter_text("")
    assert proxy.rowCount() == 8


def test_plans_are_untouched_by_plain_edits(qtbot: Any) -> None:
    project = Project(plans=[Plan("p", [Segment.line(1)])])
    model = PointsModel(project, QUndoStack())
    model.add_point()
    with qtbot.assertNotEmitted(model.planReferencesChanged):
        model.setData(model.index(0, COL_X), "3")
