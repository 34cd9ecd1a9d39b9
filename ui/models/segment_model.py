"""Qt model of the segments of one plan (:class:`SegmentTableModel`). Every edit is a
``QUndoCommand`` on the project's stack.

The model shows one plan at a time. An undo or redo of a command that belongs to another plan
first switches the model to that plan and emits ``planShown`` so that the panel selects it in
the list: the operator always sees what an undo changed.

The results of the checks (:func:`app.plan.checks.check_plan`) and the estimates
(:func:`app.plan.estimates.estimate_plan`) are given to the model by the panel
(:meth:`SegmentTableModel.set_issues`, :meth:`SegmentTableModel.set_estimate`); each row shows
its issues as an icon and a tooltip in the ``#`` column. What an edit accepts and the segment a
new row starts with are :mod:`ui.models.segment_edits`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np
from PySide6.QtCore import (
    QCoreApplication,
    QModelIndex,
    Qt,
    Signal,
)
from PySide6.QtGui import QBrush, QColor, QIcon, QUndoStack

from app.errors import InvalidInput
from app.plan.checks import IssueKind, PlanIssue
from app.plan.segments import (
    Plan,
    Segment,
    SegmentKind,
)
from app.points.ledger import PointLedger
from ui.messages import issue_line, refusal_text
from ui.models.plan_columns import (
    COL_END,
    COL_IGNORE,
    COL_INDEX,
    COL_KIND,
    COL_LENGTH,
    COL_ORIENTATION,
    COL_SPEED,
    COL_TIME,
    COL_TOOL,
    COL_VIA,
    EDITABLE_COLUMNS,
    ISSUE_LEVEL_ROLE,
    ISSUE_ORDER,
    ISSUE_ROLE,
    RIGHT_ALIGNED,
    SEG_COLUMNS,
    ModelIndex,
    issue_icon,
    kind_text,
    orientation_text,
)
from ui.models.point_columns import tool_display
from ui.models.segment_edits import default_segment, edited_segment, is_checked
from ui.models.undo_list import (
    InsertRowsCommand,
    MoveRowsCommand,
    RemoveRowsCommand,
    ReplaceRowCommand,
    UndoableListModel,
)
from ui.palette import COLOR_ACTIVE_BG, COLOR_ERROR, COLOR_ERROR_BG


class SegmentTableModel(UndoableListModel):
    """The segments of one plan: type, middle point, end point, speed, orientation,
    ignore-middle, tool (editable), estimated length and time, checks (icon + tooltip).

    Signals: ``editRejected(str)``, ``listEdited(object)`` (inherited: the plan changed),
    ``planShown(object)`` (an undo / redo switched to another plan).
    """

    planShown = Signal(object)

    def __init__(self, undo_stack: QUndoStack, ledger: PointLedger | None = None, parent: Any = None) -> None:
        super().__init__(undo_stack, parent)
        self._plan: Plan | None = None
        self._ledger = ledger if ledger is not None else PointLedger()  # an empty ledger is falsy
        self._issues: dict[int, list[PlanIssue]] = {}
        self._lengths: np.ndarray = np.empty(0)
        self._times: np.ndarray = np.empty(0)
        self._active: int | None = None
        self._failed: int | None = None
        self._locked = False
        self._headers: tuple[str, ...] = ()
        self._icons: dict[IssueKind, QIcon] = {}  # made on first use (pixmaps need a GUI application)
        self._missing = QBrush(QColor(COLOR_ERROR))
        self._active_bg = QBrush(QColor(COLOR_ACTIVE_BG))
        self._failed_bg = QBrush(QColor(COLOR_ERROR_BG))
        role = Qt.ItemDataRole
        self._role_data: dict[int, Callable[[int, Segment, int], Any]] = {
            role.DisplayRole: self._display,
            role.EditRole: lambda _row, seg, column: self._edit_value(seg, column),
            role.CheckStateRole: self._check_state,
            role.DecorationRole: self._decoration,
            role.ToolTipRole: self._tooltip,
            role.ForegroundRole: self._foreground,
            role.BackgroundRole: self._background,
            role.TextAlignmentRole: self._alignment,
            ISSUE_ROLE: lambda row, _seg, _column: self.issues_of(row),
            ISSUE_LEVEL_ROLE: lambda row, _seg, _column: self._worst(row),
        }
        self.retranslate()

    def tr(self, text: str, disambiguation: str | None = None, n: int = -1) -> str:
        return QCoreApplication.translate("SegmentTableModel", text, disambiguation, n)

    def retranslate(self) -> None:
        self._headers = (
            self.tr("Check"),
            self.tr("Type"),
            self.tr("Middle point"),
            self.tr("End point"),
            self.tr("Speed"),
            self.tr("Orientation"),
            self.tr("Ignore mid."),
            self.tr("Tool"),
            self.tr("Length"),
            self.tr("Time"),
        )
        self.headerDataChanged.emit(Qt.Orientation.Horizontal, 0, len(SEG_COLUMNS) - 1)

    # --- what is shown
    @property
    def plan(self) -> Plan | None:
        return self._plan

    @property
    def ledger(self) -> PointLedger:
        return self._ledger

    def set_plan(self, plan: Plan | None) -> None:
        if plan is self._plan:
            return
        self.beginResetModel()
        self._plan = plan
        self._issues = {}
        self._lengths = np.empty(0)
        self._times = np.empty(0)
        self._active = self._failed = None
        self.endResetModel()

    def set_ledger(self, ledger: PointLedger) -> None:
        self._ledger = ledger
        self.refresh()

    def refresh(self) -> None:
        """Points changed: names, missing points."""
        if self.rowCount():
            self.dataChanged.emit(self.index(0, 0), self.index(self.rowCount() - 1, len(SEG_COLUMNS) - 1))

    def set_locked(self, locked: bool) -> None:
        """Read-only while a run uses the plan."""
        self._locked = locked

    @property
    def locked(self) -> bool:
        return self._locked

    def set_issues(self, issues: Iterable[PlanIssue]) -> None:
        by_row: dict[int, list[PlanIssue]] = {}
        for issue in issues:
            if issue.segment is not None:
                by_row.setdefault(issue.segment, []).append(issue)
        for items in by_row.values():
            items.sort(key=lambda i: ISSUE_ORDER[i.kind])
        self._issues = by_row
        if self.rowCount():
            self.dataChanged.emit(self.index(0, COL_INDEX), self.index(self.rowCount() - 1, COL_INDEX))

    def issues_of(self, row: int) -> list[PlanIssue]:
        return list(self._issues.get(row, ()))

    def set_estimate(
        self, lengths: Sequence[float] | np.ndarray, times: Sequence[float] | np.ndarray
    ) -> None:
        self._lengths = np.asarray(lengths, dtype=np.float64)
        self._times = np.asarray(times, dtype=np.float64)
        if self.rowCount():
            self.dataChanged.emit(self.index(0, COL_LENGTH), self.index(self.rowCount() - 1, COL_TIME))

    def set_run_marker(self, active: int | None, failed: int | None = None) -> None:
        """Highlight the running segment (blue) or the one a run failed at (red)."""
        if (active, failed) == (self._active, self._failed):
            return
        self._active, self._failed = active, failed
        self.refresh()

    # --- Qt model
    def rowCount(self, parent: ModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() or self._plan is None else len(self._plan)

    def columnCount(self, parent: ModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(SEG_COLUMNS)

    def segment_at(self, row: int) -> Segment:
        assert self._plan is not None
        return self._plan[row]

    def headerData(
        self, section: int, orientation: Qt.Orientation, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        if orientation == Qt.Orientation.Vertical:
            return section + 1 if role == Qt.ItemDataRole.DisplayRole else None
        if orientation == Qt.Orientation.Horizontal and 0 <= section < len(SEG_COLUMNS):
            if role == Qt.ItemDataRole.DisplayRole:
                return self._headers[section]
            if role == Qt.ItemDataRole.ToolTipRole:
                return {
                    COL_INDEX: self.tr("Checks before running: hover the icon for details"),
                    COL_SPEED: self.tr("Speed in mm/s (GV225)"),
                    COL_VIA: self.tr("Middle point of an arc (GV200)"),
                    COL_END: self.tr("End point (GV201)"),
                    COL_ORIENTATION: self.tr("Orientation kept constant or changing along the move (GV202)"),
                    COL_IGNORE: self.tr("Ignore the arc's middle point orientation (GV203)"),
                    COL_TOOL: self.tr("Tool frame of the move (GV245)"),
                    COL_LENGTH: self.tr("Estimated path length"),
                    COL_TIME: self.tr("Estimated time: length / speed plus a fixed overhead per segment"),
                }.get(section)
        return None

    def data(self, index: ModelIndex, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
        plan = self._plan
        if plan is None or not index.isValid() or not 0 <= index.row() < len(plan):
            return None
        row, column = index.row(), index.column()
        if not 0 <= column < len(SEG_COLUMNS):
            return None
        role_data = self._role_data.get(role)
        return None if role_data is None else role_data(row, plan[row], column)

    # --- what each role shows (row, segment, column) -> value; None: nothing
    def _check_state(self, _row: int, seg: Segment, column: int) -> Qt.CheckState | None:
        if column != COL_IGNORE:
            return None
        return Qt.CheckState.Checked if seg.ignore_middle else Qt.CheckState.Unchecked

    def _decoration(self, row: int, _seg: Segment, column: int) -> QIcon | None:
        worst = self._worst(row) if column == COL_INDEX else None
        if worst is None:
            return None
        if worst not in self._icons:
            self._icons[worst] = issue_icon(worst)
        return self._icons[worst]

    def _foreground(self, _row: int, seg: Segment, column: int) -> QBrush | None:
        if column not in (COL_VIA, COL_END):
            return None
        pid = seg.via_id if column == COL_VIA else seg.end_id
        return self._missing if pid is not None and self._ledger.get(pid) is None else None

    def _background(self, row: int, _seg: Segment, _column: int) -> QBrush | None:
        if row == self._failed:
            return self._failed_bg
        return self._active_bg if row == self._active else None

    @staticmethod
    def _alignment(_row: int, _seg: Segment, column: int) -> int | None:
        return (
            int(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            if column in RIGHT_ALIGNED
            else None
        )

    def _worst(self, row: int) -> IssueKind | None:
        issues = self._issues.get(row)
        return issues[0].kind if issues else None

    def _point_text(self, pid: int | None) -> str:
        if pid is None:
            return "—"
        point = self._ledger.get(pid)
        if point is None:
            return f"P{pid}  ?"
        return f"P{pid}  {point.name}" if point.name else f"P{pid}"

    def _display(self, row: int, seg: Segment, column: int) -> str | None:
        if column == COL_INDEX:
            return None  # the icon; the row number is the vertical header (a cell must not depend on its row)
        if column == COL_KIND:
            return kind_text(seg.kind)
        if column == COL_VIA:
            return self._point_text(seg.via_id) if seg.is_arc else ""
        if column == COL_END:
            return self._point_text(seg.end_id)
        if column == COL_SPEED:
            return f"{seg.speed:g} mm/s"
        if column == COL_ORIENTATION:
            return orientation_text(seg.orientation_changes)
        if column == COL_IGNORE:
            return None
        if column == COL_TOOL:
            return tool_display(seg.tool)
        values = self._lengths if column == COL_LENGTH else self._times
        if row < values.shape[0] and math.isfinite(float(values[row])):
            return f"{float(values[row]):.1f} " + ("mm" if column == COL_LENGTH else "s")
        return "—"

    @staticmethod
    def _edit_value(seg: Segment, column: int) -> Any:
        if column == COL_KIND:
            return seg.kind.value
        if column == COL_VIA:
            return "" if seg.via_id is None else str(seg.via_id)
        if column == COL_END:
            return str(seg.end_id)
        if column == COL_SPEED:
            return repr(seg.speed)
        if column == COL_ORIENTATION:
            return seg.orientation
        if column == COL_IGNORE:
            return seg.ignore_middle
        if column == COL_TOOL:
            return str(seg.tool)
        return None

    def _tooltip(self, row: int, seg: Segment, column: int) -> str | None:
        if column == COL_INDEX:
            issues = self._issues.get(row)
            if not issues:
                return self.tr("Segment {n}: no problems found").format(n=row + 1)
            return "\n".join(issue_line(i) for i in issues)
        if column in (COL_VIA, COL_END):
            pid = seg.via_id if column == COL_VIA else seg.end_id
            if pid is not None and self._ledger.get(pid) is None:
                return self.tr("Point P{id} does not exist").format(id=pid)
        return None

    def flags(self, index: ModelIndex) -> Qt.ItemFlag:
        if not index.isValid():
            return Qt.ItemFlag.NoItemFlags
        base = Qt.ItemFlag.ItemIsSelectable | Qt.ItemFlag.ItemIsEnabled
        column = index.column()
        if self._locked or column not in EDITABLE_COLUMNS or self._plan is None:
            return base
        if column == COL_IGNORE:
            return base | Qt.ItemFlag.ItemIsUserCheckable
        if column == COL_VIA and 0 <= index.row() < len(self._plan) and not self._plan[index.row()].is_arc:
            return base
        return base | Qt.ItemFlag.ItemIsEditable

    def setData(self, index: ModelIndex, value: Any, role: int = Qt.ItemDataRole.EditRole) -> bool:
        plan = self._plan
        if plan is None or not index.isValid() or value is None or self._locked:
            return False
        row, column = index.row(), index.column()
        if not 0 <= row < len(plan) or column not in EDITABLE_COLUMNS:
            return False
        if column == COL_IGNORE:
            if role != Qt.ItemDataRole.CheckStateRole:
                return False
            value = is_checked(value)
        elif role != Qt.ItemDataRole.EditRole:
            return False
        name = SEG_COLUMNS[column]
        try:
            return self.edit_field(row, name, value)
        except InvalidInput as exc:
            reason = refusal_text(exc)
            self.editRejected.emit(
                self.tr("Segment {n}, {column}: refused, {reason}").format(
                    n=row + 1, column=self._headers[column], reason=reason
                )
            )
            return False

    # --- edits (undoable; raise InvalidInput when refused)
    def edit_field(self, row: int, name: str, value: object) -> bool:
        plan = self._require_plan()
        old = plan[row]
        new = edited_segment(old, name, value, self._ledger)
        if new == old:
            return False
        column = self._headers[SEG_COLUMNS.index(name)] if name in SEG_COLUMNS else name
        text = self.tr("Edit segment {n} {column}").format(n=row + 1, column=column)
        self._stack.push(ReplaceRowCommand(self, plan, row, old, new, text))
        return True

    def insert_segment(self, row: int | None, kind: SegmentKind = SegmentKind.LINE) -> int:
        """A new segment after ``row`` (default: at the end), with points guessed from the
        previous segment (the next points of the ledger), its speed and tool."""
        plan = self._require_plan()
        at = len(plan) if row is None else max(0, min(row, len(plan)))
        segment = self.default_segment(at, kind)
        self._stack.push(
            InsertRowsCommand(
                self, plan, [(at, segment)], self.tr("Add {kind} segment").format(kind=kind_text(kind))
            )
        )
        return at

    def default_segment(self, at: int, kind: SegmentKind) -> Segment:
        """End = the point after the previous segment's end (the first point at the start);
        an arc's middle point is that point and its end the one after. Refused (InvalidInput)
        when there are not enough points: a segment never starts on an id that does not exist."""
        return default_segment(self._require_plan(), self._ledger.ids(), at, kind)

    def insert_segments(self, at: int, segments: Sequence[Segment]) -> None:
        plan = self._require_plan()
        at = max(0, min(at, len(plan)))
        items = [(at + k, seg) for k, seg in enumerate(segments)]
        if items:
            self._stack.push(
                InsertRowsCommand(self, plan, items, self.tr("Add {n} segments").format(n=len(items)))
            )

    def remove_rows(self, rows: Iterable[int]) -> int:
        plan = self._require_plan()
        chosen = sorted({r for r in rows if 0 <= r < len(plan)})
        if not chosen:
            return 0
        text = (
            self.tr("Delete segment {n}").format(n=chosen[0] + 1)
            if len(chosen) == 1
            else self.tr("Delete {n} segments").format(n=len(chosen))
        )
        self._stack.push(RemoveRowsCommand(self, plan, chosen, text))
        return len(chosen)

    def can_move(self, rows: Iterable[int], delta: int) -> bool:
        chosen = sorted(set(rows))
        if not chosen or self._plan is None:
            return False
        return chosen[0] + delta >= 0 if delta < 0 else chosen[-1] + delta < len(self._plan)

    def move_rows(self, rows: Iterable[int], delta: int) -> list[int]:
        plan = self._require_plan()
        chosen = sorted(set(rows))
        if not self.can_move(chosen, delta):
            return chosen
        command = MoveRowsCommand(
            self,
            plan,
            chosen,
            delta,
            self.tr("Move segment up") if delta < 0 else self.tr("Move segment down"),
        )
        self._stack.push(command)
        return list(command.new_rows)

    def _require_plan(self) -> Plan:
        if self._plan is None:
            raise InvalidInput("no plan is selected")
        if self._locked:
            raise InvalidInput("the plan is running: stop it before editing")
        return self._plan

    # --- command hooks
    def _show(self, target: Any) -> None:
        if target is not self._plan:
            self.set_plan(target)
            self.planShown.emit(target)
