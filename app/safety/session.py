"""One object for the GUI: the role in force, the envelope, reduced-speed mode and the audit.

:class:`SafetySession` ties :class:`~app.safety.roles.RoleStore`,
:class:`~app.safety.roles.IdleLock`, the profile's :class:`~app.safety.envelope.Envelope` and
:class:`~app.safety.audit.AuditLog` together so that the GUI's wiring stays thin:

* ``reason(action)`` for a control's enabled state and tooltip (no audit; called on every
  repaint); ``require(action)`` when the user actually does it (refusals are audited);
* ``login`` / ``logout`` / ``touch`` / ``poll_idle`` (audited: logins, wrong passwords, the
  lock-back);
* ``check_step`` / ``check_move`` / ``check_jog_start`` before sending (refusals are audited and
  raised as :class:`~app.safety.envelope.EnvelopeRefused`), ``jog_guard(poll_period)`` for the
  worker, ``set_reduced`` (on: anyone; off: engineer);
* ``set_register_profile`` (administrator; saved atomically, audited with what changed),
  ``set_password`` / ``clear_password`` / ``set_idle_timeout`` (administrator, audited; never a
  password in the audit);
* ``audit.record_write`` is the client's hook, and the audit's role follows the session.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

from app.errors import InvalidInput, TeachPadError
from app.models import Pose
from app.plan.geometry import PointLike
from app.plan.segments import Segment
from app.points.ledger import PointLedger
from app.safety.audit import AuditLog
from app.safety.audit_read import Result
from app.safety.envelope import (
    Envelope,
    EnvelopeRefused,
    EnvelopeViolation,
    check_segment,
    check_step,
)
from app.safety.jog_guard import JOG_GUARD_LATENCY, ArmSpeeds, JogGuard, JogMotion
from app.safety.register_profile import RegisterProfile, save_register_profile
from app.safety.roles import (
    REQUIRED_ROLE,
    Action,
    IdleLock,
    Role,
    RoleStore,
    WrongPassword,
    permission_reason,
)


class PermissionRefused(TeachPadError):
    """The role in force may not do this; the message says which role may."""

    def __init__(self, role: Role, action: Action) -> None:
        super().__init__(permission_reason(role, action) or action.value)
        self.role = role
        self.action = action


class SafetySession:
    def __init__(
        self,
        store: RoleStore,
        audit: AuditLog,
        envelope: Envelope | None = None,
        *,
        idle_lock: IdleLock | None = None,
        speeds: ArmSpeeds | None = None,
        on_role_changed: Callable[[Role], None] | None = None,
    ) -> None:
        self.store = store
        self.audit = audit
        self.envelope = envelope or Envelope()
        self.speeds = speeds or ArmSpeeds()
        self.reduced = False
        self._on_role_changed = on_role_changed
        self.idle = idle_lock or IdleLock(store.idle_timeout)
        self.idle.on_lock = self._locked  # the session owns the lock-back notification
        audit.set_role(lambda: self.role.text)

    # --- roles ------------------------------------------------------------------------------
    @property
    def role(self) -> Role:
        return self.idle.role

    def reason(self, action: Action) -> str | None:
        """Why the role in force may not do ``action`` (None: it may). For tooltips."""
        return permission_reason(self.role, action)

    def require(self, action: Action, args: dict[str, Any] | None = None) -> None:
        """Raise :class:`PermissionRefused` (audited) unless the role may do ``action``."""
        why = self.reason(action)
        if why is not None:
            # the reason's code and arguments beside the English, for the viewer's words
            words = {"need": REQUIRED_ROLE[action].text, "role": self.role.text}
            self.audit.record_refused(
                action.value, why, {**(args or {}), "reason": "role_refused", "reason_args": words}
            )
            raise PermissionRefused(self.role, action)

    def login(self, role: Role, password: str) -> Role:
        try:
            self.store.login(role, password)
        except WrongPassword as exc:
            self.audit.record("login", f"log in as {role.text}", result=Result.REFUSED, detail=str(exc))
            raise
        self.idle.login(role)
        self.audit.record("login", f"log in as {role.text}")
        self._changed()
        return role

    def logout(self) -> None:
        if self.role is not Role.OPERATOR:
            self.audit.record("login", f"log out ({self.role.text})")
            self.idle.logout()
            self._changed()

    def touch(self) -> None:
        self.idle.touch()

    def poll_idle(self) -> Role:
        return self.idle.poll()

    def _locked(self, previous: Role) -> None:
        self.audit.record(
            "login", f"locked back to operator after {self.idle.timeout:g} s idle", role=previous.text
        )
        self._changed()

    def _changed(self) -> None:
        if self._on_role_changed is not None:
            self._on_role_changed(self.role)

    # --- administration ---------------------------------------------------------------------
    def set_register_profile(
        self, path: str | os.PathLike[str], profile: RegisterProfile, current: RegisterProfile | None = None
    ) -> RegisterProfile:
        """Save ``profile`` as the one in force (administrator only, audited with the fields that
        changed from ``current``); returns it as saved (its next revision)."""
        changes = current.changes(profile) if current is not None else profile.protocol_dict()
        self.require(Action.REGISTER_PROFILE, {"name": profile.name, "changes": changes})
        saved = save_register_profile(path, profile)
        self.audit.record(
            "action",
            "change register profile",
            args={"name": saved.name, "revision": saved.revision, "changes": changes},
        )
        return saved

    def set_password(self, role: Role, password: str) -> None:
        """Set or change ``role``'s password (administrator; the first one: anyone, while no
        administrator password exists). Audited without the password."""
        if self.store.has_password(Role.ADMINISTRATOR):
            self.require(Action.MANAGE_ROLES, {"role": role.text})
        changed = self.store.has_password(role)
        self.store.set_password(role, password, by=self.role)
        self.audit.record("action", f"{'change' if changed else 'set'} the {role.text} password")

    def clear_password(self, role: Role) -> None:
        """Remove ``role``'s password (administrator). The administrator's own cannot be cleared:
        without it anyone could set a new one and become administrator."""
        self.require(Action.MANAGE_ROLES, {"role": role.text})
        if role is Role.ADMINISTRATOR:
            why = "the administrator password can be changed, not removed (anyone could then set it)"
            self.audit.record_refused("clear the administrator password", why)
            raise InvalidInput(why)
        self.store.clear_password(role, by=self.role)
        self.audit.record("action", f"clear the {role.text} password")

    def set_idle_timeout(self, seconds: float) -> None:
        """The idle time before the lock-back to operator (administrator; saved, audited)."""
        self.require(Action.MANAGE_ROLES, {"idle_timeout": seconds})
        if not seconds > 0:
            raise InvalidInput("the idle time must be > 0 s")
        self.store.idle_timeout = float(seconds)
        self.idle.timeout = float(seconds)
        self.store.save()
        self.audit.record("action", "set the idle lock time", args={"seconds": float(seconds)})

    # --- the robot model ---------------------------------------------------------------------
    def require_robot_model(self, file: str) -> None:
        """Raise :class:`PermissionRefused` (audited with the file) unless the role may change
        the robot model (an engineer's: it feeds the reach checks that block or allow a run)."""
        self.require(Action.ROBOT_MODEL, {"file": file} if file else None)

    def robot_model_loaded(self, file: str, name: str) -> None:
        """Audit the robot model now in use: its file and its name."""
        self.audit.record("action", "change robot model", args={"file": file, "name": name})

    # --- envelope ---------------------------------------------------------------------------
    def set_envelope(self, envelope: Envelope) -> None:
        self.require(Action.EDIT_ENVELOPE)
        self.envelope = envelope
        self.audit.record("action", "edit envelope")

    def set_reduced(self, on: bool) -> None:
        if on == self.reduced:
            return
        self.require(Action.REDUCED_SPEED if on else Action.LEAVE_REDUCED_SPEED)
        self.reduced = on
        self.audit.record("action", "reduced speed on" if on else "reduced speed off")

    def _refuse(self, action: str, violation: EnvelopeViolation | None, args: dict[str, Any]) -> None:
        if violation is not None:
            refused = EnvelopeRefused(violation, action)
            plain = {
                k: v
                for k, v in refused.params.items()
                if v is None or isinstance(v, str | int | float | bool)
            }
            self.audit.record_refused(
                action, violation.message, {**args, "reason": refused.code, "reason_args": plain}
            )
            raise refused

    def check_step(
        self, pose: Pose, offsets: list[float], *, joint: bool, speed: float | None = None
    ) -> None:
        """Before a step (function 1): refused (audited) when it would leave the envelope."""
        self.require(Action.STEP)
        violation = check_step(self.envelope, pose, offsets, joint=joint, speed=None if joint else speed)
        self._refuse("step", violation, {"offsets": list(offsets), "joint": joint})

    def check_move(self, start: PointLike, segment: Segment, ledger: PointLedger) -> None:
        """Before a move to a point (function 3) from ``start``."""
        violation = check_segment(self.envelope, start, segment, ledger)
        self._refuse(
            "move to point", violation, {"end": segment.end_id, "via": segment.via_id, "speed": segment.speed}
        )

    def jog_guard(self, poll_period: float, latency: float = JOG_GUARD_LATENCY) -> JogGuard:
        return JogGuard(
            self.envelope, poll_period=poll_period, latency=latency, speeds=self.speeds, reduced=self.reduced
        )

    def jog_ratio(self, ratio: float) -> float:
        """The ratio to send for a requested one (capped by the envelope and reduced mode)."""
        return self.envelope.cap_jog_ratio(ratio, self.reduced)

    def check_jog_start(self, pose: Pose, motion: JogMotion, poll_period: float) -> None:
        """Before a jog starts: refused (audited) when it would already have to stop."""
        self.require(Action.JOG)
        decision = self.jog_guard(poll_period).decide(pose, motion)
        if not decision.allow:
            args = {
                "frame": motion.frame.name.lower(),
                "axis": motion.axis,
                "direction": motion.direction,
                "ratio": motion.ratio,
            }
            self._refuse("jog", decision.violation, args)
