"""Planner: plan and segment models (model tester, validation, undo), checks on their rows,
the run controller's sequencing with a fake link, and the panel's run / upload flow.

Every run is guarded (each segment's points created again, then the move, then the arrival
checked): :class:`Worker` plays the worker's side of that on the fake link."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoStack

from app.link.ops import MoveToPoint, Pause, Resume, Stop, UploadPoints
from app.link.types import WorkerError
from app.models import Pose
from app.plan.issue_kind import IssueKind
from app.plan.runner import RunState
from app.plan.segments import Segment, SegmentKind
from app.points.point import SyncState
from app.points.project import load_project
from app.points.project_model import Project
from app.points.upload import UploadOutcome, UploadReport
from tests.ui.fake_link import FakeLink
from ui.controllers.plan_run_controller import PlanRunController
from ui.controllers.point_sync import PointSyncController
from ui.models.plan_columns import (
    COL_END,
    COL_IGNORE,
    COL_INDEX,
    COL_KIND,
    COL_SPEED,
    COL_VIA,
    ISSUE_LEVEL_ROLE,
    PLAN_COL_LOOPS,
    PLAN_COL_NAME,
)
from ui.models.plan_model import PlanListModel
from ui.models.points_model import PointsModel
from ui.models.segment_model import SegmentTableModel
from ui.palette import COLOR_ERROR, COLOR_WARN_TEXT
from ui.panels.planner_panel import PlannerPanel

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"


@pytest.fixture
def project() -> Project:
    return load_project(SAMPLE)


@pytest.fixture
def stack() -> QUndoStack:
    return QUndoStack()


@pytest.fixture
def segments(qtbot: Any, project: Project, stack: QUndoStack) -> SegmentTableModel:
    model = SegmentTableModel(stack, project.ledger)
    model.set_plan(project.plans[1])  # circle: line, arc, arc, line
    return model


def all_uploaded(project: Project) -> None:
    for point in project.ledger:
        project.ledger.set_sync(point.id, SyncState.ON_CONTROLLER)


# --- models ------------------------------------------------------------------------------------


def test_models_pass_qt_model_tester(
    qtmodeltester: Any, project: Project, stack: QUndoStack, segments: SegmentTableModel
) -> None:
    plans = PlanListModel(project, stack)
    qtmodeltester.check(plans, force_py=False)
    qtmodeltester.check(segments, force_py=False)
    segments.insert_segment(1, SegmentKind.ARC)
    segments.remove_rows([0, 2])
    segments.move_rows([0], 1)
    checked = Qt.CheckState.Checked.value
    segments.setData(segments.index(0, COL_IGNORE), checked, Qt.ItemDataRole.CheckStateRole)
    plans.add_plan()
    plans.setData(plans.index(0, PLAN_COL_NAME), "renamed")
    segments.set_plan(project.plans[0])
    while stack.canUndo():  # undoing segment edits of "circle" switches the model back to it
        stack.undo()
    assert segments.plan is project.plans[1]
    qtmodeltester.check(segments, force_py=False)


def test_segment_display(segments: SegmentTableModel) -> None:
    def text(row: int, column: int) -> Any:
        return segments.data(segments.index(row, column))

    assert [text(r, COL_KIND) for r in range(4)] == ["line", "arc", "arc", "line"]
    assert text(1, COL_VIA) == "P6  circle N" and text(0, COL_VIA) == ""
    assert text(1, COL_END) == "P7  circle E" and text(1, COL_SPEED) == "50 mm/s"
    assert not segments.flags(segments.index(0, COL_VIA)) & Qt.ItemFlag.ItemIsEditable  # a line has none
    assert segments.flags(segments.index(1, COL_VIA)) & Qt.ItemFlag.ItemIsEditable
    assert segments.flags(segments.index(1, COL_IGNORE)) & Qt.ItemFlag.ItemIsUserCheckable


@pytest.mark.parametrize(
    ("column", "value", "reason"),
    [
        (COL_SPEED, "abc", "'abc' is not a number"),
        (COL_SPEED, "0", "must be above 0"),
        (COL_SPEED, "nan", "not a finite number"),
        (COL_END, "x", "not a number"),
        (COL_END, "20000", "outside"),
        (COL_VIA, "7", "must differ from its end point"),
        (COL_KIND, "circle", "is not a line or an arc"),
    ],
)
def test_bad_segment_input_is_refused(
    qtbot: Any, segments: SegmentTableModel, column: int, value: str, reason: str
) -> None:
    plan = segments.plan
    assert plan is not None
    before = list(plan.segments)
    with qtbot.waitSignal(segments.editRejected) as blocker:
        assert segments.setData(segments.index(1, column), value) is False
    assert reason in blocker.args[0] and "Segment 2" in blocker.args[0]
    assert plan.segments == before and segments.undo_stack.count() == 0


def test_segment_edits_undo_redo(segments: SegmentTableModel) -> None:
    plan = segments.plan
    assert plan is not None
    stack = segments.undo_stack
    assert segments.setData(segments.index(0, COL_SPEED), "75")
    assert segments.setData(segments.index(0, COL_END), "P6")  # what the cell shows is accepted
    assert segments.setData(segments.index(0, COL_KIND), "arc")
    assert plan[0].is_arc and plan[0].via_id is None and plan[0].end_id == 6 and plan[0].speed == 75.0
    assert segments.setData(segments.index(0, COL_VIA), "8")
    assert plan[0].via_id == 8
    for _ in range(4):
        stack.undo()
    assert plan[0] == Segment.line(5, 100.0)
    for _ in range(4):
        stack.redo()
    assert plan[0] == Segment.arc(8, 6, 75.0)


def test_segment_add_delete_move_undo(segments: SegmentTableModel) -> None:
    plan = segments.plan
    assert plan is not None
    before = list(plan.segments)
    row = segments.insert_segment(2, SegmentKind.LINE)
    assert row == 2 and len(plan) == 5
    assert plan[2].end_id == 8 and plan[2].speed == 50.0  # after P7 (previous end) comes P8
    segments.remove_rows([0, 4])
    assert len(plan) == 3
    assert segments.move_rows([2], -1) == [1]
    stack = segments.undo_stack
    for _ in range(3):
        stack.undo()
    assert plan.segments == before


def test_plan_list_edits(qtbot: Any, project: Project, stack: QUndoStack) -> None:
    plans = PlanListModel(project, stack)
    assert plans.data(plans.index(0, PLAN_COL_LOOPS)) == "2"
    with qtbot.waitSignal(plans.editRejected) as blocker:
        assert not plans.setData(plans.index(0, PLAN_COL_NAME), "circle")
    assert "already exists" in blocker.args[0]
    assert not plans.setData(plans.index(0, PLAN_COL_LOOPS), "-1")
    assert plans.setData(plans.index(0, PLAN_COL_LOOPS), "0")
    assert plans.data(plans.index(0, PLAN_COL_LOOPS)) == "endless"
    row = plans.add_plan()
    assert project.plans[row].name == "plan"
    plans.remove_plan(0)
    assert project.plan_names() == ["circle", "plan"]
    for _ in range(3):
        stack.undo()
    assert project.plan_names() == ["pick and place", "circle"] and project.plans[0].loops == 2


def test_issues_shown_on_their_rows(segments: SegmentTableModel, project: Project) -> None:
    from app.plan.checks import check_plan

    plan = segments.plan
    assert plan is not None
    plan.replace(3, Segment.line(99))
    segments.set_issues(check_plan(plan, project.ledger))
    assert segments.data(segments.index(3, COL_INDEX), ISSUE_LEVEL_ROLE) is IssueKind.ERROR
    assert segments.data(segments.index(3, COL_INDEX), Qt.ItemDataRole.DecorationRole) is not None
    tip = segments.data(segments.index(3, COL_INDEX), Qt.ItemDataRole.ToolTipRole)
    assert "P99 does not exist" in tip
    assert segments.data(segments.index(3, COL_END), Qt.ItemDataRole.ForegroundRole) is not None
    assert segments.data(segments.index(0, COL_INDEX), ISSUE_LEVEL_ROLE) is IssueKind.NEEDS_UPLOAD


# --- run controller --------------------------------------------------------------------------------


@pytest.fixture
def runner(qtbot: Any, link: FakeLink, project: Project) -> PlanRunController:
    return PlanRunController(link, points=PointsModel(project, QUndoStack()))


@pytest.fixture
def link() -> FakeLink:
    return FakeLink()


class Worker:
    """The worker's side of a guarded run on the fake link: each upload the run asks for creates
    all its points, and a move that ends well leaves the arm at its end point (the pose polled
    with the completion), as the simulator does."""

    def __init__(self, link: FakeLink, project: Project) -> None:
        self.link = link
        self.project = project
        self._answered: set[int] = set()

    def create_points(self) -> None:
        """Answer the latest upload (if not yet answered): every point created."""
        uploads, tickets = self.link.named(UploadPoints), self.link.ids(UploadPoints)
        if not uploads or tickets[-1] in self._answered:
            return
        self._answered.add(tickets[-1])
        ids = [point_id for point_id, _, _ in uploads[-1].items]
        self.link.point_ok(*ids)
        self.link.upload_summary(len(ids), len(ids))

    def finish_move(self, ok: bool = True, code: int = 0xFF, message: str = "") -> None:
        """The latest move ends (see :meth:`FakeLink.finish_move`); the next segment's points are
        then created at once."""
        if ok:
            end = self.link.named(MoveToPoint)[-1].end_id
            x, y, z, a, b, c = self.project.ledger.point(end).xyzabc
            self.link.state.set_pose(Pose(x, y, z, a, b, c, ext=(0.0,) * 5))
        self.link.finish_move(ok, code, message)
        self.create_points()


@pytest.fixture
def worker(link: FakeLink, project: Project) -> Worker:
    return Worker(link, project)


def moves(link: FakeLink) -> list[tuple[int, int | None]]:
    return [(c.end_id, c.via_id) for c in link.named(MoveToPoint)]


def test_segments_sent_in_order_each_after_the_previous_result(
    qtbot: Any, runner: PlanRunController, link: FakeLink, project: Project, worker: Worker
) -> None:
    plan = project.plans[0]  # line P2, arc P4 -> P3, line P1; 2 loops
    with qtbot.waitSignal(runner.runningChanged, check_params_cb=lambda running: running):
        runner.run(plan)
    assert moves(link) == []  # the segment's points are created first
    worker.create_points()
    assert moves(link) == [(2, None)]
    call = link.named(MoveToPoint)[0]
    assert call == MoveToPoint(2, None, orientation_changes=True, ignore_middle=False, speed=100.0, tool=200)
    worker.finish_move()
    assert moves(link) == [(2, None), (3, 4)]
    assert link.named(MoveToPoint)[1].orientation_changes is False  # "kept"
    link.commandFinished.emit(_ack("pause: sent"))  # not a move result: ignored
    assert len(moves(link)) == 2
    assert runner.progress is not None and runner.progress.text == "loop 1/2, segment 2/3"
    with qtbot.waitSignal(runner.runFinished) as finished:
        for _ in range(5):
            worker.finish_move()
    assert moves(link) == [(2, None), (3, 4), (1, None)] * 2
    assert finished.args[0].state is RunState.FINISHED and not runner.running


def _ack(text: str) -> Any:
    from app.models import CommandResult

    return CommandResult(None, None, None, True, text)


def test_pause_resume_stop_are_forwarded(
    qtbot: Any, runner: PlanRunController, link: FakeLink, project: Project, worker: Worker
) -> None:
    runner.run(project.plans[1])
    worker.create_points()
    runner.pause()
    assert runner.paused and link.named(Pause)
    runner.resume()
    assert not runner.paused and link.named(Resume)
    runner.stop()
    assert link.named(Stop) and runner.running  # until the link reports the stopped move
    with qtbot.waitSignal(runner.runFinished) as finished:
        link.finish_move(False, code=0, message="stopped")
    outcome = finished.args[0]
    assert outcome.state is RunState.STOPPED and outcome.resume_from == 0
    assert moves(link) == [(5, None)]


def test_error_at_segment_k_stops_and_resume_from_k_continues(
    qtbot: Any, runner: PlanRunController, link: FakeLink, project: Project, worker: Worker
) -> None:
    runner.run(project.plans[1])  # circle: P5, arc P6->P7, arc P8->P5, P1
    worker.create_points()
    worker.finish_move()
    with qtbot.waitSignal(runner.runFinished) as finished:
        worker.finish_move(False, code=3, message="servo alarm")
    outcome = finished.args[0]
    assert outcome.state is RunState.FAILED and outcome.resume_from == 1
    assert "segment 2/4" in outcome.message and "servo alarm" in outcome.message
    assert runner.can_resume
    runner.resume_run()
    worker.create_points()
    assert moves(link) == [(5, None), (7, 6), (7, 6)]
    with qtbot.waitSignal(runner.runFinished) as finished:
        for _ in range(3):
            worker.finish_move()
    assert finished.args[0].state is RunState.FINISHED
    assert moves(link)[3:] == [(5, 8), (1, None)]


def test_lost_link_and_refusal_end_the_run(
    qtbot: Any, runner: PlanRunController, link: FakeLink, project: Project, worker: Worker
) -> None:
    runner.run(project.plans[1])
    worker.create_points()
    with qtbot.waitSignal(runner.runFinished) as finished:
        link.set_connected(False, "connection reset")
    assert finished.args[0].state is RunState.FAILED and "connection reset" in finished.args[0].message
    link.set_connected(True)
    runner.resume_run()
    worker.create_points()
    previous_move = link.ids(MoveToPoint)[-2]  # the one the lost link ended
    link.errorOccurred.emit(WorkerError("move to point", "another request's error", previous_move))
    assert runner.running  # not ours
    with qtbot.waitSignal(runner.runFinished) as finished:
        link.errorOccurred.emit(
            WorkerError("move to point", "jog is still under way", link.last_id(MoveToPoint))
        )
    assert finished.args[0].resume_from == 0 and "jog is still under way" in finished.args[0].message


def test_step_runs_one_segment(
    qtbot: Any, runner: PlanRunController, link: FakeLink, project: Project, worker: Worker
) -> None:
    runner.step(project.plans[1], 2)
    worker.create_points()
    with qtbot.waitSignal(runner.runFinished) as finished:
        worker.finish_move()
    assert moves(link) == [(5, 8)]
    assert finished.args[0].state is RunState.FINISHED and finished.args[0].next_position == (3, 1)


def test_start_needs_a_connection(runner: PlanRunController, link: FakeLink, project: Project) -> None:
    from app.errors import LinkError

    link.set_connected(False)
    with pytest.raises(LinkError):
        runner.run(project.plans[0])
    assert link.submitted == []


# --- the panel -------------------------------------------------------------------------------------


# Read through calls: mypy would keep an asserted attribute narrowed across the run's steps.
def is_live(planner: PlannerPanel) -> bool:
    return planner.preview.live


def is_locked(planner: PlannerPanel) -> bool:
    return planner.segments.locked


@pytest.fixture
def planner(qtbot: Any, project: Project, link: FakeLink) -> Iterator[PlannerPanel]:
    stack = QUndoStack()
    points = PointsModel(project, stack)
    sync = PointSyncController(points, link)
    answers: list[bool] = []
    questions: list[str] = []

    def confirm(title: str, text: str) -> bool:
        questions.append(text)
        return answers.pop(0) if answers else False

    panel = PlannerPanel(
        PlanListModel(project, stack), points, PlanRunController(link, points=points), sync, confirm=confirm
    )
    panel.answers = answers  # type: ignore[attr-defined]
    panel.questions = questions  # type: ignore[attr-defined]
    qtbot.addWidget(panel)
    panel.resize(1280, 700)
    yield panel
    if panel.run_controller.running:
        panel.run_controller.stop()
        link.finish_move(False, code=0, message="stopped")


def test_panel_summary_and_upload_now_then_run(
    qtbot: Any, planner: PlannerPanel, link: FakeLink, project: Project, worker: Worker
) -> None:
    planner.select_plan(1)
    assert planner.summary_text.startswith("5 point(s) need upload")
    assert planner.upload_button.isVisibleTo(planner)
    planner.answers.extend([True, True])  # type: ignore[attr-defined]
    assert planner.run(0)
    assert "not on the controller" in planner.questions[0]  # type: ignore[attr-defined]
    (upload,) = link.named(UploadPoints)
    assert sorted(pid for pid, _, _ in upload.items) == [1, 5, 6, 7, 8]
    assert moves(link) == []
    link.point_ok(1, 5, 6, 7, 8)
    with qtbot.waitSignal(planner.run_controller.runningChanged):
        link.upload_summary(5, 5)
    worker.create_points()  # the run's own: segment 1's point again, right before its move
    assert moves(link) == [(5, None)]
    assert "The robot will move" in planner.questions[1]  # type: ignore[attr-defined]
    assert planner.summary_text == "Checks passed: ready to run"
    assert is_locked(planner) and not planner.action_add_line.isEnabled()
    assert is_live(planner)
    worker.finish_move()
    assert "Segment 2 of 4, loop 1 of 1" in planner.run_label.text()
    with qtbot.waitSignal(planner.run_controller.runFinished):
        worker.finish_move(False, code=3, message="servo alarm")
    assert not is_locked(planner) and not is_live(planner)
    assert planner.action_resume_from.isEnabled()
    assert planner.action_resume_from.text() == "Resume from segment 2"
    assert planner.selected_segments() == [1]
    planner.answers.append(True)  # type: ignore[attr-defined]
    planner.resume_from()
    worker.create_points()
    assert moves(link)[-1] == (7, 6) and is_live(planner)
    with qtbot.waitSignal(planner.run_controller.runFinished):
        for _ in range(3):
            worker.finish_move()
    assert not is_live(planner) and "Finished" in planner.run_label.text()


def test_panel_refuses_a_plan_with_errors(planner: PlannerPanel, link: FakeLink, project: Project) -> None:
    all_uploaded(project)
    planner.select_plan(1)
    plan = planner.current_plan()
    assert plan is not None
    plan.replace(2, plan[2].with_field("end", 42))  # e.g. P42 was deleted: a picker offers no such id
    planner.recheck()
    assert not planner.action_run.isEnabled()
    assert planner.summary_text.startswith("1 error(s)")
    assert not planner.run(0)
    assert "Cannot run" in planner.status.text() and "P42 does not exist" in planner.status.text()
    assert planner.selected_segments() == [2]
    assert link.submitted == []


def test_panel_step_and_run_from_here(
    qtbot: Any, planner: PlannerPanel, link: FakeLink, project: Project, worker: Worker
) -> None:
    all_uploaded(project)
    planner.select_plan(1)
    planner.select_segments([2])
    planner.answers.append(True)  # type: ignore[attr-defined]
    planner.action_step.trigger()
    worker.create_points()
    assert moves(link) == [(5, 8)]
    with qtbot.waitSignal(planner.run_controller.runFinished):
        worker.finish_move()
    assert planner.selected_segments() == [3]  # the next step
    planner.answers.append(True)  # type: ignore[attr-defined]
    planner.select_segments([1])
    planner.action_run_from.trigger()
    worker.create_points()
    assert moves(link)[-1] == (7, 6)
    planner.action_stop.trigger()
    with qtbot.waitSignal(planner.run_controller.runFinished):
        link.finish_move(False, code=0, message="stopped")
    assert "Stopped" in planner.run_label.text()


def test_panel_undo_of_other_plan_switches_to_it(planner: PlannerPanel) -> None:
    planner.select_plan(0)
    planner.segments.setData(planner.segments.index(0, COL_SPEED), "60")
    planner.select_plan(1)
    planner.segments.undo_stack.undo()
    assert planner.current_plan() is planner.segments.plan
    plan = planner.current_plan()
    assert plan is not None and plan.name == "pick and place"
    assert planner.plan_view.currentIndex().row() == 0


def test_panel_plan_and_segment_edits_through_the_actions(planner: PlannerPanel, project: Project) -> None:
    count = len(project.plans)
    planner.select_plan(1)
    planner.action_duplicate_plan.trigger()
    assert len(project.plans) == count + 1 and planner.plan_view.currentIndex().row() == 2
    copy = planner.current_plan()
    assert copy is not None and copy is project.plans[2] and len(copy) == len(project.plans[1])
    planner.select_segments([0])
    planner.action_add_arc.trigger()  # after the selection, and selected
    assert copy[1].is_arc and planner.selected_segments() == [1]
    planner.action_segment_up.trigger()
    assert copy[0].is_arc and planner.selected_segments() == [0]
    planner.action_delete_segment.trigger()
    assert len(copy) == len(project.plans[1])
    planner.action_delete_plan.trigger()
    assert len(project.plans) == count and copy not in project.plans
    assert planner.status.text() == f"Deleted plan {copy.name} (Ctrl+Z to undo)"
    planner.segments.undo_stack.undo()
    assert project.plans[2] is copy


def test_panel_status_levels_use_the_palette(planner: PlannerPanel) -> None:
    planner.show_message("refused", "error")
    assert COLOR_ERROR in planner.status.styleSheet()
    planner.show_message("careful", "warn")
    assert COLOR_WARN_TEXT in planner.status.styleSheet()
    planner.show_message("plain", "other")
    assert planner.status.styleSheet() == ""


def test_points_upload_updates_the_checks(planner: PlannerPanel, project: Project) -> None:
    planner.select_plan(0)
    assert "need upload" in planner.summary_text
    points = [UploadOutcome(p.id, True, sent=p) for p in project.ledger]
    sync = planner.point_sync
    assert sync is not None
    sync.model.apply_upload(UploadReport(points))
    assert planner.summary_text == "Checks passed: ready to run"
    length = planner.segments.data(planner.segments.index(1, planner.segments.columnCount() - 2))
    assert length.endswith(" mm")


def test_many_segments_plan(planner: PlannerPanel, project: Project) -> None:
    segments = [Segment.arc(6, 7) if k % 2 else Segment.line(5) for k in range(1000)]
    planner.segments.set_plan(None)
    project.plans[1].segments[:] = segments
    planner.select_plan(1)
    assert planner.segments.rowCount() == 1000
    assert planner.preview.path is not None and planner.preview.path.xyz.shape[0] >= 1000


def test_bad_end_point_marks_points_unknown_and_offers_restore(
    qtbot: Any, planner: PlannerPanel, link: FakeLink, project: Project, worker: Worker
) -> None:
    all_uploaded(project)
    planner.select_plan(1)
    sync = planner.point_sync
    assert sync is not None and not sync.restore_offered
    planner.answers.append(True)  # type: ignore[attr-defined]
    assert planner.run(0)
    worker.create_points()
    with qtbot.waitSignal(sync.restoreOffered):
        link.finish_move(False, code=13, message="move to temp point refused: bad end point id")
    assert project.ledger.point(5).sync is SyncState.UNKNOWN
    assert project.ledger.point(6).sync is SyncState.ON_CONTROLLER
    assert "Upload now?" in planner.summary_text


def test_resume_after_an_edit_runs_the_edited_segments(
    qtbot: Any, planner: PlannerPanel, link: FakeLink, project: Project, worker: Worker
) -> None:
    all_uploaded(project)
    planner.select_plan(1)
    planner.answers.append(True)  # type: ignore[attr-defined]
    assert planner.run(0)
    worker.create_points()
    worker.finish_move()
    with qtbot.waitSignal(planner.run_controller.runFinished):
        worker.finish_move(False, code=12, message="motion timeout")
    assert planner.segments.setData(planner.segments.index(1, COL_SPEED), "20")
    planner.answers.append(True)  # type: ignore[attr-defined]
    planner.action_resume_from.trigger()
    worker.create_points()
    last = link.named(MoveToPoint)[-1]
    assert (last.end_id, last.via_id, last.speed) == (7, 6, 20.0)
    with qtbot.waitSignal(planner.run_controller.runFinished) as finished:
        for _ in range(3):
            worker.finish_move()
    assert finished.args[0].state is RunState.FINISHED
