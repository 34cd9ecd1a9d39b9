"""The points table's filter: a proxy over :class:`~ui.models.points_model.PointsModel`."""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QModelIndex, QPersistentModelIndex, QSortFilterProxyModel

from ui.models.points_model import PointsModel

ModelIndex = QModelIndex | QPersistentModelIndex


class PointFilterProxy(QSortFilterProxyModel):
    """Rows whose id equals the filter text or whose name contains it (case-insensitive)."""

    def __init__(self, parent: Any = None) -> None:
        super().__init__(parent)
        self._needle = ""

    @property
    def filter_text(self) -> str:
        return self._needle

    def set_filter_text(self, text: str) -> None:
        needle = text.strip().casefold()
        if needle != self._needle:
            self.beginFilterChange()
            self._needle = needle
            self.endFilterChange(QSortFilterProxyModel.Direction.Rows)

    def filterAcceptsRow(self, source_row: int, source_parent: ModelIndex) -> bool:
        if not self._needle:
            return True
        model = self.sourceModel()
        if not isinstance(model, PointsModel) or source_row >= model.rowCount():
            return True
        point = model.point_at(source_row)
        return self._needle == str(point.id) or self._needle in point.name.casefold()
