"""The pendant's main window: control column, work tabs, docked status / log panels.

Layout (fits 1280×800 and grows to 1920×1080): on the left the control column (control bar
with the big STOP, then the Jog / Step / Program tabs); on the right the work tabs
Monitor | Points | Planner | 3D; docks: Status (left, narrow), Event log, Modbus traffic and
Alarms (bottom, tabified). STOP stays visible whatever tab is shown.

The window only composes: the robot's state lives in one :class:`~app.link.state.RobotState`
(``link.state``) and every panel and part subscribes to the fields it shows
(``part.bind(state)``), the window keeps no copy; controllers turn the panels' intents into link
requests. Its parts: :class:`~ui.window_column.ControlColumn` (the left column),
:class:`~ui.window_docks.WindowDocks`, :class:`~ui.window_status.WindowStatusBar`,
:class:`~ui.window_actions.WindowActions` (menus, toolbar), :mod:`~ui.window_rows` (the alarm
banner and the pose strip above everything); the window keeps their widgets under
its own names too (``window.control_bar``, ``window.event_log``, ``window.status_link``...).
One :class:`ProjectController` owns the open project (File and Edit menus); the points panel
and the planner share its models, a :class:`PointSyncController` and a
:class:`PlanRunController`; a :class:`MotionController` drives the motion panels and enables
them only while the link is up and writable (not monitor-only). Any jog ends when the window
loses the focus, is hidden or closed, and when the link goes down.

Close order: jog release first (before any question), then "save changes?" (Cancel keeps the
window and the link), then, when motion or a program may be under way, "stop first?"
(:class:`~ui.controllers.link_guard.LinkGuard`; Cancel keeps both too), then the window state is
saved and the link shut down (a Stop chosen goes out before). A close that is not the operator's
(:meth:`MainWindow.close_unattended`: ``teachpad --screenshot``) asks nothing and stops what is
under way.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QCoreApplication, QEvent, Qt, QTimer, Slot
from PySide6.QtGui import QCloseEvent, QHideEvent, QShowEvent
from PySide6.QtWidgets import (
    QApplication,
    QMainWindow,
    QSizePolicy,
    QSplitter,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from app import __version__
from app.connection import ConnectionSettings
from app.link.ops import Pause, Resume, Stop
from app.link.robot_link import RobotLink
from app.link.types import WorkerError
from app.models import LINK_FAILURE_CODES
from app.protocol.word_order_check import WordOrderVerdict
from app.safety.location import Scope
from app.safety.roles import Action
from ui.controllers.link_guard import LinkGuard
from ui.controllers.motion import MotionController
from ui.controllers.plan_run_controller import PlanRunController
from ui.controllers.plan_run_reasons import foreign_pause_text
from ui.controllers.point_sync import PointSyncController
from ui.controllers.project_controller import ProjectController
from ui.controllers.project_dialogs import ProjectDialogs
from ui.controllers.safety_menu import SafetyParts, install_safety
from ui.controllers.selftest_watch import install_register_map_check
from ui.controllers.stop_timing import StopTiming
from ui.controllers.word_order_watch import WordOrderWatch
from ui.dialogs.confirm import ConfirmFn
from ui.i18n import Translator
from ui.joins import labelled
from ui.messages import error_text
from ui.models.point_provenance import controller_text
from ui.panels.monitor_panel import MonitorPanel
from ui.panels.view3d_host import install_view3d
from ui.settings import AppSettings
from ui.touch import apply_touch_mode, mark_motion
from ui.window_actions import WindowActions
from ui.window_cell import install_cell
from ui.window_column import ControlColumn
from ui.window_compare import install_compare
from ui.window_docks import WindowDocks
from ui.window_geometry import MIN_SIZE, default_size, restore_window
from ui.window_rows import add_window_rows
from ui.window_status import WindowStatusBar
from ui.window_tabs import LazyTab
from ui.window_watch_list import install_watch_list

if TYPE_CHECKING:  # built on first show (LazyTab): not imported before the window's first paint
    from ui.panels.planner_panel import PlannerPanel
    from ui.panels.points_panel import PointsPanel
    from ui.panels.program_panel import ProgramPanel
    from ui.panels.step_panel import StepPanel
    from ui.panels.traffic_panel import TrafficPanel

TAB_MONITOR, TAB_POINTS, TAB_PLANNER = range(3)
TAB_NAMES = ("monitor", "points", "planner")


class MainWindow(QMainWindow):
    """See the module docstring. ``confirm`` (settable) is used by every panel that asks."""

    def __init__(
        self,
        link: RobotLink,
        settings: AppSettings,
        translator: Translator | None = None,
        parent: QWidget | None = None,
        *,
        shutdown_link_on_close: bool = True,
        project_dialogs: Any = None,
        autosave_dir: str | os.PathLike[str] | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("MainWindow")
        self.link = link
        self.settings = settings
        self.translator = translator
        self.shutdown_link_on_close = shutdown_link_on_close
        self._close_accepted = False
        self._confirm: ConfirmFn | None = None  # given to the lazily built panels too

        # --- the project and its controllers (no widgets) ---------------------------------
        self.project = ProjectController(
            dialogs=project_dialogs or ProjectDialogs(self), autosave_dir=autosave_dir, parent=self
        )
        self.point_sync = PointSyncController(self.project.points_model, link, self)
        # points made here record the controller the link reaches (provenance, issue 24)
        self.project.points_model.stamps.controller = lambda: controller_text(
            link.state.connection.controller
        )
        self.run_controller = PlanRunController(link, self, points=self.project.points_model)

        # --- left: control bar + motion tabs ----------------------------------------------
        self.control_column = column = ControlColumn(self)
        self.control_bar, self.motion_banner = column.control_bar, column.motion_banner
        self.tabs, self.jog_panel = column.tabs, column.jog_panel
        self.step_tab, self.program_tab = column.step_tab, column.program_tab  # built on first use

        # --- right: the work tabs (Points and Planner are built when first shown or asked for) --
        self.monitor_panel = MonitorPanel(self)
        self.work_tabs = QTabWidget(self)
        self.work_tabs.setObjectName("WorkTabs")
        self.work_tabs.addTab(self.monitor_panel, "")
        tabs = self.work_tabs
        self.points_tab: LazyTab[PointsPanel] = LazyTab(tabs, self._build_points_panel, "Points")
        self.planner_tab: LazyTab[PlannerPanel] = LazyTab(tabs, self._build_planner_panel, "Planner")

        self.splitter = QSplitter(Qt.Orientation.Horizontal, self)
        self.splitter.setObjectName("MainSplitter")
        self.splitter.addWidget(self.control_column)
        self.splitter.addWidget(self.work_tabs)
        self.splitter.setStretchFactor(0, 0)
        self.splitter.setStretchFactor(1, 1)
        self.splitter.setChildrenCollapsible(False)
        central = QWidget(self)
        outer = QVBoxLayout(central)
        outer.setContentsMargins(4, 4, 4, 0)
        outer.addWidget(self.splitter)
        # the work area, not the docks, takes the spare width of a resized window
        central.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setCentralWidget(central)

        # --- docks: the display panels --------------------------------------------------
        self.docks = docks = WindowDocks(self, link)
        self.status_panel, self.event_log = docks.status_panel, docks.event_log
        self.alarm_list = docks.alarm_list  # traffic_panel: a property (built when first seen)
        self.status_dock, self.event_dock = docks.status_dock, docks.event_dock
        self.traffic_dock, self.alarm_dock = docks.traffic_dock, docks.alarm_dock

        # --- actions, menus, toolbar, status bar ---------------------------------------
        # Disconnect and the close ask first when the robot may be moving; Reconnect (any role)
        self.link_guard = LinkGuard(link, self.jog_panel, self.run_controller, settings, self)
        self.menus = WindowActions(
            self,
            connect=self.open_connection_dialog,
            disconnect=self.link_guard.disconnect_link,
            reconnect=self.reconnect,
            can_reconnect=lambda: self.link_guard.last_connection() is not None,
            stop=self._menu_stop,
            pause=lambda: link.submit(Pause()),
            resume=lambda: link.submit(Resume()),
            about=self.show_about,
            show_tab=self.show_tab,
            tab_count=len(TAB_NAMES),
            set_language=self.set_language,
            language=translator.language if translator else "en",
            file_actions=self.project.file_actions(),
            edit_actions=[self.project.action_undo, self.project.action_redo],
            docks=docks.docks,
            set_touch_mode=self.set_touch_mode,
            touch_mode=settings.touch_mode,
        )
        rows = add_window_rows(self)  # above everything: the alarm banner, the pose strip
        self.alarm_banner, self.pose_strip, self.pose_bar = rows.alarm_banner, rows.pose_strip, rows.pose_bar
        self.status_bar = WindowStatusBar(self.statusBar())
        labels = self.status_bar
        self.status_link, self.status_rtt = labels.link_label, labels.rtt_label
        self.status_project, self.status_monitor_only = labels.project_label, labels.monitor_only_label

        self._wire()
        bar = self.control_bar
        mark_motion(bar.stop_button, bar.pause_button, bar.resume_button)
        self.set_touch_mode(settings.touch_mode)
        self.view3d = install_view3d(self)  # the 3D tab (and its dock beside the planner)
        self.safety_menu = install_safety(self._safety_parts())  # roles, envelope, audit (Safety menu)
        self.motion.safety = self.safety_menu.safety
        self.run_controller.audit = self.safety_menu.safety.session.audit  # a run's own pause (issue 19)
        self.stop_timing.audit = self.safety_menu.safety.session.audit  # each stop measured
        self.cell = install_cell(self)  # File → Open cell…, the Cell tab (issue 23)
        self.register_map_check = install_register_map_check(self)  # Help → register map (issue 24)
        self.watch_list = install_watch_list(self)  # View → Watch list (issue 24)
        self.compare = install_compare(self)  # File → Compare with… (issue 24)
        self.setMinimumSize(*MIN_SIZE)
        self.resize(*default_size())
        self.splitter.setSizes([360, max(600, self.width() - 360)])
        self._docks_sized = restore_window(self, settings)  # else sized at the first show
        self.alarm_banner.sync()  # shown exactly while an alarm is set, whatever was saved
        self.pose_bar.setVisible(True)
        app = QApplication.instance()
        self._app_state_hooked = isinstance(app, QApplication)
        if isinstance(app, QApplication):
            app.applicationStateChanged.connect(self._on_application_state)
        self.retranslate()

    # --- construction -----------------------------------------------------------------
    def _wire(self) -> None:
        """Every part follows the link's RobotState itself; the window keeps no copy of it."""
        link, state = self.link, self.link.state
        for panel in (
            self.monitor_panel,
            self.status_panel,
            self.event_log,
            self.control_bar,
            self.pose_strip,
            self.alarm_banner,
            self.alarm_list,
            self.control_column,
            self.menus,
            self.status_bar,
        ):
            panel.bind(state)
        state.connectionChanged.connect(self._update_title)
        link.errorOccurred.connect(self._on_error)
        link.errorOccurred.connect(self.control_column.refusal_line.on_error)  # a motion refused: said there
        # the register profile's float word order probably wrong: said once per connection
        self.word_order_watch = WordOrderWatch(link, self)
        self.word_order_watch.warned.connect(self.control_column.show_word_order)
        self.word_order_watch.warned.connect(self._on_word_order)
        link.controllerReconnected.connect(self._on_reconnected)
        link.controllerRestarted.connect(self._on_restarted)
        link.foreignMaster.connect(self._on_foreign_master)
        self.run_controller.pausedByForeign.connect(self._on_run_paused_by_foreign)
        self.motion = MotionController(
            link, self.control_bar, self.jog_panel, None, None, self.run_controller, self
        )
        # measured stopping: an observer of the Stop, the jog release and the polls (issue 24)
        self.stop_timing = StopTiming(state, self.control_bar, self.jog_panel, self)
        self.stop_timing.measured.connect(self.monitor_panel.show_last_stop)
        # Step and Program are built on first use: gated the moment they exist, before shown
        self.step_tab.on_built(self.motion.add_step_panel)  # enabled or not at once, as the others
        self.program_tab.on_built(self.motion.add_program_panel)
        for tab in (self.step_tab, self.program_tab):
            tab.on_built(self._join_motion_tab)  # then the question and the touch mode
        project = self.project
        project.titleChanged.connect(self._on_project_title)
        project.pathChanged.connect(self._on_project_path)
        project.statusMessage.connect(self._show_message)

    def _safety_parts(self) -> SafetyParts:
        """What the guard rails work with (:func:`~ui.controllers.safety_menu.install_safety`)."""
        return SafetyParts(
            host=self,
            menu_before=self.menus.help_menu.menuAction(),
            link=self.link,
            settings=self.settings,
            project=self.project,
            event_log=self.event_log,
            status_panel=self.status_panel,
            traffic_panel=lambda: self.traffic_panel,
            release_jogs=self.jog_panel.release_all,
            connect_action=self.menus.connect_action,
            points_tab=self.points_tab,
            planner_tab=self.planner_tab,
            view3d=self.view3d,
            refusal_line=self.control_column.refusal_line,
            stopping=self.stop_timing.log.summary_lines,
        )

    def _menu_stop(self) -> None:
        """The menu's Stop (and Esc): to the link first; the measuring only watches (from the
        moment before the Stop was sent)."""
        clicked = time.monotonic()
        self.link.submit(Stop())
        self.stop_timing.note_stop(clicked)

    @property
    def traffic_panel(self) -> TrafficPanel:  # built when its dock is first seen (WindowDocks)
        return self.docks.traffic_panel

    # --- the lazily built motion and work tabs (LazyTab) -------------------------------------
    @property
    def step_panel(self) -> StepPanel:  # built on first use (LazyTab), like the next three
        return self.step_tab.panel

    @property
    def program_panel(self) -> ProgramPanel:
        return self.program_tab.panel

    def _join_motion_tab(self, panel: StepPanel | ProgramPanel) -> None:
        """A lazily built motion panel (already gated by the motion controller) gets the question
        and the touch mode."""
        if self._confirm is not None:
            panel.confirm = self._confirm
        apply_touch_mode((panel,), self.settings.touch_mode)

    @property
    def points_panel(self) -> PointsPanel:
        return self.points_tab.panel

    @property
    def planner_panel(self) -> PlannerPanel:
        return self.planner_tab.panel

    def _build_points_panel(self) -> PointsPanel:
        from ui.panels.points_panel import PointsPanel

        panel = PointsPanel(self.project.points_model, self.point_sync, self)
        panel.set_run_active(self.run_controller.running)
        self.run_controller.runningChanged.connect(panel.set_run_active)
        self._join_work_tab(panel)
        return panel

    def _build_planner_panel(self) -> PlannerPanel:
        from ui.panels.planner_panel import PlannerPanel

        project = self.project
        panel = PlannerPanel(
            project.plans_model, project.points_model, self.run_controller, self.point_sync, self
        )
        self._join_work_tab(panel)
        return panel

    def _join_work_tab(self, panel: PointsPanel | PlannerPanel) -> None:
        """A lazily built work panel gets the alarm hold, status bar, question and touch mode."""
        panel.set_alarm_hold(self.motion.alarm_hold)
        self.motion.alarmHoldChanged.connect(panel.set_alarm_hold)
        panel.statusMessage.connect(self._show_message)
        if self._confirm is not None:
            panel.set_confirm(self._confirm)
        apply_touch_mode((panel,), self.settings.touch_mode)  # as set_touch_mode did for the others

    # --- texts ------------------------------------------------------------------------
    def retranslate(self) -> None:
        self._update_title()
        self.work_tabs.setTabText(TAB_MONITOR, self.tr("Monitor"))
        self.work_tabs.setTabText(TAB_POINTS, self.tr("Points"))
        self.work_tabs.setTabText(TAB_PLANNER, self.tr("Planner"))
        for part in (self.control_column, self.docks, self.status_bar, self.menus, self.project):
            part.retranslate()
        self._on_project_title(self.project.title)

    def changeEvent(self, event: QEvent) -> None:
        kind = event.type()
        if kind == QEvent.Type.LanguageChange:
            self.retranslate()
        elif kind == QEvent.Type.ActivationChange and not self.isActiveWindow():
            self.jog_panel.release_all()  # dead-man: focus went to another window
        super().changeEvent(event)

    def event(self, event: QEvent) -> bool:
        if event.type() == QEvent.Type.WindowDeactivate:
            self.jog_panel.release_all()
        return super().event(event)

    @Slot()
    def _update_title(self) -> None:
        endpoint = self.link.state.connection.endpoint
        parts = [self.tr("TeachPad"), self.project.title]
        if endpoint:
            parts.append(endpoint)
        self.setWindowTitle(" — ".join(parts))

    # --- link -> the window ----------------------------------------------------------------
    @property
    def motion_enabled(self) -> bool:
        return self.motion.motion_enabled

    @Slot(WorkerError)
    def _on_error(self, error: WorkerError) -> None:
        operation = self.event_log.operation_text(error.operation)
        silence = error.reason is not None and error.reason.code in LINK_FAILURE_CODES
        self.status_bar.show_message(labelled(operation, error_text(error)), until_answering=silence)

    @Slot(object)
    def _on_word_order(self, verdict: WordOrderVerdict | None) -> None:
        if verdict is None:
            return
        from ui.messages_word_order import word_order_details, word_order_text

        self.event_log.add_event(
            "warning",
            lambda: self.tr("link"),
            lambda: f"{word_order_text(verdict)} {word_order_details(verdict)}",
        )
        self.status_bar.show_message(word_order_text(verdict))

    @Slot(str)
    def _show_message(self, text: str) -> None:
        self.status_bar.show_message(text)

    @Slot(str)
    def _on_project_title(self, title: str) -> None:
        self.status_bar.show_project(title, str(self.project.path or ""))
        self._update_title()

    @Slot(str)
    def _on_project_path(self, path: str) -> None:
        if path:
            self.settings.last_project = path

    @Slot()
    def _on_restarted(self) -> None:
        text = self.tr(
            "The controller restarted (its temp points are gone): restore them from the Points tab"
        )
        self.event_log.add_event("warning", self.tr("link"), text)

    @Slot(str, float)
    def _on_foreign_master(self, what: str, value: float) -> None:
        """Another Modbus master is on the controller (app/link/foreign.py): banner (it follows the
        language), status bar, and the event log once per episode (the worker audited it)."""
        new = self.control_column.show_foreign_master(what, value)
        text = self.control_column.foreign_banner.text()
        if new:
            self.event_log.add_event("warning", self.tr("link"), text)
        self._show_message(text)

    @Slot(str, float)
    def _on_run_paused_by_foreign(self, what: str, value: float) -> None:
        """The plan run paused itself at a sign of another master: the event log says why."""
        self.event_log.add_event(
            "warning", lambda: self.tr("plan run"), lambda: foreign_pause_text(what, value)
        )

    @Slot()
    def _on_reconnected(self) -> None:
        text = self.tr("Reconnected to the controller: jog stopped and teach mode switched off")
        self.event_log.add_event("warning", self.tr("link"), text)

    # --- confirmation (one setter for every panel that asks) --------------------------
    @property
    def confirm(self) -> ConfirmFn:
        return self._confirm if self._confirm is not None else self.program_panel.confirm

    @confirm.setter
    def confirm(self, fn: ConfirmFn) -> None:
        self._confirm = fn
        for motion_tab in (self.step_tab, self.program_tab):
            if motion_tab.built:
                motion_tab.panel.confirm = fn
        for tab in (self.points_tab, self.planner_tab):
            if tab.built:
                tab.panel.set_confirm(fn)

    # --- project -----------------------------------------------------------------------
    def show_tab(self, index: int | str) -> None:
        """Bring a work tab to the front: 0..2 or "monitor" / "points" / "planner"."""
        if isinstance(index, str):
            index = TAB_NAMES.index(index)
        self.work_tabs.setCurrentIndex(index)

    def start_project(
        self,
        path: str | os.PathLike[str] | None = None,
        *,
        reopen_last: bool = True,
        offer_recovery: bool = True,
    ) -> bool:
        """At startup: open ``path`` (else the last project, if it still exists), then offer to
        recover an autosave a crash left behind. True when a project was opened or recovered."""
        opened = False
        if path is None and reopen_last:
            last = self.settings.last_project
            if last and Path(last).is_file():
                path = last
        if path is not None:
            opened = self.project.open_file(path)
        recovered = offer_recovery and self.project.offer_recovery()
        return opened or recovered

    # --- actions ----------------------------------------------------------------------
    @Slot()
    def open_connection_dialog(self) -> None:
        self.jog_panel.release_all()
        if not self.safety_menu.safety.allowed(Action.CONNECTION):  # the administrator's (audited)
            return
        from ui.dialogs.connection_dialog import ConnectionDialog  # not needed for the first paint

        dialog = ConnectionDialog.for_link(self.link, self.settings.connection(), self.settings.poll_hz, self)
        if dialog.exec() == ConnectionDialog.DialogCode.Accepted:
            self.connect_with(dialog.settings())
            self.safety_menu.safety.set_poll_rate(self.settings.poll_hz)

    @Slot()
    def reconnect(self) -> None:
        """Connect again to the last controller, its settings unchanged: any role's (audited
        like every role check); another controller is :meth:`open_connection_dialog`'s."""
        if self.safety_menu.safety.allowed(Action.RECONNECT):
            self.link_guard.reconnect()

    def connect_with(self, settings: ConnectionSettings) -> None:
        """Remember ``settings`` and connect (the link retries by itself until it succeeds)."""
        self.settings.save_connection(settings)
        self.link.connect_to(settings)

    @Slot()
    def show_about(self) -> None:
        from PySide6.QtWidgets import QMessageBox  # dialogs: imported when one is shown, not at start-up

        QMessageBox.about(
            self,
            self.tr("About TeachPad"),
            self.tr(
                "<b>TeachPad {version}</b><br>Desktop teach pendant for Bochuang robot controllers "
                "(Modbus TCP / RTU).<br><br>Esc stops all motion. Jog buttons and keys move only while held."
            ).format(version=__version__)
            + "<br><br>"
            + self._safety_state_text(),
        )

    def _safety_state_text(self) -> str:
        """Where the roles, the envelope and the audit trail live (never beside the settings file)."""
        from html import escape

        where = self.safety_menu.safety.location
        if where.scope is Scope.MACHINE:
            text = self.tr("Safety state (roles, envelope, audit trail), machine-wide: {folder}")
            return escape(text.format(folder=where.config_dir))
        text = self.tr("Safety state (roles, envelope), this user's: {folder}<br>Audit trail: {audit}")
        return text.format(folder=escape(str(where.config_dir)), audit=escape(str(where.audit_dir)))

    @property
    def touch_mode(self) -> bool:
        return self.settings.touch_mode

    def set_touch_mode(self, on: bool) -> None:
        """Bigger motion buttons and a keypad for number fields (remembered)."""
        self.settings.touch_mode = on
        apply_touch_mode((self.control_column, self.work_tabs), on)
        self.jog_panel.set_touch(on)  # its rows in three lines of two (issue 21)
        self.menus.touch_action.setChecked(on)

    def set_language(self, code: str) -> None:
        """Switch the UI language at runtime and remember it."""
        self.jog_panel.release_all()
        if self.translator is not None and not self.translator.set_language(code):
            self.event_log.add_event(
                "warning", self.tr("language"), self.tr("No translation file for {code}").format(code=code)
            )
            code = self.translator.language
        self.settings.language = code
        # Qt posts LanguageChange to the windows: deliver it now so the switch is immediate.
        QCoreApplication.sendPostedEvents(None, QEvent.Type.LanguageChange)
        action = self.menus.language_actions.get(code)
        if action is not None:
            action.setChecked(True)

    # --- focus, visibility, close ------------------------------------------------------
    @Slot(Qt.ApplicationState)
    def _on_application_state(self, state: Qt.ApplicationState) -> None:
        if state != Qt.ApplicationState.ApplicationActive:
            self.jog_panel.release_all()

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        if not self._docks_sized:  # first start: a narrow status dock, a short log
            self._docks_sized = True
            QTimer.singleShot(0, self.docks, self.docks.size_first_time)  # once the layout is real

    def hideEvent(self, event: QHideEvent) -> None:
        self.jog_panel.release_all()
        super().hideEvent(event)

    def close_unattended(self) -> bool:
        """Close without any question (nobody is there to answer): unsaved changes are not
        saved to the project file but kept in its autosave, which the next start offers; motion
        under way is stopped (nobody is left to stop it)."""
        if not self._close_accepted:
            if self.project.is_dirty:
                self.project.autosave_now()
            self.link_guard.stop_if_under_way()
        self._close_accepted = True
        return self.close()

    def closeEvent(self, event: QCloseEvent) -> None:
        self.jog_panel.release_all()  # first, before any question
        if not self._close_accepted:
            if not self.project.maybe_save():
                event.ignore()  # the operator cancelled: the window and the link stay
                return
            if not self.link_guard.allow_close():  # motion under way: stop first? (or cancel)
                event.ignore()
                return
            self._close_accepted = True
        self.project.close()
        self.settings.save_window(self.saveGeometry(), self.saveState())
        self.settings.sync()
        if self._app_state_hooked:
            self._app_state_hooked = False
            app = QApplication.instance()
            if isinstance(app, QApplication):
                app.applicationStateChanged.disconnect(self._on_application_state)
        self.stop_timing.cancel()  # no measurement outlives the window
        if self.shutdown_link_on_close:
            self.link.shutdown()
        super().closeEvent(event)
