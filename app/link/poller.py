"""The poller: one read of status and pose per tick, published as signals (worker thread).

Order of a poll: a stop the controller has not confirmed goes out again first
(:meth:`~app.link.jog.JogMachine.settle_halt`); then **status first, then pose** -- so when the
status says a motion ended, the pose read after it is the final one -- with the urgent jobs run
between the two reads. Then, in this order: one ``publish_polled`` of the pose / status /
alarms (each only on change) and of the good poll, the restart canary, ``commandFinished`` of
the command the poll completed, the RTT and the link statistics (the captured traffic goes out
on the worker's own period, not per poll: see :mod:`app.link.worker`). The clock (and the
canary) are read every :data:`app.timing.CLOCK_POLL_PERIOD`. Polls use the poll timeout
(``settings.effective_poll_timeout``), not the command timeout: a silent controller shows as
``NOT_ANSWERING`` after one poll.
"""

from __future__ import annotations

import dataclasses
import logging
import time

from app import timing
from app.errors import LinkError, MalformedResponse, ResponseTimeout, TeachPadError
from app.link.capture import LinkStatsReporter, RttMeter
from app.link.client import RobotClient
from app.link.foreign import audit_sighting
from app.link.host import WorkerHost
from app.link.types import Operation
from app.models import ControllerStatus, Pose
from app.safety.envelope import EnvelopeViolation

__all__ = ["JOG_POLL_HZ_MIN", "Poller"]

#: While a jog is held (or teach mode moves at a non-zero ratio) the poller keeps at least this
#: rate whatever the GUI's setting: the controller's watchdog (0.3 s on the simulator) stops a jog
#: that sees no traffic, so a slow poll setting (below ~3.4 Hz) would stop the operator's own jog.
JOG_POLL_HZ_MIN = 10.0

_log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True, slots=True)
class _Reading:
    """What one poll read (see :meth:`Poller._read`)."""

    status: ControllerStatus
    pose: Pose
    guard_stop: EnvelopeViolation | None  # the jog guard's stop (ratio 0 before a boundary)
    canary: float | None  # the restart canary, read on the slow clock
    read_time: float  # s: the two reads' time on the wire, for the RTT


class Poller:
    """Reads, publishes on change, feeds the active command and the jog's teach watch."""

    def __init__(self, host: WorkerHost) -> None:
        self._host = host
        self.last_pose: Pose | None = None
        self.last_status: ControllerStatus | None = None
        self._last_alarms: int | None = None
        self._next_clock = 0.0
        self._error: str | None = None  # the last poll error reported (once per distinct error)
        self._unread_since: float | None = None  # polls failing since (monotonic) under a command
        self.last_poll = 0.0  # monotonic time of the last poll attempt
        self.rtt = RttMeter(timing.RTT_REPORT_PERIOD)
        self.stats = LinkStatsReporter(timing.RTT_REPORT_PERIOD)

    def rate(self, setting_hz: float) -> float:
        """The poll rate to use now: the GUI's setting, at least :data:`JOG_POLL_HZ_MIN` while jogging."""
        jog = self._host.jog
        if jog.jogging or jog.halting:  # a jog's stop is confirmed by polls too (app/link/halt.py)
            return max(setting_hz, JOG_POLL_HZ_MIN)
        return setting_hz

    def reset(self, now: float) -> None:
        """A link just came up."""
        self._error = None
        self._unread_since = None
        self._next_clock = now + timing.CLOCK_POLL_PERIOD
        self.rtt.period = self.stats.period = timing.RTT_REPORT_PERIOD
        self.rtt.reset(now)

    def forget(self) -> None:
        """The link was closed: the next values are published even if equal to the last ones."""
        self.last_pose = None
        self.last_status = None
        self._last_alarms = None
        self.rtt.forget()
        self.stats.forget()

    def publish(self, pose: Pose, status: ControllerStatus, good_at: float | None = None) -> None:
        """One delivery of what changed (pose, status, alarms; each None when unchanged) and of the
        good poll at ``good_at`` (None: the connect read): one queued call to the GUI thread."""
        new_pose: Pose | None = None
        new_status: ControllerStatus | None = None
        new_alarms: int | None = None
        if pose != self.last_pose:
            self.last_pose = new_pose = pose
        if status != self.last_status:
            self.last_status = new_status = status
        alarms = int(status.alarms)
        if alarms != self._last_alarms:
            self._last_alarms = new_alarms = alarms
        if new_pose is not None or new_status is not None or new_alarms is not None or good_at is not None:
            self._host.publish_polled(new_pose, new_status, new_alarms, good_at)

    def poll_once(self) -> None:
        client = self._host.client
        if client is None:
            return
        now = time.monotonic()
        self.last_poll = now
        with_clock = now >= self._next_clock
        try:
            reading = self._read(client, with_clock)
        except TeachPadError as exc:
            self._poll_failed(exc)
            return
        if reading is not None:
            self._poll_answered(client, reading, now, with_clock)

    def _read(self, client: RobotClient, with_clock: bool) -> _Reading | None:
        """The poll's reads, status first, then pose, the urgent jobs run between them and after
        them (None: the link went down meanwhile), and the canary on the slow clock."""
        host = self._host
        timeout = client.settings.effective_poll_timeout
        if host.supervisor.answering:
            host.jog.settle_halt()  # a stop the controller has not confirmed: again, first
        t0 = time.perf_counter()
        status = client.read_status(with_clock=with_clock, timeout=timeout)
        t1 = time.perf_counter()
        host.run_urgent()  # a stop goes out between the two reads
        if not host.link_up:
            return None
        t2 = time.perf_counter()
        pose = client.read_pose(timeout=timeout)
        t3 = time.perf_counter()
        guard_stop = host.jog.guard_pose(pose, t2, t3)  # ratio 0 before the TCP crosses a boundary
        host.jog.halt_pose(pose)  # a jog's stop is over once answered and the pose is still
        host.run_urgent()  # and before this poll's publishing: a stop waits one read at most
        if not host.link_up:
            return None
        canary: float | None = None
        gv = host.supervisor.canary_gv
        if with_clock and host.supervisor.canary_token is not None and gv is not None:
            canary = client.read_gv(gv)[0]  # the restart canary, on the slow clock
        return _Reading(status, pose, guard_stop, canary, (t1 - t0) + (t3 - t2))

    def _poll_failed(self, exc: TeachPadError) -> None:
        """A failed poll: reported once per distinct error, the command in flight told; silence
        and a failed transaction go to the supervisor."""
        host = self._host
        self._report_error(exc)
        self._command_unread(exc)
        if isinstance(exc, ResponseTimeout):
            host.supervisor.poll_silent(exc, time.monotonic())
        elif isinstance(exc, (LinkError, MalformedResponse)):
            # A malformed answer is a failed poll: the transport counted it and resynchronised
            # (a TCP link is reopened by the next request); none of its values are published;
            # LINK_LOSS_POLLS of them in a row take the link down like any failed transaction.
            host.supervisor.transport_failed(exc)
        else:
            return
        self._report_stats()

    def _poll_answered(self, client: RobotClient, reading: _Reading, now: float, with_clock: bool) -> None:
        """A good poll: published, then the canary, another master's signs, the command in
        flight, the jog, the RTT and the link statistics."""
        host = self._host
        answered = time.monotonic()
        self._error = None
        self._unread_since = None
        host.supervisor.poll_answered()
        if not host.link_up:
            return
        if reading.guard_stop is not None:
            host.publish_guard_stop(reading.guard_stop)
        status, pose = self._clocked(client, reading.status, now, with_clock), reading.pose
        self.publish(pose, status, good_at=answered)
        if reading.canary is not None:
            host.supervisor.canary_read(reading.canary)
        self._report_foreign(client)
        done = host.motion.update(status, pose, answered)
        if done is not None:
            host.emit_result(*done)
        host.jog.after_status(status, answered, idle=host.motion.active is None)
        rtt = self.rtt.note(reading.read_time, 2, answered)
        if rtt is not None:
            host.publish_rtt(rtt)
        self._report_stats()

    def _clocked(
        self, client: RobotClient, status: ControllerStatus, now: float, with_clock: bool
    ) -> ControllerStatus:
        """The status with the controller's clock: read on the slow clock (and noted by the
        audit), else the last one read."""
        if with_clock:
            self._next_clock = now + timing.CLOCK_POLL_PERIOD
            if client.audit is not None and status.clock is not None:
                client.audit.note_controller_clock(status.clock.value, now)
        elif self.last_status is not None:
            status = dataclasses.replace(status, clock=self.last_status.clock)
        return status

    def _command_unread(self, exc: TeachPadError) -> None:
        """A poll failed while a command is followed: its outcome is not told by it. The polls go
        on reading; once they failed for ``timing.OUTCOME_READ_BUDGET`` and the command's own time
        ran out, it ends *unknown* ("sent; the outcome is unknown -- check the robot ..."), never
        failed (issue 19 section 3; the CLI's ``CommandClient.follow`` keeps the same rule)."""
        host = self._host
        active = host.motion.active
        if active is None:
            self._unread_since = None
            return
        now = time.monotonic()
        if self._unread_since is None:
            self._unread_since = now
        completion = active.completion
        if now < max(self._unread_since + timing.OUTCOME_READ_BUDGET, completion.deadline):
            return
        host.motion.take()
        self._unread_since = None
        host.emit_result(completion.unknown(now, exc), active.request_id)

    def _report_foreign(self, client: RobotClient) -> None:
        """Another master's signs seen by this poll (app/link/foreign.py): logged, audited, published."""
        for sighting in client.foreign.take():
            _log.warning("%s", sighting.message)
            audit_sighting(client.audit, sighting)
            self._host.publish_foreign_master(sighting.what, sighting.value)

    def _report_stats(self) -> None:
        client = self._host.client
        if client is not None:
            stats = self.stats.due(client.stats, time.monotonic())
            if stats is not None:
                self._host.publish_link_stats(stats)

    def _report_error(self, exc: TeachPadError) -> None:
        message = str(exc)
        if message != self._error:  # once per distinct error, not 50 times a second
            self._error = message
            self._host.emit_exception(Operation.POLL, exc)
