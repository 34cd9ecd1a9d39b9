"""An undoable list model: a ``QAbstractTableModel`` over a list of rows, changed only by the
generic commands here (insert, remove, move, replace rows) pushed on a ``QUndoStack``.

:class:`~ui.models.points_model.PointsModel` (the point ledger) and
:class:`~ui.models.segment_model.SegmentTableModel` (a plan's segments) derive from
:class:`UndoableListModel`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from typing import Any, Protocol, TypeVar

from PySide6.QtCore import (
    QAbstractTableModel,
    QModelIndex,
    QPersistentModelIndex,
    Signal,
)
from PySide6.QtGui import QUndoCommand, QUndoStack

ModelIndex = QModelIndex | QPersistentModelIndex


T = TypeVar("T")


class RowList(Protocol[T]):
    """What a command needs of the list it changes (``PointLedger`` and ``Plan`` both fit)."""

    def __len__(self) -> int: ...
    def __getitem__(self, row: int) -> T: ...
    def insert(self, row: int, item: T) -> int: ...
    def remove(self, row: int) -> T: ...
    def move(self, src: int, dst: int) -> None: ...
    def replace(self, row: int, item: T) -> T: ...


class UndoableListModel(QAbstractTableModel):
    """A table model whose rows are the items of a :class:`RowList`.

    Subclasses implement :meth:`_show` (make ``target`` the list on display, e.g. another
    plan) and may override :meth:`_prepare` (adjust an item before it goes back in).
    The ``_apply_*`` methods are called by the commands only.
    """

    #: An edit refused (bad value, duplicate id ...): the message for the status line.
    editRejected = Signal(str)
    #: A command changed ``target``'s list (after the change).
    listEdited = Signal(object)

    def __init__(self, undo_stack: QUndoStack, parent: Any = None) -> None:
        super().__init__(parent)
        self._stack = undo_stack

    @property
    def undo_stack(self) -> QUndoStack:
        return self._stack

    def _show(self, target: Any) -> None:
        raise NotImplementedError

    def _prepare(self, target: Any, item: Any) -> Any:
        return item

    def _after_change(self, target: Any) -> None:
        self.listEdited.emit(target)

    # --- called by the commands
    def _apply_insert(self, target: RowList[Any], items: Sequence[tuple[int, Any]]) -> None:
        """Insert ``(row, item)`` pairs in ascending row order (rows are final positions)."""
        self._show(target)
        for row, item in items:
            prepared = self._prepare(target, item)
            self.beginInsertRows(QModelIndex(), row, row)
            target.insert(row, prepared)
            self.endInsertRows()
        self._after_change(target)

    def _apply_remove(self, target: RowList[Any], rows: Sequence[int]) -> list[tuple[int, Any]]:
        self._show(target)
        removed: list[tuple[int, Any]] = []
        for row in sorted(rows, reverse=True):
            self.beginRemoveRows(QModelIndex(), row, row)
            removed.append((row, target.remove(row)))
            self.endRemoveRows()
        self._after_change(target)
        removed.reverse()
        return removed

    def _apply_move(self, target: RowList[Any], rows: Sequence[int], delta: int) -> list[int]:
        """Move each of ``rows`` by ``delta`` (+1 / -1); returns the new rows (ascending)."""
        self._show(target)
        order = sorted(rows, reverse=delta > 0)
        for row in order:
            dst = row + delta
            # beginMoveRows wants the destination *before* the move (one past for downward moves)
            self.beginMoveRows(QModelIndex(), row, row, QModelIndex(), dst + 1 if delta > 0 else dst)
            target.move(row, dst)
            self.endMoveRows()
        self._after_change(target)
        return sorted(r + delta for r in rows)

    def _apply_replace(self, target: RowList[Any], row: int, item: Any) -> Any:
        self._show(target)
        old = target.replace(row, self._prepare(target, item))
        self.dataChanged.emit(self.index(row, 0), self.index(row, self.columnCount() - 1))
        self._after_change(target)
        return old


class InsertRowsCommand(QUndoCommand):
    """Insert items at rows (rows are where they end up, ascending)."""

    def __init__(
        self, model: UndoableListModel, target: RowList[Any], items: Sequence[tuple[int, Any]], text: str
    ) -> None:
        super().__init__(text)
        self._model = model
        self._target = target
        self._items = sorted(items, key=lambda pair: pair[0])

    def redo(self) -> None:
        self._model._apply_insert(self._target, self._items)

    def undo(self) -> None:
        self._model._apply_remove(self._target, [row for row, _ in self._items])


class RemoveRowsCommand(QUndoCommand):
    def __init__(
        self, model: UndoableListModel, target: RowList[Any], rows: Iterable[int], text: str
    ) -> None:
        super().__init__(text)
        self._model = model
        self._target = target
        self._rows = sorted(set(rows))
        self._removed: list[tuple[int, Any]] = []

    def redo(self) -> None:
        self._removed = self._model._apply_remove(self._target, self._rows)

    def undo(self) -> None:
        self._model._apply_insert(self._target, self._removed)


class MoveRowsCommand(QUndoCommand):
    """Move a set of rows one place up (-1) or down (+1)."""

    def __init__(
        self, model: UndoableListModel, target: RowList[Any], rows: Iterable[int], delta: int, text: str
    ) -> None:
        super().__init__(text)
        if delta not in (-1, 1):
            raise ValueError("delta must be -1 or +1")
        self._model = model
        self._target = target
        self._rows = sorted(set(rows))
        self._delta = delta
        self.new_rows: list[int] = [r + delta for r in self._rows]

    def redo(self) -> None:
        self.new_rows = self._model._apply_move(self._target, self._rows, self._delta)

    def undo(self) -> None:
        self._model._apply_move(self._target, self.new_rows, -self._delta)


class ReplaceRowCommand(QUndoCommand):
    """One row replaced (a cell edit); ``extra`` commands run after it (redo) / before (undo)."""

    def __init__(
        self,
        model: UndoableListModel,
        target: RowList[Any],
        row: int,
        old: Any,
        new: Any,
        text: str,
        *,
        after: Callable[[bool], None] | None = None,
    ) -> None:
        super().__init__(text)
        self._model = model
        self._target = target
        self._row = row
        self._old = old
        self._new = new
        self._after = after

    def redo(self) -> None:
        self._model._apply_replace(self._target, self._row, self._new)
        if self._after is not None:
            self._after(True)

    def undo(self) -> None:
        if self._after is not None:
            self._after(False)
        self._model._apply_replace(self._target, self._row, self._old)
