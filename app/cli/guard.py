"""teachpad-cli's guard rails: the GUI's safety envelope and roles bind the CLI too.

:class:`CliSafety` is :class:`app.safety.session.SafetySession` (the GUI's core) loaded for one
command: the role store, the envelope in force and the audit trail, from the places the GUI keeps
them (the loaders of :mod:`app.safety`); the checks are the session's, not a second copy:

* **the envelope** (:func:`envelope_in_force`): ``--safety FILE`` where a command has it (``run``),
  else the GUI's envelope file, else a fresh install's (the robot model's joint limits and a
  keep-in box from its reach, as the GUI starts with). ``step`` and ``move`` are checked before
  anything is sent (:meth:`SafetySession.check_step`, :meth:`SafetySession.check_move`); a jog's
  ratio is capped (:meth:`SafetySession.jog_ratio`), refused when it would have to stop at once
  (:meth:`SafetySession.check_jog_start`) and watched on every poll by the GUI's jog guard
  (:class:`app.safety.jog_guard.JogGuard`); ``run`` checks its plan against it;
  ``--reduced-speed`` takes its caps from it. A refusal is one sentence, audited, exit 1.
* **the role** (:meth:`CliSafety.log_in`): once the administrator has a password, every command
  that writes (to the controller, to a project or a bundle: :data:`COMMAND_ACTIONS`) acts as a
  role: ``--role NAME`` (or ``TEACHPAD_ROLE``; default operator) with its password asked for on
  a terminal (getpass) or taken from ``TEACHPAD_PASSWORD`` (scripts); the GUI's permission table
  (:data:`app.safety.roles.REQUIRED_ROLE`) says what the role may do. Without an administrator
  password the CLI acts as administrator, as it always did (in the GUI, too, anyone becomes
  administrator then). Audit records carry the role (``engineer (cli)``).
"""

from __future__ import annotations

import argparse
import getpass
import os
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TextIO

from app.errors import TeachPadError
from app.models import Pose
from app.plan.segments import Segment
from app.points.ledger import PointLedger
from app.safety.audit import AuditLog
from app.safety.audit_read import Result
from app.safety.envelope import Envelope, EnvelopeRefused, EnvelopeViolation, check_speed
from app.safety.jog_guard import JogMotion
from app.safety.location import ENVELOPE_NAME
from app.safety.profile import fresh_profile, load_profile
from app.safety.roles import Action, Role, RoleStore, WrongPassword, default_config_dir, default_store_path
from app.safety.session import SafetySession

__all__ = [
    "COMMAND_ACTIONS",
    "ENVELOPE_FILE",
    "PASSWORD_ENV",
    "ROLES_TEXT",
    "ROLE_ENV",
    "CliSafety",
    "command_path",
    "envelope_in_force",
]

ROLE_ENV = "TEACHPAD_ROLE"
PASSWORD_ENV = "TEACHPAD_PASSWORD"
#: The GUI's envelope file, in the safety state's folder (:mod:`app.safety.location`)
ENVELOPE_FILE = ENVELOPE_NAME

#: What each command that writes does, in the GUI's permission table's words; a command not
#: listed only reads (status, watch, read, audit, points list / export, roles: its own check).
COMMAND_ACTIONS: dict[str, Action] = {
    "mode": Action.RUN_PROGRAM,
    "step": Action.STEP,
    "jog": Action.JOG,
    "point create": Action.TEACH,
    "move": Action.STEP,
    "zero": Action.RUN_PROGRAM,
    "program run": Action.RUN_PROGRAM,
    "stop": Action.STOP,
    "pause": Action.STOP,
    "resume": Action.STOP,
    "write": Action.WRITE_REGISTERS,
    "points upload": Action.TEACH,
    "points import": Action.EDIT_POINTS,
    "run": Action.RUN_PLAN,
    "support-bundle": Action.SUPPORT_BUNDLE,
}

ROLES_TEXT = (
    "Safety: every command obeys the safety envelope the GUI obeys (its file, else a fresh "
    "install's: the robot model's joint limits and reach). Roles: once the administrator has a "
    f"password, a command that writes acts as --role NAME (or {ROLE_ENV}; default operator), "
    f"with its password asked for in a terminal or taken from {PASSWORD_ENV} (scripts); what the "
    "role may not do is refused. Without an administrator password the CLI acts as administrator."
)


def command_path(args: argparse.Namespace) -> str:
    """The command as :data:`COMMAND_ACTIONS` names it: ``"point create"``, ``"step"``..."""
    sub = getattr(args, f"{args.command}_command", None)
    return f"{args.command} {sub}" if isinstance(sub, str) else str(args.command)


def envelope_in_force(safety_file: str | os.PathLike[str] | None = None) -> Envelope:
    """``safety_file``'s envelope, else the GUI's file, else a fresh install's
    (:func:`app.safety.profile.fresh_profile`, not written here). A file that cannot be used
    raises its :class:`~app.safety.profile.ProfileError` naming it (nothing is sent)."""
    path = Path(safety_file) if safety_file else default_config_dir() / ENVELOPE_FILE
    if safety_file or path.exists():
        return load_profile(path).envelope
    from app.view3d.profile import default_profile  # a JSON file: read only for a fresh install

    return fresh_profile(default_profile()).envelope


@dataclass
class CliSafety:
    """The GUI's :class:`SafetySession` for one command (see the module docstring)."""

    session: SafetySession
    #: asks for a password on a terminal (None: not a terminal)
    ask: Callable[[str], str] | None = None
    environ: Mapping[str, str] = field(default_factory=lambda: os.environ)

    @classmethod
    def load(
        cls,
        args: argparse.Namespace,
        audit: AuditLog,
        *,
        stdin: TextIO | None = None,
        environ: Mapping[str, str] | None = None,
    ) -> CliSafety:
        """The role store and the envelope in force (:class:`TeachPadError` for a file that
        cannot be used), reduced-speed mode as ``--reduced-speed`` says; until :meth:`log_in`
        acting as operator where roles apply, else as administrator."""
        store = RoleStore(default_store_path())
        session = SafetySession(store, audit, envelope_in_force(getattr(args, "safety", None)))
        session.reduced = bool(getattr(args, "reduced_speed", False))
        # until log_in: operator where roles apply, else administrator (as the CLI always was)
        start = Role.OPERATOR if store.has_password(Role.ADMINISTRATOR) else Role.ADMINISTRATOR
        session.idle.login(start)
        audit.set_role(lambda: _cli_role(session.role))  # the role in force, as in the GUI
        tty = (stdin or sys.stdin).isatty()
        return cls(session, getpass.getpass if tty else None, os.environ if environ is None else environ)

    @property
    def envelope(self) -> Envelope:
        return self.session.envelope

    @property
    def role(self) -> Role:
        return self.session.role

    @property
    def enforced(self) -> bool:
        """Roles apply: the administrator has a password."""
        return self.session.store.has_password(Role.ADMINISTRATOR)

    def log_in(self, args: argparse.Namespace) -> None:
        """Act as the role the command line or the environment names (see the module docstring)
        and require the command's permission; :class:`WrongPassword` / ``PermissionRefused``
        (audited) when not."""
        action = COMMAND_ACTIONS.get(command_path(args))
        if action is None:
            return  # a command that only reads
        name = getattr(args, "role", None) or self.environ.get(ROLE_ENV)
        if not self.enforced:
            role = Role.ADMINISTRATOR if name is None else Role.parse(name)
            self.session.idle.login(role)
        else:
            role = Role.parse(name or Role.OPERATOR.text)
            if role is Role.OPERATOR:
                self.session.idle.logout()  # the operator needs no password
            else:
                self.session.login(role, self._password(role))
        self.session.require(action, {"command": command_path(args)})

    def _password(self, role: Role) -> str:
        given = self.environ.get(PASSWORD_ENV)
        if given is not None:
            return given
        if self.ask is not None:
            return self.ask(f"{role.text} password: ")
        why = f"the {role.text} role needs its password: run it in a terminal, or set {PASSWORD_ENV}"
        self.session.audit.record_refused(f"log in as {role.text}", why)
        raise WrongPassword(why)

    # --- the envelope's checks, as the GUI makes them -------------------------------------
    def check_step(self, pose: Pose, offsets: list[float], *, joint: bool, speed: float) -> None:
        self.session.check_step(pose, offsets, joint=joint, speed=speed)

    def check_move(self, pose: Pose, segment: Segment, ledger: PointLedger | None) -> None:
        """A move to a temp point from ``pose``: its path when the host has the points (a
        project), else its speed; a point the host has no copy of cannot be checked against
        Cartesian limits, so with a keep-in box or keep-out zones it is refused."""
        if ledger is not None:
            self.session.check_move(pose, segment, ledger)
            return
        env = self.envelope
        too_fast = check_speed(env, segment.speed)
        if too_fast is not None:
            self.session.audit.record_refused("move to point", too_fast.message, {"speed": segment.speed})
            raise EnvelopeRefused(too_fast, "move to point")
        if env.keep_in is not None or env.keep_out:
            why = (
                f"P{segment.end_id} cannot be checked against the safety envelope: the host has no "
                "copy of it (give the project holding the point with --project)"
            )
            self.session.audit.record_refused("move to point", why, {"end": segment.end_id})
            raise EnvelopeUnchecked(f"move to point refused: {why}")

    def jog_ratio(self, ratio: float) -> float:
        return self.session.jog_ratio(ratio)

    def check_jog_start(self, pose: Pose, motion: JogMotion, poll_period: float) -> None:
        self.session.check_jog_start(pose, motion, poll_period)

    def guard_stopped(self, violation: EnvelopeViolation, motion: JogMotion) -> TeachPadError:
        """The jog guard stopped a jog (audited); the error the command ends with (exit 1)."""
        text = f"jog stopped before the limit: {violation.message}"
        self.session.audit.record(
            "action",
            "jog stopped before the limit",
            result=Result.STOPPED,
            args={"axis": motion.axis, "direction": motion.direction, "ratio": motion.ratio},
            detail=violation.message,
        )
        return TeachPadError(text, code="jog_guard_stopped")


class EnvelopeUnchecked(TeachPadError):
    """A motion the host cannot check against the envelope: refused before the wire."""

    code = "envelope_unchecked"


def _cli_role(role: Role) -> str:
    return f"{role.text} (cli)"
