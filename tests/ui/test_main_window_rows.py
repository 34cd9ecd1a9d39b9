"""The window-wide rows (ui/window_rows.py): the alarm banner, then the pose strip, each on its own
line of the top tool bar area, neither movable nor listed in the tool bars' menu."""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QMainWindow

from ui.window_rows import add_window_rows


def test_the_banner_then_the_pose_strip_each_on_its_own_line(qtbot: Any) -> None:
    window = QMainWindow()
    qtbot.addWidget(window)
    rows = add_window_rows(window)
    top = Qt.ToolBarArea.TopToolBarArea
    assert window.toolBarArea(rows.alarm_banner) == top and window.toolBarArea(rows.pose_bar) == top
    assert window.toolBarBreak(rows.pose_bar)  # a line of its own, under the banner
    assert rows.pose_strip.parentWidget() is rows.pose_bar
    assert not rows.pose_bar.isMovable() and not rows.pose_bar.isFloatable()
    assert not rows.pose_bar.toggleViewAction().isVisible()
    window.resize(900, 600)
    window.show()
    qtbot.waitExposed(window)
    rows.pose_bar.setVisible(True)
    assert rows.alarm_banner.geometry().top() <= rows.pose_bar.geometry().top()
