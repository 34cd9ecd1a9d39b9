"""The main window's docks: the display panels around the work area.

Status on the left (narrow, full height); Event log, Modbus traffic and Alarms tabified at the
bottom, the event log in front. The docks are sized once, at the window's first show, when the
layout has its real size (a remembered layout is restored instead). The traffic panel itself
(its model and the frame decoder) is built the first time its dock can be seen or
:attr:`WindowDocks.traffic_panel` is asked for: tabbed behind the log at start, the window's
first paint does not wait for it.

The worker captures the frames all the time: the last :data:`RECENT_TRAFFIC` of them are kept
here (raw records in a ring, no decoding, no painting), so the support bundle always carries
the recent Modbus traffic and the panel, built late, starts with them. :attr:`traffic_capture`
says whether the panel wants them too (its dock can be seen and its capture switch is on).
"""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QCoreApplication, QObject, Qt, Slot
from PySide6.QtWidgets import QDockWidget, QMainWindow, QWidget

from app.link.robot_link import RobotLink
from ui.panels.alarm_list import AlarmListPanel
from ui.panels.event_log import EventLogPanel
from ui.panels.status_panel import StatusPanel
from ui.touch import show_rows

if TYPE_CHECKING:  # built when its dock can first be seen (see the module docstring)
    from ui.panels.traffic_panel import TrafficPanel

__all__ = ["WindowDocks"]

# The docks were the window's: their titles keep the "MainWindow" translation context.
STATUS_DOCK_WIDTH = 265
STATUS_DOCK_MAX_WIDTH = 320  # the status column never needs more; the work tabs get the rest
DOCK_MIN_ROWS = 4  # the bottom docks (event log, traffic) show at least this many rows
RECENT_TRAFFIC = 6000  # frames kept for the support bundle (about a minute of 10 Hz polls)


class WindowDocks(QObject):
    """The panels (``status_panel``, ``event_log``, ``traffic_panel``, ``alarm_list``) and their
    docks (``status_dock``, ``event_dock``, ``traffic_dock``, ``alarm_dock``) on ``window``."""

    def __init__(self, window: QMainWindow, link: RobotLink) -> None:
        super().__init__(window)
        self._window = window
        self._link = link
        self._traffic_capture = False
        self._traffic_dock_shown = False
        self.status_panel = StatusPanel(window)
        self._traffic_panel: TrafficPanel | None = None
        self.event_log = EventLogPanel(window)
        self.alarm_list = AlarmListPanel(window)
        area = Qt.DockWidgetArea
        self.status_dock = self._dock("StatusDock", self.status_panel, area.LeftDockWidgetArea)
        # QMainWindow hands a narrow window's spare width to the docks as well: a status
        # column wider than this only steals room from the work tabs
        self.status_dock.setMaximumWidth(STATUS_DOCK_MAX_WIDTH)
        self.event_dock = self._dock("EventLogDock", self.event_log, area.BottomDockWidgetArea)
        placeholder = QWidget(window)
        placeholder.setObjectName("TrafficPlaceholder")
        self.traffic_dock = self._dock("TrafficDock", placeholder, area.BottomDockWidgetArea)
        window.tabifyDockWidget(self.event_dock, self.traffic_dock)
        self.alarm_dock = self._dock("AlarmDock", self.alarm_list, area.BottomDockWidgetArea)
        window.tabifyDockWidget(self.event_dock, self.alarm_dock)
        self.event_dock.raise_()
        window.setCorner(Qt.Corner.BottomLeftCorner, area.LeftDockWidgetArea)  # status runs full height
        show_rows(self.event_log.view, DOCK_MIN_ROWS)
        # visibilityChanged(bool) says whether the dock can be seen: False while it is tabbed
        # behind the event log, when isVisible() still says True
        self.traffic_dock.visibilityChanged.connect(self._on_traffic_dock_visibility)
        link.errorOccurred.connect(self.event_log.on_error)
        # the recent traffic, whether or not the panel was ever shown (a capture user for good)
        self._recent_traffic: deque[Any] = deque(maxlen=RECENT_TRAFFIC)
        link.trafficObserved.connect(self._keep_traffic)
        link.set_traffic_capture(True)
        self.retranslate()

    @property
    def traffic_panel(self) -> TrafficPanel:
        """The Modbus traffic panel (built now, in its dock, if it was not yet)."""
        panel = self._traffic_panel
        if panel is None:
            from ui.panels.traffic_panel import TrafficPanel

            panel = self._traffic_panel = TrafficPanel(self._window)
            show_rows(panel.view, DOCK_MIN_ROWS)
            panel.captureEnabledChanged.connect(self._update_traffic_capture)
            panel.on_traffic(tuple(self._recent_traffic))  # what came before it was built
            self._link.trafficObserved.connect(panel.on_traffic)
            placeholder = self.traffic_dock.widget()
            self.traffic_dock.setWidget(panel)
            if placeholder is not None:
                placeholder.deleteLater()
        return panel

    @property
    def docks(self) -> list[QDockWidget]:
        """In the View menu's order."""
        return [self.status_dock, self.event_dock, self.traffic_dock, self.alarm_dock]

    @property
    def traffic_capture(self) -> bool:
        """Whether the worker is asked to build traffic records now."""
        return self._traffic_capture

    def _dock(self, name: str, widget: QWidget, area: Qt.DockWidgetArea) -> QDockWidget:
        dock = QDockWidget(self._window)
        dock.setObjectName(name)
        dock.setWidget(widget)
        self._window.addDockWidget(area, dock)
        return dock

    def retranslate(self) -> None:
        self.status_dock.setWindowTitle(QCoreApplication.translate("MainWindow", "Status"))
        self.event_dock.setWindowTitle(QCoreApplication.translate("MainWindow", "Event log"))
        self.traffic_dock.setWindowTitle(QCoreApplication.translate("MainWindow", "Modbus traffic"))
        self.alarm_dock.setWindowTitle(QCoreApplication.translate("MainWindow", "Alarms"))

    @Slot()
    def size_first_time(self) -> None:
        """A narrow status dock, a short log (once the layout has its real size)."""
        window = self._window
        window.resizeDocks([self.status_dock], [STATUS_DOCK_WIDTH], Qt.Orientation.Horizontal)
        window.resizeDocks(
            [self.event_dock], [self.event_dock.minimumSizeHint().height()], Qt.Orientation.Vertical
        )

    @Slot(tuple)
    def _keep_traffic(self, records: tuple[Any, ...]) -> None:
        self._recent_traffic.extend(records)

    @Slot(bool)
    def _on_traffic_dock_visibility(self, shown: bool) -> None:
        self._traffic_dock_shown = shown
        if shown:
            self.traffic_panel  # noqa: B018 - builds it, in its dock, the first time it can be seen
        self._update_traffic_capture()

    @Slot()
    def _update_traffic_capture(self) -> None:
        panel = self._traffic_panel
        want = self._traffic_dock_shown and panel is not None and panel.capture_enabled()
        if want != self._traffic_capture:
            self._traffic_capture = want
            self._link.set_traffic_capture(want)
