"""A Qt-free host for the worker's parts: the real parts, composed like RobotWorker does, with
every output recorded in order and the timers recorded instead of run."""

from __future__ import annotations

import dataclasses
from typing import Any

from app.connection import ConnectionSettings
from app.errors import LinkError, Reason
from app.link import lifecycle
from app.link.active import MotionTracker
from app.link.capture import TrafficCapture
from app.link.client import RobotClient
from app.link.jog import JogMachine
from app.link.poller import Poller
from app.link.progress import PointUploaded, Progress
from app.link.sequence import poll
from app.link.stats import LinkStats
from app.link.supervisor import LinkSupervisor
from app.link.transport import TrafficRecord
from app.link.types import ConnectionState, LinkState, UnconfirmedHalt, WorkerError
from app.link.upload import Uploader
from app.models import CommandResult, ControllerStatus, Pose
from app.safety.audit import AuditLog
from app.safety.caps import MotionCaps
from app.safety.envelope import EnvelopeViolation


class PartsHost:
    """Composes the parts as :class:`~app.link.worker.RobotWorker` does, without Qt (the same
    sequences: :mod:`app.link.sequence`, :mod:`app.link.lifecycle`); ``out`` lists (name, payload)."""

    def __init__(self, canary_gv: int | None = None) -> None:
        self.out: list[tuple[str, Any]] = []
        self.progress: list[tuple[int | None, Progress]] = []  # (ticket, report) as published
        self.closed = False
        self.request_id: int | None = None
        self.polling = False
        self.reconnect_delays: list[float] = []
        self.urgent: list[Any] = []  # callables run by run_urgent (like urgent jobs)
        self.audit: AuditLog | None = None
        self.caps: MotionCaps | None = None
        self.capture = TrafficCapture()
        self.motion = MotionTracker()
        self.poller = Poller(self, self.motion)
        self.supervisor = LinkSupervisor(self, canary_gv, capture=self.capture)
        self.uploader = Uploader(self)
        self.jog = JogMachine(
            self,
            self.motion,
            last_pose=lambda: self.poller.last_pose,
            answering=lambda: self.supervisor.answering,
        )

    def poll(self) -> None:
        """One poll, in the worker's order (app/link/sequence.py)."""
        poll(self)

    # --- the link's changes, in the worker's order (app/link/lifecycle.py) -------------------
    def connect_to(self, settings: ConnectionSettings) -> None:
        lifecycle.connect(self, settings)

    def try_connect(self) -> None:
        lifecycle.try_connect(self)

    def link_failed(self, cause: Any) -> None:
        lifecycle.link_failed(self, cause)

    def link_lost(self, cause: Any) -> None:
        lifecycle.lose_link(self, cause)

    # --- what the parts call ---------------------------------------------------------------
    @property
    def client(self) -> RobotClient | None:
        return self.supervisor.client

    @property
    def link_up(self) -> bool:
        return self.supervisor.link_up

    def client_or_raise(self) -> RobotClient:
        if self.supervisor.client is None or not self.supervisor.link_up:
            raise LinkError("not connected to a controller")
        return self.supervisor.client

    def run_urgent(self) -> bool:
        ran = bool(self.urgent)
        while self.urgent:
            self.urgent.pop(0)()
        return ran

    def run_jobs(self) -> None:
        self.run_urgent()

    def poll_if_due(self) -> None:
        pass

    def leave_teach(self) -> None:
        self.jog.leave_teach(self.poller.last_status)

    @property
    def canary_gv(self) -> int | None:
        return self.supervisor.canary_gv

    def fail_queued(self, message: str, code: str | None = None) -> None:
        self.out.append(("failQueued", message))

    def flush_traffic(self) -> None:
        batch = self.capture.flush()
        if batch is not None:
            self.publish_traffic(batch)

    def emit_result(self, result: CommandResult, request_id: int | None = -1) -> None:
        rid = self.request_id if request_id == -1 else request_id
        self.out.append(("commandFinished", dataclasses.replace(result, request_id=rid)))

    def emit_error(
        self, operation: str, message: str, request_id: int | None = -1, reason: Reason | None = None
    ) -> None:
        rid = self.request_id if request_id == -1 else request_id
        self.out.append(("errorOccurred", WorkerError(operation, message, rid, reason)))

    def emit_exception(self, operation: str, exc: BaseException, request_id: int | None = -1) -> None:
        rid = self.request_id if request_id == -1 else request_id
        self.out.append(("errorOccurred", WorkerError.from_exception(operation, exc, rid)))

    def start_polling(self) -> None:
        self.polling = True

    def stop_polling(self) -> None:
        self.polling = False

    def start_reconnect(self, delay: float) -> None:
        self.reconnect_delays.append(delay)

    def stop_reconnect(self) -> None:
        pass

    def publish_connection(self, state: ConnectionState) -> None:
        self.out.append(("connectionChanged", state))

    def publish_rtt(self, ms: float) -> None:
        self.out.append(("rttChanged", ms))

    def publish_polled(
        self, pose: Pose | None, status: ControllerStatus | None, alarms: int | None, good_at: float | None
    ) -> None:  # recorded as the worker's separate signals, in their order
        if pose is not None:
            self.out.append(("poseChanged", pose))
        if status is not None:
            self.out.append(("statusChanged", status))
        if alarms is not None:
            self.out.append(("alarmsChanged", alarms))
        if good_at is not None:
            self.out.append(("pollSucceeded", good_at))

    def publish_link_stats(self, stats: LinkStats) -> None:
        self.out.append(("linkStatsChanged", stats))

    def publish_traffic(self, records: tuple[TrafficRecord, ...]) -> None:
        self.out.append(("trafficObserved", records))

    def publish_guard_stop(self, violation: EnvelopeViolation) -> None:
        self.out.append(("jogGuardStopped", violation))

    def publish_halt(self, halt: UnconfirmedHalt | None) -> None:
        self.out.append(("haltChanged", halt))

    def publish_reconnected(self) -> None:
        self.out.append(("controllerReconnected", None))

    def publish_restarted(self) -> None:
        self.out.append(("controllerRestarted", None))

    def publish_foreign_master(self, what: str, value: float) -> None:
        self.out.append(("foreignMaster", (what, value)))

    def publish_progress(self, ticket: int | None, progress: Progress) -> None:
        """Recorded by kind ("pointUploaded", "uploadProgress": the report's fields) and, with
        its ticket, in ``progress``."""
        name = "pointUploaded" if isinstance(progress, PointUploaded) else "uploadProgress"
        self.out.append((name, dataclasses.astuple(progress)))
        self.progress.append((ticket, progress))

    # --- helpers for tests -----------------------------------------------------------------
    def names(self) -> list[str]:
        return [name for name, _ in self.out]

    def of(self, name: str) -> list[Any]:
        return [payload for n, payload in self.out if n == name]

    def states(self) -> list[LinkState]:
        return [s.state for s in self.of("connectionChanged")]

    def poll_until_answered(self, polls: int = 50) -> None:
        """Poll until the link shows CONNECTED again (a loaded machine may need a few polls)."""
        for _ in range(polls):
            self.poll()
            if self.supervisor.answering:
                return
        raise AssertionError(f"no answer in {polls} polls: {self.out[-3:]}")

    def connect(self, sim: Any, **overrides: Any) -> None:
        # A roomy poll timeout: only the tests about silence make it short (the box may be loaded).
        values: dict[str, Any] = {"host": "127.0.0.1", "port": sim.port, "timeout": 1.0, "poll_timeout": 1.0}
        values.update(overrides)
        lifecycle.connect(self, ConnectionSettings(**values))
        assert self.link_up, self.out

    def close(self) -> None:
        lifecycle.close_link(self, "shutdown", LinkState.DISCONNECTED, "")
