"""The planner's plan on display, kept in step: the segment table shows the plan selected in
the plan list; a plan added, removed or reset in the list, an undo that switched the table to
another plan, plans and points that changed, and the selection of segments all update the
table, the list, the checks and the preview.

The panel owns the widgets and the models; :class:`PlanFollower` only connects their signals
and reacts (the run reactions stay on the panel).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

from PySide6.QtCore import QModelIndex, QObject, Slot
from PySide6.QtWidgets import QTableView

from app.plan.runner import RunState
from app.plan.segments import Plan
from ui.controllers.plan_run_controller import PlanRunController
from ui.models.plan_model import PlanListModel
from ui.models.points_model import PointsModel
from ui.models.segment_model import SegmentTableModel
from ui.panels.plan_preview import PlanPreview
from ui.panels.planner_checks import PlannerChecks
from ui.panels.planner_run import PlanRunFlow


class PlannerLists(Protocol):
    """What the follower needs of the planner panel."""

    plan_view: QTableView
    segment_view: QTableView
    preview: PlanPreview
    checks: PlannerChecks
    run_flow: PlanRunFlow

    @property
    def run_controller(self) -> PlanRunController: ...

    def current_plan(self) -> Plan | None: ...

    def select_plan(self, row: int) -> None: ...

    def selected_segments(self) -> list[int]: ...

    def recheck(self) -> None: ...


class PlanFollower(QObject):
    """Connects the plan list, the segment table and the points to the panel (see the module
    docstring); ``update_actions`` is called whenever what the actions depend on changed."""

    def __init__(
        self,
        view: PlannerLists,
        plans: PlanListModel,
        points: PointsModel,
        segments: SegmentTableModel,
        update_actions: Callable[[], None],
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._view = view
        self._plans = plans
        self._points = points
        self._segments = segments
        self._update_actions = update_actions

        plans.modelReset.connect(self._on_plans_reset)
        plans.rowsInserted.connect(self._on_plans_inserted)
        plans.rowsRemoved.connect(self._on_plans_removed)
        plans.planChanged.connect(self._on_plan_changed)
        segments.listEdited.connect(self._on_segments_edited)
        segments.modelReset.connect(view.recheck)
        segments.planShown.connect(self._on_plan_shown)
        for signal in (
            points.dataChanged,
            points.rowsInserted,
            points.rowsRemoved,
            points.rowsMoved,
            points.modelReset,
            points.planReferencesChanged,
        ):
            signal.connect(self._on_points_changed)
        points.modelReset.connect(lambda: segments.set_ledger(points.ledger))
        view.plan_view.selectionModel().currentRowChanged.connect(self._on_plan_row)
        view.segment_view.selectionModel().selectionChanged.connect(self._on_segment_selection)

    @Slot()
    def _on_plans_reset(self) -> None:
        self._segments.set_ledger(self._points.ledger)
        self._view.select_plan(0 if self._plans.rowCount() else -1)

    @Slot(QModelIndex, int, int)
    def _on_plans_inserted(self, parent: QModelIndex, first: int, last: int) -> None:
        self._view.select_plan(first)

    @Slot(QModelIndex, int, int)
    def _on_plans_removed(self, parent: QModelIndex, first: int, last: int) -> None:
        plan = self._view.current_plan()
        if plan is not None and self._plans.row_of(plan) is None:
            self._view.select_plan(min(first, self._plans.rowCount() - 1))

    @Slot(object)
    def _on_plan_changed(self, plan: object) -> None:
        if plan is self._view.current_plan():
            self._view.recheck()

    @Slot(object)
    def _on_plan_shown(self, plan: object) -> None:
        row = self._plans.row_of(plan) if isinstance(plan, Plan) else None
        if row is not None:
            plan_view = self._view.plan_view
            plan_view.blockSignals(True)
            plan_view.selectRow(row)
            plan_view.blockSignals(False)

    @Slot(object)
    def _on_segments_edited(self, plan: object) -> None:
        self._plans.refresh_plan(plan)
        self._view.recheck()

    @Slot()
    def _on_points_changed(self, *_args: Any) -> None:
        self._segments.refresh()
        self._view.recheck()

    @Slot(QModelIndex, QModelIndex)
    def _on_plan_row(self, current: QModelIndex, previous: QModelIndex) -> None:
        row = current.row()
        plan = self._plans.plan_at(row) if 0 <= row < self._plans.rowCount() else None
        self._segments.set_plan(plan)
        r = self._view.run_controller
        if not r.running:
            self._view.preview.clear_live()  # the last run's TCP trail belongs to its plan
            if (
                plan is not None
                and plan is self._view.run_flow.run_plan
                and r.can_resume
                and r.outcome is not None
            ):
                failed = r.resume_from if r.outcome.state is RunState.FAILED else None
                self._segments.set_run_marker(None, failed)
        self._update_actions()

    @Slot()
    def _on_segment_selection(self, *_args: Any) -> None:
        rows = self._view.selected_segments()
        index = rows[0] if rows else None
        self._view.preview.set_selected(index)
        self._view.checks.show_info(self._view.current_plan(), index)
        self._update_actions()
