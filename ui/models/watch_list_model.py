"""The watch list's table: one row per watched value (name, where, type, value, age).

The rows are the entries (:class:`~app.watchlist.entry.WatchEntry`, in the list's order); the
values and their times come from the :class:`~app.watchlist.history.WatchHistory` the panel
feeds. :meth:`WatchListModel.refresh_values` repaints the value and age columns only (called by
the panel's clock, a few times a second, never per poll). A value older than ``stale_after``
seconds, or read while the link is not fresh, reads *stale* in grey; a register the controller
refused reads its error in red.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

from PySide6.QtCore import QAbstractTableModel, QModelIndex, QPersistentModelIndex, Qt
from PySide6.QtGui import QBrush, QColor

from app.watchlist.entry import Source, ValueType, WatchEntry, format_value
from app.watchlist.history import WatchHistory
from ui.palette import COLOR_ERROR, COLOR_NEUTRAL

__all__ = ["COL_AGE", "COL_NAME", "COL_TYPE", "COL_VALUE", "COL_WHERE", "STALE_AFTER", "WatchListModel"]

COL_NAME, COL_WHERE, COL_TYPE, COL_VALUE, COL_AGE = range(5)
STALE_AFTER = 2.0  # s: a value older than this reads "stale"

_Index = QModelIndex | QPersistentModelIndex


class WatchListModel(QAbstractTableModel):
    """See the module docstring. ``fresh`` says whether the link is fresh now."""

    def __init__(self, history: WatchHistory, fresh: Callable[[], bool], parent: Any = None) -> None:
        super().__init__(parent)
        self._history = history
        self._fresh = fresh
        self._entries: tuple[WatchEntry, ...] = ()
        self.stale_after = STALE_AFTER
        self.clock: Callable[[], float] = time.monotonic

    @property
    def entries(self) -> tuple[WatchEntry, ...]:
        return self._entries

    def set_entries(self, entries: Sequence[WatchEntry]) -> None:
        self.beginResetModel()
        self._entries = tuple(entries)
        self.endResetModel()

    def refresh_values(self) -> None:
        if self._entries:
            self.dataChanged.emit(
                self.index(0, COL_VALUE),
                self.index(len(self._entries) - 1, COL_AGE),
                [Qt.ItemDataRole.DisplayRole],
            )

    # --- QAbstractTableModel
    def rowCount(self, parent: _Index = QModelIndex()) -> int:  # noqa: B008 - Qt's signature
        return 0 if parent.isValid() else len(self._entries)

    def columnCount(self, parent: _Index = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else 5

    def headerData(
        self, section: int, orientation: Qt.Orientation, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        if orientation != Qt.Orientation.Horizontal or role != Qt.ItemDataRole.DisplayRole:
            return None
        if not 0 <= section < 5:
            return None
        return (self.tr("Name"), self.tr("Where"), self.tr("Type"), self.tr("Value"), self.tr("Age"))[section]

    def data(self, index: _Index, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
        if not index.isValid() or not 0 <= index.row() < len(self._entries):
            return None
        entry = self._entries[index.row()]
        column = index.column()
        if role == Qt.ItemDataRole.DisplayRole:
            return self._text(entry, column)
        if role == Qt.ItemDataRole.ForegroundRole and column in (COL_VALUE, COL_AGE):
            return self._color(entry)
        if role == Qt.ItemDataRole.ToolTipRole and column == COL_VALUE:
            value = self._history.last.get(entry)
            if value is not None and value.error:
                return value.error
            if value is not None and value.raw:
                return self.tr("Registers: {raw}").format(raw=" ".join(f"{r:04X}" for r in value.raw))
        if role == Qt.ItemDataRole.TextAlignmentRole and column in (COL_VALUE, COL_AGE):
            return int(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        return None

    def _text(self, entry: WatchEntry, column: int) -> str:
        if column == COL_NAME:
            return entry.name
        if column == COL_WHERE:
            return (
                f"GV{entry.number}"
                if entry.source is Source.GV
                else self.tr("reg {n}").format(n=entry.number)
            )
        if column == COL_TYPE:
            return {ValueType.FLOAT32: "float32", ValueType.INT16: "int16", ValueType.BITS: self.tr("bits")}[
                entry.type
            ]
        value = self._history.last.get(entry)
        if value is None:
            return self.tr("not read yet") if column == COL_VALUE else ""
        if column == COL_VALUE:
            return self.tr("error") if value.error else format_value(entry, value.value)
        age = max(0.0, self.clock() - value.read_at)
        if self.is_stale(entry):
            return self.tr("stale ({age:.1f} s)").format(age=age)
        return self.tr("{age:.1f} s").format(age=age)

    def is_stale(self, entry: WatchEntry) -> bool:
        value = self._history.last.get(entry)
        return value is None or not self._fresh() or self.clock() - value.read_at > self.stale_after

    def _color(self, entry: WatchEntry) -> QBrush | None:
        value = self._history.last.get(entry)
        if value is not None and value.error:
            return QBrush(QColor(COLOR_ERROR))
        if self.is_stale(entry):
            return QBrush(QColor(COLOR_NEUTRAL))
        return None
