"""Qt model of the project's plans (:class:`PlanListModel`): name, loops, segments. Every
edit is a ``QUndoCommand`` on the project's stack.

The segments of one plan are in :mod:`ui.models.segment_model`; the columns, roles and issue
icons both use are in :mod:`ui.models.plan_columns`.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import (
    QAbstractTableModel,
    QCoreApplication,
    QModelIndex,
    Qt,
    Signal,
)
from PySide6.QtGui import QUndoCommand, QUndoStack

from app.errors import InvalidInput
from app.plan.segments import (
    Plan,
    validate_loops,
    validate_plan_name,
)
from app.points.fields import FieldError
from app.points.project_model import Project
from ui.messages import refusal_text
from ui.models.plan_columns import (
    PLAN_COL_LOOPS,
    PLAN_COL_NAME,
    PLAN_COL_SEGMENTS,
    PLAN_COLUMNS,
    ModelIndex,
)


class _PlanListCommand(QUndoCommand):
    def __init__(self, model: PlanListModel, text: str) -> None:
        super().__init__(text)
        self._model = model


class _InsertPlanCommand(_PlanListCommand):
    def __init__(
        self, model: PlanListModel, row: int, plan: Plan, text: str, *, remove: bool = False
    ) -> None:
        super().__init__(model, text)
        self._row = row
        self._plan = plan
        self._remove = remove

    def redo(self) -> None:
        if self._remove:
            self._model._remove(self._row)
        else:
            self._model._insert(self._row, self._plan)

    def undo(self) -> None:
        if self._remove:
            self._model._insert(self._row, self._plan)
        else:
            self._model._remove(self._row)


class _PlanFieldCommand(_PlanListCommand):
    def __init__(
        self, model: PlanListModel, plan: Plan, name: str, old: object, new: object, text: str
    ) -> None:
        super().__init__(model, text)
        self._plan = plan
        self._name = name
        self._old = old
        self._new = new

    def redo(self) -> None:
        self._model._set(self._plan, self._name, self._new)

    def undo(self) -> None:
        self._model._set(self._plan, self._name, self._old)


class PlanListModel(QAbstractTableModel):
    """The project's plans: name (editable, unique), loops (editable, 0 = endless), segments.

    Signals: ``editRejected(str)``, ``planChanged(object)`` (a plan's name / loops changed).
    """

    editRejected = Signal(str)
    planChanged = Signal(object)

    def __init__(self, project: Project, undo_stack: QUndoStack, parent: Any = None) -> None:
        super().__init__(parent)
        self._project = project
        self._stack = undo_stack
        self._headers: tuple[str, ...] = ()
        self.retranslate()

    def tr(self, text: str, disambiguation: str | None = None, n: int = -1) -> str:
        return QCoreApplication.translate("PlanListModel", text, disambiguation, n)

    def retranslate(self) -> None:
        self._headers = (self.tr("Plan"), self.tr("Loops"), self.tr("Segments"))
        self.headerDataChanged.emit(Qt.Orientation.Horizontal, 0, len(PLAN_COLUMNS) - 1)

    @property
    def project(self) -> Project:
        return self._project

    @property
    def undo_stack(self) -> QUndoStack:
        return self._stack

    def set_project(self, project: Project) -> None:
        self.beginResetModel()
        self._project = project
        self.endResetModel()

    def plan_at(self, row: int) -> Plan:
        return self._project.plans[row]

    def row_of(self, plan: Plan) -> int | None:
        for row, p in enumerate(self._project.plans):
            if p is plan:
                return row
        return None

    def rowCount(self, parent: ModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(self._project.plans)

    def columnCount(self, parent: ModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(PLAN_COLUMNS)

    def headerData(
        self, section: int, orientation: Qt.Orientation, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        if role != Qt.ItemDataRole.DisplayRole:
            return None
        if orientation == Qt.Orientation.Horizontal and 0 <= section < len(PLAN_COLUMNS):
            return self._headers[section]
        if orientation == Qt.Orientation.Vertical:
            return section + 1
        return None

    def data(self, index: ModelIndex, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
        if not index.isValid() or not 0 <= index.row() < len(self._project.plans):
            return None
        plan = self._project.plans[index.row()]
        column = index.column()
        if role in (Qt.ItemDataRole.DisplayRole, Qt.ItemDataRole.EditRole):
            if column == PLAN_COL_NAME:
                return plan.name
            if column == PLAN_COL_LOOPS:
                if role == Qt.ItemDataRole.EditRole:
                    return str(plan.loops)
                return self.tr("endless") if plan.loops == 0 else str(plan.loops)
            if column == PLAN_COL_SEGMENTS:
                return str(len(plan))
        if role == Qt.ItemDataRole.ToolTipRole and column == PLAN_COL_LOOPS:
            return self.tr("How many times the plan runs (0 = until stopped)")
        if role == Qt.ItemDataRole.TextAlignmentRole and column != PLAN_COL_NAME:
            return int(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        return None

    def flags(self, index: ModelIndex) -> Qt.ItemFlag:
        if not index.isValid():
            return Qt.ItemFlag.NoItemFlags
        base = Qt.ItemFlag.ItemIsSelectable | Qt.ItemFlag.ItemIsEnabled
        if index.column() in (PLAN_COL_NAME, PLAN_COL_LOOPS):
            base |= Qt.ItemFlag.ItemIsEditable
        return base

    def setData(self, index: ModelIndex, value: Any, role: int = Qt.ItemDataRole.EditRole) -> bool:
        if role != Qt.ItemDataRole.EditRole or not index.isValid() or value is None:
            return False
        if not 0 <= index.row() < len(self._project.plans):
            return False
        try:
            if index.column() == PLAN_COL_NAME:
                return self.rename(index.row(), value)
            if index.column() == PLAN_COL_LOOPS:
                return self.set_loops(index.row(), value)
        except InvalidInput as exc:
            reason = refusal_text(exc)
            self.editRejected.emit(self.tr("Plan: refused, {reason}").format(reason=reason))
        return False

    # --- edits (undoable; raise InvalidInput when refused)
    def add_plan(self, plan: Plan | None = None, row: int | None = None) -> int:
        if plan is None:
            plan = Plan(self._project.unique_plan_name(self.tr("plan")))
        elif plan.name in self._project.plan_names():
            plan = plan.copy(self._project.unique_plan_name(plan.name))
        row = len(self._project.plans) if row is None else max(0, min(row, len(self._project.plans)))
        text = self.tr("Add plan {name}").format(name=plan.name)
        self._stack.push(_InsertPlanCommand(self, row, plan, text))
        return row

    def duplicate_plan(self, row: int) -> int:
        source = self._project.plans[row]
        copy = source.copy(self._project.unique_plan_name(source.name))
        self._stack.push(
            _InsertPlanCommand(self, row + 1, copy, self.tr("Duplicate plan {name}").format(name=source.name))
        )
        return row + 1

    def remove_plan(self, row: int) -> None:
        plan = self._project.plans[row]
        text = self.tr("Delete plan {name}").format(name=plan.name)
        self._stack.push(_InsertPlanCommand(self, row, plan, text, remove=True))

    def rename(self, row: int, name: object) -> bool:
        plan = self._project.plans[row]
        new = validate_plan_name(name)
        if new == plan.name:
            return False
        if new in self._project.plan_names():
            raise FieldError("name", f"a plan named {new!r} already exists")
        text = self.tr("Rename plan {old} to {new}").format(old=plan.name, new=new)
        self._stack.push(_PlanFieldCommand(self, plan, "name", plan.name, new, text))
        return True

    def set_loops(self, row: int, loops: object) -> bool:
        plan = self._project.plans[row]
        new = validate_loops(loops)
        if new == plan.loops:
            return False
        text = self.tr("Set loops of {name} to {n}").format(name=plan.name, n=new)
        self._stack.push(_PlanFieldCommand(self, plan, "loops", plan.loops, new, text))
        return True

    def refresh_plan(self, plan: object) -> None:
        """A plan's segments changed (count column)."""
        row = self.row_of(plan) if isinstance(plan, Plan) else None
        if row is not None:
            self.dataChanged.emit(self.index(row, 0), self.index(row, len(PLAN_COLUMNS) - 1))

    # --- command hooks
    def _insert(self, row: int, plan: Plan) -> None:
        self.beginInsertRows(QModelIndex(), row, row)
        self._project.add_plan(plan, row)
        self.endInsertRows()

    def _remove(self, row: int) -> None:
        self.beginRemoveRows(QModelIndex(), row, row)
        self._project.remove_plan(row)
        self.endRemoveRows()

    def _set(self, plan: Plan, name: str, value: object) -> None:
        row = self.row_of(plan)
        if row is None:
            raise RuntimeError("undo command for a plan that is no longer in the project")
        if name == "name":
            self._project.rename_plan(row, str(value))
        else:
            plan.set_loops(value)
        self.dataChanged.emit(self.index(row, 0), self.index(row, len(PLAN_COLUMNS) - 1))
        self.planChanged.emit(plan)
