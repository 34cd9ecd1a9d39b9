"""The window-wide parts (ui/window_rows.py): the pose strip, a row of the top tool bar area, not
movable nor listed in the tool bars' menu; the alarm banner laid over the window (no row)."""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QMainWindow, QToolBar

from ui.window_rows import add_window_rows


def test_the_pose_strip_a_row_the_banner_laid_over(qtbot: Any) -> None:
    window = QMainWindow()
    qtbot.addWidget(window)
    rows = add_window_rows(window)
    assert window.toolBarArea(rows.pose_bar) == Qt.ToolBarArea.TopToolBarArea
    assert rows.alarm_banner.parentWidget() is window and rows.alarm_banner.property("overlay")
    assert not isinstance(rows.alarm_banner, QToolBar)  # no row of its own
    assert rows.pose_strip.parentWidget() is rows.pose_bar
    assert not rows.pose_bar.isMovable() and not rows.pose_bar.isFloatable()
    assert not rows.pose_bar.toggleViewAction().isVisible()
    window.resize(900, 600)
    window.show()
    qtbot.waitExposed(window)
    rows.pose_bar.setVisible(True)
    top = rows.pose_bar.geometry().top()
    rows.alarm_banner.on_alarms(1)
    assert rows.alarm_banner.isVisible() and rows.pose_bar.geometry().top() == top  # moves nothing
