"""The link to the controller for the GUI: a worker in its own QThread that composes small parts.

:class:`RobotWorker` lives in a ``QThread`` and is the only owner of the :class:`RobotClient`
(created in the worker thread, like its timers). The GUI thread never waits for the network:
requests go into a thread-safe :class:`~app.link.jobs.JobQueue` and results come back as signals.
The worker only composes its parts, each a Qt-free class in its own module, all on the worker
thread; each gets only what it uses (:mod:`app.link.host`: the client, ``run_urgent``, the
emitters, a narrow view or callable of another part), none gets the worker with its siblings.
The worker sequences them: a poll's outcome through :mod:`app.link.sequence`, the link's changes
(connect, silence, failures, loss, close) through :mod:`app.link.lifecycle`, the supervisor
deciding and the other parts told in turn:

* :class:`~app.link.supervisor.LinkSupervisor` -- connect, backoff, link loss, *not answering*,
  the restart canary.
* :class:`~app.link.poller.Poller` -- status then pose per tick, one ``polled`` (PollUpdate: the
  changed data and the poll's time), then the ``commandFinished`` that poll completed.
* :class:`~app.link.jobs.JobQueue` -- urgent jobs (stop, pause, resume, jog release, cancel
  upload) first, also between any two transactions of a poll, a jog, a teach command or an
  upload. A stop cancels the motion jobs queued before it; a release drops a queued jog press.
* :class:`~app.link.jog.JogMachine` -- jog (function 4) and the dead-man.
* :class:`~app.link.motion.MotionCommands` / :class:`~app.link.motion.MotionTracker` -- the long
  commands, started without waiting, and the completion of the one under way (one motion at a
  time; Stop clears it). A create point while another short command is tracked waits in
  ``_held`` until that one's outcome is known (GV291 tells one command at a time).
* :class:`~app.link.upload.Uploader` -- chunked upload of many points, its progress
  (``progressed``, keyed by the upload's ticket: :mod:`app.link.progress`) per point and
  overall, one final ``commandFinished``; ``cancel_upload`` or a stop end it.
* :class:`~app.link.capture.TrafficCapture`, RTT and link statistics. The captured frames go
  out in batches (``trafficObserved``) every :data:`app.timing.TRAFFIC_DELIVERY_PERIOD` from the
  worker's own timer, not once per poll (one queued call into the GUI thread instead of ten at
  100 Hz); whatever is pending goes out at once before a ``commandFinished`` / ``errorOccurred``
  (a command's frames reach the GUI before its outcome), before a ``connectionChanged``, when
  polling stops, when capture is switched off and at shutdown: no frame is left behind.

Requests are operations as data (:mod:`app.link.ops`): :meth:`RobotWorker.submit` queues one
and returns its ticket (request id); the worker runs each through one table, operation type ->
handler (``handlers``). The handlers of the short commands (``pause`` ...) are in
:class:`~app.link.commands.WorkerCommands`, those of the long ones in
:class:`~app.link.motion.MotionCommands`, the Stop's in :class:`~app.link.halt.StopJob`: parts
the worker composes, like the others.

Stop latency (everything a Stop does: :mod:`app.link.halt`): :meth:`RobotWorker.submit` of a
:class:`~app.link.ops.Stop` writes the stop from the calling thread on the stop line
(:func:`~app.link.halt.post_stop`, :mod:`app.link.stop_line`) when there is one; the stop job
then writes it on the main link too, after the transaction in flight (ordering), and reads the
line's answer. Without a line the GUI thread waits (GIL released, at most
:data:`STOP_HANDOFF_WAIT`) for the worker to write it.

Every submitted operation gets an ``int`` request id; each :class:`CommandResult` /
:class:`WorkerError` it causes carries it. Every failure becomes a signal (``commandFinished``:
the outcome of every command that reached the controller; ``errorOccurred``: everything else).

Shutdown is a queued call: the worker stops motion, closes the client, hands itself back to the
GUI thread and quits its thread (docs/DESIGN.md, "Worker / RobotLink").
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from collections import deque
from collections.abc import Callable

import numpy  # noqa: F401 - the jog guard's arithmetic (app/lazy_numpy.py): imported with the worker,
from PySide6.QtCore import QCoreApplication, QObject, Qt, QTimer, Signal, Slot  # not by a check mid-jog

from app import timing
from app.connection import ConnectionSettings
from app.errors import (
    CommandRefused,
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    Reason,
    ResponseTimeout,
    TeachPadError,
    WriteBlocked,
)
from app.link import lifecycle
from app.link.active import MotionTracker
from app.link.capture import TrafficCapture
from app.link.client import RobotClient
from app.link.commands import WorkerCommands
from app.link.halt import StopJob, post_stop
from app.link.jobs import Job, JobQueue
from app.link.jog import JogMachine, PreemptedError
from app.link.motion import MotionCommands
from app.link.ops import CancelUpload, Handlers, LinkOp, Stop
from app.link.poller import Poller
from app.link.progress import Progress
from app.link.register_reads import RegisterReads
from app.link.sequence import poll
from app.link.state import PollUpdate
from app.link.stats import LinkStats
from app.link.stop_line import StopLine
from app.link.supervisor import Cause, LinkSupervisor
from app.link.transport import TrafficRecord
from app.link.types import ConnectionState, LinkState, Operation, UnconfirmedHalt, WorkerError
from app.link.upload import Uploader
from app.link.watch_list import WatchListReader
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.registers import CANARY_GV
from app.safety.audit import AuditLog
from app.safety.caps import MotionCaps
from app.safety.envelope import EnvelopeViolation
from app.safety.jog_guard import JogGuard

__all__ = ["SHUTDOWN_TIMEOUT_MS", "RobotWorker"]

_log = logging.getLogger(__name__)

#: Kept for importers; the GUI's shutdown waits :data:`app.timing.SHUTDOWN_WAIT` (read at use time).
SHUTDOWN_TIMEOUT_MS = round(timing.SHUTDOWN_WAIT * 1000)

#: How long a thread that submits a Stop waits (GIL released) for the worker to send it (s). While
#: it waits, the poster (the GUI thread) cannot hold the GIL the worker needs to write the stop:
#: measured, that wait was most of a Stop's latency (the worker waiting for a busy GUI thread's
#: GIL, the in-flight poll finishing in slow motion). A rare event: a short freeze is the price.
STOP_HANDOFF_WAIT = 0.005


class RobotWorker(QObject):
    """Owns the RobotClient in the worker thread and composes the parts; see the module docstring."""

    polled = Signal(object)  # PollUpdate: a poll's pose/status/alarms/freshness, its one delivery
    connectionChanged = Signal(ConnectionState)  # noqa: N815
    rttChanged = Signal(float)  # noqa: N815 - ms, mean over RTT_REPORT_PERIOD
    linkStatsChanged = Signal(object)  # noqa: N815 - LinkStats, at most every RTT_REPORT_PERIOD, on change
    commandFinished = Signal(CommandResult)  # noqa: N815
    errorOccurred = Signal(WorkerError)  # noqa: N815
    # tuple[TrafficRecord, ...] (immutable, handed over as it is; Signal(list) was a QVariantList,
    # converted record by record in both threads), a batch every TRAFFIC_DELIVERY_PERIOD, only while capturing
    trafficObserved = Signal(tuple)  # noqa: N815
    controllerReconnected = Signal()  # noqa: N815
    controllerRestarted = Signal()  # noqa: N815 - the canary GV changed while the link stayed up
    foreignMaster = Signal(str, float)  # noqa: N815 - another master seen: what ("gv291", "canary"), the value
    progressed = Signal(int, object)  # ticket (request id), Progress (app/link/progress.py): an upload's
    jogGuardStopped = Signal(object)  # noqa: N815 - EnvelopeViolation: the jog guard wrote ratio 0
    haltChanged = Signal(object)  # noqa: N815 - UnconfirmedHalt | None: a stop the controller has not confirmed
    watchRead = Signal(object)  # noqa: N815 - WatchReadings: the watch list's reads of a poll (none: no list)
    stopped = Signal()  # the worker has closed the link and is quitting its thread (shutdown)

    # Wakes the worker from any thread (a queued call, since the worker lives in its thread).
    _wake = Signal()
    # The next chunk of an upload, one event-loop turn later (polls and queued calls in between).
    _uploadStep = Signal()  # noqa: N815

    def __init__(self, poll_hz: float = timing.POLL_HZ_DEFAULT, *, canary_gv: int | None = CANARY_GV) -> None:
        super().__init__()
        self._poll_hz = float(poll_hz)
        self._jobs = JobQueue(halting=(Stop.operation, CancelUpload.operation))
        self._wake.connect(self._on_wake, Qt.ConnectionType.QueuedConnection)
        self._uploadStep.connect(self._upload_step, Qt.ConnectionType.QueuedConnection)
        # Everything below is touched only in the worker thread.
        self.closed = False
        self.audit: AuditLog | None = None  # set before connecting (set_audit); thread-safe
        self.caps: MotionCaps | None = None  # reduced-speed mode's caps (set_motion_caps)
        self.request_id: int | None = None  # request id of the job being executed
        self._current_job: Job | None = None
        self._in_urgent = False
        self._worker_ident: int | None = None  # the worker thread, once started (request_stop)
        # Short commands (create point) that wait for the one being tracked to end: GV291 tells
        # only one command's outcome at a time, so a second one goes out after the first ended.
        self._held: deque[Job] = deque()
        self._poll_timer: QTimer | None = None
        self._reconnect_timer: QTimer | None = None
        self._traffic_timer: QTimer | None = None  # delivers the captured frames while capturing
        self.capture = TrafficCapture()
        self.motion = MotionTracker()
        self.poller = Poller(self, self.motion)
        self.supervisor = LinkSupervisor(self, canary_gv, capture=self.capture)  # raises on a bad canary GV
        self.stop_line = StopLine()  # the stop's own connection; send_stop from any thread
        # a stop counts on the stop line before its 441 goes out, then (and a cancel) in the queue
        self.uploader = Uploader(self, lambda: self.stop_line.stops_requested + self._jobs.halts)
        self.jog = JogMachine(
            self,
            self.motion,
            last_pose=lambda: self.poller.last_pose,
            answering=lambda: self.supervisor.answering,
        )
        self.motions = MotionCommands(
            self, self.motion, self.jog, self.poller, uploading=lambda: self.uploader.run is not None
        )
        self.use_stop_line = True  # False: every stop goes through the queue (set before connecting)
        self.stop_job = StopJob(  # everything a Stop does: app/link/halt.py
            self,
            line=self.stop_line,
            capture=self.capture,
            jog=self.jog,
            tracker=self.motion,
            end_upload=self.uploader.end,
        )
        # the short commands' handlers
        self.commands = WorkerCommands(self, jog=self.jog, motions=self.motions, uploader=self.uploader)
        self.register_reads = RegisterReads(self)  # write-free block reads (the register-map self-test)
        self.watch_list = WatchListReader(self, self.watchRead.emit)  # read after the pose (poller.py)
        self.poller.watch_list = self.watch_list
        self.handlers = self._make_handlers()

    def _make_handlers(self) -> Handlers:
        """The one table: operation type -> what runs it (worker thread); each part registers
        the operations it runs."""
        handlers = Handlers()
        self.stop_job.register(handlers)  # the Stop
        self.commands.register(handlers)  # the short ones (pause, the jog ...)
        self.motions.register(handlers)  # the long ones (step, move to point ...)
        self.register_reads.register(handlers)  # block reads
        self.watch_list.register(handlers)  # the watch list and an engineer's write of a value
        return handlers

    # --- requests (any thread) ----------------------------------------------------------
    def submit(self, op: LinkOp) -> int:
        """Queue ``op`` and wake the worker; returns the request id its results will carry.

        A :class:`~app.link.ops.Stop` is written now on the stop line when there is one
        (app/link/stop_line.py), then queued first in line (the main link's stop, the line's
        answer, the bookkeeping). Without a stop line, from another thread, this waits (GIL
        released) until the worker has written it, at most :data:`STOP_HANDOFF_WAIT`, so nothing
        of the caller's runs first. The stop runs whatever the link's state: without a link it
        goes over a fresh connection to the last controller (:class:`~app.link.halt.StopJob`)."""
        if not isinstance(op, Stop):
            request_id = self._jobs.put(Job(op))
            self._wake.emit()
            return request_id
        return post_stop(
            op,
            self.stop_line,
            self._jobs.put,
            self._wake.emit,
            worker_thread=self._worker_ident,
            handoff_wait=STOP_HANDOFF_WAIT,
        )

    # --- lifecycle (worker thread) ------------------------------------------------------
    @Slot()
    def start(self) -> None:
        """Run by ``QThread.started``: the timers are created here, in the worker thread."""
        self._worker_ident = threading.get_ident()
        self._poll_timer = QTimer(self)
        self._poll_timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._poll_timer.setInterval(self._poll_interval_ms())
        self._poll_timer.timeout.connect(self._on_tick)
        self._reconnect_timer = QTimer(self)
        self._reconnect_timer.setSingleShot(True)
        self._reconnect_timer.timeout.connect(self._try_connect)
        self._traffic_timer = QTimer(self)
        self._traffic_timer.timeout.connect(self.flush_traffic)
        if self.capture.on:
            self._traffic_timer.start(max(1, round(timing.TRAFFIC_DELIVERY_PERIOD * 1000)))

    @Slot(object)
    def connect_to(self, settings: ConnectionSettings) -> None:
        """(Re)connect with ``settings``; retries by itself until :meth:`disconnect_link`."""
        if not self.closed:
            self.stop_line.reset(settings if self.use_stop_line else None)
            lifecycle.connect(self, settings)

    @Slot()
    def disconnect_link(self) -> None:
        """Stop jogging, switch teach off, close the link, stop retrying."""
        if not self.closed:
            lifecycle.close_link(self, Operation.DISCONNECT, LinkState.DISCONNECTED, "")

    @Slot()
    def shutdown(self) -> None:
        """Queued from the GUI: stop motion, close, hand the object back, quit this thread."""
        if self.closed:
            return
        lifecycle.close_link(self, Operation.SHUTDOWN, LinkState.DISCONNECTED, "", short=True)
        self.flush_traffic()  # the close's own frames (teach off) before the thread ends
        self.closed = True
        self._worker_ident = None
        for timer in (self._poll_timer, self._reconnect_timer, self._traffic_timer):
            if timer is not None:
                timer.stop()
        thread = self.thread()
        app = QCoreApplication.instance()
        own_thread = app is not None and thread is not app.thread()
        if own_thread and app is not None:
            # Back to the GUI thread so the object (and its stopped timers) dies there cleanly.
            self.moveToThread(app.thread())
        self.stopped.emit()
        if own_thread:
            thread.quit()  # the event loop ends when this slot returns

    @Slot(float)
    def set_poll_rate(self, hz: float) -> None:
        if hz <= 0 or self.closed:
            return
        self._poll_hz = float(hz)
        if self._poll_timer is not None:
            self._poll_timer.setInterval(self._poll_interval_ms())

    @Slot(object)
    def set_jog_guard(self, guard: JogGuard | None) -> None:
        """The safety envelope's jog guard (immutable, so safe to pass between threads); None: off."""
        self.jog.guard = guard

    @Slot(object)
    def set_motion_caps(self, caps: MotionCaps | None) -> None:
        """Reduced-speed mode's caps (immutable) for this connection's client and the next ones."""
        self.caps = caps
        client = self.supervisor.client
        if client is not None:
            client.caps = caps

    @Slot(object)
    def set_audit(self, audit: AuditLog | None) -> None:
        """The audit trail for the writes of the next connections (and of the current one)."""
        self.audit = audit
        client = self.supervisor.client
        if client is not None:
            client.audit = audit

    @Slot(bool)
    def set_traffic_capture(self, on: bool) -> None:
        """Capture on: frames go out every :data:`app.timing.TRAFFIC_DELIVERY_PERIOD` (read now);
        off: what was captured goes out first."""
        if self.closed:
            return
        if not on:
            self.flush_traffic()
        self.capture.set(on, self.supervisor.client)
        timer = self._traffic_timer
        if timer is not None:
            if on:
                timer.start(max(1, round(timing.TRAFFIC_DELIVERY_PERIOD * 1000)))
            else:
                timer.stop()

    def _poll_interval_ms(self) -> int:
        return max(1, round(1000.0 / self._poll_rate()))

    def _poll_rate(self) -> float:
        """The poll rate now: the GUI's setting, raised while a jog is held or halting (poller.py)."""
        return self.poller.rate(self._poll_hz, jogging=self.jog.jogging or self.jog.halting)

    def _follow_poll_rate(self) -> None:
        """Keep the timer at the poller's rate (faster while jogging, see ``Poller.rate``)."""
        timer = self._poll_timer
        if timer is not None and timer.isActive():
            interval = self._poll_interval_ms()
            if timer.interval() != interval:
                timer.setInterval(interval)

    # --- the host of the parts (worker thread) ------------------------------------------
    @property
    def current_job(self) -> Job | None:
        """The job being executed (None between jobs)."""
        return self._current_job

    def cancel_queued(self, predicate: Callable[[Job], bool]) -> list[Job]:
        return self._jobs.cancel(predicate)

    def next_upload_step(self) -> None:
        self._uploadStep.emit()

    @property
    def client(self) -> RobotClient | None:
        return self.supervisor.client

    @property
    def link_up(self) -> bool:
        return self.supervisor.link_up

    @property
    def last_settings(self) -> ConnectionSettings | None:
        """The last controller's settings (None: none asked for yet)."""
        return self.supervisor.settings

    def client_or_raise(self) -> RobotClient:
        client = self.supervisor.client
        if client is None or not self.supervisor.link_up:
            raise LinkError("not connected to a controller")
        return client

    def poll_if_due(self) -> None:
        if time.monotonic() - self.poller.last_poll >= 1.0 / self._poll_rate():
            self._poll()

    def link_failed(self, cause: Cause) -> None:
        """A failed transaction counted against the link (lost after too many in a row)."""
        lifecycle.link_failed(self, cause)

    def leave_teach(self) -> None:
        """Teach mode off (the jog ended) before a command that moves the arm (an upload)."""
        self.jog.leave_teach(self.poller.last_status)

    @property
    def canary_gv(self) -> int | None:
        return self.supervisor.canary_gv

    def start_polling(self) -> None:
        if self._poll_timer is not None:
            self._poll_timer.start(self._poll_interval_ms())

    def stop_polling(self) -> None:
        if self._poll_timer is not None:
            self._poll_timer.stop()
        self.flush_traffic()  # the last poll's frames do not wait for the delivery timer
        # link_up is already False when the link was lost, still True when it is being closed
        self.stop_line.main_link_closed(time.monotonic(), lost=not self.supervisor.link_up)

    def start_reconnect(self, delay: float) -> None:
        if self._reconnect_timer is not None and not self.closed:
            self._reconnect_timer.start(max(1, round(delay * 1000)))

    def stop_reconnect(self) -> None:
        if self._reconnect_timer is not None:
            self._reconnect_timer.stop()

    @Slot()
    def flush_traffic(self) -> None:
        """``trafficObserved`` with the frames captured since the last batch (none: nothing)."""
        batch = self.capture.flush()
        if batch is not None:
            self.trafficObserved.emit(batch)

    def publish_connection(self, state: ConnectionState) -> None:
        self.flush_traffic()  # the frames of the link that ended (or the connect) come first
        self.connectionChanged.emit(state)

    def publish_rtt(self, ms: float) -> None:
        self.rttChanged.emit(ms)

    def publish_polled(
        self, pose: Pose | None, status: ControllerStatus | None, alarms: int | None, good_at: float | None
    ) -> None:
        """``polled``: the poll's one delivery (one queued call per poll into the GUI thread), nothing
        beside it; RobotLink applies it to its RobotState and re-emits the link's own signals."""
        self.polled.emit(PollUpdate(pose, status, alarms, good_at))

    def publish_link_stats(self, stats: LinkStats) -> None:
        self.linkStatsChanged.emit(stats)

    def publish_traffic(self, records: tuple[TrafficRecord, ...]) -> None:
        self.trafficObserved.emit(records)

    def publish_reconnected(self) -> None:
        self.controllerReconnected.emit()

    def publish_restarted(self) -> None:
        self.controllerRestarted.emit()

    def publish_foreign_master(self, what: str, value: float) -> None:
        self.foreignMaster.emit(what, value)

    def publish_progress(self, ticket: int | None, progress: Progress) -> None:
        self.progressed.emit(0 if ticket is None else ticket, progress)

    def publish_guard_stop(self, violation: EnvelopeViolation) -> None:
        self.jogGuardStopped.emit(violation)

    def publish_halt(self, halt: UnconfirmedHalt | None) -> None:
        self.haltChanged.emit(halt)

    def emit_result(self, result: CommandResult, request_id: int | None = -1) -> None:
        """``commandFinished`` with the request id (default: the job being executed)."""
        rid = self.request_id if request_id == -1 else request_id
        if result.request_id is None and rid is not None:
            result = dataclasses.replace(result, request_id=rid)
        self.flush_traffic()  # the command's frames reach the GUI before its outcome
        self.commandFinished.emit(result)

    def emit_error(
        self, operation: str, message: str, request_id: int | None = -1, reason: Reason | None = None
    ) -> None:
        """``errorOccurred`` with the request id (default: the job being executed) and, when the
        cause is known, its reason (code + arguments) for the operator's language."""
        rid = self.request_id if request_id == -1 else request_id
        self.flush_traffic()
        self.errorOccurred.emit(WorkerError(operation, message, rid, reason))

    def emit_exception(self, operation: str, exc: BaseException, request_id: int | None = -1) -> None:
        """``errorOccurred`` for ``exc`` (its English text and, for a typed error, its reason)."""
        rid = self.request_id if request_id == -1 else request_id
        self.flush_traffic()
        self.errorOccurred.emit(WorkerError.from_exception(operation, exc, rid))

    def fail_queued(self, message: str, code: str | None = None) -> None:
        held, self._held = list(self._held), deque()
        for job in [*held, *self._jobs.clear()]:
            if job.needs_link:
                reason = Reason(code, {"operation": job.operation}) if code else None
                self.emit_error(job.operation, message, job.request_id, reason=reason)

    # --- timers and queued calls (worker thread) ----------------------------------------
    @Slot()
    def _try_connect(self) -> None:
        lifecycle.try_connect(self)

    @Slot()
    def _on_tick(self) -> None:
        if self.closed or not self.link_up:
            return
        self.run_jobs()
        if self.link_up and not self.closed:
            self._poll()
            if self._held and self.motion.active is None:
                self.run_jobs()  # the tracked command just ended: the held one goes out now
            if self.link_up:
                self.stop_line.maintain(time.monotonic())  # open when due, keep alive

    def _poll(self) -> None:
        """One poll; results emitted from here belong to no request (even inside a job)."""
        outer_id, self.request_id = self.request_id, None
        try:
            poll(self)  # the poller reads; its outcome handed to the parts in order
        finally:
            self.request_id = outer_id

    @Slot()
    def _on_wake(self) -> None:
        if not self.closed:
            self.run_jobs()

    @Slot()
    def _upload_step(self) -> None:
        if self.uploader.step():
            self._uploadStep.emit()

    # --- job execution (worker thread) --------------------------------------------------
    def run_jobs(self) -> None:
        while not self.closed:
            job = self._jobs.pop_urgent()
            if job is None and self._held and self.motion.active is None:
                self._execute(self._held.popleft(), held=True)
                continue
            if job is None:
                job = self._jobs.pop()
            if job is None:
                self._follow_poll_rate()
                return
            self._execute(job)

    def run_urgent(self) -> bool:
        """Run the urgent jobs queued now; True if any ran. Never re-entered."""
        if self._in_urgent or self.closed:
            return False
        self._in_urgent = True
        ran = False
        try:
            while (job := self._jobs.pop_urgent()) is not None:
                self._execute(job)
                ran = True
        finally:
            self._in_urgent = False
        return ran

    def _must_wait(self, job: Job) -> bool:
        """A create point while another command is tracked (or held before it) waits its turn."""
        if job.operation != Operation.CREATE_POINT:
            return False
        active = self.motion.active
        return bool(self._held) or (active is not None and not active.motion)

    def _execute(self, job: Job, *, held: bool = False) -> None:
        if job.needs_link and not self.link_up:
            self.emit_error(
                job.operation, "not connected to a controller", job.request_id, Reason("not_connected")
            )
            return
        if not held and self._must_wait(job):
            self._held.append(job)
            return
        outer = (self.request_id, self._current_job)
        self.request_id, self._current_job = job.request_id, job
        try:
            self.handlers.run(job.op)
        except PreemptedError:
            pass
        except Exception as exc:  # every failure becomes a signal; the worker stays alive
            self._report_failure(job.operation, exc)
        finally:
            if job.sent is not None:
                job.sent.set()  # also when it failed: the poster waits no longer
            self.request_id, self._current_job = outer

    def _report_failure(self, operation: str, exc: Exception) -> None:
        """A job's failure as its signal: the controller's refusal (a Modbus exception, a refused
        status) is the request's failed result; anything else an error, and a link failure (or a
        malformed answer: the transport resynchronised, the outcome is unknown) also counts
        against the link. Monitor-only's refusal before the wire is only an error."""
        if isinstance(exc, ModbusExceptionError):
            text = f"{operation}: {exc}"
            named = Reason(exc.code, {**exc.params, "operation": operation})  # the words name the request
            self.emit_result(CommandResult(None, None, None, False, text, reason=named))
            return
        if isinstance(exc, CommandRefused):
            status = exc.status
            self.emit_result(
                CommandResult(None, status.kind, status, False, str(exc), reason=exc.as_reason())
            )
            return
        if not isinstance(exc, TeachPadError):  # a bug: report it plainly
            _log.error("%s failed", operation, exc_info=exc)
        self.emit_exception(operation, exc)
        if isinstance(exc, LinkError | ResponseTimeout | MalformedResponse) and not isinstance(
            exc, WriteBlocked
        ):
            self.link_failed(exc)
