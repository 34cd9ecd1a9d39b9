"""Touch mode and motion buttons: sizes that do not move under the operator's finger.

A *motion button* (anything that moves the arm or stops it) carries the dynamic property
``motion=True`` (:func:`mark_motion`, read by the layout check); it is at least
:data:`MOTION_MIN_HEIGHT` px high, :data:`TOUCH_MOTION_HEIGHT` px in touch mode.
:func:`apply_touch_mode` sizes them and gives every number field the on-screen keypad.
:class:`RowsScrollArea` lets a column of rows scroll up and down, never sideways.
"""

from __future__ import annotations

from collections.abc import Iterable

from PySide6.QtCore import QObject, QSize, Qt
from PySide6.QtWidgets import (
    QAbstractButton,
    QDoubleSpinBox,
    QFrame,
    QScrollArea,
    QSpinBox,
    QTableView,
    QWidget,
)

MOTION_MIN_HEIGHT = 40  # px, every motion button
TOUCH_MOTION_HEIGHT = 56  # px, motion buttons in touch mode
SCROLL_MIN_ROWS_HEIGHT = 3 * MOTION_MIN_HEIGHT  # px, a scrolled column shows at least this much


def mark_motion(*buttons: QAbstractButton) -> None:
    """Mark buttons that move (or stop) the arm: the layout check and touch mode size them."""
    for button in buttons:
        button.setProperty("motion", True)
        button.setMinimumHeight(max(button.minimumHeight(), MOTION_MIN_HEIGHT))


def mark_touch_target(*buttons: QAbstractButton) -> None:
    """Mark buttons a finger picks often that move nothing (the step increments 0.1/1/10): touch
    mode gives them the motion buttons' height."""
    for button in buttons:
        button.setProperty("touch_target", True)


def motion_height(touch: bool) -> int:
    return TOUCH_MOTION_HEIGHT if touch else MOTION_MIN_HEIGHT


def show_rows(view: QTableView, rows: int) -> None:
    """Make ``view`` at least tall enough for ``rows`` rows under its header (its panel and
    dock grow from that)."""
    header = view.horizontalHeader()
    header_height = header.sizeHint().height() if not header.isHidden() else 0
    view.setMinimumHeight(
        header_height + rows * view.verticalHeader().defaultSectionSize() + 2 * view.frameWidth()
    )


class RowsScrollArea(QScrollArea):
    """Rows that scroll vertically; as wide as the rows need, so nothing is cut on the right."""

    def __init__(self, rows: QWidget, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWidgetResizable(True)
        self.setFrameShape(QFrame.Shape.NoFrame)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setWidget(rows)

    def _width(self, inner: QSize) -> int:
        return inner.width() + self.verticalScrollBar().sizeHint().width() + 2 * self.frameWidth()

    def minimumSizeHint(self) -> QSize:
        rows = self.widget()
        if rows is None:  # (only while being built)
            return super().minimumSizeHint()
        inner = rows.minimumSizeHint()
        return QSize(self._width(inner), min(inner.height(), SCROLL_MIN_ROWS_HEIGHT))

    def sizeHint(self) -> QSize:
        rows = self.widget()
        if rows is None:
            return super().sizeHint()
        inner = rows.sizeHint()
        return QSize(self._width(inner), inner.height())


def apply_touch_mode(roots: Iterable[QWidget], touch: bool) -> None:
    """Size the motion buttons under ``roots`` and give their number fields the keypad (or not)."""
    height = motion_height(touch)
    for root in roots:
        for button in root.findChildren(QAbstractButton):
            if button.property("motion"):
                button.setMinimumHeight(height)
            elif button.property("touch_target"):
                button.setMinimumHeight(TOUCH_MOTION_HEIGHT if touch else 0)
        for field in root.findChildren(QSpinBox) + root.findChildren(QDoubleSpinBox):
            if touch or _has_keypad(field):  # else nothing to do (touch mode off, no keypad yet)
                from ui.keypad import install_keypad  # the keypad: imported by the first one wanted

                install_keypad(field, touch)


def _has_keypad(field: QWidget) -> bool:
    """``field`` has the keypad's opener (ui/keypad.py names it so), looked up without the keypad's module."""
    opener = field.findChild(QObject, "KeypadOpener", Qt.FindChildOption.FindDirectChildrenOnly)
    return opener is not None
