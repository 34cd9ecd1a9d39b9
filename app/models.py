"""Payload dataclasses shared by the client, the worker and the GUI."""

from __future__ import annotations

from dataclasses import dataclass, field

from app.errors import Reason
from app.protocol.datetime_regs import ControllerClock
from app.protocol.enums import (
    Alarm,
    CommandKind,
    CommandStatus,
    ControllerMode,
    ProgramState,
    RunCommand,
)


@dataclass(frozen=True)
class Pose:
    """Live position: XYZABC in the base frame (mm, degrees), external axes, joints."""

    x: float
    y: float
    z: float
    a: float
    b: float
    c: float
    ext: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)
    joints: tuple[float, ...] | None = None  # J1..J6 (project extension GV250..255)

    @property
    def xyzabc(self) -> tuple[float, float, float, float, float, float]:
        return (self.x, self.y, self.z, self.a, self.b, self.c)


@dataclass(frozen=True)
class ControllerStatus:
    """Table 2 decoded. ``mode``/``program_state`` keep raw ints when the value is unknown."""

    mode: ControllerMode | int
    program_state: ProgramState | int
    alarms: Alarm
    command_status_code: int  # GV291 as decoded from either encoding
    clock: ControllerClock | None = None


#: The reason codes of a failure that leaves the link's state unknown: the link is gone or could
#: not be made (:class:`~app.errors.LinkError` and its codes), a request got no answer in time
#: (:class:`~app.errors.ResponseTimeout`), or an answer did not match its request
#: (:class:`~app.errors.MalformedResponse`: the byte stream may be out of step -- the next answer
#: read may be this one's tail or a late answer to an earlier request -- so only a fresh connection
#: can be trusted). Every other code is the controller's answer (a Modbus exception, a refused or
#: failed command, a command timeout whose status reads were answered, a stop, an alarm) or the
#: host's own refusal before the wire: the link is fine.
LINK_FAILURE_CODES = frozenset(
    {
        "link_lost",
        "link_closed",
        "not_connected",
        "connect_failed",
        "connect_timeout",
        "connection_refused",
        "host_unresolved",
        "host_invalid",
        "serial_open_failed",
        "no_answer",
        "malformed_answer",
        "stop_unreachable",  # a Stop's fresh connection to the controller failed too
    }
)


@dataclass(frozen=True)
class CommandResult:
    """How a command sent by the host ended."""

    command: RunCommand | None
    kind: CommandKind | None
    status: CommandStatus | None
    ok: bool
    message: str = ""
    details: dict[str, float] = field(default_factory=dict)
    request_id: int | None = None  # the id RobotLink returned for the request (None: not from one)
    # ok, but not proven: the controller's status never changed (GV291 kept the 0xFF it had
    # before the command and the host cannot write a sentinel). Only for the idempotent instant
    # commands (create point, teach enable/disable), never for moves; see app/link/tracker.py.
    unconfirmed: bool = False
    # why it ended, as a code and arguments beside the English ``message`` (see app/errors.py;
    # ui/messages.py renders it). None: an older producer; the GUI falls back to ``message``.
    reason: Reason | None = None

    @property
    def link_failed(self) -> bool:
        """The link failed during it (its outcome is unknown, the connection is not to be trusted):
        a reason in :data:`LINK_FAILURE_CODES`. False for a success and for any refusal, the
        controller's own answer (a Modbus exception included). A failure without a reason (an
        older producer) counts as a link failure only when it carries no controller status.
        """
        if self.ok:
            return False
        if self.reason is None:
            return self.status is None
        return self.reason.code in LINK_FAILURE_CODES

    @property
    def stopped_by_operator(self) -> bool:
        """The operator's own stop ended it: not a failure (ok is False, shown neutral)."""
        return self.reason is not None and self.reason.code == "stopped_by_operator"
