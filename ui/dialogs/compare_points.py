"""*Compare with…*: the project's points against another project's or a points CSV's.

The same comparison as ``teachpad-cli points diff`` (:func:`app.points.diff.diff_points`): one
row per point added, removed, moved (distance and orientation change) or given another tool,
over tolerances the operator can change here (default 0.1 mm / 0.1°). A row's tooltip says how
the point was made in each (its provenance).
"""

from __future__ import annotations

from collections.abc import Sequence

from PySide6.QtCore import QEvent, Qt, Slot
from PySide6.QtWidgets import (
    QAbstractItemView,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from app.points.diff import (
    DEFAULT_TOL_DEG,
    DEFAULT_TOL_MM,
    ChangeKind,
    PointChange,
    PointsDiff,
    diff_points,
    signed_mm,
)
from app.points.point import TempPoint
from ui.models.point_provenance import provenance_tip

__all__ = ["ComparePointsDialog"]

COLUMNS = ("change", "point", "distance", "turn", "delta", "tool")


class ComparePointsDialog(QDialog):
    """See the module docstring. ``diff`` is the comparison shown."""

    def __init__(
        self,
        points_a: Sequence[TempPoint],
        name_a: str,
        points_b: Sequence[TempPoint],
        name_b: str,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("ComparePointsDialog")
        self._a, self._b = list(points_a), list(points_b)
        self._names = (name_a, name_b)
        self.diff: PointsDiff = diff_points(self._a, self._b)
        self.sources = QLabel(self)
        self.sources.setTextFormat(Qt.TextFormat.PlainText)
        self.summary = QLabel(self)
        self.summary.setObjectName("CompareSummary")
        self.tol_mm = self._spin(DEFAULT_TOL_MM, 3, 1000.0)
        self.tol_deg = self._spin(DEFAULT_TOL_DEG, 3, 180.0)
        self._tol_mm_label, self._tol_deg_label = QLabel(self), QLabel(self)
        tolerances = QFormLayout()
        tolerances.addRow(self._tol_mm_label, self.tol_mm)
        tolerances.addRow(self._tol_deg_label, self.tol_deg)
        self.table = QTableWidget(0, len(COLUMNS), self)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.verticalHeader().setVisible(False)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.table.horizontalHeader().setStretchLastSection(True)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close, self)
        buttons.rejected.connect(self.reject)
        top = QHBoxLayout()
        top.addWidget(self.sources, 1)
        top.addLayout(tolerances)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addWidget(self.summary)
        layout.addWidget(self.table, 1)
        layout.addWidget(buttons)
        self.tol_mm.valueChanged.connect(self.refresh)
        self.tol_deg.valueChanged.connect(self.refresh)
        self.resize(860, 480)
        self.retranslate()

    def _spin(self, value: float, decimals: int, maximum: float) -> QDoubleSpinBox:
        spin = QDoubleSpinBox(self)
        spin.setDecimals(decimals)
        spin.setRange(0.0, maximum)
        spin.setSingleStep(0.05)
        spin.setValue(value)
        return spin

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    def retranslate(self) -> None:
        self.setWindowTitle(self.tr("Compare points"))
        self._tol_mm_label.setText(self.tr("Distance tolerance (mm):"))
        self._tol_deg_label.setText(self.tr("Angle tolerance (°):"))
        self.table.setHorizontalHeaderLabels(
            [
                self.tr("Change"),
                self.tr("Point"),
                self.tr("Distance (mm)"),
                self.tr("Turn (°)"),
                self.tr("dx, dy, dz (mm)"),
                self.tr("Tool"),
            ]
        )
        self.refresh()

    @Slot()
    def refresh(self) -> None:
        """Compare again with the tolerances shown."""
        self.diff = diff = diff_points(
            self._a, self._b, tol_mm=self.tol_mm.value(), tol_deg=self.tol_deg.value()
        )
        name_a, name_b = self._names
        self.sources.setText(
            self.tr("A: {a} (points: {n})").format(a=name_a, n=diff.count_a)
            + "\n"
            + self.tr("B: {b} (points: {n})").format(b=name_b, n=diff.count_b)
        )
        if diff.differ:
            self.summary.setText(
                self.tr("Differences: {n}; points the same: {same}").format(
                    n=len(diff.changes), same=diff.same
                )
            )
        else:
            self.summary.setText(self.tr("The same within the tolerances (points: {n})").format(n=diff.same))
        self.table.setRowCount(len(diff.changes))
        for row, change in enumerate(diff.changes):
            self._fill(row, change)

    def _fill(self, row: int, change: PointChange) -> None:
        kind = {
            ChangeKind.ADDED: self.tr("added in B"),
            ChangeKind.REMOVED: self.tr("removed in B"),
            ChangeKind.MOVED: self.tr("moved"),
            ChangeKind.TOOL: self.tr("other tool"),
        }[change.kind]
        both = change.before is not None and change.after is not None
        dx, dy, dz = change.delta
        tool = ""
        if change.tool_changed and change.before is not None and change.after is not None:
            tool = f"{change.before.tool} → {change.after.tool}"
        cells = (
            kind,
            change.point.label,
            f"{change.distance_mm:.3f}" if both else "",
            f"{change.rotation_deg:.2f}" if both else "",
            f"{signed_mm(dx)}, {signed_mm(dy)}, {signed_mm(dz)}" if both else "",  # numbers, not words
            tool,
        )
        tip = self._tip(change)
        for column, text in enumerate(cells):
            item = QTableWidgetItem(text)
            if column in (2, 3, 4):
                item.setTextAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            item.setToolTip(tip)
            self.table.setItem(row, column, item)

    def _tip(self, change: PointChange) -> str:
        parts = []
        if change.before is not None:
            parts.append(self.tr("In A:") + "\n" + provenance_tip(change.before.made))
        if change.after is not None:
            parts.append(self.tr("In B:") + "\n" + provenance_tip(change.after.made))
        return "\n\n".join(parts)
