"""The planner's edits of the plan list and of the segments: add, rename, duplicate and delete
plans; add, delete and move segments. The models make them undoable; this keeps the selection
on what was edited and reports refusals on the panel's status line. :func:`install_point_pickers`
puts the point pickers in the segment table's middle / end point columns."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from PySide6.QtCore import QObject, Slot
from PySide6.QtWidgets import QTableView

from app.errors import InvalidInput
from app.plan.segments import Plan, SegmentKind
from app.points.ledger import PointLedger
from ui.messages import refusal_text
from ui.models.plan_columns import COL_END, COL_VIA, PLAN_COL_NAME
from ui.models.plan_model import PlanListModel
from ui.models.segment_model import SegmentTableModel
from ui.widgets.point_picker import PointPickerDelegate


def install_point_pickers(
    view: QTableView, ledger: Callable[[], PointLedger]
) -> tuple[PointPickerDelegate, PointPickerDelegate]:
    """Point pickers (existing points by id and name, no free number) for the middle point
    (may stay blank) and the end point columns of ``view``; returns (middle, end)."""
    via = PointPickerDelegate(ledger, view, allow_blank=True)
    end = PointPickerDelegate(ledger, view)
    view.setItemDelegateForColumn(COL_VIA, via)
    view.setItemDelegateForColumn(COL_END, end)
    return via, end


class PlanEditView(Protocol):
    """What the edits need of the planner panel."""

    plan_view: QTableView

    def current_plan(self) -> Plan | None: ...

    def select_plan(self, row: int) -> None: ...

    def selected_segments(self) -> list[int]: ...

    def select_segments(self, rows: Sequence[int]) -> None: ...

    def show_message(self, text: str, level: str = "info") -> None: ...


class PlanEdits(QObject):
    """Plan and segment edits on behalf of the planner panel (its actions call these)."""

    def __init__(
        self,
        view: PlanEditView,
        plans: PlanListModel,
        segments: SegmentTableModel,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._view = view
        self._plans = plans
        self._segments = segments

    @Slot()
    def add_plan(self) -> None:
        row = self._plans.add_plan()
        self._view.select_plan(row)

    @Slot()
    def rename_plan(self) -> None:
        """Edit the selected plan's name in place (undoable like every edit)."""
        row = self._view.plan_view.currentIndex().row()
        if row >= 0:
            self._view.plan_view.setFocus()
            self._view.plan_view.edit(self._plans.index(row, PLAN_COL_NAME))

    @Slot()
    def duplicate_plan(self) -> None:
        row = self._view.plan_view.currentIndex().row()
        if row >= 0:
            self._view.select_plan(self._plans.duplicate_plan(row))

    @Slot()
    def delete_plan(self) -> None:
        row = self._view.plan_view.currentIndex().row()
        if row < 0:
            return
        name = self._plans.plan_at(row).name
        self._plans.remove_plan(row)
        self._view.select_plan(min(row, self._plans.rowCount() - 1))
        self._view.show_message(self.tr("Deleted plan {name} (Ctrl+Z to undo)").format(name=name))

    def add_segment(self, kind: SegmentKind) -> None:
        """A segment of ``kind`` after the selection (a new plan first when there is none)."""
        if self._view.current_plan() is None:
            self.add_plan()
        rows = self._view.selected_segments()
        at = rows[-1] + 1 if rows else None
        try:
            row = self._segments.insert_segment(at, kind)
        except InvalidInput as exc:
            self._view.show_message(refusal_text(exc), "error")
            return
        self._view.select_segments([row])

    @Slot()
    def delete_segments(self) -> None:
        rows = self._view.selected_segments()
        try:
            n = self._segments.remove_rows(rows)
        except InvalidInput as exc:
            self._view.show_message(refusal_text(exc), "error")
            return
        if n:
            left = min(rows[0], self._segments.rowCount() - 1)
            self._view.select_segments([left] if left >= 0 else [])

    def move_segments(self, delta: int) -> None:
        try:
            rows = self._segments.move_rows(self._view.selected_segments(), delta)
        except InvalidInput as exc:
            self._view.show_message(refusal_text(exc), "error")
            return
        self._view.select_segments(rows)
