"""Where the 3D view lives in the main window: its own work tab ("3D"), or a dock beside the
planner when the panel's "Beside the planner" button is on (the planner tab comes to the front).

:func:`install_view3d` is the window's only line about it: it builds the panel, connects it to
the robot's state, the points table, the planner and the run controller, and keeps the tab's
title translated.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QObject, Qt, Slot
from PySide6.QtWidgets import QDockWidget

from ui.panels.view3d_panel import View3DPanel


class View3DHost(QObject):
    """Moves the panel between its tab and the dock."""

    def __init__(self, window: Any) -> None:
        super().__init__(window)
        self.window = window
        self.panel = View3DPanel(window.project.points_model, window)
        self.panel.bind(window.link.state)
        self.panel.attach_points(window.points_panel)
        self.panel.attach_planner(window.planner_panel)
        self.panel.attach_runner(window.run_controller)
        self.tabs = window.work_tabs
        self.tabs.addTab(self.panel, "")
        self.dock = QDockWidget(window)
        self.dock.setObjectName("View3DDock")
        area = Qt.DockWidgetArea
        self.dock.setAllowedAreas(area.RightDockWidgetArea | area.LeftDockWidgetArea)
        window.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.dock)
        self.dock.hide()
        self.dock.visibilityChanged.connect(self._on_dock_visible)
        self.panel.besideToggled.connect(self.set_beside)
        self.panel.installEventFilter(self)
        self.retranslate()

    def retranslate(self) -> None:
        index = self.tabs.indexOf(self.panel)
        if index >= 0:
            self.tabs.setTabText(index, self.tr("3D"))
        self.dock.setWindowTitle(self.tr("3D view"))

    def eventFilter(self, watched: QObject, event: Any) -> bool:
        if watched is self.panel and event.type() == event.Type.LanguageChange:
            self.retranslate()
        return False

    @Slot(bool)
    def set_beside(self, beside: bool) -> None:
        if beside and self.dock.widget() is not self.panel:
            self.tabs.removeTab(self.tabs.indexOf(self.panel))
            self.dock.setWidget(self.panel)
            self.dock.show()
            self.tabs.setCurrentWidget(self.window.planner_panel)
        elif not beside and self.dock.widget() is self.panel:
            self.dock.setWidget(None)  # type: ignore[arg-type]
            self.dock.hide()
            self.tabs.addTab(self.panel, "")
            self.panel.show()
            self.retranslate()
        self.panel.beside_button.blockSignals(True)
        self.panel.beside_button.setChecked(beside)
        self.panel.beside_button.blockSignals(False)

    @Slot(bool)
    def _on_dock_visible(self, visible: bool) -> None:
        # closing the dock (its X) puts the view back into its tab
        if not visible and self.dock.widget() is self.panel and not self.dock.isVisible():
            self.set_beside(False)


def install_view3d(window: Any) -> View3DHost:
    return View3DHost(window)
