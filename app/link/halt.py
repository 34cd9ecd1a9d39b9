"""Everything a Stop does, in one module: what it writes, where and in what order, what it ends,
and how a write that stops motion is followed until the controller has confirmed it.

**The operator's Stop** (:class:`~app.link.ops.Stop`, the worker's job :class:`StopJob`):

1. :func:`post_stop` (the submitting thread, at once): ``441 <- 1`` on the stop line
   (:mod:`app.link.stop_line`, the line's transport) when there is one, then the Stop queued first
   in line; without a line the poster waits (GIL released, at most ``handoff_wait``) until the
   worker has written it.
2. :meth:`StopJob.run` (the worker thread, after the transaction in flight): ``441 <- 1`` on the
   main link first -- the ordering guarantee: nothing this host wrote before the stop runs after
   it -- then the stop line's answer read, checked, audited and shown in the traffic.
3. The controller took it (:meth:`StopJob._after_stop`): the poster goes on, the upload ends
   ("stopped"), the motions queued before the Stop are cancelled ("cancelled by Stop"), the jog
   ends (speed 0: :meth:`~app.link.jog.JogMachine.on_stop`), the command in flight ends as
   stopped, then the Stop's own result.
4. The main link's stop failed: taken on the stop line and nothing of the main link can land
   after it -> a success that says which line carried it; a link failure on TCP -> the stop over
   a fresh connection to the same controller (:func:`stop_on_a_fresh_connection`); refused or
   unanswered -> the queued motions cancelled, the upload ended, and the Stop followed like a
   jog's release (below) until the controller takes it. Without a link at all (disconnected,
   lost, reconnecting) the Stop goes over a fresh connection to the last controller.

**A halt until the controller confirms it** (issue 19, item 1): :class:`HaltWatch`.
Decision on PROTOCOL.md section 7 ("Exception 6 ... a write that stops motion is retried until
answered") that lives here: **a jog is over only when the controller has answered its speed 0
(GV203 <- 0) -- or a Stop (441 <- 1) -- and the pose is then seen still.** Until then:

* the write is sent again at every poll (the GUI's worker) or every ``JOG_POLL_INTERVAL``
  (teachpad-cli), whatever the controller answered before (busy, an exception, no answer);
* after :data:`app.timing.HALT_ESCALATE_AFTER` s without that confirmation -- refused all along,
  or answered while the arm kept moving -- a Stop (441) goes out too, at every poll, before the
  speed 0; at once when the envelope guard, which keeps deciding on the jog being released, sees
  the arm heading over a boundary;
* the operator is told: the jog panel says "releasing -- the controller has not confirmed".

**A Pause the controller refused or did not answer** (``HaltKind.PAUSE``; the same PROTOCOL.md
decision): a Pause is over only when the controller has answered it (442 <- 1) -- or the program
state reads paused -- or the motion is seen to have ended (the program state reads stopped and the
pose is still). Until then it is sent again at every poll (a Pause is idempotent: a second one
of a paused program changes nothing), the operator is told ("pausing -- the controller has not
confirmed": press STOP if it must stop now), and no motion starts. It is not turned into a Stop
at once (a Pause is meant to be resumed, and *busy* means "try again later"), but the operator
asked for the arm to halt: not confirmed :data:`app.timing.PAUSE_ESCALATE_AFTER` s after the
press (or refused for good: an exception other than 4, 5, 6), a Stop (441) goes out instead, at
every poll until the controller takes it. The Pause's own request ends with the outcome: paused
(confirmed after n s), stopped instead, or nothing left to pause.

A Stop the controller refused is followed the same way (its own write, 441, from the start:
:func:`follow_refused_stop`); a halt's Stop, once answered, ends the command in flight as the
operator's does (:func:`write_halt_stop`). teachpad-cli gives up after :data:`app.timing.HALT_CONFIRM_BUDGET`
s and says so (exit 1).

:class:`HaltWatch` is the policy alone: what to write now, what the answers and the poses mean.
The caller does the writes and reads and passes the clock (the GUI's worker in
:class:`~app.link.jog.JogMachine` through :func:`settle`, the CLI in :func:`confirm_halt`), so
both follow one rule and a test can run it on an injected clock.
"""

from __future__ import annotations

import dataclasses
import enum
import logging
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

from app import timing
from app.connection import ConnectionSettings
from app.errors import (
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    Reason,
    ResponseTimeout,
    TeachPadError,
    WriteBlocked,
)
from app.link.arrival import pose_moved
from app.link.client import RobotClient
from app.link.jobs import Job
from app.link.ops import Handlers, JobKind, Stop
from app.link.types import HaltKind, JogRequest, UnconfirmedHalt
from app.models import CommandResult, Pose
from app.safety.audit import AuditLog

if TYPE_CHECKING:  # (the stop line's transport needs pymodbus: teachpad-cli loads it only to connect)
    from app.link.active import MotionTracker
    from app.link.capture import TrafficCapture
    from app.link.stop_line import StopLine, StopSent

__all__ = [
    "RETRY_EXCEPTIONS",
    "HaltWatch",
    "HaltWrite",
    "StopJob",
    "StopJog",
    "StopPorts",
    "confirm_halt",
    "follow_refused_stop",
    "halt_refusal",
    "post_stop",
    "settle",
    "stop_on_a_fresh_connection",
    "write_halt_stop",
]

_log = logging.getLogger(__name__)

#: The main link's stop failed because the link did (not the controller's refusal).
_LINK_FAILURES = (LinkError, ResponseTimeout, MalformedResponse)


class HaltWrite(enum.Enum):
    """One write that stops motion."""

    SPEED_ZERO = "jog speed 0"  # GV203 <- 0: the jog stops, teach mode stays on
    STOP = "stop"  # 441 <- 1: everything stops
    PAUSE = "pause"  # 442 <- 1: the program / move is held where it is (resumable)


#: Modbus exceptions that mean "not now" (PROTOCOL.md section 7): 4 server device failure,
#: 5 acknowledge (still working on an earlier request), 6 server device busy. Any other exception
#: (illegal function, address, value ...) refuses that write for good: it is not sent again (a
#: release then goes on with Stop at once).
RETRY_EXCEPTIONS = frozenset({4, 5, 6})


def halt_refusal(exc: TeachPadError) -> bool:
    """The controller refused the write (a Modbus exception) or did not answer it in time: the
    halt goes on. Anything else (the link is gone, a bad answer) is the link's failure and goes
    its own way (the write is tried again once the link is back)."""
    return isinstance(exc, ModbusExceptionError | ResponseTimeout)


def _for_good(exc: TeachPadError) -> bool:
    """A refusal that sending the same write again cannot change."""
    return isinstance(exc, ModbusExceptionError) and exc.exception_code not in RETRY_EXCEPTIONS


class HaltWatch:
    """One motion being stopped: a jog being released (``HaltKind.RELEASE``), a Stop the
    controller refused (``HaltKind.STOP``) or a Pause it refused (``HaltKind.PAUSE``). See the
    module docstring.

    ``request``: the jog being released (the envelope guard keeps deciding on it); None when
    there was none (a Stop of a move or program).
    """

    def __init__(
        self,
        kind: HaltKind,
        request: JogRequest | None,
        now: float,
        *,
        escalate_after: float | None = None,
    ) -> None:
        self.kind = kind
        self.request = request
        self.since = now
        self._clock_from = now  # the escalation's clock: from the release, or the controller's return
        if escalate_after is None:
            pause = kind is HaltKind.PAUSE
            escalate_after = timing.PAUSE_ESCALATE_AFTER if pause else timing.HALT_ESCALATE_AFTER
        self.escalate_after = escalate_after
        self.escalated = kind is HaltKind.STOP  # a refused Stop: 441 is the write to repeat
        self.answered_at: float | None = None  # the controller answered a halting write
        self.answered_by: HaltWrite | None = None
        self.speed_zero_answered = False
        self.refusals = 0  # halting writes refused or unanswered
        self.silent = False  # the controller stopped answering while this jog ran
        self.last_error: TeachPadError | None = None
        self.refused_for_good: set[HaltWrite] = set()  # not sent again (see RETRY_EXCEPTIONS)
        self.over = False
        self._still_from: Pose | None = None  # the pose of the last poll after the answer
        self._moving_after_answer = False  # answered, and the pose still changed after that
        self.program_paused = False  # a Pause's: the program state read paused (confirmed)
        self._program_ended = False  # a Pause's: the program state read stopped (nothing to pause)
        self._ended_at: Pose | None = None  # the pose of the last poll since it read stopped

    # -- what to send ------------------------------------------------------------------------
    @property
    def unconfirmed(self) -> bool:
        """Something went wrong on the way: a write refused or unanswered, the controller silent,
        or a Stop needed. (A release answered at once and seen still never is.)"""
        return not self.over and (self.refusals > 0 or self.silent or self.escalated)

    def due(self, now: float) -> tuple[HaltWrite, ...]:
        """The writes to send now, in order (none while an answered halt waits for a still pose)."""
        if self.over:
            return ()
        if self.answered_at is not None:
            if not self._moving_after_answer or now - self.answered_at < self.escalate_after:
                return ()
            self.answered_at = None  # answered, yet the arm still moves: a Stop
            self.escalated = True
        if now - self._clock_from >= self.escalate_after:
            self.escalated = True
        if self.kind is HaltKind.STOP and self.request is None:
            writes: tuple[HaltWrite, ...] = (HaltWrite.STOP,)
        elif self.kind is HaltKind.PAUSE:
            writes = (HaltWrite.STOP,) if self.escalated else (HaltWrite.PAUSE,)
        elif self.escalated:
            writes = (HaltWrite.STOP, HaltWrite.SPEED_ZERO)
        else:
            writes = (HaltWrite.SPEED_ZERO,)
        return tuple(w for w in writes if w not in self.refused_for_good)

    @property
    def given_up(self) -> bool:
        """Every write that could stop the arm was refused for good and none was answered: there
        is nothing left to send (the arm may still move)."""
        if self.over or self.answered_at is not None:
            return False
        return self._needed() <= self.refused_for_good

    def _needed(self) -> set[HaltWrite]:
        """The writes that could stop this motion (each refused for good: nothing left to send)."""
        if self.kind is HaltKind.PAUSE:
            return {HaltWrite.PAUSE, HaltWrite.STOP}
        if self.kind is HaltKind.STOP and self.request is None:
            return {HaltWrite.STOP}
        return {HaltWrite.SPEED_ZERO, HaltWrite.STOP}

    def answering_again(self, now: float) -> None:
        """The controller answers again after a silence: it gets the speed 0 first, and
        ``escalate_after`` from now to take it (nothing could reach it while it was silent)."""
        if self.silent and not self.escalated:
            self._clock_from = now

    def escalate(self) -> bool:
        """The envelope guard sees the arm heading over a boundary: a Stop at once -- unless the
        controller answered and the arm has not been seen moving since. True when it escalated."""
        if self.over or (self.answered_at is not None and not self._moving_after_answer):
            return False
        self.escalated = True
        self.answered_at = None
        return True

    # -- what came back ----------------------------------------------------------------------
    def took(self, write: HaltWrite, now: float) -> None:
        """The controller answered ``write``."""
        if write is HaltWrite.SPEED_ZERO:
            self.speed_zero_answered = True
        if self.answered_at is None:
            self.answered_at = now
            self.answered_by = write
            self._still_from = None
            self._moving_after_answer = False
        self.silent = False

    def refused(self, write: HaltWrite, exc: TeachPadError) -> None:
        """The controller did not take ``write``: refused (``exc``, a Modbus exception) or no
        answer. Refused for good: not sent again, and a Stop goes out at once instead."""
        self.refusals += 1
        self.last_error = exc
        if _for_good(exc):
            self.refused_for_good.add(write)
            self.escalated = True

    def program_seen(self, paused: bool, stopped: bool) -> bool:
        """A Pause's watch, per poll: the program state read ``paused`` (the Pause is confirmed,
        whoever's write did it: one that got no answer may have been carried out) or ``stopped``
        (the motion ended: over once the pose is seen still). True once over."""
        if self.kind is not HaltKind.PAUSE or self.over:
            return self.over
        if paused:  # held where it is (also once a Stop was due: the arm is halted, resumable)
            self.program_paused = True
            self.over = True
        elif not stopped:
            self._program_ended = False
            self._ended_at = None
        else:
            self._program_ended = True
        return self.over

    def _ended_and_still(self, pose: Pose) -> bool:
        """A Pause's watch: the program state reads stopped and the pose did not change since the
        last poll (the motion ended before the Pause was taken)."""
        if not self._program_ended:
            return False
        before, self._ended_at = self._ended_at, pose
        return before is not None and not pose_moved(pose, before)

    @property
    def paused(self) -> bool:
        """A Pause's watch that ended with the arm paused (answered, or read paused), not stopped."""
        return self.over and (self.program_paused or self.answered_by is HaltWrite.PAUSE)

    def pose_seen(self, pose: Pose) -> bool:
        """A poll's pose; True once the halt is over (answered, then the pose unchanged from one
        poll to the next; a Pause's also: the program read stopped, and the pose unchanged)."""
        if self.over:
            return True
        if self.kind is HaltKind.PAUSE and self._ended_and_still(pose):
            self.over = True
            return True
        if self.answered_at is None:
            self._still_from = None
            return False
        if self._still_from is not None:
            if not pose_moved(pose, self._still_from):
                self.over = True
                return True
            self._moving_after_answer = True
        self._still_from = pose
        return False

    def state(self) -> UnconfirmedHalt | None:
        """What the operator is shown: None while nothing is wrong (or once it is over)."""
        if not self.unconfirmed:
            return None
        return UnconfirmedHalt(self.kind, self.since, self.escalated)

    def words(self, now: float) -> str:
        """The English sentence for logs and the CLI: what was tried and what came back."""
        seconds = f"{now - self.since:.1f}"
        what = {HaltKind.RELEASE: "the jog's speed 0", HaltKind.STOP: "the stop", HaltKind.PAUSE: "the pause"}
        cause = f": {self.last_error}" if self.last_error is not None else ""
        stop = " and Stop (441)" if self.escalated and self.kind is not HaltKind.STOP else ""
        return (
            f"the controller did not confirm {what[self.kind]}{stop} within {seconds} s "
            f"({self.refusals} refused or unanswered{cause})"
        )


def confirm_halt(
    write: Callable[[HaltWrite], None],
    read_pose: Callable[[], Pose],
    watch: HaltWatch,
    *,
    budget: float | None = None,
    interval: float,
    clock: Callable[[], float] = time.monotonic,
    sleep: Callable[[float], None] = time.sleep,
) -> bool:
    """Blocking (teachpad-cli): send what ``watch`` asks for, read the pose, every ``interval``
    s, until the halt is over (True), or ``budget`` s (default
    :data:`app.timing.HALT_CONFIRM_BUDGET`) have passed since the watch began, or every write
    was refused for good (False).

    ``write`` raises a :class:`TeachPadError` when the controller did not take it: refused or
    unanswered (:func:`halt_refusal`) counts and is tried again; anything else is raised. A pose
    read that fails the same way is tried again at the next turn."""
    budget = timing.HALT_CONFIRM_BUDGET if budget is None else budget
    while True:
        _send_due(write, watch, clock)
        if watch.answered_at is not None and _seen_still(read_pose, watch):
            return True
        if watch.given_up or clock() - watch.since >= budget:
            return False
        sleep(interval)


def _send_due(write: Callable[[HaltWrite], None], watch: HaltWatch, clock: Callable[[], float]) -> None:
    """Send what ``watch`` asks for now; a refusal or no answer (:func:`halt_refusal`) is counted."""
    for item in watch.due(clock()):
        try:
            write(item)
        except TeachPadError as exc:
            if not halt_refusal(exc):
                raise
            watch.refused(item, exc)
        else:
            watch.took(item, clock())


def _seen_still(read_pose: Callable[[], Pose], watch: HaltWatch) -> bool:
    """The pose read now is the one read before (a read refused or unanswered: not yet)."""
    try:
        pose = read_pose()
    except TeachPadError as exc:
        if not halt_refusal(exc):
            raise
        return False
    return watch.pose_seen(pose)


def follow_refused_stop(
    halt: HaltWatch | None, jog: JogRequest | None, exc: TeachPadError, now: float
) -> HaltWatch:
    """The operator's Stop was refused or not answered (:func:`halt_refusal`): the watch that
    follows it from now on (a Stop's watch already under way goes on; else a new one, keeping
    the jog being stopped for the envelope guard), with this refusal counted."""
    if halt is None or halt.kind is not HaltKind.STOP:
        request = jog if jog is not None else (halt.request if halt is not None else None)
        halt = HaltWatch(HaltKind.STOP, request, now)
    halt.refused(HaltWrite.STOP, exc)
    return halt


def settle(write: Callable[[HaltWrite], None], watch: HaltWatch, now: float) -> TeachPadError | None:
    """Per poll (the GUI's worker): send what ``watch`` asks for now. ``write`` tells the watch
    itself what the controller took; a refusal or no answer is counted (sent again at the next
    poll); a link failure is counted too, ends this round and is returned (the caller raises it
    once the GUI is told: the poll fails as it would have)."""
    for item in watch.due(now):
        try:
            write(item)
        except TeachPadError as exc:
            watch.refused(item, exc)
            if not halt_refusal(exc):
                return exc
    return None


def write_halt_stop(
    client: RobotClient,
    watch: HaltWatch | None,
    tracker: MotionTracker,
    emit_result: Callable[[CommandResult, int | None], None],
) -> None:
    """The Stop (441) a halt asks for (escalated, or a refused Stop sent again), on the main link;
    answered: the watch counts it and the command in flight ends as stopped (as after the
    operator's Stop)."""
    client.stop()
    if watch is not None:
        watch.took(HaltWrite.STOP, time.monotonic())
    _end_command_in_flight(tracker, emit_result, time.monotonic())


def _end_command_in_flight(
    tracker: MotionTracker, emit_result: Callable[[CommandResult, int | None], None], now: float
) -> None:
    """A Stop the controller took ends the command it was carrying out: stopped, with its request id."""
    active = tracker.take()
    if active is not None:
        emit_result(active.completion.stopped(now), active.request_id)


# --- the operator's Stop -------------------------------------------------------------------------
def post_stop(
    op: Stop,
    line: StopLine,
    put: Callable[[Job], int],
    wake: Callable[[], None],
    *,
    worker_thread: int | None,
    handoff_wait: float,
) -> int:
    """Step 1 (any thread): the Stop written now on the stop line when there is one, then queued
    first in line (``put``) and the worker woken; its request id. Without a line, from another
    thread than the worker's, this waits (GIL released) until the worker has written it, at most
    ``handoff_wait`` s, so nothing of the caller's runs first."""
    on_line = line.send_stop()
    sent = threading.Event()
    request_id = put(Job(op, sent=sent, on_line=on_line))
    wake()
    if on_line is None and worker_thread is not None and worker_thread != threading.get_ident():
        sent.wait(handoff_wait)
    return request_id


def stop_on_a_fresh_connection(
    settings: ConnectionSettings,
    *,
    audit: AuditLog | None,
    capture: TrafficCapture,
    ratio_zero: bool,
    again_after: float = 0.0,
) -> float:
    """Open a new connection to the controller of ``settings``, write ``441 <- 1`` on it, close it;
    the send's ``time.monotonic()``. Raises the :class:`~app.errors.TeachPadError` of the connect
    or of the write (:class:`~app.errors.WriteBlocked` in monitor-only mode: nothing is sent).

    Worker thread (it waits for the connect and the answer, each at most the link timeout). The
    write passes the client's write guard (audited) and its frames go to the traffic capture.
    ``ratio_zero``: a jog may be under way (teach mode was on when the link went): GV203 <- 0 goes
    out right after the stop, the vendor's own jog stop. ``again_after``: a write of the old link
    without its answer may still be acted on until then (``time.monotonic()``; a controller takes
    a request within the timeout or not at all): when that is later than this stop, a second stop
    goes out on the same connection once it has passed, so nothing sent before the Stop runs after
    it (as :func:`app.cli.context.stop_on_a_fresh_link` does after Ctrl-C)."""
    client = RobotClient(dataclasses.replace(settings, retries=0))
    client.audit = audit
    capture.attach(client)
    try:
        if not settings.monitor_only:  # (monitor-only: the write guard refuses it, audited, nothing opened)
            client.connect()
        sent = time.monotonic()
        client.stop()
        if ratio_zero:
            client.teach_set_ratio(0.0)
        if again_after > sent:
            time.sleep(max(0.0, again_after - time.monotonic()))
            client.stop()
        return sent
    finally:
        capture.detach(client)
        client.close()


class StopJog(Protocol):
    """What a Stop ends of the :class:`~app.link.jog.JogMachine` (the jog's own way to end)."""

    teach_dirty: bool  # teach may be on at the controller: speed 0 and teach off before the next jog

    @property
    def jogging(self) -> bool: ...
    @property
    def halting(self) -> bool: ...

    def on_stop(self) -> None:
        """The controller took a Stop: the jog ends (speed 0 if it moved)."""
        ...

    def stop_refused(self, exc: TeachPadError) -> None:
        """The Stop was refused or not answered: followed until the controller takes it."""
        ...


class StopPorts(Protocol):
    """What the Stop job uses of the worker (worker thread)."""

    @property
    def audit(self) -> AuditLog | None: ...
    @property
    def client(self) -> RobotClient | None:
        """The main link's client (also while it is down and reconnecting; None: disconnected)."""
        ...

    @property
    def link_up(self) -> bool: ...
    @property
    def last_settings(self) -> ConnectionSettings | None:
        """The last controller's settings (None: TeachPad knows none)."""
        ...

    @property
    def current_job(self) -> Job | None:
        """The job being executed (a Stop's: its place in the queue, its stop-line write)."""
        ...

    def emit_result(self, result: CommandResult, request_id: int | None = -1) -> None: ...

    def cancel_queued(self, predicate: Callable[[Job], bool]) -> list[Job]:
        """Remove and return the queued (not urgent) jobs that match."""
        ...

    def link_failed(self, cause: TeachPadError) -> None:
        """A failed transaction, counted against the main link."""
        ...


class StopJob:
    """The worker's Stop job, steps 2-4 of the module docstring (worker thread only)."""

    def __init__(
        self,
        host: StopPorts,
        *,
        line: StopLine,
        capture: TrafficCapture,
        jog: StopJog,
        tracker: MotionTracker,
        end_upload: Callable[[str], None],
    ) -> None:
        """``line``: the stop line (its answer read here); ``capture``: the traffic inspector's
        recorder; ``jog``, ``tracker``, ``end_upload``: what a Stop ends."""
        self._host = host
        self._line = line
        self._capture = capture
        self._jog = jog
        self._tracker = tracker
        self._end_upload = end_upload

    def register(self, handlers: Handlers) -> None:
        """The Stop in the worker's one table."""
        handlers.add(Stop, self.run)

    def run(self, _op: Stop) -> None:
        """Step 2: the main link's stop first, then the stop line's answer; steps 3-4 after."""
        job = self._host.current_job
        on_line = job.on_line if job is not None else None  # already written on the stop line
        client = self._host.client
        if client is None or not self._host.link_up:
            # disconnected by the operator, lost and reconnecting, still connecting: the last
            # controller may be moving all the same (a program runs on without its host)
            self._report_stop_line(on_line)
            self._stop_on_a_fresh_connection(None)
            return
        try:
            client.stop()  # first: nothing else goes out before the stop
        except WriteBlocked:  # monitor-only: nothing is written, each queued job is refused in turn
            self._report_stop_line(on_line)
            raise
        except TeachPadError as exc:  # no answer in time, refused, link lost: the operator still asked for it
            self._main_link_failed(client, exc, on_line)
            return
        except BaseException:
            self._report_stop_line(on_line)
            raise
        self._report_stop_line(on_line)
        self._after_stop(time.monotonic(), "stop: sent")

    def _main_link_failed(self, client: RobotClient, exc: TeachPadError, on_line: StopSent | None) -> None:
        """Step 4: the main link's stop failed (raises ``exc`` when the Stop stays a failure)."""
        took = self._report_stop_line(on_line)  # ... and the controller took it on the stop line
        if (
            took
            and on_line is not None
            and client.writes_settled_before(on_line.sent_mono)
            and not self._jog.jogging
        ):
            # ... and nothing this link wrote can reach the controller after the line's stop:
            # every write before it was answered before it went out, none began since (a
            # motion write after it -- a job already under way -- would run after the stop);
            # and no jog is held (its speed 0 needs the main link: the Stop stays a failure)
            self._stopped_on_the_line_only(client, exc)
            return
        if isinstance(exc, _LINK_FAILURES) and client.settings.serial_port is None:
            # the main link did not carry it (silent, dropped, out of step): a new TCP
            # connection beside it may (a serial line has one port: the link's own)
            self._stop_on_a_fresh_connection(exc)
            return
        self._cancel_motions_before_stop()  # nothing queued before the Stop runs after it
        self._end_upload("stopped")
        self._jog.stop_refused(exc)  # sent again at every poll until the controller takes it
        raise exc

    def _stop_on_a_fresh_connection(self, main_failure: TeachPadError | None) -> None:
        """The Stop over a new connection to the last controller: the link is not up
        (``main_failure`` None) or its own stop failed (``main_failure``). Sent: the Stop's result
        says so, naming the controller (a warning); the command in flight ends as stopped. Not
        sent: a :class:`LinkError` (code ``stop_unreachable``) naming the controller and why, and
        everything queued before the Stop is cancelled all the same."""
        host = self._host
        settings = host.last_settings
        if settings is None:  # TeachPad knows no controller: nothing to stop
            raise LinkError("not connected to a controller", code="not_connected")
        prior = host.client  # the link that went (None after a disconnect): its unanswered writes
        jog = self._jog
        try:
            sent = stop_on_a_fresh_connection(
                settings,
                audit=host.audit,
                capture=self._capture,
                ratio_zero=jog.jogging or jog.teach_dirty or jog.halting,
                again_after=prior.write_lost_until if prior is not None else 0.0,
            )
        except WriteBlocked:
            raise
        except TeachPadError as exc:
            self._cancel_motions_before_stop()
            self._end_upload("stopped")
            self._end_jog_after_a_failed_stop()
            cause = exc.as_reason()
            raise LinkError(
                f"stop: could not reach the controller at {settings.endpoint} ({exc}): check the robot",
                code="stop_unreachable",
                params={"endpoint": settings.endpoint, "cause": cause.code, "cause_args": dict(cause.args)},
            ) from None
        if prior is not None:  # its writes (stop, ratio 0) are ours, not another master's
            prior.foreign.note_write(time.monotonic())
        job = host.current_job
        if job is not None and job.sent is not None:
            job.sent.set()
        now = time.monotonic()
        args: dict[str, object] = {"endpoint": settings.endpoint}
        text = f"stop: sent to {settings.endpoint} over a fresh connection"
        if main_failure is not None:
            tracker = prior.last_tracker if prior is not None else None
            if tracker is not None and not tracker.finished:
                tracker.stopped(now)
            cause = main_failure.as_reason()
            args.update(cause=cause.code, cause_args=dict(cause.args))
            text += f" (the main link's stop failed: {main_failure})"
        _log.warning("%s (sent %.3f s ago)", text, now - sent)
        self._after_stop(now, text, Reason("stop_sent_fresh", args), main_link_failed=True)
        if main_failure is not None:  # it still counts against the main link
            host.link_failed(main_failure)

    def _report_stop_line(self, on_line: StopSent | None) -> bool:
        """The stop line's answer: checked, audited, shown in the traffic. True when the
        controller took the stop there."""
        return on_line is not None and self._line.report(self._capture, self._host.audit, on_line)

    def _stopped_on_the_line_only(self, client: RobotClient, exc: TeachPadError) -> None:
        """The main link's stop failed but the controller took the stop line's: the arm was
        stopped. The command in flight ends as stopped at once (a point being created waits no
        longer for a result the stop reset), the Stop is a success that says which line carried it,
        and the main link's failure still counts against the main link (after: the motion in
        flight ended as stopped, which it was, not as "link lost, outcome unknown")."""
        now = time.monotonic()
        tracker = client.last_tracker
        if tracker is not None and not tracker.finished:
            tracker.stopped(now)
        cause = exc.as_reason()
        self._after_stop(
            now,
            f"stop: sent on the stop line (the main link's stop failed: {exc})",
            Reason("stop_sent_on_line", {"cause": cause.code, "cause_args": dict(cause.args)}),
            main_link_failed=True,
        )
        if isinstance(exc, _LINK_FAILURES):
            self._host.link_failed(exc)

    def _after_stop(
        self, now: float, text: str, reason: Reason | None = None, *, main_link_failed: bool = False
    ) -> None:
        """Step 3, the controller took the stop: end the upload, cancel the motions queued before
        the Stop (first: whatever fails after, none of them runs after it), end the jog and the
        motion in flight; then the Stop's own result."""
        host = self._host
        job = host.current_job
        if job is not None and job.sent is not None:
            job.sent.set()  # the poster (the GUI thread) may go on
        self._end_upload("stopped")
        self._cancel_motions_before_stop()
        # no jog held, or its speed 0 went on the other connection: nothing to say if this fails
        if main_link_failed:
            self._end_jog_after_a_failed_stop()
        else:
            self._jog.on_stop()  # speed 0; a failure here is the Stop's error, as before
        _end_command_in_flight(self._tracker, host.emit_result, now)
        host.emit_result(CommandResult(None, None, None, True, text, reason=reason))

    def _end_jog_after_a_failed_stop(self) -> None:
        """The stop line's stop was taken, the main link failed: the held jog ends (a jog sequence
        still starting gives way before its ratio goes out), and speed 0 is tried; if that fails
        too, teach mode counts as unknown (speed 0 and teach off before anything else)."""
        try:
            self._jog.on_stop()
        except TeachPadError:
            self._jog.teach_dirty = True

    def _cancel_motions_before_stop(self) -> None:
        """The motions queued before the Stop (its place in the queue) get "cancelled by Stop"."""
        host = self._host
        stop = host.current_job
        stop_seq = stop.seq if stop is not None else 0
        for job in host.cancel_queued(lambda j: j.kind is JobKind.MOTION and j.seq < stop_seq):
            reason = Reason("cancelled_by_stop", {"operation": str(job.operation)})
            text = f"{job.operation}: cancelled by Stop"
            host.emit_result(CommandResult(None, None, None, False, text, reason=reason), job.request_id)
