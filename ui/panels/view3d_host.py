"""Where the 3D view lives in the main window: its own work tab ("3D"), or a dock beside the
planner when the panel's "Beside the planner" button is on (the planner tab comes to the front).

:func:`install_view3d` is the window's only line about it. It also sets up the active robot
model (:class:`~ui.panels.view3d_robot.RobotModelSource`: the profile remembered in the settings,
or the default one, saying in the event log why a remembered one could not be loaded) and gives
its reach check to the planner, whose checks list then shows what the 3D view marks red and
follows a change of profile and the model's agreement with the controller (compared live from
the robot's state; a model that starts to disagree is also a warning in the event log). The
panel is built the first time it is needed (its tab comes to the front, or someone asks for
:attr:`View3DHost.panel`): until then the tab holds an empty placeholder, so the window's first
paint does not wait for the 3D view's module (and the pyqtgraph it imports). Once built it is
connected to the robot's state, the points table, the planner and the run controller, and its
tab title is kept translated.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QObject, Qt, Slot
from PySide6.QtWidgets import QDockWidget, QWidget

from ui.panels.view3d_robot import RobotModelSource

if TYPE_CHECKING:
    from app.view3d.agreement import ModelAgreement
    from app.view3d.profile import RobotProfile
    from ui.panels.view3d_panel import View3DPanel


class View3DHost(QObject):
    """Builds the panel on first use and moves it between its tab and the dock."""

    def __init__(self, window: Any) -> None:
        super().__init__(window)
        self.window = window
        self.robot = RobotModelSource(getattr(window, "settings", None), self)
        self.robot.problemRaised.connect(self._on_profile_problem)
        self.robot.restore()
        self.robot.bind(window.link.state)
        self.robot.agreementChanged.connect(self._on_agreement)
        self._disagreeing = False
        self._planner: Any = None  # the planner, once built (its checks follow the agreement)
        # the planner is built on first show (ui/window_tabs.py): it gets the reach check then
        window.planner_tab.on_built(self._attach_planner_reach)
        self._panel: View3DPanel | None = None
        self.tabs = window.work_tabs
        self._when_built: list[Callable[[View3DPanel], object]] = []
        self._placeholder: QWidget | None = QWidget()
        self._placeholder.setObjectName("View3DPlaceholder")
        self.tabs.addTab(self._placeholder, "")
        self.dock = QDockWidget(window)
        self.dock.setObjectName("View3DDock")
        area = Qt.DockWidgetArea
        self.dock.setAllowedAreas(area.RightDockWidgetArea | area.LeftDockWidgetArea)
        window.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.dock)
        self.dock.hide()
        self.dock.visibilityChanged.connect(self._on_dock_visible)
        self.tabs.currentChanged.connect(self._on_tab)
        self.retranslate()

    def _attach_planner_reach(self, planner: Any) -> None:
        planner.set_reach(self.robot.plan_issues, self.robot.profile.name)

        def follow(profile: RobotProfile) -> None:
            planner.set_reach_model(profile.name)
            planner.recheck()

        self.robot.profileChanged.connect(follow)
        self._planner = planner

    @property
    def panel(self) -> View3DPanel:
        """The 3D view (built now if it was not yet)."""
        if self._panel is None:
            self._panel = self._build()
        return self._panel

    @property
    def built(self) -> bool:
        return self._panel is not None

    def on_built(self, callback: Callable[[View3DPanel], object]) -> None:
        """Call ``callback(panel)`` once the panel exists (now, if it does): what the view needs
        from elsewhere (the safety envelope) must not build it before its tab is shown."""
        if self._panel is not None:
            callback(self._panel)
        else:
            self._when_built.append(callback)

    def _build(self) -> View3DPanel:
        from ui.panels.view3d_panel import View3DPanel  # deferred: see the module docstring

        window = self.window
        panel = View3DPanel(window.project.points_model, window, robot=self.robot)
        panel.bind(window.link.state)
        panel.attach_points(window.points_panel)
        panel.attach_planner(window.planner_panel)
        panel.attach_runner(window.run_controller)
        panel.besideToggled.connect(self.set_beside)
        panel.installEventFilter(self)
        placeholder, self._placeholder = self._placeholder, None
        index = self.tabs.indexOf(placeholder) if placeholder is not None else -1
        if index >= 0:
            current = self.tabs.currentIndex() == index
            self.tabs.blockSignals(True)
            try:
                self.tabs.insertTab(index, panel, "")
                self.tabs.removeTab(index + 1)
                if current:
                    self.tabs.setCurrentIndex(index)
            finally:
                self.tabs.blockSignals(False)
        if placeholder is not None:
            placeholder.deleteLater()
        self._panel = panel
        self.retranslate()
        for callback in self._when_built:
            callback(panel)
        self._when_built.clear()
        return panel

    @Slot(int)
    def _on_tab(self, index: int) -> None:
        if self._placeholder is not None and self.tabs.widget(index) is self._placeholder:
            self.panel  # noqa: B018 - builds it, in place of the placeholder

    def _tab_widget(self) -> QWidget | None:
        return self._panel if self._panel is not None else self._placeholder

    def retranslate(self) -> None:
        widget = self._tab_widget()
        index = self.tabs.indexOf(widget) if widget is not None else -1
        if index >= 0:
            self.tabs.setTabText(index, self.tr("3D"))
        self.dock.setWindowTitle(self.tr("3D view"))

    def eventFilter(self, watched: QObject, event: Any) -> bool:
        if watched is self._panel and event.type() == event.Type.LanguageChange:
            self.retranslate()
        return False

    @Slot(str)
    def _on_profile_problem(self, text: str) -> None:
        self.window.event_log.add_event("warning", self.tr("3D view"), text)

    @Slot(object)
    def _on_agreement(self, agreement: ModelAgreement | None) -> None:
        """A model that starts to disagree with the controller: a warning in the event log (once
        per disagreement, not at every drift of its size) and the planner's checks again (only
        a disagreement is a check: a model found to agree changes none)."""
        disagreeing = agreement is not None and not agreement.agrees
        if disagreeing and not self._disagreeing and agreement is not None:
            from app.view3d.agreement import model_issue
            from ui.messages_plan import issue_text

            self.window.event_log.add_event("warning", self.tr("3D view"), issue_text(model_issue(agreement)))
        if (disagreeing or self._disagreeing) and self._planner is not None:
            self._planner.recheck()
        self._disagreeing = disagreeing

    @Slot(bool)
    def set_beside(self, beside: bool) -> None:
        panel = self.panel
        if beside and self.dock.widget() is not panel:
            self.tabs.removeTab(self.tabs.indexOf(panel))
            self.dock.setWidget(panel)
            self.dock.show()
            self.tabs.setCurrentWidget(self.window.planner_panel)
        elif not beside and self.dock.widget() is panel:
            self.dock.setWidget(None)  # type: ignore[arg-type]
            self.dock.hide()
            self.tabs.addTab(panel, "")
            panel.show()
            self.retranslate()
        panel.beside_button.blockSignals(True)
        panel.beside_button.setChecked(beside)
        panel.beside_button.blockSignals(False)

    @Slot(bool)
    def _on_dock_visible(self, visible: bool) -> None:
        # closing the dock (its X) puts the view back into its tab
        if (
            not visible
            and self._panel is not None
            and self.dock.widget() is self._panel
            and not self.dock.isVisible()
        ):
            self.set_beside(False)


def install_view3d(window: Any) -> View3DHost:
    return View3DHost(window)
