"""What the worker's parts see of the worker: the Protocol between :class:`RobotWorker` and them.

The parts (supervisor, poller, jog, upload, motion tracker, capture) live on the worker thread
and never talk to Qt: they call the worker back through this interface, which turns their
outputs into signals and runs the urgent jobs between two transactions.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

from app.errors import Reason, TeachPadError
from app.link.types import ConnectionState, UnconfirmedHalt
from app.models import CommandResult, ControllerStatus, Pose

if TYPE_CHECKING:
    from app.link.client import RobotClient
    from app.link.progress import Progress
    from app.link.stats import LinkStats
    from app.link.transport import TrafficRecord
    from app.safety.audit import AuditLog
    from app.safety.caps import MotionCaps
    from app.safety.envelope import EnvelopeViolation

__all__ = ["PartLink", "Readings", "TeachGate", "UploadLink", "WorkerOutputs"]


class WorkerOutputs(Protocol):
    """The worker's signals, as the parts emit them (each maps to one signal of RobotWorker)."""

    def publish_connection(self, state: ConnectionState) -> None: ...
    def publish_rtt(self, ms: float) -> None: ...
    def publish_polled(
        self, pose: Pose | None, status: ControllerStatus | None, alarms: int | None, good_at: float | None
    ) -> None:
        """A poll's changes (None: unchanged) and its time (None: the connect read), in one go."""

    def publish_link_stats(self, stats: LinkStats) -> None: ...
    def publish_traffic(self, records: tuple[TrafficRecord, ...]) -> None: ...
    def publish_reconnected(self) -> None: ...
    def publish_restarted(self) -> None: ...
    def publish_foreign_master(self, what: str, value: float) -> None:
        """Another master was seen (app/link/foreign.py): ``what`` ("gv291", "canary"), the value."""

    def publish_progress(self, ticket: int | None, progress: Progress) -> None:
        """A request's progress (an upload's points and count), keyed by its ticket."""

    def publish_guard_stop(self, violation: EnvelopeViolation) -> None: ...
    def publish_halt(self, halt: UnconfirmedHalt | None) -> None:
        """A write that stops motion is not confirmed by the controller (None: nothing is)."""


# What one part uses of another, and no more (this module imports no part, so no part's module
# is in a circle with another). No part gets the worker with its siblings: the worker sequences
# them (app/link/sequence.py, app/link/lifecycle.py).


class Readings(Protocol):
    """The last pose and status the polls read (:class:`~app.link.poller.Poller`)."""

    @property
    def last_pose(self) -> Pose | None: ...
    @property
    def last_status(self) -> ControllerStatus | None: ...


class TeachGate(Protocol):
    """What a motion or an upload asks the :class:`~app.link.jog.JogMachine` before it starts."""

    def require_no_halt(self, operation: str) -> None:
        """Refuse ``operation`` while a stop is not confirmed by the controller."""
        ...

    def leave_teach(self, last_status: ControllerStatus | None) -> None:
        """Teach mode off (the jog ended) before a command that moves the arm."""
        ...


class PartLink(WorkerOutputs, Protocol):
    """What every part may use of the worker: the client, the urgent jobs, the emitters (worker
    thread only); no sibling."""

    closed: bool
    audit: AuditLog | None  # given to each new client (thread-safe)
    caps: MotionCaps | None  # reduced-speed mode's caps, given to each new client
    request_id: int | None  # of the job being executed (results and errors carry it)

    @property
    def client(self) -> RobotClient | None: ...

    @property
    def link_up(self) -> bool: ...

    def client_or_raise(self) -> RobotClient: ...

    def run_urgent(self) -> bool:
        """Run the urgent jobs queued now (stop, release, ...); True if any ran."""
        ...

    def emit_result(self, result: CommandResult, request_id: int | None = -1) -> None: ...

    def emit_error(
        self, operation: str, message: str, request_id: int | None = -1, reason: Reason | None = None
    ) -> None: ...

    def emit_exception(self, operation: str, exc: BaseException, request_id: int | None = -1) -> None: ...


class UploadLink(PartLink, Protocol):
    """What the :class:`~app.link.upload.Uploader` uses of the worker besides :class:`PartLink`:
    the callables the worker composes from the other parts, no part itself."""

    @property
    def canary_gv(self) -> int | None:
        """The restart canary's GV (the upload's second pose block moves past it; None: none)."""
        ...

    def leave_teach(self) -> None:
        """Teach mode off (the jog ended) before the upload's commands."""
        ...

    def poll_if_due(self) -> None:
        """A poll now if one is due (long jobs keep the monitor live)."""
        ...

    def link_failed(self, cause: TeachPadError | str) -> None:
        """A failed transaction, counted against the link (lost after too many in a row)."""
        ...
