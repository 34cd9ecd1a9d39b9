"""RobotLink: the GUI-thread facade of the worker (owns the thread, ``submit(op)``, shutdown).

Besides the worker's signals (re-exposed for logs, benchmarks and tests) the link holds the
GUI side's one picture of the robot, :class:`~app.link.state.RobotState` (``link.state``), and
matches request ids in one place: ``link.track(link.submit(MoveToPoint(...)))`` gives a
:class:`Pending` whose ``progressed(Progress)``, ``finished(CommandResult)`` and
``failed(WorkerError)`` fire only for that request. Every request's progress also goes out on
``progressed(ticket, Progress)`` (:mod:`app.link.progress`: an upload's points and count), keyed
by the ticket ``submit`` returned. :class:`LinkPort` is the typed port that panels and
controllers use (RobotLink fits; tests use a small fake that fits too).
"""

from __future__ import annotations

import logging
import sys
from types import EllipsisType
from typing import TYPE_CHECKING

from PySide6.QtCore import (
    QCoreApplication,
    QMetaObject,
    QObject,
    Qt,
    QThread,
    Signal,
    Slot,
)

from app import timing
from app.connection import ConnectionSettings
from app.errors import Reason
from app.link.link_port import Pending, RequestRouter
from app.link.ops import LinkOp, Stop
from app.link.progress import Progress
from app.link.state import DEFAULT_FRESHNESS_LIMIT, PollUpdate, RobotState
from app.link.stats import LinkStats
from app.link.types import ConnectionState, LinkState, WorkerError
from app.models import CommandResult, ControllerStatus

if TYPE_CHECKING:  # the worker (pymodbus, the envelope's numpy) is imported by the first request
    from app.link.worker import RobotWorker
    from app.safety.audit import AuditLog
    from app.safety.caps import MotionCaps
    from app.safety.jog_guard import JogGuard

__all__ = ["RobotLink", "wait_for_detached_threads"]

_log = logging.getLogger(__name__)

#: The interpreter's GIL switch interval while a link exists (s). CPython's default, 5 ms, is
#: how long the worker thread can wait for the GIL while the GUI thread runs Python (a paint, a
#: slot): a Stop posted by the GUI then sat up to 5 ms before its write. 0.5 ms bounds that wait;
#: the cost is more frequent GIL hand-offs, only when two threads want it at once.
GIL_SWITCH_INTERVAL = 0.0005


class RobotLink(QObject):
    """Owns the worker thread; plain methods that never block on the network (except shutdown)."""

    statusChanged = Signal(ControllerStatus)  # noqa: N815
    alarmsChanged = Signal(int)  # noqa: N815
    connectionChanged = Signal(ConnectionState)  # noqa: N815
    rttChanged = Signal(float)  # noqa: N815
    commandFinished = Signal(CommandResult)  # noqa: N815
    errorOccurred = Signal(WorkerError)  # noqa: N815
    trafficObserved = Signal(tuple)  # noqa: N815 - tuple[TrafficRecord, ...]: see RobotWorker
    controllerReconnected = Signal()  # noqa: N815
    controllerRestarted = Signal()  # noqa: N815
    foreignMaster = Signal(str, float)  # noqa: N815
    progressed = Signal(int, object)  # ticket, Progress (app/link/progress.py): a request's progress
    jogGuardStopped = Signal(object)  # noqa: N815 - EnvelopeViolation: the jog guard stopped a jog
    watchRead = Signal(object)  # noqa: N815 - WatchReadings: the watch list's values (app/link/watch_list.py)

    _connectRequested = Signal(object)  # noqa: N815
    _disconnectRequested = Signal()  # noqa: N815
    _shutdownRequested = Signal()  # noqa: N815
    _pollRateRequested = Signal(float)  # noqa: N815
    _captureRequested = Signal(bool)  # noqa: N815
    _guardRequested = Signal(object)  # noqa: N815
    _auditRequested = Signal(object)  # noqa: N815
    _capsRequested = Signal(object)  # noqa: N815

    def __init__(
        self,
        parent: QObject | None = None,
        *,
        poll_hz: float = timing.POLL_HZ_DEFAULT,
        canary_gv: int | EllipsisType | None = ...,
        freshness_limit: float = DEFAULT_FRESHNESS_LIMIT,
        stop_line: bool = True,
    ) -> None:
        """``canary_gv``: the restart canary's spare GV (``...``: the supervisor's default; None:
        none). ``stop_line`` False: never open the stop's own connection
        (app/link/stop_line.py); every stop goes through the worker's queue on the main link."""
        super().__init__(parent)
        if sys.getswitchinterval() > GIL_SWITCH_INTERVAL:
            sys.setswitchinterval(GIL_SWITCH_INTERVAL)  # see GIL_SWITCH_INTERVAL: a stop never waits 5 ms
        if isinstance(canary_gv, int):  # a bad one raises here, not at the first request
            from app.link.supervisor import check_canary_gv

            check_canary_gv(canary_gv)
        self._settings: ConnectionSettings | None = None
        self._state = RobotState(self, freshness_limit=freshness_limit)
        self._router = RequestRouter()
        self._motions: dict[int, str] = {}  # request id -> operation: motions sent, outcome not known yet
        self._shut = False
        self._capture_users = 0
        # What the worker gets when it is made (it is made by the first request: see _worker).
        self._poll_hz = float(poll_hz)
        self._canary_gv = canary_gv
        self._use_stop_line = stop_line
        self._guard: JogGuard | None = None
        self._caps: MotionCaps | None = None
        self._audit: AuditLog | None = None
        self._made: RobotWorker | None = None
        self._shutdownRequested.connect(self._on_shut_down)  # the GUI-side state: disconnected
        self._thread = QThread()
        self._thread.setObjectName("RobotWorker")
        app = QCoreApplication.instance()
        if app is not None:
            app.aboutToQuit.connect(self.shutdown)
        self._thread.start()

    @property
    def _worker(self) -> RobotWorker:
        """The worker, made (and moved to its running thread) by the first request that needs it.

        Building the window makes no worker: importing it means pymodbus and the envelope's
        numpy (≈ 0.15 s), which the first paint does not need. Settings given before (poll rate,
        audit, jog guard, capture) reach it first, in order, through the same queued signals."""
        worker = self._made
        if worker is None:
            worker = self._made = self._make_worker()
        return worker

    def _make_worker(self) -> RobotWorker:
        from app.link.worker import RobotWorker

        canary = self._canary_gv
        w = RobotWorker(self._poll_hz) if canary is ... else RobotWorker(self._poll_hz, canary_gv=canary)
        w.use_stop_line = self._use_stop_line
        w.moveToThread(self._thread)
        # queued (in order, before the request that made it): the thread runs, its timers start there
        QMetaObject.invokeMethod(w, "start", Qt.ConnectionType.QueuedConnection)
        state = self._state
        for source, target in (  # the model first, so a view of the re-emitted signal reads the new value
            (w.polled, self._on_polled),  # pose, status, alarms, good poll: one queued call per poll
            (w.rttChanged, state.set_rtt),
            (w.linkStatsChanged, self._on_stats),
            (w.commandFinished, self._on_result),
            (w.errorOccurred, self._on_error),
            (w.connectionChanged, self._on_connection),
            (w.rttChanged, self.rttChanged),
            (w.trafficObserved, self.trafficObserved),
            (w.controllerReconnected, self.controllerReconnected),
            (w.controllerRestarted, self.controllerRestarted),
            (w.foreignMaster, self.foreignMaster),
            (w.progressed, self._on_progress),
            (w.jogGuardStopped, self.jogGuardStopped),
            (w.watchRead, self.watchRead),
            (w.haltChanged, state.set_halt),
            (self._connectRequested, w.connect_to),
            (self._disconnectRequested, w.disconnect_link),
            (self._pollRateRequested, w.set_poll_rate),
            (self._captureRequested, w.set_traffic_capture),
            (self._guardRequested, w.set_jog_guard),
            (self._auditRequested, w.set_audit),
            (self._capsRequested, w.set_motion_caps),
        ):
            source.connect(target)
        self._shutdownRequested.connect(w.shutdown, Qt.ConnectionType.QueuedConnection)
        # queued, so in this order before the request that made the worker
        if self._audit is not None:
            self._auditRequested.emit(self._audit)
        if self._guard is not None:
            self._guardRequested.emit(self._guard)
        if self._caps is not None:
            self._capsRequested.emit(self._caps)
        if self._capture_users > 0:
            self._captureRequested.emit(True)
        return w

    # --- state --------------------------------------------------------------------------
    @property
    def state(self) -> RobotState:
        """The observable robot state (connection, freshness, pose, status, ...)."""
        return self._state

    @property
    def connection(self) -> ConnectionState:
        return self._state.connection

    @property
    def settings(self) -> ConnectionSettings | None:
        return self._settings

    @property
    def monitor_only(self) -> bool:
        return bool(self._settings and self._settings.monitor_only)

    @property
    def is_running(self) -> bool:
        return self._thread.isRunning()

    @property
    def motions_in_flight(self) -> tuple[str, ...]:
        """The operations (:class:`~app.link.types.Operation` values) of the motion requests
        (step, go to zero, run program, move to point) whose outcome has not come back yet."""
        return tuple(self._motions.values())

    def track(self, request_id: int) -> Pending:
        """The :class:`Pending` of a request id this link returned (call it right away, in the
        GUI thread: outcomes arrive through queued signals, so none can be missed)."""
        return self._router.track(request_id)

    @Slot(object)
    def _on_polled(self, update: PollUpdate) -> None:
        """One poll's delivery, in the order of the separate signals it replaces: each datum to
        the model first, then the link's own signal (a view of that reads the new value), then
        the good poll (freshness), all before the ``commandFinished`` that poll completed."""
        state = self._state
        pose, status, alarms = update.pose, update.status, update.alarms
        if pose is not None:
            state.set_pose(pose)  # its poseChanged is the pose's one signal (views connect there)
        if status is not None:
            state.set_status(status)
            self.statusChanged.emit(status)
        if alarms is not None:
            state.set_alarms(alarms)
            self.alarmsChanged.emit(alarms)
        if update.good_at is not None:
            state.note_good_poll(update.good_at)

    @Slot(ConnectionState)
    def _on_connection(self, state: ConnectionState) -> None:
        self._state.set_connection(state)
        self.connectionChanged.emit(state)

    @Slot()
    def _on_shut_down(self) -> None:
        """Nothing is live after a shutdown: the state says so (and its freshness timer stops)."""
        endpoint = self._state.connection.endpoint
        shut = ConnectionState(
            LinkState.DISCONNECTED, "the link was shut down", endpoint, reason=Reason("link_was_shut_down")
        )
        self._state.set_connection(shut)

    @Slot(int, object)
    def _on_progress(self, ticket: int, progress: Progress) -> None:
        self._router.on_progress(ticket, progress)
        self.progressed.emit(ticket, progress)

    @Slot(CommandResult)
    def _on_result(self, result: CommandResult) -> None:
        if result.request_id is not None:
            self._motions.pop(result.request_id, None)
        self._state.set_last_result(result)
        self._router.on_result(result)
        self.commandFinished.emit(result)

    @Slot(WorkerError)
    def _on_error(self, error: WorkerError) -> None:
        if error.request_id is not None:
            self._motions.pop(error.request_id, None)
        self._router.on_error(error)
        self.errorOccurred.emit(error)

    @Slot(object)
    def _on_stats(self, stats: LinkStats) -> None:
        self._state.set_stats(stats)

    # --- connection ---------------------------------------------------------------------
    def connect_to(self, settings: ConnectionSettings) -> None:
        if self._shut:
            return
        self._settings = settings
        _ = self._worker  # made now, at the latest
        self._connectRequested.emit(settings)

    def disconnect(self) -> None:  # type: ignore[override]  # QObject.disconnect is not used on links
        if not self._shut and self._made is not None:  # no worker: no link to close
            self._disconnectRequested.emit()

    def set_poll_rate(self, hz: float) -> None:
        if not self._shut:
            self._poll_hz = float(hz)
            if self._made is not None:
                self._pollRateRequested.emit(float(hz))

    def set_jog_guard(self, guard: JogGuard | None) -> None:
        """The jog guard the worker applies on every poll during a jog (None: no envelope)."""
        if not self._shut:
            self._guard = guard
            if self._made is not None:
                self._guardRequested.emit(guard)

    def set_motion_caps(self, caps: MotionCaps | None) -> None:
        """Reduced-speed mode's caps, applied by the worker's client to every speed it writes
        (None: not reduced). A request made after this call is capped: the caps (immutable) are
        set on the worker at once -- a queued call alone came after a motion the worker took from
        its queue inside a poll -- and again by the queued call, in the worker's thread (a client
        it made meanwhile gets them too)."""
        if not self._shut:
            self._caps = caps
            if self._made is not None:
                self._made.caps = caps  # read by the worker when it makes or runs a motion
                client = self._made.supervisor.client
                if client is not None:
                    client.caps = caps
                self._capsRequested.emit(caps)

    def set_audit(self, audit: AuditLog | None) -> None:
        """The audit trail every write of this link goes to (call before :meth:`connect_to`)."""
        if not self._shut:
            self._audit = audit
            if self._made is not None:
                self._auditRequested.emit(audit)

    def set_traffic_capture(self, on: bool) -> None:
        """Reference-counted: capture runs while at least one user asked for it."""
        if self._shut:
            return
        self._capture_users = max(0, self._capture_users + (1 if on else -1))
        if self._made is not None:
            self._captureRequested.emit(self._capture_users > 0)

    # --- requests (queued; results come back as signals) -------------------------------
    def submit(self, op: LinkOp) -> int:
        """Queue the operation ``op`` (:mod:`app.link.ops`); returns its ticket, the request id
        its ``CommandResult`` / ``WorkerError`` will carry (:meth:`track` it). 0 after shutdown:
        nothing was queued. A :class:`~app.link.ops.Stop` is written at once on the stop line
        when there is one and goes before every queued job."""
        if isinstance(op, Stop):
            self._state.note_stop()  # counted even after shutdown: state.stops_requested
        if self._shut:
            return 0
        request_id = self._worker.submit(op)
        if op.tracks_motion and request_id:
            self._motions[request_id] = op.operation
        return request_id

    # --- shutdown -----------------------------------------------------------------------
    @Slot()
    def shutdown(self) -> None:
        """Stop jogging and close the client, without blocking the GUI on the network. Idempotent.

        The worker is asked with a queued call: it writes ratio 0 / teach disable, closes the
        client and quits its own thread. The GUI waits at most :data:`app.timing.SHUTDOWN_WAIT`;
        a worker still inside a network call (a dead controller) finishes on its own, and its
        thread is kept referenced until it has ended: a running QThread is never destroyed."""
        if self._shut:
            return
        self._shut = True
        self._motions.clear()
        thread = self._thread
        if not thread.isRunning():
            return
        worker = self._made
        self._shutdownRequested.emit()  # queued: runs once the transaction in flight is over
        if worker is None:  # never made: nothing was sent, no link to close, only the thread
            thread.quit()
        wait_ms = max(1, round(timing.SHUTDOWN_WAIT * 1000))
        if not thread.wait(wait_ms) and worker is not None:
            _log.warning(
                "the robot worker is still inside a network call after %d ms; "
                "it ends on its own in the background",
                wait_ms,
            )
            _keep_until_finished(thread, worker)


# Threads still running after shutdown's wait, kept referenced until they end (GUI thread only).
_detached: list[tuple[QThread, QObject]] = []


class _Reaper(QObject):
    """Lives in the GUI thread; drops the references to detached threads once they ended."""

    @Slot()
    def reap(self) -> None:
        ended = self.sender()
        for entry in list(_detached):
            thread = entry[0]
            # ``finished`` is emitted right before the thread ends: waiting for it is short.
            if (thread is ended or thread.isFinished()) and thread.wait(1000):
                _detached.remove(entry)


_reaper: _Reaper | None = None


def _keep_until_finished(thread: QThread, worker: QObject) -> None:
    global _reaper
    if _reaper is None:
        _reaper = _Reaper()
    _detached.append((thread, worker))
    thread.finished.connect(_reaper.reap, Qt.ConnectionType.QueuedConnection)


def wait_for_detached_threads(timeout: float) -> bool:
    """At the very end of the program: wait up to ``timeout`` s for detached worker threads.
    True when none is left running."""
    deadline_ms = max(1, round(timeout * 1000))
    ok = all(thread.wait(deadline_ms) for thread, _ in list(_detached))
    if ok:
        _detached.clear()
    return ok
