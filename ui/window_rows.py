"""The main window's window-wide rows above everything (its main toolbar sits in the menu bar's
corner): the alarm banner (only while an alarm is set), then the pose strip (always). Neither can
be moved or hidden by hand; the window binds both to the link's state like its other parts."""

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
    alarm_banner: AlarmBanner  # a tool bar of its own
    pose_strip: PoseStrip
    pose_bar: QToolBar  # holds the pose strip


def add_window_rows(window: QMainWindow) -> WindowRows:
    """Add the two rows to ``window``'s top tool bar area, the banner first, each on its own line."""
    banner = AlarmBanner(window)
    window.addToolBar(Qt.ToolBarArea.TopToolBarArea, banner)
    strip = PoseStrip(window)
    bar = QToolBar(window)
    bar.setObjectName("PoseStripBar")
    bar.setMovable(False)
    bar.setFloatable(False)
    bar.toggleViewAction().setVisible(False)
    bar.setStyleSheet(POSE_BAR_STYLE)
    bar.addWidget(strip)
    window.addToolBarBreak(Qt.ToolBarArea.TopToolBarArea)
    window.addToolBar(Qt.ToolBarArea.TopToolBarArea, bar)
    return WindowRows(banner, strip, bar)
