"""The guard rails in the GUI: one :class:`SafetyController` holding the :class:`SafetySession`.

* **Roles**: every gated control is registered with :meth:`SafetyController.gate` (an action or
  a widget and the :class:`~app.safety.roles.Action` it performs); on each role change it is
  enabled or disabled with a tooltip naming the role it needs — never hidden. Panels with their
  own enable logic get ``set_edit_permission(reason)`` instead (points, planner).
* **Idle lock**: ``touch()`` on every key or mouse press, wheel turn or touch; a
  :data:`IDLE_POLL_MS` timer calls ``poll_idle()``, which locks back to operator. The input is
  seen by an event filter on each window (:class:`QWindow`), where the window system delivers
  it before it is passed on to the widget under the cursor or with the focus: an
  application-wide filter would bring every event of every object (paints, timers, queued
  calls: thousands a second while streaming) into Python. Windows are picked up when the focus
  moves (a dialog, a new window) and on every idle poll (a popup); installing twice is a no-op.
* **Envelope**: loaded from the profile file, edited in :class:`~ui.dialogs.envelope_dialog.
  EnvelopeDialog`; pushed whenever it or the mode changes to the views that draw it
  (:class:`EnvelopeView`: the 3D view's canvas; the planner hands it to its 2D preview), to the
  checks that use it with the speed caps (:class:`EnvelopeChecker`: the planner) and to the
  worker's jog guard (with reduced-speed mode). The seams are Protocols checked by mypy.
* **Reduced-speed caps**: while reduced-speed mode is on, :attr:`SafetyController.caps` (the
  envelope's reduced caps, the joint steps' from the robot model's reach) go to the link, whose
  client caps every speed it writes (jog, program, steps, moves, plan segments) and refuses go to
  zero; ``capsChanged`` tells the panels that show the cap where the speed is set.
* **A fresh install** (no envelope file yet) starts with :func:`~app.safety.profile.
  fresh_profile`: the robot model's joint limits and a keep-in box from its reach, on; in force at
  once, saved (revision 1) and audited after the window's first paint.
* **Audit**: the link's :class:`~app.safety.audit.AuditLog` follows the role in force.

Files: where :func:`~app.safety.location.safety_location` says (machine-wide when an administrator
made the folder, else the user's), the same for the CLI; never beside a settings file, which
``teachpad --settings`` can point anywhere.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

from PySide6.QtCore import QEvent, QObject, QTimer, Signal, Slot
from PySide6.QtGui import QAction, QGuiApplication
from PySide6.QtWidgets import QAbstractItemView, QWidget

from app import timing
from app.errors import TeachPadError
from app.link.robot_link import RobotLink
from app.link.types import ConnectionState, JogRequest
from app.models import Pose
from app.plan.geometry import PointLike
from app.plan.segments import Segment
from app.points.ledger import PointLedger
from app.safety.audit import AuditLog
from app.safety.caps import MotionCaps
from app.safety.envelope import Envelope, EnvelopeRefused, EnvelopeViolation, ViolationCode
from app.safety.jog_guard import JogMotion
from app.safety.location import SafetyLocation, safety_location
from app.safety.profile import SafetyProfile, fresh_profile, load_profile, save_profile
from app.safety.roles import REQUIRED_ROLE, Action, Role, RoleStore
from app.safety.session import PermissionRefused, SafetySession

if TYPE_CHECKING:  # the robot model is read by its first use (a fresh install, reduced speed)
    from app.view3d.profile import RobotProfile

IDLE_POLL_MS = 1000
FRESH_SAVE_LATEST_MS = 5000  # a fresh install's envelope is saved then, even with no paint yet
_TOUCH_EVENTS = (
    QEvent.Type.MouseButtonPress,
    QEvent.Type.KeyPress,
    QEvent.Type.TouchBegin,
    QEvent.Type.Wheel,
)


class EnvelopeView(Protocol):
    """Draws the envelope (the 3D view's canvas, the planner's 2D preview)."""

    def set_envelope(self, envelope: Envelope | None) -> None: ...


class EnvelopeChecker(Protocol):
    """Checks with the envelope and the speed caps of the mode in force (the planner)."""

    def set_envelope(self, envelope: Envelope | None, reduced_speed: bool) -> None: ...


class EditGated(Protocol):
    """A panel with its own enable logic: edits only while ``reason`` is None (the points
    table, the planner); else disabled, not hidden, with ``reason`` as the tooltip."""

    def set_edit_permission(self, reason: str | None) -> None: ...


def lock_editing(view: QAbstractItemView, locked: bool) -> None:
    """Role gating of a table's cell edits: off while ``locked``, its own triggers back after."""
    if locked:
        if view.property("safetyEditTriggers") is None:
            view.setProperty("safetyEditTriggers", int(view.editTriggers().value))
        view.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
    elif view.property("safetyEditTriggers") is not None:
        view.setEditTriggers(QAbstractItemView.EditTrigger(view.property("safetyEditTriggers")))


class SafetyController(QObject):
    """See the module docstring. ``session`` is the Qt-free core; ``message`` reports refusals."""

    roleChanged = Signal(object)
    envelopeChanged = Signal(object)
    reducedChanged = Signal(bool)
    capsChanged = Signal(object)  # MotionCaps | None: after every change of the envelope or the mode
    message = Signal(str)  # a refusal or a problem, already translated, for the event log / status
    # (emitted in the GUI thread only: its receivers touch widgets)
    # A motion refused (a jog, a step, a move to a point) or a jog the guard stopped: a way to word
    # it in the language in force (Callable[[], str]), for the motion area (ui/panels/jog_refusal.py)
    motionRefused = Signal(object)
    motionAccepted = Signal()  # a motion the guard rails let go (a jog, a step, a move to a point)
    _auditFailed = Signal(str)  # from the audit's own thread (the worker records writes)

    def __init__(
        self,
        link: RobotLink | None,
        *,
        parent: QObject | None = None,
        scrypt_n: int | None = None,
    ) -> None:
        # (no settings store: the safety state does not follow it; an old call passing one fails)
        super().__init__(parent)
        self.link = link
        self.location: SafetyLocation = safety_location()  # not beside the settings file (see above)
        roles_path, audit_dir = self.location.roles, self.location.audit_dir
        self.audit_dir = audit_dir
        self.profile_path = self.location.envelope
        try:
            roles = RoleStore(roles_path) if scrypt_n is None else RoleStore(roles_path, scrypt_n=scrypt_n)
        except TeachPadError as exc:  # a damaged store: operator only, and say so
            roles = RoleStore(roles_path.with_name("roles-unreadable.json"))
            self._problem = str(exc)
        else:
            self._problem = ""
        # The audit hears of a problem in the thread that wrote: mostly the link's worker. Its
        # callback only emits _auditFailed, whose receiver (a slot of this object, GUI thread) is
        # reached by a queued call; ``message`` is then emitted in the GUI thread.
        self._auditFailed.connect(self._on_audit_failed)
        audit = AuditLog(audit_dir, on_error=self._auditFailed.emit)
        self._reach: float | None = None  # the robot model's reach bound (mm), read when first needed
        self.profile = SafetyProfile()
        fresh = not self.profile_path.exists()
        if fresh:
            self.profile = fresh_profile(self.robot_model())
        else:
            try:
                self.profile = load_profile(self.profile_path)
            except TeachPadError as exc:
                self._problem = str(exc)
        self.session = SafetySession(roles, audit, self.profile.envelope, on_role_changed=self._role_changed)
        # A fresh install's envelope is in force from here; its file and its audit record wait for
        # the window's first paint (install_safety; ~8 ms: a file synced, the audit's hashing) or
        # FRESH_SAVE_LATEST_MS, whichever comes first, and for nothing else that saves an envelope.
        self._fresh_unsaved = fresh
        if fresh:
            QTimer.singleShot(FRESH_SAVE_LATEST_MS, self, self.save_fresh_envelope)
        self._gated: list[tuple[QAction | QWidget, Action]] = []
        self._panels: list[tuple[EditGated, Action]] = []
        self._views: list[EnvelopeView] = []
        self._checkers: list[EnvelopeChecker] = []
        self.poll_period = 1.0 / timing.POLL_HZ_DEFAULT
        if link is not None:
            link.set_audit(audit)
            link.jogGuardStopped.connect(self._on_guard_stopped)
            link.connectionChanged.connect(self._on_connection)
        self._idle_timer = QTimer(self)
        self._idle_timer.setInterval(IDLE_POLL_MS)
        self._idle_timer.timeout.connect(self._poll_idle)
        self._idle_timer.start()
        # A window may come before the focus moves to it or just after: look at once and again
        # when the event loop is back (a zero timer, started at most once at a time).
        self._look_again = QTimer(self)
        self._look_again.setSingleShot(True)
        self._look_again.setInterval(0)
        self._look_again.timeout.connect(self._watch_windows)
        app = QGuiApplication.instance()
        self._app = app if isinstance(app, QGuiApplication) else None
        if self._app is not None:
            self._app.focusWindowChanged.connect(self._focus_moved)
            self._app.focusObjectChanged.connect(self._focus_moved)
        self._watch_windows()
        self._push_guard()

    @property
    def fresh_unsaved(self) -> bool:
        """A fresh install's envelope, in force, not saved yet (:meth:`save_fresh_envelope`)."""
        return self._fresh_unsaved

    @Slot()
    def save_fresh_envelope(self) -> None:
        """A fresh install's envelope (the robot model's defaults) saved and audited, once: it is
        the envelope in force, revision 1, read by every later start. Nothing when none waits."""
        if not self._fresh_unsaved:
            return
        self._fresh_unsaved = False
        try:
            self.profile_path.parent.mkdir(parents=True, exist_ok=True)
            self.profile = save_profile(self.profile_path, self.profile)
        except (OSError, TeachPadError) as exc:  # it applies all the same; say that it is not saved
            self._problem = f"the default safety envelope could not be saved in {self.profile_path}: {exc}"
            self.message.emit(self._problem)
            return
        self.session.audit.record(
            "action",
            "create the default envelope",
            args={"robot": self.profile.robot, "revision": self.profile.revision},
        )

    @Slot(str)
    def _on_audit_failed(self, text: str) -> None:
        self.message.emit(text)

    @property
    def problem(self) -> str:
        """A problem met while loading the role store or the profile ("" when none)."""
        return self._problem

    # --- roles --------------------------------------------------------------------------------
    @property
    def role(self) -> Role:
        return self.session.role

    def role_name(self, role: Role) -> str:
        return {
            Role.OPERATOR: self.tr("operator"),
            Role.ENGINEER: self.tr("engineer"),
            Role.ADMINISTRATOR: self.tr("administrator"),
        }[role]

    def reason(self, action: Action) -> str | None:
        """Why the role in force may not do ``action``, translated (None: it may)."""
        if self.session.reason(action) is None:
            return None
        return self.tr("Needs the {need} role (you are {role}); log in from the Safety menu").format(
            need=self.role_name(REQUIRED_ROLE[action]), role=self.role_name(self.role)
        )

    def allowed(self, action: Action, *, say: bool = True) -> bool:
        """``require`` for a control that was used: audited, with a translated message."""
        try:
            self.session.require(action)
        except PermissionRefused:
            if say:
                self.message.emit(self.reason(action) or "")
            return False
        return True

    def gate(self, target: QAction | QWidget, action: Action) -> None:
        """Enable ``target`` only for roles that may do ``action`` (tooltip says why not)."""
        self._gated.append((target, action))
        self._apply(target, action)

    def gate_panel(self, panel: EditGated, action: Action) -> None:
        """A panel with its own enable logic: ``panel.set_edit_permission(reason)``."""
        self._panels.append((panel, action))
        panel.set_edit_permission(self.reason(action))

    def _apply(self, target: QAction | QWidget, action: Action) -> None:
        why = self.reason(action)
        target.setEnabled(why is None)
        shown = target.property("safetyReason")
        if shown is None or target.toolTip() != shown:  # the tooltip is the control's own (retranslated)
            target.setProperty("safetyTip", target.toolTip())
        target.setProperty("safetyReason", why)
        target.setToolTip(why if why is not None else str(target.property("safetyTip") or ""))

    def refresh(self) -> None:
        for target, action in self._gated:
            self._apply(target, action)
        for panel, action in self._panels:
            panel.set_edit_permission(self.reason(action))

    def login(self, role: Role, password: str) -> None:
        """Raises :class:`~app.safety.roles.WrongPassword` (audited)."""
        self.session.login(role, password)

    def logout(self) -> None:
        self.session.logout()

    def _role_changed(self, _role: Role) -> None:
        self.refresh()
        self.roleChanged.emit(self.role)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        # Installed on windows only (see the module docstring): input, and a few window events.
        if event.type() in _TOUCH_EVENTS:
            self.session.touch()
        return False

    @Slot()
    def _focus_moved(self) -> None:
        self._watch_windows()
        self._look_again.start()

    @Slot()
    def _watch_windows(self) -> None:
        """Watch every window for operator input (the ones already watched are left as they are)."""
        for window in QGuiApplication.allWindows():
            window.installEventFilter(self)

    @Slot()
    def _poll_idle(self) -> None:
        self._watch_windows()
        self.session.poll_idle()

    def set_idle_polling(self, on: bool) -> None:
        if on:
            self._watch_windows()
            self._idle_timer.start()
        else:
            self._idle_timer.stop()

    def set_idle_timeout(self, seconds: float) -> None:
        self.session.idle.timeout = seconds

    # --- the robot model (ui.panels.view3d_robot.ModelGuard) ------------------------------------
    def robot_model_refusal(self, path: str) -> str | None:
        """None when the role may change the robot model; else why not (audited, said)."""
        try:
            self.session.require_robot_model(path)
        except PermissionRefused:
            why = self.reason(Action.ROBOT_MODEL) or ""
            self.message.emit(why)
            return why
        return None

    def robot_model_loaded(self, path: str, name: str) -> None:
        self.session.robot_model_loaded(path, name)

    # --- envelope and reduced speed ------------------------------------------------------------
    @property
    def envelope(self) -> Envelope:
        return self.session.envelope

    def attach_view(self, view: EnvelopeView) -> None:
        """A view that draws the envelope: given it now and whenever it changes."""
        self._views.append(view)
        view.set_envelope(self.envelope)

    def attach_checker(self, checker: EnvelopeChecker) -> None:
        """Checks that use the envelope and the speed caps: given both now and on every change
        of either (the envelope, reduced-speed mode)."""
        self._checkers.append(checker)
        checker.set_envelope(self.envelope, self.session.reduced)

    def save_envelope(self, envelope: Envelope) -> SafetyProfile:
        """Set (role checked, audited) and save the profile atomically with its next revision."""
        self.save_fresh_envelope()  # a fresh install's first (revision 1), when it still waits
        self.session.set_envelope(envelope)
        self.profile = save_profile(
            self.profile_path, SafetyProfile(self.profile.robot, envelope, self.profile.revision)
        )
        self._envelope_changed()
        return self.profile

    def set_reduced(self, on: bool) -> bool:
        """Reduced-speed mode on (anyone) or off (engineer); False (and a message) when refused."""
        try:
            self.session.set_reduced(on)
        except PermissionRefused:
            self.message.emit(self.reason(Action.LEAVE_REDUCED_SPEED) or "")
            return False
        self._envelope_changed()
        self.reducedChanged.emit(self.session.reduced)
        return True

    def _envelope_changed(self) -> None:
        for view in self._views:
            view.set_envelope(self.envelope)
        for checker in self._checkers:
            checker.set_envelope(self.envelope, self.session.reduced)
        self._push_guard()
        self.envelopeChanged.emit(self.envelope)
        self.capsChanged.emit(self.caps)

    def set_poll_rate(self, hz: float) -> None:
        if hz > 0:
            self.poll_period = 1.0 / hz
            self._push_guard()

    def _push_guard(self) -> None:
        if self.link is not None:
            self.link.set_jog_guard(self.session.jog_guard(self.poll_period))
            self.link.set_motion_caps(self.caps)

    def jog_ratio(self, ratio: float) -> float:
        return self.session.jog_ratio(ratio)

    @staticmethod
    def robot_model() -> RobotProfile:
        """The robot model the defaults and the joint steps' cap come from: the default one."""
        from app.view3d.profile import default_profile  # a JSON file: read when first needed

        return default_profile()

    @property
    def caps(self) -> MotionCaps | None:
        """Reduced-speed mode's caps (None while it is off)."""
        if not self.session.reduced:
            return None
        if self._reach is None:
            self._reach = self.robot_model().reach
        return self.envelope.motion_caps(self._reach)

    def jog_ratio_cap(self) -> float:
        """The jog ratio the envelope allows in the mode in force (%)."""
        return self.envelope.jog_ratio_cap(self.session.reduced)

    # --- checks before sending ------------------------------------------------------------------
    def refusal(self, exc: TeachPadError) -> str:
        """A refusal in the operator's language."""
        if isinstance(exc, EnvelopeRefused):
            return self.violation_text(exc.violation)
        if isinstance(exc, PermissionRefused):
            return self.reason(exc.action) or str(exc)
        return str(exc)

    def check_step(
        self, pose: Pose, offsets: list[float], *, joint: bool, speed: float | None = None
    ) -> str | None:
        """None when the step may go; else the translated reason (the refusal is audited)."""
        try:
            self.session.check_step(pose, offsets, joint=joint, speed=speed)
        except (EnvelopeRefused, PermissionRefused) as exc:
            return self._motion_refused(exc)
        self.motionAccepted.emit()
        return None

    def check_jog(self, pose: Pose | None, request: JogRequest) -> str | None:
        """Before a jog press (``request``'s ratio already capped): None, or why it would stop at
        once (audited). The worker's guard decides again on every poll."""
        if pose is None:
            self.motionAccepted.emit()
            return None
        motion = JogMotion(request.frame, request.axis, request.direction, request.ratio)
        try:
            self.session.check_jog_start(pose, motion, self.poll_period)
        except (EnvelopeRefused, PermissionRefused) as exc:
            return self._motion_refused(exc)
        self.motionAccepted.emit()
        return None

    def check_move(self, start: PointLike, segment: Segment, ledger: PointLedger) -> str | None:
        try:
            self.session.check_move(start, segment, ledger)
        except EnvelopeRefused as exc:
            return self.refusal(exc)
        return None

    def check_move_to(
        self, pose: Pose | None, point_id: int, speed: float, ledger: PointLedger
    ) -> str | None:
        """Move to a point in a straight line (function 3) from ``pose`` (None: not known, the
        target and the speed are checked)."""
        start = pose if pose is not None else ledger.get(point_id)
        if start is None:
            return None  # an unknown point: the move refuses it itself
        try:
            self.session.check_move(start, Segment.line(point_id, speed), ledger)
        except EnvelopeRefused as exc:
            return self._motion_refused(exc)
        except TeachPadError as exc:
            text = str(exc)
            self.motionRefused.emit(lambda: text)
            return text
        self.motionAccepted.emit()
        return None

    def _motion_refused(self, exc: EnvelopeRefused | PermissionRefused) -> str:
        """A motion refused before it went out: told to the motion area (worded again on a language
        change), its words in the language in force returned."""
        self.motionRefused.emit(lambda: self.refusal(exc))
        return self.refusal(exc)

    def violation_text(self, v: EnvelopeViolation) -> str:
        """:class:`EnvelopeViolation` in the operator's language."""
        if v.approaching:
            if v.box:
                text = self.tr(
                    "{axis} = {value:.1f} is within stopping distance of the keep-out zone "
                    "'{box}' (at {limit:.1f})"
                )
            else:
                text = self.tr("{axis} = {value:.1f} is within stopping distance of the limit at {limit:.1f}")
        elif v.code is ViolationCode.KEEP_IN:
            text = self.tr("{axis} = {value:.1f} mm is outside the allowed work space (limit {limit:.1f} mm)")
        elif v.code is ViolationCode.KEEP_OUT:
            text = self.tr(
                "The path enters the keep-out zone '{box}' ({axis} = {value:.1f} mm, "
                "its face at {limit:.1f} mm)"
            )
        elif v.code is ViolationCode.JOINT_LIMIT:
            text = self.tr("{axis} = {value:.1f}° is beyond its limit {limit:.1f}°")
        elif v.code is ViolationCode.SPEED:
            text = (
                self.tr("Speed {value:g} mm/s is above the {limit:g} mm/s allowed in reduced-speed mode")
                if v.reduced
                else self.tr("Speed {value:g} mm/s is above the {limit:g} mm/s allowed")
            )
        else:
            text = (
                self.tr("Jog speed {value:g} % is above the {limit:g} % allowed in reduced-speed mode")
                if v.reduced
                else self.tr("Jog speed {value:g} % is above the {limit:g} % allowed")
            )
        text = text.format(axis=v.axis, value=v.value, limit=v.limit, box=v.box)
        if v.segment is None:
            return text
        return self.tr("Segment {k}: {text}").format(k=v.segment + 1, text=text)

    @Slot(object)
    def _on_guard_stopped(self, violation: EnvelopeViolation) -> None:
        self.motionRefused.emit(lambda: self.guard_stop_text(violation))
        self.message.emit(self.guard_stop_text(violation))

    def guard_stop_text(self, violation: EnvelopeViolation) -> str:
        """The jog guard's stop before a boundary, in the operator's language."""
        why = self.violation_text(violation)
        return self.tr("Jog stopped before the limit: {why}").format(why=why)

    @Slot(ConnectionState)
    def _on_connection(self, _state: ConnectionState) -> None:
        settings = self.link.settings if self.link is not None else None
        if settings is not None:  # the audit describes float writes in the link's word order
            self.session.audit.word_order = settings.word_order

    def close(self) -> None:
        self._idle_timer.stop()
        self._look_again.stop()
        if self._app is not None:
            self._app.focusWindowChanged.disconnect(self._focus_moved)
            self._app.focusObjectChanged.disconnect(self._focus_moved)
            self._app = None
        for window in QGuiApplication.allWindows():
            window.removeEventFilter(self)
        self.session.audit.close()
