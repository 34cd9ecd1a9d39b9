"""The main window's window-wide parts (its main toolbar sits in the menu bar's corner): the pose
strip, a row above everything (always), and the alarm banner, laid over the window while an alarm
is set (it moves nothing: ui/panels/alarm_banner.py). Neither can be moved or hidden by hand; the
window binds both to the link's state like its other parts."""

from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QMainWindow, QToolBar

from ui.panels.alarm_banner import AlarmBanner
from ui.panels.pose_strip import PoseStrip

__all__ = ["WindowRows", "add_window_rows"]

POSE_BAR_STYLE = "QToolBar { padding: 0px; spacing: 0px; border: none; }"  # every px for the strip


@dataclass(frozen=True)
class WindowRows:
    alarm_banner: AlarmBanner  # laid over the window, a child of it
    pose_strip: PoseStrip
    pose_bar: QToolBar  # holds the pose strip


def add_window_rows(window: QMainWindow) -> WindowRows:
    """Add the pose strip to ``window``'s top tool bar area and the alarm banner over the window."""
    banner = AlarmBanner(window)
    strip = PoseStrip(window)
    bar = QToolBar(window)
    bar.setObjectName("PoseStripBar")
    bar.setMovable(False)
    bar.setFloatable(False)
    bar.toggleViewAction().setVisible(False)
    bar.setStyleSheet(POSE_BAR_STYLE)
    bar.addWidget(strip)
    window.addToolBar(Qt.ToolBarArea.TopToolBarArea, bar)
    return WindowRows(banner, strip, bar)
