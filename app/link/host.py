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

__all__ = [
    "JogView",
    "PartLink",
    "PollerView",
    "Readings",
    "SupervisorView",
    "TeachGate",
    "UploaderView",
    "WorkerHost",
    "WorkerOutputs",
]


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


# What one part uses of another, and no more: each view lists exactly the members the other
# parts reach (this module imports no part, so no part's module is in a circle with another).


class SupervisorView(Protocol):
    """The :class:`~app.link.supervisor.LinkSupervisor` as the poller, the jog and the upload see it."""

    @property
    def answering(self) -> bool: ...
    @property
    def canary_gv(self) -> int | None: ...
    @property
    def canary_token(self) -> float | None: ...
    def canary_read(self, value: float) -> None: ...
    def poll_answered(self) -> None: ...
    def poll_silent(self, cause: TeachPadError | str, now: float) -> None: ...
    def transport_failed(self, cause: TeachPadError | str) -> None: ...


class Readings(Protocol):
    """The last pose and status the polls read (:class:`~app.link.poller.Poller`)."""

    @property
    def last_pose(self) -> Pose | None: ...
    @property
    def last_status(self) -> ControllerStatus | None: ...


class PollerView(Readings, Protocol):
    """The :class:`~app.link.poller.Poller` as the supervisor sees it."""

    def reset(self, now: float) -> None: ...
    def forget(self) -> None: ...
    def publish(self, pose: Pose, status: ControllerStatus, good_at: float | None = None) -> None: ...


class TeachGate(Protocol):
    """What a motion or an upload asks the :class:`~app.link.jog.JogMachine` before it starts."""

    def require_no_halt(self, operation: str) -> None:
        """Refuse ``operation`` while a stop is not confirmed by the controller."""
        ...

    def leave_teach(self, last_status: ControllerStatus | None) -> None:
        """Teach mode off (the jog ended) before a command that moves the arm."""
        ...


class JogView(TeachGate, Protocol):
    """The :class:`~app.link.jog.JogMachine` as the supervisor and the upload see it."""

    @property
    def jogging(self) -> bool: ...
    @property
    def halting(self) -> bool: ...
    def reset(self) -> None: ...
    def link_lost(self) -> None: ...
    def controller_silent(self) -> None: ...
    def controller_answers(self) -> None: ...
    def make_teach_safe(self, status: ControllerStatus, ever_connected: bool) -> None: ...
    def stop_jog_and_teach(self) -> None: ...
    def after_status(self, status: ControllerStatus, now: float, *, idle: bool) -> None: ...
    def guard_pose(
        self, pose: Pose, read_at: float | None = None, answered_at: float | None = None
    ) -> EnvelopeViolation | None: ...
    def halt_pose(self, pose: Pose) -> None: ...
    def settle_halt(self) -> None: ...


class UploaderView(Protocol):
    """The :class:`~app.link.upload.Uploader` as the supervisor and the commands see it."""

    @property
    def run(self) -> object | None:
        """The upload under way (None: none)."""
        ...

    def end(self, reason: str) -> None: ...


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


class WorkerHost(PartLink, Protocol):
    """The worker as the parts not yet narrowed use it: the siblings through their views."""

    @property
    def supervisor(self) -> SupervisorView: ...
    @property
    def poller(self) -> PollerView: ...
    @property
    def jog(self) -> JogView: ...
    @property
    def uploader(self) -> UploaderView: ...

    def run_jobs(self) -> None: ...

    def poll_if_due(self) -> None:
        """A poll now if one is due (long jobs keep the monitor live)."""
        ...

    def fail_queued(self, message: str, code: str | None = None) -> None: ...

    def flush_traffic(self) -> None:
        """Publish the frames captured so far now (the worker also does on its own period)."""
        ...

    def start_polling(self) -> None: ...

    def stop_polling(self) -> None: ...

    def start_reconnect(self, delay: float) -> None: ...

    def stop_reconnect(self) -> None: ...
