"""The Safety menu and the window's role gating, composed onto the window's parts in one call.

:func:`install_safety` takes the parts it works with by name (:class:`SafetyParts`; it does not
know the window, which composes it), creates the :class:`SafetyController`, gates the controls by
role (connection, register profile, passwords: administrator; point and plan edits, the envelope,
the robot model: engineer), feeds the envelope to the planner, the 3D view and the worker, and
adds the menu: log in / out, reduced speed, envelope, register profile, passwords and lock, audit
trail, support bundle; a status-bar label shows the role.

The register profile in force is a file beside the role store (``AppSettings.register_profile_path``,
:mod:`app.safety.location`; never beside the settings file);
``AppSettings.connection()`` applies it, so every connection made from the remembered settings
uses it. :meth:`SafetyMenu.apply_register_profile` saves a new one (administrator, audited) and can
reconnect the link at once with it.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject, QTimer, Slot
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QLabel, QMainWindow, QMenu

from app.errors import TeachPadError
from app.link.types import LinkState
from app.safety.register_profile import RegisterProfile
from app.safety.roles import Action, Role
from app.safety.session import PermissionRefused
from ui.controllers.safety import SafetyController
from ui.first_paint import AfterFirstPaint

if TYPE_CHECKING:  # types only (the dialogs and the lazily built panels are imported when opened
    # or built: the window's first paint does not wait for them)
    from app.link.robot_link import RobotLink
    from ui.controllers.project_controller import ProjectController
    from ui.dialogs.register_profile_dialog import RegisterProfileDialog
    from ui.panels.event_log import EventLogPanel
    from ui.panels.jog_refusal import MotionRefusalLine
    from ui.panels.planner_panel import PlannerPanel
    from ui.panels.points_panel import PointsPanel
    from ui.panels.status_panel import StatusPanel
    from ui.panels.traffic_panel import TrafficPanel
    from ui.panels.view3d_host import View3DHost
    from ui.panels.view3d_panel import View3DPanel
    from ui.settings import AppSettings
    from ui.window_tabs import LazyTab


@dataclass(frozen=True)
class SafetyParts:
    """What the guard rails are composed onto, each part by name."""

    host: QMainWindow  # its menu bar and status bar; the dialogs' parent; its show, hide, language
    menu_before: QAction  # the Safety menu goes before this one in the menu bar (Help's)
    link: RobotLink
    settings: AppSettings  # the register profile in force, the poll rate, the bundle's settings
    project: ProjectController  # its file (the bundle), its points (the move-to check)
    event_log: EventLogPanel  # refusals are logged; the bundle carries it
    status_panel: StatusPanel  # refusals show as its last command
    traffic_panel: Callable[[], TrafficPanel]  # the bundle carries it (built when first asked for)
    release_jogs: Callable[[], None]  # before a reconnect with a new register profile
    connect_action: QAction  # gated: changing the connection is the administrator's
    points_tab: LazyTab[PointsPanel]
    planner_tab: LazyTab[PlannerPanel]
    view3d: View3DHost
    refusal_line: MotionRefusalLine  # a refused motion is said under the motion buttons too
    #: measured stopping's summary lines for the bundle (app/safety/stopping.py; None: none kept)
    stopping: Callable[[], list[str]] | None = None


class SafetyMenu(QObject):
    """See the module docstring. ``save_path(title, suggested)`` is replaceable (tests)."""

    def __init__(self, parts: SafetyParts, safety: SafetyController) -> None:
        window = parts.host
        super().__init__(window)
        self.window = window
        self.parts = parts
        self.safety = safety
        self.save_path: Callable[[str, str], str | None] = self._ask_save_path
        self.login_action = QAction(self)
        self.login_action.triggered.connect(self.open_role_dialog)
        self.logout_action = QAction(self)
        self.logout_action.triggered.connect(safety.logout)
        self.reduced_action = QAction(self)
        self.reduced_action.setObjectName("ReducedSpeedAction")
        self.reduced_action.setCheckable(True)
        self.reduced_action.toggled.connect(self._on_reduced)
        self.envelope_action = QAction(self)
        self.envelope_action.setObjectName("EnvelopeAction")
        self.envelope_action.triggered.connect(self.open_envelope_dialog)
        self.register_profile_action = QAction(self)
        self.register_profile_action.setObjectName("RegisterProfileAction")
        self.register_profile_action.triggered.connect(self.open_register_profile_dialog)
        self.passwords_action = QAction(self)
        self.passwords_action.setObjectName("PasswordsAction")
        self.passwords_action.triggered.connect(self.open_password_dialog)
        self.audit_action = QAction(self)
        self.audit_action.triggered.connect(self.open_audit_viewer)
        self.bundle_action = QAction(self)
        self.bundle_action.triggered.connect(self.write_bundle)
        self.menu = QMenu(window)
        for action in (
            self.login_action,
            self.logout_action,
            None,
            self.reduced_action,
            self.envelope_action,
            None,
            self.register_profile_action,
            self.passwords_action,
            None,
            self.audit_action,
            self.bundle_action,
        ):
            if action is None:
                self.menu.addSeparator()
            else:
                self.menu.addAction(action)
        window.menuBar().insertMenu(parts.menu_before, self.menu)
        self.role_label = QLabel(window)
        self.role_label.setObjectName("RoleLabel")
        window.statusBar().addPermanentWidget(self.role_label)
        safety.roleChanged.connect(self._update)
        safety.reducedChanged.connect(self._update)
        window.installEventFilter(self)
        self.retranslate()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.window:
            kind = event.type()
            if kind == QEvent.Type.LanguageChange:
                self.retranslate()
            elif kind == QEvent.Type.Show:
                self.safety.set_idle_polling(True)
            elif kind in (QEvent.Type.Hide, QEvent.Type.Close):
                self.safety.set_idle_polling(False)  # no timer outlives the window
        return False

    def retranslate(self) -> None:
        self.menu.setTitle(self.tr("&Safety"))
        self.login_action.setText(self.tr("Log &in…"))
        self.logout_action.setText(self.tr("Log &out (operator)"))
        self.reduced_action.setText(self.tr("&Reduced speed"))
        self.envelope_action.setText(self.tr("Safety &envelope…"))
        self.register_profile_action.setText(self.tr("Re&gister profile…"))
        self.register_profile_action.setToolTip(
            self.tr("Word order, unit id, completion rule, poll timeout (administrator)")
        )
        self.passwords_action.setText(self.tr("&Passwords and lock…"))
        self.passwords_action.setToolTip(
            self.tr("Set, change or clear passwords; the idle lock time (administrator)")
        )
        self.audit_action.setText(self.tr("&Audit trail…"))
        self.bundle_action.setText(self.tr("Write a &support bundle…"))
        # after the window's own retranslate (it sets tooltips); dropped with the window (its child)
        QTimer.singleShot(0, self, self._refresh)
        self._update()

    @Slot()
    def _refresh(self) -> None:
        self.safety.refresh()
        self._update()

    @Slot()
    def _update(self, *_args: Any) -> None:
        safety = self.safety
        role = safety.role_name(safety.role)
        text = self.tr("Role: {role} · reduced speed") if safety.session.reduced else self.tr("Role: {role}")
        self.role_label.setText(text.format(role=role))
        self.logout_action.setEnabled(safety.role is not Role.OPERATOR)
        self.reduced_action.blockSignals(True)
        self.reduced_action.setChecked(safety.session.reduced)
        self.reduced_action.blockSignals(False)
        leave = safety.reason(Action.LEAVE_REDUCED_SPEED)
        self.reduced_action.setToolTip(
            leave
            if safety.session.reduced and leave
            else self.tr("Cap jog and move speeds (anyone may switch it on)")
        )

    @Slot(str)
    def show_message(self, text: str) -> None:
        """A refusal or a problem of the guard rails: where the operator looks for what became of
        the command (the status dock's *Last command*), the event log and the status bar."""
        self.parts.event_log.add_event("warning", self.source_name(), text)
        self.parts.status_panel.show_refusal(text)
        self.window.statusBar().showMessage(text, 8000)

    def source_name(self) -> str:
        """The event log's source column for safety messages."""
        return self.tr("safety")

    @Slot(bool)
    def _on_reduced(self, on: bool) -> None:
        if not self.safety.set_reduced(on):
            self._update()

    # --- dialogs -------------------------------------------------------------------------------
    @Slot()
    def open_role_dialog(self) -> None:
        from ui.dialogs.role_dialog import RoleDialog

        RoleDialog(self.safety, self.window).exec()

    @Slot()
    def open_envelope_dialog(self) -> None:
        if self.safety.allowed(Action.EDIT_ENVELOPE):
            from ui.dialogs.envelope_dialog import EnvelopeDialog

            EnvelopeDialog(self.safety, self.window).exec()

    @Slot()
    def open_password_dialog(self) -> None:
        if self.safety.allowed(Action.MANAGE_ROLES):
            from ui.dialogs.password_dialog import PasswordDialog

            PasswordDialog(self.safety, self.window).exec()

    def register_profile(self) -> RegisterProfile:
        """The register profile in force."""
        return self.parts.settings.register_profile()[0]

    def register_profile_dialog(self) -> RegisterProfileDialog:
        from ui.dialogs.register_profile_dialog import RegisterProfileDialog

        link = self.parts.link
        connected = link.settings is not None and link.connection.state is not LinkState.DISCONNECTED
        return RegisterProfileDialog(
            self.register_profile(),
            self.apply_register_profile,
            self.window,
            reason=self.safety.reason(Action.REGISTER_PROFILE),
            connected=connected,
        )

    @Slot()
    def open_register_profile_dialog(self) -> None:
        if self.safety.allowed(Action.REGISTER_PROFILE):
            self.register_profile_dialog().exec()

    def apply_register_profile(self, profile: RegisterProfile, reconnect: bool = False) -> str | None:
        """Save ``profile`` as the one in force (administrator only: refused and audited otherwise)
        and, with ``reconnect``, connect the link again with it. None when done, else why not."""
        parts = self.parts
        try:
            saved = self.safety.session.set_register_profile(
                parts.settings.register_profile_path(), profile, self.register_profile()
            )
        except PermissionRefused:
            why = self.safety.reason(Action.REGISTER_PROFILE) or ""
            self.safety.message.emit(why)
            return why
        except (OSError, TeachPadError) as exc:
            return self.tr("The register profile could not be saved: {why}").format(why=str(exc)[:200])
        link = parts.link
        if reconnect and link.settings is not None:
            parts.release_jogs()
            link.connect_to(saved.apply(link.settings))
        text = self.tr("Register profile \u201c{name}\u201d saved (revision {rev})")
        self.window.statusBar().showMessage(text.format(name=saved.name, rev=saved.revision), 8000)
        return None

    @Slot()
    def open_audit_viewer(self) -> None:
        from ui.panels.audit_viewer import AuditViewer

        viewer = AuditViewer(self.safety.audit_dir, self.window)
        viewer.exec()

    def _ask_save_path(self, title: str, suggested: str) -> str | None:
        from PySide6.QtWidgets import QFileDialog  # dialogs: imported when one is shown, not at start-up

        path, _ = QFileDialog.getSaveFileName(self.window, title, suggested, self.tr("Zip files (*.zip)"))
        return path or None

    @Slot()
    def write_bundle(self) -> Path | None:
        """The support bundle: versions, settings without passwords, project, profile, audit,
        event log and the recent Modbus traffic, in one zip."""
        path = self.save_path(self.tr("Write a support bundle"), "teachpad-support.zip")
        if not path:
            return None
        window, parts = self.window, self.parts
        store = parts.settings.store
        settings = {key: store.value(key) for key in store.allKeys()}
        settings["safety_state"] = self.safety.location.describe()  # where roles, envelope, audit live
        project = parts.project.path
        profile = self.safety.profile_path if self.safety.profile_path.exists() else None
        register_profile: Path | None = parts.settings.register_profile_path()
        if register_profile is not None and not register_profile.exists():
            register_profile = None
        from app.safety.bundle import write_support_bundle  # importlib.metadata: not at start-up

        try:
            with tempfile.TemporaryDirectory() as tmp:
                parts.event_log.export_to(Path(tmp) / "events.txt")
                events = (Path(tmp) / "events.txt").read_text(encoding="utf-8-sig").splitlines()
                parts.traffic_panel().export_to(Path(tmp) / "traffic.txt", visible_only=False)
                traffic = (Path(tmp) / "traffic.txt").read_text(encoding="utf-8-sig").splitlines()
                manifest = write_support_bundle(
                    path,
                    settings=settings,
                    project=project,
                    profile=profile,
                    register_profile=register_profile,
                    audit_dir=self.safety.audit_dir,
                    events=events,
                    traffic=traffic,
                    stopping=parts.stopping() if parts.stopping is not None else None,
                )
        except (OSError, TeachPadError) as exc:
            why = self.tr("The support bundle could not be written: {why}").format(why=str(exc)[:200])
            from PySide6.QtWidgets import QMessageBox

            QMessageBox.warning(window, self.tr("Support bundle"), why)
            return None
        self.safety.session.audit.record(
            "action", "support bundle written", args={"files": len(manifest.files)}
        )
        window.statusBar().showMessage(
            self.tr("Support bundle written: {file} ({n} files)").format(
                file=Path(path).name, n=len(manifest.files)
            ),
            8000,
        )
        return Path(path)


def gate_points(safety: SafetyController, parts: SafetyParts, panel: PointsPanel) -> None:
    """The points table's edits by role; its move-to checked against the envelope."""
    safety.gate_panel(panel, Action.EDIT_POINTS)
    link, project = parts.link, parts.project
    panel.move_check = lambda point_id, speed: safety.check_move_to(
        link.state.pose, point_id, speed, project.points_model.ledger
    )
    panel.set_caps(safety.caps)
    safety.capsChanged.connect(panel.set_caps)


def gate_planner(safety: SafetyController, panel: PlannerPanel) -> None:
    """The planner's edits by role; its checks (and its 2D preview) with the envelope."""
    safety.gate_panel(panel, Action.EDIT_PLANS)
    safety.attach_checker(panel)


def attach_view3d(safety: SafetyController, panel: View3DPanel) -> None:
    """The 3D view draws the envelope; its Robot model… button is an engineer's."""
    safety.attach_view(panel.canvas)
    safety.gate(panel.profile_button, Action.ROBOT_MODEL)


def install_safety(parts: SafetyParts, *, scrypt_n: int | None = None) -> SafetyMenu:
    """Compose the guard rails onto ``parts`` (the 3D view already installed)."""
    safety = SafetyController(parts.link, parent=parts.host, scrypt_n=scrypt_n)
    if safety.fresh_unsaved:  # a fresh install's envelope: saved and audited after the first paint
        AfterFirstPaint(parts.host, safety.save_fresh_envelope)
    safety.set_poll_rate(parts.settings.poll_hz)  # the jog guard's margin follows the poll period
    menu = SafetyMenu(parts, safety)
    safety.gate(parts.connect_action, Action.CONNECTION)
    safety.gate(menu.envelope_action, Action.EDIT_ENVELOPE)
    safety.gate(menu.register_profile_action, Action.REGISTER_PROFILE)
    safety.gate(menu.passwords_action, Action.MANAGE_ROLES)
    # Points and Planner are built on first show (ui/window_tabs.py): each is gated the moment
    # it exists, before it is in its tab, with the role in force then and at every change after.
    parts.points_tab.on_built(lambda panel: gate_points(safety, parts, panel))
    parts.planner_tab.on_built(lambda panel: gate_planner(safety, panel))
    # the robot model is an engineer's: its loads pass the guard (refused and audited otherwise);
    # the 3D view is built on first show: its canvas and its Robot model… button are attached then
    parts.view3d.robot.guard = safety
    parts.view3d.on_built(lambda panel: attach_view3d(safety, panel))
    safety.message.connect(menu.show_message)  # a slot of the menu: a receiver in the GUI thread
    # a refused motion is said in the motion area too, under its buttons, until the next accepted one
    refusal_line = parts.refusal_line
    safety.motionRefused.connect(refusal_line.show_words)
    safety.motionAccepted.connect(refusal_line.clear_refusal)
    if safety.problem:
        safety.message.emit(safety.problem)
    register_problem = parts.settings.register_profile()[1]
    if register_problem:
        safety.message.emit(register_problem)
    return menu
