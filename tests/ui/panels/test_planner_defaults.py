"""Sane defaults in the planner (issue 9): segments pick existing points (a searchable picker,
missing ids refused or shown in red), new segments default to sensible points, Run is disabled
while the plan's checks find errors (the tooltip says why), a new plan's preview shows points."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoStack

from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.points.point import SyncState
from app.points.project import load_project
from app.points.project_model import Project
from tests.ui.fake_link import FakeLink
from ui.controllers.plan_run_controller import PlanRunController
from ui.controllers.point_sync import PointSyncController
from ui.models.plan_columns import COL_END, COL_VIA
from ui.models.plan_model import PlanListModel
from ui.models.points_model import PointsModel
from ui.panels.planner_panel import PlannerPanel
from ui.widgets.point_picker import PointPicker, parse_choice, point_choice_text

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"


@pytest.fixture
def project() -> Project:
    return load_project(SAMPLE)


@pytest.fixture
def link() -> FakeLink:
    return FakeLink()


@pytest.fixture
def planner(qtbot: Any, project: Project, link: FakeLink) -> Iterator[PlannerPanel]:
    stack = QUndoStack()
    points = PointsModel(project, stack)
    panel = PlannerPanel(
        PlanListModel(project, stack),
        points,
        PlanRunController(link, points=points),
        PointSyncController(points, link),
        confirm=lambda title, text: False,
    )
    qtbot.addWidget(panel)
    panel.resize(1280, 700)
    yield panel


def all_uploaded(project: Project) -> None:
    for point in project.ledger:
        project.ledger.set_sync(point.id, SyncState.ON_CONTROLLER)


# --- the picker -------------------------------------------------------------------------------------


def test_picker_lists_points_by_id_and_name_and_searches(qtbot: Any, project: Project) -> None:
    picker = PointPicker(project.ledger)
    qtbot.addWidget(picker)
    assert picker.count() == len(project.ledger) and picker.ids == project.ledger.ids()
    assert picker.itemText(4) == "P5 — circle W" == point_choice_text(5, "circle W")
    completer = picker.completer()
    assert completer is not None
    completer.setCompletionPrefix("CIRCLE")  # any part of the name, any case
    assert completer.completionCount() == 4
    completer.setCompletionPrefix("p7")
    assert completer.completionCount() == 1 and completer.currentCompletion() == "P7 — circle E"
    picker.set_point_id(6)
    assert picker.point_id() == 6 and picker.currentText() == "P6 — circle N" and picker.is_valid()
    assert parse_choice("p12 — x") == 12 and parse_choice(" 7 ") == 7 and parse_choice("abc") is None


def test_picker_shows_a_missing_point_in_red(qtbot: Any, project: Project) -> None:
    picker = PointPicker(project.ledger)
    qtbot.addWidget(picker)
    picker.set_point_id(42)
    assert picker.currentText() == "P42" and picker.point_id() is None and not picker.is_valid()
    edit = picker.lineEdit()
    assert edit is not None
    assert "color" in edit.styleSheet() and "P42 does not exist" in picker.toolTip()
    edit.setText("P3")  # typing an existing id is fine again
    assert picker.point_id() == 3 and edit.styleSheet() == ""
    edit.setText("")
    assert not picker.is_valid()  # an end point may not stay blank
    blank_ok = PointPicker(project.ledger, allow_blank=True)  # an arc's middle point may
    qtbot.addWidget(blank_ok)
    assert blank_ok.is_valid()


def test_segment_cells_edit_with_the_picker(qtbot: Any, planner: PlannerPanel, project: Project) -> None:
    planner.select_plan(1)  # circle: line P5, arc P6 -> P7, arc P8 -> P5, line P1
    view, segments = planner.segment_view, planner.segments
    planner.show()
    qtbot.waitExposed(planner)
    index = segments.index(0, COL_END)
    view.setCurrentIndex(index)
    view.edit(index)
    editor = view.findChild(PointPicker)
    assert editor is not None and editor.point_id() == 5  # opens on the segment's point
    editor.setCurrentIndex(editor.findData(3))
    qtbot.keyClick(editor, Qt.Key.Key_Return)  # commit as the operator does (Qt commits queued)
    plan = planner.current_plan()
    assert plan is not None
    qtbot.waitUntil(lambda: plan[0].end_id == 3)
    assert segments.data(segments.index(1, COL_VIA), Qt.ItemDataRole.EditRole) == "6"


def test_an_id_that_does_not_exist_is_refused(qtbot: Any, planner: PlannerPanel) -> None:
    planner.select_plan(1)
    plan = planner.current_plan()
    assert plan is not None
    before = list(plan.segments)
    for column, value in ((COL_END, "42"), (COL_VIA, "P99")):
        assert not planner.segments.setData(planner.segments.index(1, column), value)
        assert "does not exist" in planner.status.text() and "Segment 2" in planner.status.text()
    assert plan.segments == before and planner.segments.undo_stack.count() == 0
    assert planner.segments.setData(planner.segments.index(1, COL_VIA), "")  # blank middle: allowed


# --- new segments ---------------------------------------------------------------------------------


def test_new_segments_pick_the_next_existing_points(planner: PlannerPanel) -> None:
    planner.select_plan(1)
    plan = planner.current_plan()
    assert plan is not None
    planner.select_segments([1])  # the arc that ends at P7
    planner.action_add_line.trigger()
    assert plan[2] == Segment.line(8, 50.0)  # the point after P7, the previous speed
    planner.action_add_arc.trigger()  # after P8 the list wraps: middle P1, end P2
    assert plan[3].is_arc and (plan[3].via_id, plan[3].end_id) == (1, 2)
    planner.action_add_plan.trigger()
    new = planner.current_plan()
    assert new is not None and new is not plan
    planner.action_add_line.trigger()  # a new plan starts at the first point
    assert new.segments == [Segment.line(1)]


def test_no_segment_without_points(qtbot: Any, link: FakeLink) -> None:
    project = Project(ledger=PointLedger(), plans=[Plan("empty")])
    stack = QUndoStack()
    points = PointsModel(project, stack)
    panel = PlannerPanel(
        PlanListModel(project, stack),
        points,
        PlanRunController(link, points=points),
        confirm=lambda title, text: False,
    )
    qtbot.addWidget(panel)
    panel.action_add_line.trigger()
    assert len(project.plans[0]) == 0 and "no points yet" in panel.status.text()
    points.add_point(name="only", pose=(400, 0, 300, 180, 0, 0))
    panel.action_add_arc.trigger()
    assert len(project.plans[0]) == 0 and "two points" in panel.status.text()
    panel.action_add_line.trigger()
    assert project.plans[0].segments == [Segment.line(project.ledger.ids()[0])]


# --- Run and the checks -----------------------------------------------------------------------------


def test_run_is_disabled_while_the_checks_fail_and_says_why(planner: PlannerPanel, project: Project) -> None:
    all_uploaded(project)
    planner.select_plan(1)
    assert planner.action_run.isEnabled() and planner.action_step.isEnabled()
    plan = planner.current_plan()
    assert plan is not None
    good = plan[2]
    plan.replace(2, good.with_field("end", 42))  # P42 deleted since: the checks fail
    planner.recheck()
    assert not (planner.action_run.isEnabled() or planner.action_step.isEnabled())
    tip = planner.action_run.toolTip()
    assert "checks found errors" in tip and "P42 does not exist" in tip
    assert planner.action_add_line.isEnabled()  # the operator can still fix the plan
    plan.replace(2, good)
    planner.recheck()
    assert planner.action_run.isEnabled() and "disabled" not in planner.action_run.toolTip()


def test_a_new_plan_is_not_ready_and_its_preview_shows_the_points(
    planner: PlannerPanel, project: Project
) -> None:
    planner.action_add_plan.trigger()
    assert not planner.summary_text.startswith("Checks passed")
    assert not planner.action_run.isEnabled()
    assert "no segments" in planner.action_run.toolTip()
    top = planner.preview.projections["top"]
    assert top.points.data.shape[0] == len(project.ledger)
