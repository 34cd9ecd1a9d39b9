"""The planner models' columns and roles, and how an issue of the checks is drawn in a row
(colour, glyph icon, words)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import (
    QCoreApplication,
    QModelIndex,
    QPersistentModelIndex,
    Qt,
)
from PySide6.QtGui import QColor, QFont

from app.plan.issue_kind import IssueKind
from app.plan.segments import TR_CONTEXT as PLAN_CORE_CONTEXT
from app.plan.segments import (
    SegmentKind,
)
from ui.palette import COLOR_ERROR, COLOR_INFO, COLOR_WARN, COLOR_WHITE

if TYPE_CHECKING:  # the icons are drawn by the planner (built after the window's first paint)
    from PySide6.QtGui import QIcon

ModelIndex = QModelIndex | QPersistentModelIndex

SEG_COLUMNS: tuple[str, ...] = (
    "index",
    "kind",
    "via",
    "end",
    "speed",
    "orientation",
    "ignore_middle",
    "tool",
    "length",
    "time",
)
COL_INDEX = 0
COL_KIND = 1
COL_VIA = 2
COL_END = 3
COL_SPEED = 4
COL_ORIENTATION = 5
COL_IGNORE = 6
COL_TOOL = 7
COL_LENGTH = 8
COL_TIME = 9
EDITABLE_COLUMNS: frozenset[int] = frozenset(range(COL_KIND, COL_TOOL + 1))

PLAN_COLUMNS: tuple[str, ...] = ("name", "loops", "segments")
PLAN_COL_NAME, PLAN_COL_LOOPS, PLAN_COL_SEGMENTS = range(3)

ISSUE_ROLE = Qt.ItemDataRole.UserRole + 10  # list[PlanIssue] of the row
ISSUE_LEVEL_ROLE = Qt.ItemDataRole.UserRole + 11  # IssueKind | None: the worst issue of the row

ISSUE_COLOURS: dict[IssueKind, str] = {
    IssueKind.ERROR: COLOR_ERROR,
    IssueKind.NEEDS_UPLOAD: COLOR_INFO,
    IssueKind.WARNING: COLOR_WARN,
}
ISSUE_ORDER = {IssueKind.ERROR: 0, IssueKind.NEEDS_UPLOAD: 1, IssueKind.WARNING: 2}
ISSUE_GLYPH = {IssueKind.ERROR: "✕", IssueKind.NEEDS_UPLOAD: "↑", IssueKind.WARNING: "!"}
RIGHT_ALIGNED = frozenset((COL_SPEED, COL_LENGTH, COL_TIME))


def kind_text(kind: SegmentKind) -> str:
    return QCoreApplication.translate(PLAN_CORE_CONTEXT, kind.text)


def orientation_text(changes: bool) -> str:
    if changes:
        return QCoreApplication.translate("SegmentTableModel", "changes")
    return QCoreApplication.translate("SegmentTableModel", "kept")


def issue_icon(kind: IssueKind, size: int = 16) -> QIcon:
    """A filled circle with a glyph, in the issue's colour (no theme icons needed)."""
    from PySide6.QtGui import QIcon, QPainter, QPixmap

    pixmap = QPixmap(size, size)
    pixmap.fill(Qt.GlobalColor.transparent)
    painter = QPainter(pixmap)
    painter.setRenderHint(QPainter.RenderHint.Antialiasing)
    painter.setPen(Qt.PenStyle.NoPen)
    painter.setBrush(QColor(ISSUE_COLOURS[kind]))
    painter.drawEllipse(1, 1, size - 2, size - 2)
    painter.setPen(QColor(COLOR_WHITE))
    font = QFont()
    font.setBold(True)
    font.setPixelSize(int(size * 0.7))
    painter.setFont(font)
    painter.drawText(pixmap.rect(), Qt.AlignmentFlag.AlignCenter, ISSUE_GLYPH[kind])
    painter.end()
    return QIcon(pixmap)


def issue_kind_text(kind: IssueKind) -> str:
    return {
        IssueKind.ERROR: QCoreApplication.translate("SegmentTableModel", "error"),
        IssueKind.NEEDS_UPLOAD: QCoreApplication.translate("SegmentTableModel", "needs upload"),
        IssueKind.WARNING: QCoreApplication.translate("SegmentTableModel", "warning"),
    }[kind]
