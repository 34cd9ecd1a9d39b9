"""The poller: one read of status and pose per tick, published as signals (worker thread).

Order of a poll: a stop the controller has not confirmed goes out again first
(:meth:`~app.link.jog.JogMachine.settle_halt`); then **status first, then pose** -- so when the
status says a motion ended, the pose read after it is the final one -- with the urgent jobs run
between the two reads, the jog guard and the halt watch seeing the pose at once; after the pose,
the watch list's reads when it has entries (:mod:`app.link.watch_list`; none at all for an empty
list), the urgent jobs once more after them. The poller
returns what the poll read (:class:`Polled`, or :class:`PollFailed`) and
:func:`app.link.sequence.poll` hands it on, in this order: one ``publish_polled`` of the pose /
status / alarms (each only on change) and of the good poll, the restart canary (the supervisor),
``commandFinished`` of the command the poll completed (the tracker), the jog's teach watch, the
RTT and the link statistics (the captured traffic goes out on the worker's own period, not per
poll: see :mod:`app.link.worker`). The poller calls no other part. The clock (and the
canary) are read every :data:`app.timing.CLOCK_POLL_PERIOD`. Polls use the poll timeout
(``settings.effective_poll_timeout``), not the command timeout: a silent controller shows as
``NOT_ANSWERING`` after one poll.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Callable
from typing import Protocol

from app import timing
from app.errors import LinkError, MalformedResponse, ResponseTimeout, TeachPadError
from app.link.active import MotionTracker
from app.link.capture import LinkStatsReporter, RttMeter
from app.link.client import RobotClient
from app.link.foreign import audit_sighting
from app.link.host import PartLink
from app.link.types import Operation
from app.link.watch_list import WatchListReader
from app.models import ControllerStatus, Pose
from app.safety.envelope import EnvelopeViolation
from app.watchlist.plan import WatchReadings

__all__ = ["JOG_POLL_HZ_MIN", "PollFailed", "Polled", "Poller", "PoseWatch"]

#: While a jog is held (or teach mode moves at a non-zero ratio) the poller keeps at least this
#: rate whatever the GUI's setting: the controller's watchdog (0.3 s on the simulator) stops a jog
#: that sees no traffic, so a slow poll setting (below ~3.4 Hz) would stop the operator's own jog.
JOG_POLL_HZ_MIN = 10.0

_log = logging.getLogger(__name__)


class PoseWatch(Protocol):
    """What watches a poll's reads as they come (the jog: :class:`~app.link.jog.JogMachine`)."""

    def settle_halt(self) -> None:
        """A stop the controller has not confirmed: written again, before the reads."""
        ...

    def guard_pose(
        self, pose: Pose, read_at: float | None = None, answered_at: float | None = None
    ) -> EnvelopeViolation | None:
        """The jog guard's check of the pose just read (ratio 0 before a boundary)."""
        ...

    def halt_pose(self, pose: Pose) -> None:
        """A jog's stop is over once answered and the pose is still."""
        ...


@dataclasses.dataclass(frozen=True, slots=True)
class _Reading:
    """What one poll read (see :meth:`Poller._read`)."""

    status: ControllerStatus
    pose: Pose
    guard_stop: EnvelopeViolation | None  # the jog guard's stop (ratio 0 before a boundary)
    canary: float | None  # the restart canary, read on the slow clock
    read_time: float  # s: the two reads' time on the wire, for the RTT
    watched: WatchReadings | None = None  # the watch list's reads after the pose (None: none)


@dataclasses.dataclass(frozen=True, slots=True)
class Polled:
    """A good poll, to hand on (:func:`app.link.sequence.poll`)."""

    client: RobotClient
    reading: _Reading
    started: float  # monotonic: when the poll began
    answered: float  # monotonic: when its reads were done
    with_clock: bool  # the slow clock's reads (controller clock, canary) were made


@dataclasses.dataclass(frozen=True, slots=True)
class PollFailed:
    """A failed poll, to hand on: silence and a failed transaction go to the supervisor."""

    error: TeachPadError

    @property
    def silent(self) -> bool:
        """No answer in time (the link still open)."""
        return isinstance(self.error, ResponseTimeout)

    @property
    def transport_failed(self) -> bool:
        """The transaction failed (a malformed answer too: the transport counted it)."""
        return isinstance(self.error, (LinkError, MalformedResponse))


class Poller:
    """Reads and returns what it read; publishes on change, tells the command its polls fail."""

    def __init__(self, host: PartLink, tracker: MotionTracker) -> None:
        self._host = host
        self._tracker = tracker
        self.last_pose: Pose | None = None
        self.last_status: ControllerStatus | None = None
        self._last_alarms: int | None = None
        self._next_clock = 0.0
        self._error: str | None = None  # the last poll error reported (once per distinct error)
        self._unread_since: float | None = None  # polls failing since (monotonic) under a command
        self.last_poll = 0.0  # monotonic time of the last poll attempt
        self.rtt = RttMeter(timing.RTT_REPORT_PERIOD)
        self.stats = LinkStatsReporter(timing.RTT_REPORT_PERIOD)
        #: the watch list's reads after the pose (app/link/watch_list.py; None: no watch list)
        self.watch_list: WatchListReader | None = None

    @staticmethod
    def rate(setting_hz: float, *, jogging: bool) -> float:
        """The poll rate to use now: the GUI's setting, at least :data:`JOG_POLL_HZ_MIN` while
        ``jogging`` (a jog held or halting: a jog's stop is confirmed by polls too, app/link/halt.py)."""
        if jogging:
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

    def poll_once(
        self, watch: PoseWatch, *, settle: bool, canary_gv: Callable[[], int | None]
    ) -> Polled | PollFailed | None:
        """One poll's reads (None: no client, or the link went down meanwhile). ``settle``: the
        controller answers, so an unconfirmed stop is written again first; ``canary_gv``: the
        restart canary's GV to read on the slow clock (None: not checking), asked after the reads."""
        client = self._host.client
        if client is None:
            return None
        now = time.monotonic()
        self.last_poll = now
        with_clock = now >= self._next_clock
        try:
            reading = self._read(client, watch, settle=settle, with_clock=with_clock, canary_gv=canary_gv)
        except TeachPadError as exc:
            return PollFailed(exc)
        if reading is None:
            return None
        return Polled(client, reading, now, time.monotonic(), with_clock)

    def _read(
        self,
        client: RobotClient,
        watch: PoseWatch,
        *,
        settle: bool,
        with_clock: bool,
        canary_gv: Callable[[], int | None],
    ) -> _Reading | None:
        """The poll's reads, status first, then pose, the urgent jobs run between them and after
        them (None: the link went down meanwhile), and the canary on the slow clock."""
        host = self._host
        timeout = client.settings.effective_poll_timeout
        if settle:
            watch.settle_halt()  # a stop the controller has not confirmed: again, first
        t0 = time.perf_counter()
        status = client.read_status(with_clock=with_clock, timeout=timeout)
        t1 = time.perf_counter()
        host.run_urgent()  # a stop goes out between the two reads
        if not host.link_up:
            return None
        t2 = time.perf_counter()
        pose = client.read_pose(timeout=timeout)
        t3 = time.perf_counter()
        guard_stop = watch.guard_pose(pose, t2, t3)  # ratio 0 before the TCP crosses a boundary
        watch.halt_pose(pose)  # a jog's stop is over once answered and the pose is still
        host.run_urgent()  # and before this poll's publishing: a stop waits one read at most
        if not host.link_up:
            return None
        watched = self._read_watch_list(client, timeout)  # then the urgent jobs again
        if not host.link_up:
            return None
        canary: float | None = None
        gv = canary_gv() if with_clock else None
        if gv is not None:
            canary = client.read_gv(gv)[0]  # the restart canary, on the slow clock
        return _Reading(status, pose, guard_stop, canary, (t1 - t0) + (t3 - t2), watched)

    def _read_watch_list(self, client: RobotClient, timeout: float) -> WatchReadings | None:
        """The watch list's reads due in this poll, after the pose, then the urgent jobs (a stop
        waits one read at most); nothing at all for an empty list."""
        watch = self.watch_list
        if watch is None or not watch.active:
            return None
        watched = watch.read(client, timeout)
        if watched is not None:
            self._host.run_urgent()
        return watched

    def failed(self, exc: TeachPadError) -> None:
        """A failed poll: reported once per distinct error, the command in flight told."""
        self._report_error(exc)
        self._command_unread(exc)

    def answered(self) -> None:
        """A good poll: the errors reported so far are over."""
        self._error = None
        self._unread_since = None

    def publish_reading(self, polled: Polled) -> tuple[ControllerStatus, Pose]:
        """A good poll's delivery (the jog guard's stop, then the changes); its status (with the
        controller's clock) and pose."""
        reading = polled.reading
        if reading.guard_stop is not None:
            self._host.publish_guard_stop(reading.guard_stop)
        status = self._clocked(polled.client, reading.status, polled.started, polled.with_clock)
        self.publish(reading.pose, status, good_at=polled.answered)
        if reading.watched is not None and self.watch_list is not None:
            self.watch_list.publish(reading.watched)
        return status, reading.pose

    def report_rtt(self, polled: Polled) -> None:
        """The RTT of a good poll's reads, when one is due, then the link statistics."""
        rtt = self.rtt.note(polled.reading.read_time, 2, polled.answered)
        if rtt is not None:
            self._host.publish_rtt(rtt)
        self.report_stats()

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
        tracker = self._tracker
        active = tracker.active
        if active is None:
            self._unread_since = None
            return
        now = time.monotonic()
        if self._unread_since is None:
            self._unread_since = now
        completion = active.completion
        if now < max(self._unread_since + timing.OUTCOME_READ_BUDGET, completion.deadline):
            return
        tracker.take()
        self._unread_since = None
        self._host.emit_result(completion.unknown(now, exc), active.request_id)

    def report_foreign(self, client: RobotClient) -> None:
        """Another master's signs seen by this poll (app/link/foreign.py): logged, audited, published."""
        for sighting in client.foreign.take():
            _log.warning("%s", sighting.message)
            audit_sighting(client.audit, sighting)
            self._host.publish_foreign_master(sighting.what, sighting.value)

    def report_stats(self) -> None:
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
