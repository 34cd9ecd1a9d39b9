"""The link's public data types: what the GUI and the worker say to each other."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from app.errors import Reason, TeachPadError
from app.protocol.enums import RunCommand, TeachFrame

__all__ = [
    "ConnectionState",
    "ControllerIdentity",
    "HaltKind",
    "JogRequest",
    "LinkState",
    "Operation",
    "StepFrame",
    "UnconfirmedHalt",
    "WorkerError",
]


class StepFrame(enum.Enum):
    """Frame of an incremental move (function 1)."""

    JOINT = "joint"
    BASE = "base"

    @property
    def command(self) -> RunCommand:
        return RunCommand.STEP_JOINT if self is StepFrame.JOINT else RunCommand.STEP_BASE


class Operation:
    """The operation names in ``WorkerError.operation`` and ``CommandResult.operation``."""

    STOP = "stop"
    PAUSE = "pause"
    RESUME = "resume"
    JOG = "jog"
    JOG_RELEASE = "jog release"
    JOG_SPEED = "jog speed"
    STEP = "step"
    SET_MODE = "set mode"
    GO_ZERO = "go to zero"
    RUN_PROGRAM = "run program"
    CREATE_POINT = "create point"
    MOVE_TO_POINT = "move to point"
    UPLOAD_POINTS = "upload points"
    CANCEL_UPLOAD = "cancel upload"
    TEACH_DISABLE = "teach disable"
    POLL = "poll"
    CONNECT = "connect"
    DISCONNECT = "disconnect"
    SHUTDOWN = "shutdown"
    CANARY = "restart check"
    READ_REGISTERS = "read registers"


class LinkState(enum.Enum):
    CONNECTING = "connecting"
    CONNECTED = "connected"
    NOT_ANSWERING = "not answering"  # the link is up but the controller is silent (poll timed out)
    DOWN = "down"  # lost or unreachable; the worker is retrying by itself
    DISCONNECTED = "disconnected"  # by request (or never connected)


@dataclass(frozen=True)
class ControllerIdentity:
    """Which controller, and which boot of it, a connection talks to; decided at every connect
    (start-up, *Connect…*, a reconnect after a loss, a changed register profile) and again when
    the restart canary changes under a live link (:mod:`app.link.supervisor`).

    * ``endpoint`` (``host:port`` or the serial device) and ``unit`` (the Modbus unit id): where
      the controller answers.
    * ``word_order``: how its floats are written; a point written in another word order is
      another point.
    * ``canary_gv`` and ``boot``: the random token this TeachPad wrote into the restart canary (a
      spare GV, GV99 by default) of this boot of the controller; None when there is none
      (monitor-only mode, the canary switched off, its write refused). A controller clears its
      temp points *and* GV0..GV99 when its system logs in again, so a canary that still reads
      our token on a reconnect proves the same boot: its temp points are the ones we left.

    Two connections reach the same controller boot (:meth:`same_boot`) only when every field
    agrees and the token is known; anything else (another endpoint or unit, a restart, a token
    we never saw -- another master may have written it after a restart while we were away --,
    no canary at all) is "another controller" and every point's sync state becomes unknown.
    Deliberately not part of it: the controller's clock (it changes every second and any master
    may set it), GV291 and the parameter GVs (every master writes them); the protocol has no
    serial number or model register to read. So nothing here changes in another master's normal
    work: under a live link the canary reads a restart only as 0 (a restart clears GV0..GV99);
    another TeachPad's token is another master, not a restart, and keeps this identity
    (``LinkSupervisor.canary_read`` in :mod:`app.link.supervisor`).
    """

    endpoint: str
    unit: int
    word_order: str
    canary_gv: int | None
    boot: float | None

    def same_boot(self, other: ControllerIdentity | None) -> bool:
        """True when ``other`` is provably this controller in this boot (see the class)."""
        return other is not None and self.boot is not None and self == other

    def same_place(self, other: ControllerIdentity | None) -> bool:
        """True when ``other`` answers at the same endpoint and unit (maybe in another boot)."""
        return other is not None and (self.endpoint, self.unit) == (other.endpoint, other.unit)


@dataclass(frozen=True)
class ConnectionState:
    """Link state for the GUI: ``message`` says why in plain English (logs, CLI); ``reason`` is
    the same as a code and its arguments, which the GUI turns into the operator's language
    (None: nothing to say, as when connected or disconnected by request)."""

    state: LinkState
    message: str = ""
    endpoint: str = ""
    monitor_only: bool = False
    reason: Reason | None = None
    #: the controller (and boot) this link reaches while it is up; None when it is not
    controller: ControllerIdentity | None = None

    @property
    def connected(self) -> bool:
        return self.state is LinkState.CONNECTED


@dataclass(frozen=True)
class WorkerError:
    """Something that went wrong, for the operator: which operation and why."""

    operation: str
    message: str  # plain English (logs, CLI)
    request_id: int | None = None  # the request it belongs to (None: polls, the link itself)
    reason: Reason | None = None  # code + arguments the GUI translates (None: only ``message``)

    @classmethod
    def from_exception(cls, operation: str, exc: BaseException, request_id: int | None = None) -> WorkerError:
        """The error for ``exc``: its English text and, for a typed error, its reason."""
        if isinstance(exc, TeachPadError):
            return cls(operation, str(exc), request_id, exc.as_reason())
        return cls(
            operation,
            f"{type(exc).__name__}: {str(exc)[:200]}",
            request_id,
            Reason("unexpected", {"type": type(exc).__name__}),
        )


@dataclass(frozen=True)
class JogRequest:
    """A held jog button: frame, axis (0-5 X..C, joint frame 0-10 J1..J11), direction, ratio %."""

    frame: TeachFrame
    axis: int
    direction: int  # 0 negative, 1 positive
    ratio: float  # 0 < ratio <= 100
    user: int = 0  # user frame id (frame USER)
    tool: int = 0  # tool frame id (frame TOOL)

    @property
    def frame_key(self) -> tuple[TeachFrame, int, int]:
        return (
            self.frame,
            self.user if self.frame is TeachFrame.USER else 0,
            self.tool if self.frame is TeachFrame.TOOL else 0,
        )


class HaltKind(enum.Enum):
    """What is being stopped (app/link/halt.py)."""

    RELEASE = "release"  # a jog the operator let go of: speed 0
    STOP = "stop"  # the operator's Stop (441)
    PAUSE = "pause"  # the operator's Pause (442), refused or unanswered: sent again until answered


@dataclass(frozen=True)
class UnconfirmedHalt:
    """A write that stops motion the controller has not confirmed yet (refused, unanswered, or
    answered while the arm kept moving): the worker sends it again at every poll. ``since``:
    ``time.monotonic()`` of the release / Stop; ``escalated``: a Stop (441) goes out too."""

    kind: HaltKind
    since: float
    escalated: bool
