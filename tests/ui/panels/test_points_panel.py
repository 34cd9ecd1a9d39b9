"""PointsPanel and PointSyncController with the typed fake link: teach, upload / cancel / restore,
move to point (confirmation injected), validation messages, filter, undo of teach."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtGui import QUndoStack

from app.link.ops import CancelUpload, CreatePoint, MoveToPoint, Stop, UploadPoints
from app.link.types import ConnectionState, ControllerIdentity, LinkState, WorkerError
from app.models import CommandResult, Pose
from app.points.point import SyncState, make_point
from app.points.project import load_project
from app.protocol.enums import CommandKind, RunCommand
from tests.ui.fake_link import FAKE_CONTROLLER, FakeLink
from ui.controllers.point_sync import PointSyncController
from ui.models.point_columns import COL_E1, COL_TOOL, COL_X
from ui.models.points_model import PointsModel
from ui.panels.points_panel import PointsPanel

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"


# --- fixtures -------------------------------------------------------------------------------


@pytest.fixture
def link() -> FakeLink:
    return FakeLink()


@pytest.fixture
def model() -> PointsModel:
    return PointsModel(load_project(SAMPLE), QUndoStack())


@pytest.fixture
def answers() -> list[bool]:
    return []


@pytest.fixture
def panel(qtbot: Any, model: PointsModel, link: FakeLink, answers: list[bool]) -> Iterator[PointsPanel]:
    questions: list[str] = []

    def confirm(title: str, text: str) -> bool:
        questions.append(text)
        return answers.pop(0) if answers else False

    widget = PointsPanel(model, PointSyncController(model, link), confirm=confirm)
    widget.questions = questions  # type: ignore[attr-defined]
    qtbot.addWidget(widget)
    widget.resize(1000, 500)
    yield widget


# --- teach ----------------------------------------------------------------------------------


def test_teach_creates_next_point_from_the_current_pose(
    qtbot: Any, panel: PointsPanel, link: FakeLink
) -> None:
    assert panel.action_teach.isEnabled()
    assert panel.action_teach.shortcut().toString() == "Ctrl+T"
    panel.action_teach.trigger()
    assert link.named(CreatePoint) == [CreatePoint(9, None, 200)]
    assert not panel.action_teach.isEnabled()  # one operation at a time
    assert 9 not in panel.model.ledger  # nothing until the controller confirms
    link.state.set_pose(Pose(0, 0, 0, 0, 0, 0, ext=(1, 2, 3, 4, 5)))
    with qtbot.waitSignal(panel.controller.pointTaught) as taught:
        link.finish_create(True, pose=(410.5, -20.0, 300.25, 180.0, 0.0, 45.0))
    assert taught.args == [9]
    point = panel.model.ledger.point(9)
    assert point.xyzabc == (410.5, -20.0, 300.25, 180.0, 0.0, 45.0)  # from the result's details
    assert point.ext == (1, 2, 3, 4, 5) and point.sync is SyncState.ON_CONTROLLER
    assert panel.selected_rows() == [panel.model.row_of(9)]
    assert "Taught P9" in panel.status.text()
    # undo / redo of teach
    panel.model.undo_stack.undo()
    assert 9 not in panel.model.ledger
    panel.model.undo_stack.redo()
    assert panel.model.ledger.point(9).sync is SyncState.ON_CONTROLLER


def test_teach_without_pose_details_uses_the_latest_pose(
    qtbot: Any, panel: PointsPanel, link: FakeLink
) -> None:
    panel.teach()
    link.state.set_pose(Pose(1.0, 2.0, 3.0, 4.0, 5.0, 6.0))
    with qtbot.waitSignal(panel.controller.pointTaught):
        link.finish_create(True)
    assert panel.model.ledger.point(9).xyzabc == (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)


def test_teach_refused_by_the_controller(qtbot: Any, panel: PointsPanel, link: FakeLink) -> None:
    panel.teach()
    with qtbot.assertNotEmitted(panel.controller.pointTaught):
        link.finish_create(False, message="bad point id")
    assert 9 not in panel.model.ledger
    assert "bad point id" in panel.status.text()
    assert panel.action_teach.isEnabled()


def test_teach_ignores_unrelated_results_and_ends_on_link_loss(
    qtbot: Any, panel: PointsPanel, link: FakeLink
) -> None:
    panel.teach()
    link.commandFinished.emit(CommandResult(None, None, None, True, "pause: sent"))
    link.finish_move(True)
    stale = CommandResult(
        RunCommand.CREATE_POINT,
        CommandKind.CREATE_POINT,
        None,
        True,
        "",
        request_id=link.last_id(CreatePoint) - 1,
    )  # an older create's result
    link.commandFinished.emit(stale)
    assert panel.controller.busy
    link.set_connected(False, "connection refused")
    assert not panel.controller.busy
    assert "connection refused" in panel.status.text()
    assert not panel.action_teach.isEnabled()


def test_teach_needs_a_connection(panel: PointsPanel, link: FakeLink) -> None:
    link.set_connected(False)
    assert not panel.action_teach.isEnabled()
    panel.controller.teach()
    assert link.submitted == []
    assert "not connected" in panel.status.text()


# --- upload ----------------------------------------------------------------------------------


def test_upload_selected_with_progress_and_a_refused_point(
    qtbot: Any, panel: PointsPanel, link: FakeLink
) -> None:
    panel.select_rows([0, 2, 4])
    panel.action_upload_selected.trigger()
    (call,) = link.named(UploadPoints)
    assert [(pid, tool) for pid, _, tool in call.items] == [(1, 200), (3, 200), (5, 200)]
    assert call.items[0][1] == (400.0, 0.0, 450.0, 180.0, 0.0, 0.0)
    assert panel.progress_row.isVisibleTo(panel)
    ledger = panel.model.ledger
    link.point_ok(1)
    link.upload_progress(1, 3)
    assert panel.progress.value() == 1
    assert ledger.point(1).sync is SyncState.ON_CONTROLLER  # marked as it goes
    link.point_failed(3, "point 3: bad point id")
    link.point_ok(5)
    link.upload_progress(3, 3)
    assert ledger.point(3).sync is SyncState.FAILED and "bad point id" in ledger.point(3).sync_error
    with qtbot.waitSignal(panel.controller.uploadFinished) as finished:
        link.upload_summary(2, 3)
    report = finished.args[0]
    assert report.ok_count == 2 and [o.point_id for o in report.failed] == [3]
    assert ledger.point(1).sync is SyncState.ON_CONTROLLER
    assert ledger.point(5).sync is SyncState.ON_CONTROLLER
    assert ledger.point(2).sync is SyncState.UNKNOWN  # not part of it
    assert not panel.progress_row.isVisibleTo(panel)


def test_cancel_half_way_keeps_what_was_uploaded(qtbot: Any, panel: PointsPanel, link: FakeLink) -> None:
    ledger = panel.model.ledger
    panel.model.setData(panel.model.index(5, COL_X), "401")  # P6 changed on host
    panel.upload_all()
    link.point_ok(1, 2)
    link.upload_progress(2, 8)
    panel.action_cancel_upload.trigger()
    assert link.named(CancelUpload) and not link.named(Stop)  # no controller stop
    assert panel.controller.busy  # until the link says the batch ended
    with qtbot.waitSignal(panel.controller.uploadFinished) as finished:
        link.upload_summary(2, 8, "cancelled")
    report = finished.args[0]
    assert report.aborted == "cancelled" and report.not_attempted == [3, 4, 5, 6, 7, 8]
    assert [p.sync for p in ledger][:2] == [SyncState.ON_CONTROLLER] * 2
    assert ledger.point(6).sync is SyncState.CHANGED  # kept its state
    assert ledger.point(7).sync is SyncState.UNKNOWN
    assert "stopped after 2 of 8" in panel.status.text()


def test_a_stopped_upload_says_why(qtbot: Any, panel: PointsPanel, link: FakeLink) -> None:
    panel.controller.upload([1, 2, 3])
    link.point_ok(1)
    with qtbot.waitSignal(panel.controller.uploadFinished) as finished:
        link.upload_summary(1, 3, "stopped")
    assert finished.args[0].aborted == "stopped" and finished.args[0].not_attempted == [2, 3]
    assert panel.model.ledger.point(1).sync is SyncState.ON_CONTROLLER  # applied at the end too


def test_upload_sends_each_points_tool_in_one_request(qtbot: Any, panel: PointsPanel, link: FakeLink) -> None:
    panel.model.setData(panel.model.index(1, COL_TOOL), "4")  # P2 tool 4
    panel.controller.upload([1, 2, 3])
    (call,) = link.named(UploadPoints)
    assert [(pid, tool) for pid, _, tool in call.items] == [(1, 200), (2, 4), (3, 200)]
    link.point_ok(1, 3, 2)
    with qtbot.waitSignal(panel.controller.uploadFinished) as finished:
        link.upload_progress(3, 3)
        assert panel.progress.value() == 3
        link.upload_summary(3, 3)
    assert finished.args[0].all_ok


def test_results_of_other_requests_are_ignored(qtbot: Any, panel: PointsPanel, link: FakeLink) -> None:
    panel.controller.upload([1])
    other = CommandResult(
        RunCommand.CREATE_POINT,
        None,
        None,
        True,
        "uploaded 1 of 1 points",
        {"uploaded": 1.0},
        request_id=link.last_id(UploadPoints) - 1,
    )
    link.commandFinished.emit(other)
    link.errorOccurred.emit(WorkerError("upload points", "someone else's", request_id=None))
    assert panel.controller.busy


def test_upload_refused_by_the_worker(qtbot: Any, panel: PointsPanel, link: FakeLink) -> None:
    panel.controller.upload([1])
    with qtbot.waitSignal(panel.controller.uploadFinished) as finished:
        link.errorOccurred.emit(
            WorkerError("upload points", "move to point is still under way", link.last_id(UploadPoints))
        )
    assert finished.args[0].aborted == "move to point is still under way"
    assert panel.model.ledger.point(1).sync is SyncState.UNKNOWN


def test_link_loss_during_an_upload_keeps_the_late_reports(
    qtbot: Any, panel: PointsPanel, link: FakeLink
) -> None:
    panel.controller.upload([1, 2, 3])
    link.point_ok(1)
    link.set_connected(False, "link lost: timeout")
    assert panel.controller.busy
    link.point_ok(2)  # finished before the worker noticed
    with qtbot.waitSignal(panel.controller.uploadFinished) as finished:
        link.upload_summary(2, 3, "link lost: timeout")
    assert finished.args[0].not_attempted == [3] and "link lost" in (finished.args[0].aborted or "")
    ledger = panel.model.ledger
    assert [ledger.point(i).sync for i in (1, 2, 3)] == [
        SyncState.ON_CONTROLLER,
        SyncState.ON_CONTROLLER,
        SyncState.UNKNOWN,
    ]


@pytest.mark.parametrize(
    "controller",
    [
        dataclasses.replace(FAKE_CONTROLLER, endpoint="other:502"),  # Connect… to another controller
        dataclasses.replace(FAKE_CONTROLLER, unit=2),  # another unit behind the same gateway
        dataclasses.replace(FAKE_CONTROLLER, boot=2.0),  # a restart: the canary holds another token
        dataclasses.replace(FAKE_CONTROLLER, boot=None),  # no canary: the boot cannot be told
    ],
    ids=["endpoint", "unit", "restart", "no canary"],
)
def test_another_controller_marks_unknown_and_offers_restore(
    qtbot: Any, panel: PointsPanel, link: FakeLink, controller: ControllerIdentity
) -> None:
    model = panel.model
    model.apply_upload(_report_ok(model, [1, 2]))
    assert not panel.banner.isVisibleTo(panel)
    link.set_connected(False, "link lost")
    link.set_connected(True, controller=controller)
    assert [p.sync for p in model.ledger][:2] == [SyncState.UNKNOWN] * 2
    assert panel.banner.isVisibleTo(panel) and panel.restore_button.isEnabled()
    panel.restore_button.click()
    (call,) = link.named(UploadPoints)
    assert [pid for pid, _, _ in call.items] == model.ledger.ids()
    link.point_ok(*model.ledger.ids())
    with qtbot.waitSignal(panel.controller.uploadFinished):
        link.upload_summary(8, 8)
    assert all(p.sync is SyncState.ON_CONTROLLER for p in model.ledger)
    assert not panel.banner.isVisibleTo(panel)


def test_the_same_controller_boot_keeps_the_points(qtbot: Any, panel: PointsPanel, link: FakeLink) -> None:
    model = panel.model
    model.apply_upload(_report_ok(model, [1, 2]))
    link.set_connected(False, "link lost")
    link.controllerReconnected.emit()  # a reconnect alone says nothing about the points
    link.set_connected(True)  # the same endpoint, unit and canary token: the same boot
    assert [p.sync for p in model.ledger][:2] == [SyncState.ON_CONTROLLER] * 2
    assert not panel.banner.isVisibleTo(panel)


def test_a_silence_on_the_same_connection_keeps_the_points(panel: PointsPanel, link: FakeLink) -> None:
    """Not answering for a while and back, the link never down: the same connection, even with no
    canary to prove the boot by (a new connection without one would make them unknown)."""
    unprovable = dataclasses.replace(FAKE_CONTROLLER, boot=None)
    link.set_connected(False)
    link.set_connected(True, controller=unprovable)
    model = panel.model
    model.apply_upload(_report_ok(model, [1, 2]))
    for state in (LinkState.NOT_ANSWERING, LinkState.CONNECTED):
        link.state.set_connection(ConnectionState(state, "", "fake:502", controller=unprovable))
    assert [p.sync for p in model.ledger][:2] == [SyncState.ON_CONTROLLER] * 2
    link.set_connected(False)
    link.set_connected(True, controller=unprovable)
    assert [p.sync for p in model.ledger][:2] == [SyncState.UNKNOWN] * 2


def _report_ok(model: PointsModel, ids: list[int]) -> Any:
    from app.points.upload import UploadOutcome, UploadReport

    return UploadReport([UploadOutcome(pid, True, sent=model.ledger.point(pid)) for pid in ids])


# --- move to point ---------------------------------------------------------------------------


def test_move_to_point_asks_first(
    qtbot: Any, panel: PointsPanel, link: FakeLink, answers: list[bool]
) -> None:
    model = panel.model
    model.apply_upload(_report_ok(model, [2]))
    panel.select_rows([1])
    panel.speed.setValue(120.0)
    answers.append(False)
    panel.action_move_to.trigger()
    assert "P2" in panel.questions[-1] and "120" in panel.questions[-1]  # type: ignore[attr-defined]
    assert link.named(MoveToPoint) == [] and link.named(UploadPoints) == []
    answers.append(True)
    panel.move_to_selected()
    # the point guard: P2 is created again from the ledger first, the move waits for it
    (create,) = link.named(UploadPoints)
    assert create.items == ((2, model.ledger.point(2).xyzabc, 200),)
    assert link.named(MoveToPoint) == []
    with qtbot.waitSignal(panel.controller.movePrepared) as prepared:
        link.point_ok(2)
        link.upload_summary(1, 1)
    assert prepared.args == [2]
    (call,) = link.named(MoveToPoint)
    assert (call.end_id, call.via_id, call.speed, call.tool) == (2, None, 120.0, 200)
    with qtbot.waitSignal(panel.controller.moveFinished) as done:
        link.finish_move(False, code=13, message="bad end-point id")
    assert done.args[0] is False and "bad end point id" in done.args[1]  # GV291 13, in words
    # the controller does not hold P2: not known to be on it, Restore all offered
    assert model.ledger.point(2).sync is SyncState.UNKNOWN
    assert panel.banner.isVisibleTo(panel) and "Move to P2 failed" in panel.status.text()


def test_move_to_a_point_not_on_the_controller_creates_it_first(
    qtbot: Any, panel: PointsPanel, link: FakeLink, answers: list[bool]
) -> None:
    point = panel.model.ledger[0]
    assert point.needs_upload
    panel.select_rows([0])
    answers.append(True)
    panel.move_to_selected()
    assert panel.questions  # type: ignore[attr-defined]  # asked, like any move
    assert [c.items[0][0] for c in link.named(UploadPoints)] == [point.id]
    link.point_failed(point.id, "bad point id")
    with qtbot.waitSignal(panel.controller.moveFinished) as done:
        link.upload_summary(0, 1)
    assert done.args[0] is False and link.named(MoveToPoint) == []  # never sent
    assert f"Move to P{point.id} failed" in panel.status.text() and "not moved" in panel.status.text()


def test_a_stop_while_the_point_is_created_sends_no_move(
    qtbot: Any, panel: PointsPanel, link: FakeLink, answers: list[bool]
) -> None:
    panel.select_rows([1])
    answers.append(True)
    panel.move_to_selected()
    panel.controller.stop()
    assert link.named(Stop)
    with qtbot.waitSignal(panel.controller.moveFinished) as done:
        link.upload_summary(0, 1, "stopped")  # the worker's upload ends at the stop
    assert done.args[0] is False and link.named(MoveToPoint) == []
    assert "stopped by the operator" in panel.status.text()


def test_an_arm_that_stops_elsewhere_is_a_failed_move(
    qtbot: Any, panel: PointsPanel, link: FakeLink, answers: list[bool]
) -> None:
    model = panel.model
    point = model.ledger[1]
    panel.select_rows([1])
    answers.append(True)
    panel.move_to_selected()
    link.point_ok(point.id)
    link.upload_summary(1, 1)
    assert model.ledger.point(point.id).sync is SyncState.ON_CONTROLLER
    link.state.set_pose(Pose(point.x + 3.0, point.y, point.z, point.a, point.b, point.c))  # 3 mm off
    with qtbot.waitSignal(panel.controller.moveFinished) as done:
        link.finish_move(True)
    assert done.args[0] is False and "3.00 mm from" in done.args[1]
    assert "Reached" not in panel.status.text() and f"Move to P{point.id} failed" in panel.status.text()
    assert model.ledger.point(point.id).sync is SyncState.UNKNOWN


def test_run_active_disables_motion(panel: PointsPanel) -> None:
    panel.select_rows([0])
    assert panel.action_move_to.isEnabled()
    panel.set_run_active(True)
    assert not panel.action_move_to.isEnabled() and not panel.action_teach.isEnabled()
    assert panel.action_delete.isEnabled()


# --- editing from the panel ---------------------------------------------------------------------


def test_rejected_edit_shows_the_reason(panel: PointsPanel) -> None:
    panel.model.setData(panel.model.index(0, COL_X), "abc")
    assert "'abc' is not a number" in panel.status.text()


def test_add_delete_move_from_the_panel(panel: PointsPanel) -> None:
    model = panel.model
    panel.select_rows([1])
    panel.action_add.trigger()
    assert model.ledger.ids()[2] == 9 and panel.selected_rows() == [2]
    panel.select_rows([0, 1])
    panel.action_move_down.trigger()
    assert model.ledger.ids()[:3] == [9, 1, 2] and panel.selected_rows() == [1, 2]
    panel.action_delete.trigger()
    assert model.ledger.ids()[:2] == [9, 3]
    assert "used by plan" in panel.status.text()
    model.undo_stack.undo()
    assert model.ledger.ids()[:3] == [9, 1, 2]


def test_find_filters_and_selection_maps_to_the_model(panel: PointsPanel) -> None:
    panel.find_edit.setText("circle")
    assert panel.proxy.rowCount() == 4
    panel.table.selectRow(1)
    assert panel.selected_rows() == [5]
    panel.action_duplicate.trigger()
    assert panel.model.ledger.ids()[6] == 9


def test_external_axes_columns_hideable(panel: PointsPanel) -> None:
    assert panel.table.isColumnHidden(COL_E1)
    panel.action_show_ext.setChecked(True)
    assert not panel.table.isColumnHidden(COL_E1)


def test_points_with_other_ids_work(qtbot: Any) -> None:
    from app.points.project_model import Project

    project = Project()
    project.ledger.replace_all([make_point(10000, "last")])
    model = PointsModel(project, QUndoStack())
    assert model.next_id() == 0  # the highest id is at the limit: smallest free one


# --- a new point's pose (issue 9: sane defaults) ----------------------------------------------------


def test_add_takes_the_current_pose_while_the_link_is_fresh(panel: PointsPanel, link: FakeLink) -> None:
    import time

    link.state.set_pose(Pose(412.5, -30.0, 250.0, 180.0, 0.5, 90.0))
    link.state.note_good_poll(time.monotonic())
    assert link.state.fresh
    panel.select_rows([1])
    panel.action_add.trigger()
    point = panel.model.ledger.point(9)
    assert point.xyzabc == (412.5, -30.0, 250.0, 180.0, 0.5, 90.0)
    assert "current pose" in panel.status.text() and "no live pose" not in panel.status.text()
    link.set_connected(False)  # a lost link is never fresh (and stops the freshness timer)
    panel.action_add.trigger()
    assert panel.model.ledger.point(10).xyzabc == point.xyzabc and "no live pose" in panel.status.text()


def test_add_without_a_live_pose_copies_a_point_and_says_so(
    qtbot: Any, panel: PointsPanel, link: FakeLink
) -> None:
    import time

    link.state.set_freshness_limit(0.05)
    link.state.set_pose(Pose(999.0, 999.0, 999.0, 0.0, 0.0, 0.0))
    link.state.note_good_poll(time.monotonic())
    qtbot.waitUntil(lambda: not link.state.fresh)  # the pose got old: not the robot's any more
    panel.select_rows([1])
    selected = panel.model.ledger[1]
    panel.action_add.trigger()
    point = panel.model.ledger.point(9)
    assert point.xyzabc == selected.xyzabc and point.xyzabc[0] != 999.0  # never the stale pose
    text = panel.status.text()
    assert "not from the controller: no live pose" in text and f"copied from P{selected.id}" in text


def test_add_to_an_empty_list_without_a_link_is_zeros_and_says_so(qtbot: Any) -> None:
    from app.points.project_model import Project

    model = PointsModel(Project(), QUndoStack())
    panel = PointsPanel(model, PointSyncController(model), confirm=lambda title, text: False)
    qtbot.addWidget(panel)
    panel.action_add.trigger()
    assert model.ledger[0].xyzabc == (0.0,) * 6
    assert "no live pose (pose set to zeros)" in panel.status.text()
