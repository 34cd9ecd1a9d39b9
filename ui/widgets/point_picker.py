"""Picking a point for a segment's end or middle point: a searchable combo box of the points
that exist ("P5 — circle W"), never a free number.

:class:`PointPicker` lists the ledger's points; typing filters them (a completer that matches
any part of "id — name", case-insensitive). Text that names no existing point turns the field
red and :meth:`PointPicker.point_id` gives None. A segment that refers to a missing point shows
that id in red, with a tooltip, so that the operator sees what to fix.

:class:`PointPickerDelegate` puts a picker in the segment table's middle / end point cells.
The model (:class:`~ui.models.segment_model.SegmentTableModel`) has the last word: it refuses an
id that does not exist, with the reason on the panel's status line.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QAbstractItemModel, QModelIndex, QPersistentModelIndex, Qt, Slot
from PySide6.QtWidgets import (
    QComboBox,
    QCompleter,
    QStyledItemDelegate,
    QStyleOptionViewItem,
    QWidget,
)

from app.points.ledger import PointLedger
from ui.palette import COLOR_ERROR

ModelIndex = QModelIndex | QPersistentModelIndex
ID_ROLE = Qt.ItemDataRole.UserRole  # the point's id (int) on each item


def point_choice_text(point_id: int, name: str) -> str:
    """``P5 — circle W`` (``P5`` for a point without a name)."""
    return f"P{point_id} — {name}" if name else f"P{point_id}"


def parse_choice(text: str) -> int | None:
    """The id in what the operator typed or picked: ``P5 — W``, ``p5``, ``5``; None otherwise."""
    head = text.strip().split(" ", 1)[0] if text.strip() else ""
    if head[:1] in ("P", "p"):
        head = head[1:]
    return int(head) if head.isdigit() else None


class PointPicker(QComboBox):
    """An editable, searchable combo box of the existing points (see the module docstring)."""

    def __init__(
        self, ledger: PointLedger, parent: QWidget | None = None, *, allow_blank: bool = False
    ) -> None:
        super().__init__(parent)
        self.setObjectName("PointPicker")
        self.setEditable(True)
        self.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        self.setMaxVisibleItems(20)
        self._ledger = ledger
        self._allow_blank = allow_blank
        completer = QCompleter(self.model(), self)
        completer.setCompletionMode(QCompleter.CompletionMode.PopupCompletion)
        completer.setFilterMode(Qt.MatchFlag.MatchContains)
        completer.setCaseSensitivity(Qt.CaseSensitivity.CaseInsensitive)
        self.setCompleter(completer)
        self.editTextChanged.connect(self._show_validity)
        self.set_ledger(ledger)

    def set_ledger(self, ledger: PointLedger) -> None:
        self._ledger = ledger
        typed = self.currentText()
        self.blockSignals(True)
        self.clear()
        for point in ledger:
            self.addItem(point_choice_text(point.id, point.name), point.id)
        self.setEditText(typed)
        self.blockSignals(False)
        self._show_validity()

    @property
    def ids(self) -> list[int]:
        return [int(self.itemData(i, ID_ROLE)) for i in range(self.count())]

    def set_point_id(self, point_id: int | None) -> None:
        """Show ``point_id`` (blank for None); a missing point stays visible, in red."""
        if point_id is None:
            self.setCurrentIndex(-1)
            self.setEditText("")
        else:
            found = self.findData(point_id, ID_ROLE)
            if found >= 0:
                self.setCurrentIndex(found)
                self.setEditText(self.itemText(found))
            else:
                self.setCurrentIndex(-1)
                self.setEditText(f"P{point_id}")
        self._show_validity()

    def point_id(self) -> int | None:
        """The picked point's id; None when the text names no existing point (or is blank)."""
        pid = parse_choice(self.currentText())
        return pid if pid is not None and pid in self._ledger else None

    def is_blank(self) -> bool:
        return not self.currentText().strip()

    def is_valid(self) -> bool:
        return self.point_id() is not None or (self._allow_blank and self.is_blank())

    @Slot()
    def _show_validity(self, *_args: object) -> None:
        line = self.lineEdit()
        if line is None:
            return
        if self.is_valid():
            line.setStyleSheet("")
            self.setToolTip("")
        else:
            line.setStyleSheet(f"color: {COLOR_ERROR};")
            pid = parse_choice(self.currentText())
            self.setToolTip(
                self.tr("Point P{id} does not exist").format(id=pid)
                if pid is not None
                else self.tr("Pick an existing point (type its id or part of its name)")
            )


class PointPickerDelegate(QStyledItemDelegate):
    """A :class:`PointPicker` in a segment table cell; ``ledger()`` gives the current points.
    ``allow_blank``: the middle point column (an arc's middle point may be left empty)."""

    def __init__(
        self, ledger: Callable[[], PointLedger], parent: QWidget | None = None, *, allow_blank: bool = False
    ) -> None:
        super().__init__(parent)
        self._ledger = ledger
        self._allow_blank = allow_blank

    def createEditor(self, parent: QWidget, option: QStyleOptionViewItem, index: ModelIndex) -> QWidget:
        return PointPicker(self._ledger(), parent, allow_blank=self._allow_blank)

    def setEditorData(self, editor: QWidget, index: ModelIndex) -> None:
        assert isinstance(editor, PointPicker)
        editor.set_point_id(parse_choice(str(index.data(Qt.ItemDataRole.EditRole) or "")))

    def setModelData(self, editor: QWidget, model: QAbstractItemModel, index: ModelIndex) -> None:
        """The picked id; typed text that names no point goes to the model, which refuses it
        with the reason (one place decides)."""
        assert isinstance(editor, PointPicker)
        pid = editor.point_id()
        value = "" if editor.is_blank() else (str(pid) if pid is not None else editor.currentText())
        model.setData(index, value, Qt.ItemDataRole.EditRole)


__all__ = ["ID_ROLE", "PointPicker", "PointPickerDelegate", "parse_choice", "point_choice_text"]
