"""The link to the controller for the GUI: a worker in its own QThread, and its facade.

:class:`RobotWorker` lives in a ``QThread`` and is the only owner of the :class:`RobotClient`
(created in the worker thread, like its timers). It polls pose and status, emits one typed
signal per datum only when the datum changed, and runs the operator's commands from a
thread-safe queue: the GUI thread never waits for the network.

* **Urgent jobs** (stop, pause, resume, jog release) jump ahead of everything: they are checked
  between any two transactions (between the pose and the status read of a poll, between the
  steps of a jog sequence, while a short teach command completes, between uploaded points),
  and the GUI wakes the worker with a queued call, so a stop goes out right after the
  transaction in flight. A stop also cancels the motion jobs queued before it (and ends a
  running upload), and a jog release drops a jog press that has not started yet.
* **Long commands** (step, move to point, go to zero, run program, create point) are started
  without waiting; the regular polls feed their :class:`CommandTracker` (or, for the two
  commands without GV291, a watch on program state and pose) until a
  :class:`CommandResult` comes out. Only one motion is tracked at a time: a motion requested
  while another is under way is refused, Stop clears it.
* **Jog** (function 4) is a small state machine, see :meth:`RobotWorker._do_jog_press`.
  Release writes ratio 0 and keeps teach enabled; teach is disabled after
  :data:`TEACH_IDLE_DISABLE` s without a jog, before any other motion, on disconnect and on
  shutdown. When the link comes back after a loss, the worker writes ratio 0 and teach disable
  before anything else, because a real controller keeps jogging when its master goes away.
* **Link loss**: :data:`app.timing.LINK_LOSS_POLLS` failed transactions in a row declare the
  link down (``connectionChanged(DOWN)`` at once); reconnection follows
  :data:`app.timing.RECONNECT_BACKOFF` by itself and ends with ``controllerReconnected``.

* **Request ids**: every :class:`RobotLink` command returns an ``int`` id; each
  :class:`CommandResult` / :class:`WorkerError` that request causes carries it (``request_id``).
* **Uploads** (``upload_points`` of ``(id, pose6, tool)`` items) are grouped by tool frame and run
  in chunks (:data:`UPLOAD_CHUNK_POINTS` points or :data:`UPLOAD_CHUNK_SECONDS` per event-loop
  turn), so polls and queued calls keep flowing; ``pointUploaded`` per point, ``uploadProgress``
  at most every :data:`UPLOAD_PROGRESS_PERIOD`, one final ``commandFinished``. ``cancel_upload``
  ends it between points without a controller stop; a stop ends it too.
* **Restart canary**: a random token in a spare GV (:data:`DEFAULT_CANARY_GV`), read back on the
  clock poll; a change means the controller restarted under a live link: ``controllerRestarted``.

See docs/DESIGN.md, "Worker / RobotLink", for the whole contract.

Errors: every failure becomes a signal, never an exception in the GUI thread.
``commandFinished`` carries the outcome of every command that reached the controller (success,
refusal, Modbus exception, timeout, stop); ``errorOccurred`` carries everything else (link
down, monitor-only refusals, invalid input, failed reads), in plain English.

:class:`RobotLink` is the GUI-thread facade: it owns the thread and the worker, offers plain
methods, re-exposes the worker's signals and shuts everything down with a blocking queued call.
"""

from __future__ import annotations

import dataclasses
import enum
import itertools
import logging
import math
import random
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Protocol

from PySide6.QtCore import QCoreApplication, QObject, Qt, QTimer, Signal, Slot

from app import timing
from app.errors import (
    CommandRefused,
    InvalidInput,
    LinkError,
    ModbusExceptionError,
    ResponseTimeout,
    TeachPadError,
    WriteBlocked,
)
from app.link.client import ConnectionSettings, RobotClient, StepFrame, TrafficRecord
from app.link.tracker import CommandTracker, pose_moved
from app.link.types import ConnectionState, JogRequest, LinkState, Operation, WorkerError
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol import registers
from app.protocol.enums import (
    ControllerMode,
    ProgramMotionMode,
    ProgramState,
    RunCommand,
    TeachFrame,
    WorkMode,
    alarm_names,
    controller_mode_text,
)

__all__ = [
    "DEFAULT_CANARY_GV",
    "RTT_REPORT_PERIOD",
    "SHUTDOWN_TIMEOUT_MS",
    "TEACH_IDLE_DISABLE",
    "UPLOAD_CHUNK_POINTS",
    "UPLOAD_CHUNK_SECONDS",
    "UPLOAD_PROGRESS_PERIOD",
    "RobotWorker",
]

_log = logging.getLogger(__name__)
_FLOAT32_MAX = 3.4028234663852886e38

# Timing of the worker (module constants so tests can shrink them; read at use time).
RTT_REPORT_PERIOD = 0.5  # s between rttChanged emissions (mean of the period's transactions)
TEACH_IDLE_DISABLE = 30.0  # s after the last jog release before teach mode is disabled
TEACH_MODE_GRACE = 0.3  # s after teach enable during which a status without mode 2 is not "teach lost"
SHUTDOWN_TIMEOUT_MS = 10_000  # ms to wait for the worker thread to end
UPLOAD_CHUNK_POINTS = 20  # points per event-loop turn of an upload, at most ...
UPLOAD_CHUNK_SECONDS = 0.03  # ... or this long (s), whichever comes first
UPLOAD_PROGRESS_PERIOD = 0.05  # s between uploadProgress emissions (the last one always goes out)

#: The spare general-purpose GV holding the restart canary (registers 198-199); None disables it.
DEFAULT_CANARY_GV: int | None = 99
UPLOAD_POSE_GV = 0  # an upload passes each pose in GV0..GV5 (case 2.2)


# --------------------------------------------------------------------------------------------
# The job queue (the only state shared between the GUI thread and the worker thread)
# --------------------------------------------------------------------------------------------


class _JobKind(enum.Enum):
    URGENT = "urgent"  # stop / pause / resume / jog release: ahead of everything
    MOTION = "motion"  # cancelled by a stop queued after it
    PLAIN = "plain"


@dataclass
class _Job:
    operation: str
    run: Callable[[], None]
    kind: _JobKind
    seq: int = 0
    request_id: int = 0
    coalesce: str | None = None  # a newer job with the same key replaces a queued one
    needs_link: bool = True
    cancels: tuple[str, ...] = ()  # an urgent job drops the queued jobs with these coalesce keys


_JOG_PRESS = "jog press"
_JOG_RATIO = "jog ratio"


class _JobQueue:
    """Two deques under one lock; urgent jobs first. Safe to call from any thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._urgent: deque[_Job] = deque()
        self._normal: deque[_Job] = deque()
        self._seq = itertools.count(1)
        self._ids = itertools.count(1)

    def put(self, job: _Job) -> int:
        """Queue ``job``; returns its request id (unique, increasing, never 0). A coalesced job
        takes the place of the queued one it replaces, which then never runs (and has no result)."""
        with self._lock:
            job.seq = next(self._seq)
            job.request_id = next(self._ids)
            if job.kind is _JobKind.URGENT:
                if job.cancels:  # e.g. a release drops a press still waiting: it must never start
                    self._normal = deque(q for q in self._normal if q.coalesce not in job.cancels)
                self._urgent.append(job)
                return job.request_id
            if job.coalesce is not None:
                for i, queued in enumerate(self._normal):
                    if queued.coalesce == job.coalesce:
                        job.seq = queued.seq  # keep its place in the queue
                        self._normal[i] = job
                        return job.request_id
            self._normal.append(job)
            return job.request_id

    def pop_urgent(self) -> _Job | None:
        with self._lock:
            return self._urgent.popleft() if self._urgent else None

    def pop(self) -> _Job | None:
        with self._lock:
            if self._urgent:
                return self._urgent.popleft()
            return self._normal.popleft() if self._normal else None

    def cancel(self, predicate: Callable[[_Job], bool]) -> list[_Job]:
        """Remove and return the queued normal jobs matching ``predicate``."""
        with self._lock:
            cancelled = [job for job in self._normal if predicate(job)]
            if cancelled:
                self._normal = deque(job for job in self._normal if not predicate(job))
            return cancelled

    def clear(self) -> list[_Job]:
        with self._lock:
            jobs = [*self._urgent, *self._normal]
            self._urgent.clear()
            self._normal.clear()
            return jobs


# --------------------------------------------------------------------------------------------
# Completion of commands without GV291 (run program, go to zero)
# --------------------------------------------------------------------------------------------


class _Completion(Protocol):
    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None: ...

    def stopped(self, now: float) -> CommandResult: ...


class _MotionWatch:
    """Program state and pose decide how a program run / go to zero ended (GV291 is not used).

    Started once the program state shows running/paused or the pose moves; done once it reads
    stopped with the pose standing still. No sign of motion within ``timing.ACK_TIMEOUT``
    means the controller did not start it (refused, or already there).
    """

    def __init__(self, command: RunCommand | None, text: str, before_pose: Pose | None, now: float) -> None:
        self.command = command
        self.text = text
        self.started = now
        self.ack_timeout = timing.ACK_TIMEOUT
        self._before_pose = before_pose
        self._last_pose = before_pose
        self._seen = False

    def _result(self, ok: bool, message: str, now: float) -> CommandResult:
        return CommandResult(self.command, None, None, ok, message, {"elapsed": now - self.started})

    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None:
        if status.alarms:
            names = ", ".join(alarm_names(int(status.alarms)))
            return self._result(False, f"{self.text}: alarm: {names}", now)
        running = status.program_state in (ProgramState.RUNNING, ProgramState.PAUSED)
        moved = pose is not None and self._last_pose is not None and pose_moved(pose, self._last_pose)
        if pose is not None:
            self._last_pose = pose
        if not self._seen:
            if running or moved:
                self._seen = True
            elif now - self.started >= self.ack_timeout:
                return self._result(
                    False, f"{self.text}: no motion within {self.ack_timeout:g} s "
                    "(refused by the controller, or already there)", now)
            return None
        if not running and not moved:
            return self._result(True, f"{self.text}: done", now)
        return None

    def stopped(self, now: float) -> CommandResult:
        return self._result(False, f"{self.text} stopped by the host", now)


@dataclass
class _Active:
    operation: str
    completion: _Completion
    motion: bool  # a motion (blocks other motions) rather than a short command
    request_id: int | None = None


UploadItem = tuple[int, tuple[float, ...], int]  # (point id, pose X Y Z A B C, tool frame)


@dataclass
class _UploadRun:
    """An upload under way: processed a chunk per event-loop turn (see ``RobotWorker._upload_step``)."""

    request_id: int | None
    items: list[UploadItem]  # grouped by tool frame: GV245 is written once per group
    index: int = 0  # items attempted so far
    good: int = 0
    end: str | None = None  # why it ends early ("cancelled", "stopped", "link lost: ..."), once set
    progress_at: float = 0.0  # when uploadProgress was last emitted
    progress_done: int = -1  # the ``done`` it carried


def group_by_tool(items: Iterable[UploadItem]) -> list[UploadItem]:
    """Stable grouping: the tools in order of first appearance, each tool's points in input order."""
    groups: dict[int, list[UploadItem]] = {}
    for item in items:
        groups.setdefault(item[2], []).append(item)
    return [item for group in groups.values() for item in group]


@dataclass
class _TeachState:
    enabled: bool = False  # we enabled teach mode and have not seen it end
    frame_key: tuple[TeachFrame, int, int] | None = None
    axis: tuple[int, int] | None = None  # (axis, direction) last written
    ratio: float = 0.0  # last GV203 we wrote
    enabled_at: float = 0.0


class _PreemptedError(Exception):
    """A jog sequence gave way to an urgent job (release / stop) or to a link loss."""


# --------------------------------------------------------------------------------------------
# The worker
# --------------------------------------------------------------------------------------------


class RobotWorker(QObject):
    """Owns the RobotClient in the worker thread; see the module docstring."""

    poseChanged = Signal(Pose)  # noqa: N815
    statusChanged = Signal(ControllerStatus)  # noqa: N815
    alarmsChanged = Signal(int)  # noqa: N815
    connectionChanged = Signal(ConnectionState)  # noqa: N815
    rttChanged = Signal(float)  # noqa: N815 - ms, mean over RTT_REPORT_PERIOD
    commandFinished = Signal(CommandResult)  # noqa: N815
    errorOccurred = Signal(WorkerError)  # noqa: N815
    trafficObserved = Signal(list)  # noqa: N815 - list[TrafficRecord], one batch per poll, only while capturing
    controllerReconnected = Signal()  # noqa: N815
    controllerRestarted = Signal()  # noqa: N815 - the canary GV changed while the link stayed up
    uploadProgress = Signal(int, int)  # noqa: N815 - points done, total
    pointUploaded = Signal(int, bool, str)  # noqa: N815 - point id, ok, reason ("" when ok)
    # provided by the worker split (declared here so robot-state can consume them before the merge)
    pollSucceeded = Signal(float)  # noqa: N815 - time.monotonic() of a good poll, after its pose/status
    linkStatsChanged = Signal(object)  # noqa: N815 - LinkStats snapshot, at most 2 Hz

    # Wakes the worker from any thread (a queued call, since the worker lives in its thread).
    _wake = Signal()
    # The next chunk of an upload, one event-loop turn later (polls and queued calls in between).
    _uploadStep = Signal()  # noqa: N815

    def __init__(self, poll_hz: float = timing.POLL_HZ_DEFAULT, *,
                 canary_gv: int | None = DEFAULT_CANARY_GV) -> None:
        super().__init__()
        if canary_gv is not None and not (UPLOAD_POSE_GV + 6 <= canary_gv <= registers.GV_GENERAL_LAST):
            raise ValueError(f"the restart canary must be a spare general-purpose GV in "
                             f"GV{UPLOAD_POSE_GV + 6}..GV{registers.GV_GENERAL_LAST} (uploads use "
                             f"GV{UPLOAD_POSE_GV}..GV{UPLOAD_POSE_GV + 5}), got GV{canary_gv}")
        self._poll_hz = float(poll_hz)
        self._canary_gv = canary_gv
        self._jobs = _JobQueue()
        self._wake.connect(self._on_wake, Qt.ConnectionType.QueuedConnection)
        self._uploadStep.connect(self._upload_step, Qt.ConnectionType.QueuedConnection)
        # Everything below is touched only in the worker thread.
        self._client: RobotClient | None = None
        self._settings: ConnectionSettings | None = None
        self._poll_timer: QTimer | None = None
        self._reconnect_timer: QTimer | None = None
        self._state = ConnectionState(LinkState.DISCONNECTED)
        self._link_up = False
        self._ever_connected = False
        self._failures = 0
        self._backoff_index = 0
        self._closed = False
        self._in_urgent = False
        self._last_pose: Pose | None = None
        self._last_status: ControllerStatus | None = None
        self._last_alarms: int | None = None
        self._next_clock = 0.0
        self._poll_error: str | None = None
        self._active: _Active | None = None
        self._teach = _TeachState()
        self._teach_dirty = False  # teach may be on at the controller though we could not switch it off
        self._jog: JogRequest | None = None
        self._jog_serial = 0
        self._released_at = 0.0
        self._capture = False
        self._traffic: list[TrafficRecord] = []
        self._rtt_sum = 0.0
        self._rtt_count = 0
        self._rtt_since = 0.0
        self._last_rtt: float | None = None
        self._stats_sent = 0.0  # provided by the worker split: monotonic time of the last linkStatsChanged
        self._last_poll = 0.0
        self._current_seq = 0  # sequence number of the job being executed
        self._request_id: int | None = None  # request id of the job being executed
        self._upload: _UploadRun | None = None
        self._upload_busy = False  # inside a chunk (client.upload_points is running)
        self._canary_token: float | None = None  # what we wrote to the canary GV (None: not checking)
        self._random = random.Random()

    # --- lifecycle (worker thread) ------------------------------------------------------
    @Slot()
    def start(self) -> None:
        """Run by ``QThread.started``: the timers are created here, in the worker thread."""
        self._poll_timer = QTimer(self)
        self._poll_timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._poll_timer.setInterval(self._poll_interval_ms())
        self._poll_timer.timeout.connect(self._on_tick)
        self._reconnect_timer = QTimer(self)
        self._reconnect_timer.setSingleShot(True)
        self._reconnect_timer.timeout.connect(self._try_connect)

    @Slot(object)
    def connect_to(self, settings: ConnectionSettings) -> None:
        """(Re)connect with ``settings``; retries by itself until :meth:`disconnect`."""
        if self._closed:
            return
        # Jobs queued since the GUI asked for this connection run once it is up.
        self._close_link(Operation.CONNECT, LinkState.DISCONNECTED, "", emit=False, fail_queued=False)
        self._settings = settings
        self._client = RobotClient(settings)
        if self._capture:
            self._client.add_observer(self._on_traffic)
        self._ever_connected = False
        self._backoff_index = 0
        self._teach = _TeachState()
        self._teach_dirty = False
        self._set_state(LinkState.CONNECTING, "")
        self._try_connect()

    @Slot()
    def disconnect_link(self) -> None:
        """Stop jogging, switch teach off, close the link, stop retrying."""
        if self._closed:
            return
        self._close_link(Operation.DISCONNECT, LinkState.DISCONNECTED, "")

    @Slot()
    def shutdown(self) -> None:
        """Called with a blocking queued connection: stop motion, close, hand the object back."""
        if self._closed:
            return
        self._close_link(Operation.SHUTDOWN, LinkState.DISCONNECTED, "")
        self._closed = True
        for timer in (self._poll_timer, self._reconnect_timer):
            if timer is not None:
                timer.stop()
        app = QCoreApplication.instance()
        if app is not None:
            # Back to the GUI thread so the object (and its stopped timers) dies there cleanly.
            self.moveToThread(app.thread())

    @Slot(float)
    def set_poll_rate(self, hz: float) -> None:
        if hz <= 0 or self._closed:
            return
        self._poll_hz = float(hz)
        if self._poll_timer is not None:
            self._poll_timer.setInterval(self._poll_interval_ms())

    @Slot(bool)
    def set_traffic_capture(self, on: bool) -> None:
        if self._closed or on == self._capture:
            return
        self._capture = on
        self._traffic.clear()
        if self._client is not None:
            if on:
                self._client.add_observer(self._on_traffic)
            else:
                self._client.remove_observer(self._on_traffic)

    def _poll_interval_ms(self) -> int:
        return max(1, round(1000.0 / self._poll_hz))

    # --- requests (any thread) ----------------------------------------------------------
    def post(self, operation: str, run: Callable[[], None], kind: _JobKind = _JobKind.PLAIN,
             *, coalesce: str | None = None, needs_link: bool = True, cancels: tuple[str, ...] = ()) -> int:
        """Queue a job and wake the worker; returns the request id its results will carry."""
        request_id = self._jobs.put(_Job(operation, run, kind, coalesce=coalesce, needs_link=needs_link,
                                         cancels=cancels))
        self._wake.emit()
        return request_id

    def request_stop(self) -> int:
        return self.post(Operation.STOP, self._do_stop, _JobKind.URGENT)

    def request_pause(self) -> int:
        return self.post(Operation.PAUSE, self._do_pause, _JobKind.URGENT)

    def request_resume(self) -> int:
        return self.post(Operation.RESUME, self._do_resume, _JobKind.URGENT)

    def request_jog_press(self, request: JogRequest) -> int:
        return self.post(Operation.JOG, lambda: self._do_jog_press(request), _JobKind.MOTION,
                         coalesce=_JOG_PRESS)

    def request_jog_release(self) -> int:
        return self.post(Operation.JOG_RELEASE, self._do_jog_release, _JobKind.URGENT, needs_link=False,
                         cancels=(_JOG_PRESS, _JOG_RATIO))

    def request_jog_ratio(self, ratio: float) -> int:
        return self.post(Operation.JOG_SPEED, lambda: self._do_jog_ratio(ratio), _JobKind.MOTION,
                         coalesce=_JOG_RATIO)

    def request_step(self, frame: StepFrame, offsets: Sequence[float], ext_offsets: Sequence[float],
                     speed: float) -> int:
        offs, ext = tuple(offsets), tuple(ext_offsets)
        return self.post(Operation.STEP, lambda: self._do_step(frame, offs, ext, speed), _JobKind.MOTION)

    def request_set_mode(self, mode: WorkMode) -> int:
        return self.post(Operation.SET_MODE, lambda: self._do_set_mode(mode))

    def request_go_zero(self, axis: int | None) -> int:
        return self.post(Operation.GO_ZERO, lambda: self._do_go_zero(axis), _JobKind.MOTION)

    def request_run_program(self, program_id: int, mode: ProgramMotionMode, cycles: int,
                            speed_ratio: int) -> int:
        return self.post(Operation.RUN_PROGRAM,
                         lambda: self._do_run_program(program_id, mode, cycles, speed_ratio), _JobKind.MOTION)

    def request_create_point(self, point_id: int, pose: Sequence[float] | None, tool: int) -> int:
        values = None if pose is None else tuple(pose)
        return self.post(Operation.CREATE_POINT, lambda: self._do_create_point(point_id, values, tool))

    def request_move_to_point(self, end_id: int, via_id: int | None, orientation_changes: bool,
                              ignore_middle: bool, speed: float, tool: int) -> int:
        return self.post(Operation.MOVE_TO_POINT,
                         lambda: self._do_move_to_point(end_id, via_id, orientation_changes, ignore_middle,
                                                        speed, tool),
                         _JobKind.MOTION)

    def request_upload_points(self, points: Iterable[tuple[int, Sequence[float], int]]) -> int:
        """Items (id, pose6, tool); copied here, checked in the worker before the first write."""
        items: list[tuple[object, tuple[object, ...], object]] = [
            (pid, tuple(pose), tool) for pid, pose, tool in points]
        return self.post(Operation.UPLOAD_POINTS, lambda: self._do_upload_points(items), _JobKind.MOTION)

    def request_cancel_upload(self) -> int:
        """End the running upload after the point in progress, without a controller stop."""
        return self.post(Operation.CANCEL_UPLOAD, self._do_cancel_upload, _JobKind.URGENT, needs_link=False)

    # --- connection (worker thread) -----------------------------------------------------
    def _set_state(self, state: LinkState, message: str) -> None:
        settings = self._settings
        new = ConnectionState(state, message, settings.endpoint if settings else "",
                              bool(settings and settings.monitor_only))
        if new != self._state:
            self._state = new
            self.connectionChanged.emit(new)

    @Slot()
    def _try_connect(self) -> None:
        """One connection attempt: open, read status and pose, make jogging safe, go live."""
        client = self._client
        if self._closed or client is None or self._link_up:
            return
        try:
            client.close()
            client.connect()
            status = client.read_status(with_clock=True)
            pose = client.read_pose()
            if self._ever_connected or status.mode == ControllerMode.MODBUS_TEACH:
                self._make_teach_safe(status)
        except TeachPadError as exc:
            self._schedule_reconnect(str(exc))
            return
        self._link_up = True
        self._failures = 0
        self._backoff_index = 0
        self._poll_error = None
        now = time.monotonic()
        self._next_clock = now + timing.CLOCK_POLL_PERIOD
        self._rtt_since = now
        reconnected = self._ever_connected
        self._ever_connected = True
        self._arm_canary()  # before the GUI hears of the link: a restart from now on is noticed
        self._set_state(LinkState.CONNECTED, "")
        self._publish(pose, status)
        if reconnected:
            self.controllerReconnected.emit()
        if self._poll_timer is not None:
            self._poll_timer.start(self._poll_interval_ms())
        self._run_jobs()

    def _arm_canary(self) -> None:
        """Write a fresh random token to the canary GV (not in monitor-only mode, not when disabled)."""
        self._canary_token = None
        client = self._client
        gv = self._canary_gv
        if gv is None or client is None or client.settings.monitor_only:
            return
        token = float(self._random.randint(1, 1 << 23))  # nonzero, exact in float32
        try:
            client.write_gv(gv, [token])
        except TeachPadError as exc:
            self._emit_error(Operation.CANARY, f"could not write the restart canary GV{gv}: {exc}", None)
            if isinstance(exc, (LinkError, ResponseTimeout)):
                self._transport_failed(str(exc))
            return
        self._canary_token = token

    def _canary_changed(self, value: float) -> None:
        """The canary GV no longer holds our token: the controller restarted under a live link."""
        _log.warning("restart canary GV%s reads %g instead of %g: the controller restarted",
                     self._canary_gv, value, self._canary_token)
        if self._client is not None:
            self._client.invalidate_cache()  # GV245 and friends may have been reset too
        self.controllerRestarted.emit()
        self._arm_canary()

    def _make_teach_safe(self, status: ControllerStatus) -> None:
        """On (re)connection: a jog left running by a lost link is stopped before anything else."""
        client = self._client
        assert client is not None
        maybe_on = self._teach.enabled or self._teach_dirty or status.mode == ControllerMode.MODBUS_TEACH
        self._end_jog()
        if not maybe_on or client.settings.monitor_only:
            return
        self._teach_dirty = True
        self._stop_jog_and_teach()

    def _schedule_reconnect(self, message: str) -> None:
        backoff = timing.RECONNECT_BACKOFF
        delay = backoff[min(self._backoff_index, len(backoff) - 1)]
        self._backoff_index += 1
        self._set_state(LinkState.DOWN, message)
        if self._reconnect_timer is not None and not self._closed:
            self._reconnect_timer.start(max(1, round(delay * 1000)))

    def _link_lost(self, message: str) -> None:
        """Declare the link down at once; the reconnect timer takes over."""
        if not self._link_up:
            return
        self._link_up = False
        self._failures = 0
        if self._poll_timer is not None:
            self._poll_timer.stop()
        if self._teach.enabled or self._jog is not None:
            self._teach_dirty = True  # a real controller keeps jogging: switch it off on return
        self._end_jog()
        self._teach = _TeachState()
        self._canary_token = None
        self._end_upload(f"link lost: {message}")
        self._fail_active("link lost while the command was under way; its outcome is unknown")
        self._fail_queued("the link to the controller is down")
        if self._client is not None:
            self._client.close()
        self._backoff_index = 0
        self._schedule_reconnect(f"link lost: {message}")

    def _close_link(self, operation: str, state: LinkState, message: str, *, emit: bool = True,
                    fail_queued: bool = True) -> None:
        if self._reconnect_timer is not None:
            self._reconnect_timer.stop()
        if self._poll_timer is not None:
            self._poll_timer.stop()
        client = self._client
        if client is not None and self._link_up and not client.settings.monitor_only:
            try:
                self._stop_jog_and_teach()
            except TeachPadError as exc:
                self._emit_error(operation, f"could not stop teach mode: {exc}", None)
        self._canary_token = None
        self._end_upload(f"{operation}: the link was closed")
        self._fail_active(f"{operation}: the link was closed while the command was under way")
        if fail_queued:
            self._fail_queued(f"{operation}: the link was closed")
        self._link_up = False
        if client is not None:
            client.remove_observer(self._on_traffic)
            client.close()
        self._client = None
        self._last_pose = None
        self._last_status = None
        self._last_alarms = None
        self._last_rtt = None
        if emit:
            self._set_state(state, message)

    def _end_jog(self) -> None:
        """Forget the held jog; a jog sequence still running for it gives way."""
        if self._jog is not None:
            self._released_at = time.monotonic()
        self._jog = None
        self._jog_serial += 1

    def _stop_jog_and_teach(self) -> None:
        """Jog ratio 0 and teach disable, if we may have teach on (no urgent jobs in between:
        used while connecting, closing and from the idle timer)."""
        self._end_jog()
        if not (self._teach.enabled or self._teach_dirty):
            return
        client = self._client
        assert client is not None
        client.teach_set_ratio(0.0)
        self._teach.ratio = 0.0
        client.teach_disable(wait=False)
        self._teach = _TeachState()
        self._teach_dirty = False
        tracker = client.last_tracker
        assert tracker is not None
        result = self._await_short(tracker, urgent=False)
        if not result.ok:
            self._emit_result(result)

    # --- job execution (worker thread) --------------------------------------------------
    @Slot()
    def _on_wake(self) -> None:
        if not self._closed:
            self._run_jobs()

    def _run_jobs(self) -> None:
        while not self._closed:
            job = self._jobs.pop()
            if job is None:
                return
            self._execute(job)

    def _run_urgent(self) -> bool:
        """Run the urgent jobs queued now; True if any ran. Never re-entered."""
        if self._in_urgent or self._closed:
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

    def _execute(self, job: _Job) -> None:
        if job.needs_link and not self._link_up:
            self._emit_error(job.operation, "not connected to a controller", job.request_id)
            return
        outer_seq, self._current_seq = self._current_seq, job.seq
        outer_id, self._request_id = self._request_id, job.request_id
        try:
            job.run()
        except _PreemptedError:
            pass
        except WriteBlocked as exc:
            self._emit_error(job.operation, str(exc))
        except (LinkError, ResponseTimeout) as exc:
            self._emit_error(job.operation, str(exc))
            self._transport_failed(str(exc))
        except ModbusExceptionError as exc:
            self._emit_result(CommandResult(None, None, None, False, f"{job.operation}: {exc}"))
        except CommandRefused as exc:
            self._emit_result(CommandResult(None, exc.status.kind, exc.status, False, str(exc)))
        except TeachPadError as exc:  # InvalidInput and the rest
            self._emit_error(job.operation, str(exc))
        except Exception as exc:  # a bug: report it plainly, keep the worker alive
            _log.exception("%s failed", job.operation)
            message = f"internal error: {type(exc).__name__}: {exc}"
            self._emit_error(job.operation, message)
        finally:
            self._current_seq = outer_seq
            self._request_id = outer_id

    def _emit_result(self, result: CommandResult, request_id: int | None = -1) -> None:
        """``commandFinished`` with the request id (default: the job being executed)."""
        rid = self._request_id if request_id == -1 else request_id
        if result.request_id is None and rid is not None:
            result = dataclasses.replace(result, request_id=rid)
        self.commandFinished.emit(result)

    def _emit_error(self, operation: str, message: str, request_id: int | None = -1) -> None:
        """``errorOccurred`` with the request id (default: the job being executed)."""
        rid = self._request_id if request_id == -1 else request_id
        self.errorOccurred.emit(WorkerError(operation, message, rid))

    def _transport_failed(self, message: str) -> None:
        self._failures += 1
        if self._failures >= timing.LINK_LOSS_POLLS:
            self._link_lost(message)

    def _fail_queued(self, message: str) -> None:
        for job in self._jobs.clear():
            if job.needs_link:
                self._emit_error(job.operation, message, job.request_id)

    def _fail_active(self, message: str) -> None:
        active, self._active = self._active, None
        if active is not None:
            self._failed(f"{active.operation}: {message}", active.request_id)

    def _client_or_raise(self) -> RobotClient:
        if self._client is None or not self._link_up:
            raise LinkError("not connected to a controller")
        return self._client

    def _require_no_motion(self, operation: str) -> None:
        active = self._active
        if active is not None and active.motion:
            raise InvalidInput(f"{active.operation} is still under way: wait for it or press Stop")
        if self._upload is not None:
            raise InvalidInput(f"{Operation.UPLOAD_POINTS} is still under way: wait for it, cancel it "
                               "or press Stop")

    def _track(self, operation: str, completion: _Completion, *, motion: bool) -> None:
        self._active = _Active(operation, completion, motion, self._request_id)

    # --- plain and urgent commands ------------------------------------------------------
    def _done(self, text: str) -> None:
        self._emit_result(CommandResult(None, None, None, True, text))

    def _failed(self, text: str, request_id: int | None = -1) -> None:
        self._emit_result(CommandResult(None, None, None, False, text), request_id)

    def _do_stop(self) -> None:
        client = self._client_or_raise()
        client.stop()  # first: nothing else goes out before the stop
        now = time.monotonic()
        self._end_upload("stopped")
        self._end_jog()
        if self._teach.enabled and self._teach.ratio != 0.0:
            client.teach_set_ratio(0.0)
            self._teach.ratio = 0.0
        active, self._active = self._active, None
        stop_seq = self._current_seq
        for job in self._jobs.cancel(lambda j: j.kind is _JobKind.MOTION and j.seq < stop_seq):
            self._failed(f"{job.operation}: cancelled by Stop", job.request_id)
        if active is not None:
            self._emit_result(active.completion.stopped(now), active.request_id)
        self._done("stop: sent")

    def _do_cancel_upload(self) -> None:
        """No controller stop: the upload ends after the point in progress; queued uploads are dropped."""
        for job in self._jobs.cancel(lambda j: j.operation == Operation.UPLOAD_POINTS):
            self._failed(f"{job.operation}: cancelled", job.request_id)
        if self._upload is None:
            self._done(f"{Operation.CANCEL_UPLOAD}: no upload under way")
            return
        self._end_upload("cancelled")
        self._done(f"{Operation.CANCEL_UPLOAD}: the upload ends after the current point")

    def _do_pause(self) -> None:
        self._client_or_raise().pause()
        self._done("pause: sent")

    def _do_resume(self) -> None:
        self._client_or_raise().resume()
        self._done("resume: sent")

    def _do_set_mode(self, mode: WorkMode) -> None:
        mode = WorkMode(mode)
        client = self._client_or_raise()
        if mode is WorkMode.MANUAL:
            self._stop_jog_and_teach()
        client.set_work_mode(mode)
        self._done(f"work mode: {mode.name.lower()}")

    # --- jog (function 4) ---------------------------------------------------------------
    def _check_jog(self, serial: int) -> None:
        """Between two steps of a jog sequence: let urgent jobs in; stop if one ended this jog."""
        self._run_urgent()
        if serial != self._jog_serial or not self._link_up or self._closed:
            raise _PreemptedError

    def _do_jog_press(self, request: JogRequest) -> None:
        """The jog state machine (PROTOCOL.md case 4).

        * teach enabled with the same frame: same axis/direction -> only the ratio;
          other axis/direction -> ratio 0, GV201-202, ratio.
        * teach off, or another frame -> ratio 0 and disable (if it was on), then
          GV200-203 = (frame, axis, direction, 0), 0x80 (auto mode first if needed), wait for
          GV291 while servicing urgent jobs, then the ratio.
        A release or stop arriving in between ends the sequence before the ratio is written.
        """
        self._require_no_motion(Operation.JOG)
        client = self._client_or_raise()
        if not 0.0 < request.ratio <= 100.0:
            raise InvalidInput(f"jog speed must be 1..100 %, got {request.ratio:g}")
        self._jog = request
        self._jog_serial += 1
        serial = self._jog_serial
        teach = self._teach
        if teach.enabled and teach.frame_key == request.frame_key:
            if teach.axis != (request.axis, request.direction):
                client.teach_set_axis(request.axis, request.direction)  # ratio 0 first, then GV201-202
                teach.ratio = 0.0
                teach.axis = (request.axis, request.direction)
                self._check_jog(serial)
            if teach.ratio != request.ratio:
                client.teach_set_ratio(request.ratio)
                teach.ratio = request.ratio
            return
        if teach.enabled or self._teach_dirty:
            client.teach_set_ratio(0.0)
            teach.ratio = 0.0
            self._check_jog(serial)
            self._disable_teach()
            self._check_jog(serial)
        client.teach_enable(request.frame, request.axis, request.direction, user_frame=request.user,
                            tool_frame=request.tool, wait=False)
        self._teach = _TeachState(True, request.frame_key, (request.axis, request.direction), 0.0,
                                  time.monotonic())
        tracker = client.last_tracker
        assert tracker is not None
        result = self._await_short(tracker, urgent=True)  # a release meanwhile writes ratio 0
        if not result.ok:
            self._teach = _TeachState()
            # Refused: teach is off for sure. Stopped / timed out: it may be on, switch it off later.
            self._teach_dirty = not isinstance(tracker.error, CommandRefused)
            self._end_jog()
            self._emit_result(result)
            return
        self._check_jog(serial)
        client.teach_set_ratio(request.ratio)
        self._teach.ratio = request.ratio

    def _do_jog_release(self) -> None:
        """The dead-man: ratio 0, teach stays enabled (disabled later when idle)."""
        self._end_jog()
        self._released_at = time.monotonic()
        if not self._link_up or self._client is None:
            return
        if self._teach.enabled:
            self._client.teach_set_ratio(0.0)
            self._teach.ratio = 0.0

    def _do_jog_ratio(self, ratio: float) -> None:
        """Speed slider moved while jogging: GV203 changes the speed live."""
        jog = self._jog
        if jog is None:
            return
        if not 0.0 < ratio <= 100.0:
            raise InvalidInput(f"jog speed must be 1..100 %, got {ratio:g}")
        self._jog = dataclasses.replace(jog, ratio=ratio)
        if self._teach.enabled and self._teach.ratio != 0.0 and self._teach.ratio != ratio:
            self._client_or_raise().teach_set_ratio(ratio)
            self._teach.ratio = ratio

    def _disable_teach(self) -> None:
        """0x81 and wait for its GV291 (servicing urgent jobs); a refusal is reported and ends the job."""
        client = self._client_or_raise()
        client.teach_disable(wait=False)
        self._teach = _TeachState()
        self._teach_dirty = False
        tracker = client.last_tracker
        assert tracker is not None
        result = self._await_short(tracker, urgent=True)
        if not result.ok:
            self._teach_dirty = True
            self._emit_result(result)
            raise _PreemptedError

    def _leave_teach(self) -> None:
        """Before a motion of another kind: ratio 0 and teach disable (the controller refuses otherwise)."""
        status = self._last_status
        if not (self._teach.enabled or self._teach_dirty
                or (status is not None and status.mode == ControllerMode.MODBUS_TEACH)):
            return
        self._end_jog()
        self._client_or_raise().teach_set_ratio(0.0)
        self._disable_teach()

    def _await_short(self, tracker: CommandTracker, *, urgent: bool) -> CommandResult:
        """Status reads until a short command (teach enable/disable) ends -- the tracker's own
        timeouts bound this to a few seconds at worst; with ``urgent`` the urgent jobs (stop,
        release) run between two reads, so they are never held up."""
        client = self._client
        if client is None:
            raise LinkError("not connected to a controller")
        while True:
            result = tracker.update(client.read_status(), None, time.monotonic())
            if result is not None:
                return result
            if urgent:
                self._run_urgent()
                if not self._link_up or self._closed:
                    raise _PreemptedError
            time.sleep(timing.STATUS_POLL_INTERVAL)

    # --- long commands ------------------------------------------------------------------
    def _do_step(self, frame: StepFrame, offsets: Sequence[float], ext: Sequence[float],
                 speed: float) -> None:
        self._require_no_motion(Operation.STEP)
        client = self._client_or_raise()
        self._leave_teach()
        client.step(frame, offsets, ext, speed, wait=False)
        tracker = client.last_tracker
        assert tracker is not None
        self._track(Operation.STEP, tracker, motion=True)

    def _do_move_to_point(self, end_id: int, via_id: int | None, orientation_changes: bool,
                          ignore_middle: bool, speed: float, tool: int) -> None:
        self._require_no_motion(Operation.MOVE_TO_POINT)
        client = self._client_or_raise()
        self._leave_teach()
        client.move_to_point(end_id, via_id=via_id, orientation_changes=orientation_changes,
                             ignore_middle=ignore_middle, speed=speed, tool=tool, wait=False)
        tracker = client.last_tracker
        assert tracker is not None
        self._track(Operation.MOVE_TO_POINT, tracker, motion=True)

    def _do_go_zero(self, axis: int | None) -> None:
        self._require_no_motion(Operation.GO_ZERO)
        client = self._client_or_raise()
        self._leave_teach()
        before = self._last_pose
        client.go_zero(axis)
        which = "all axes" if axis is None else f"J{axis + 1}"
        self._track(Operation.GO_ZERO, _MotionWatch(None, f"go to zero ({which})", before, time.monotonic()),
                    motion=True)

    def _do_run_program(self, program_id: int, mode: ProgramMotionMode, cycles: int,
                        speed_ratio: int) -> None:
        self._require_no_motion(Operation.RUN_PROGRAM)
        client = self._client_or_raise()
        self._leave_teach()
        before = self._last_pose
        client.run_program(program_id, mode, cycles, speed_ratio)
        watch = _MotionWatch(RunCommand.RUN_PROGRAM, f"run program {program_id}", before, time.monotonic())
        self._track(Operation.RUN_PROGRAM, watch, motion=True)

    def _do_create_point(self, point_id: int, pose: Sequence[float] | None, tool: int) -> None:
        self._require_no_motion(Operation.CREATE_POINT)
        client = self._client_or_raise()
        client.create_point(point_id, pose=pose, tool=tool, wait=False)
        tracker = client.last_tracker
        assert tracker is not None
        self._track(Operation.CREATE_POINT, tracker, motion=False)

    def _do_upload_points(self, raw: list[tuple[object, tuple[object, ...], object]]) -> None:
        """Case 2.2 for many points, tool by tool; runs in chunks, see :meth:`_upload_step`."""
        self._require_no_motion(Operation.UPLOAD_POINTS)
        client = self._client_or_raise()
        if client.settings.monitor_only:
            raise WriteBlocked(f"monitor-only mode: {Operation.UPLOAD_POINTS} was not sent")
        items = group_by_tool(self._check_upload_items(client, raw))  # all checked before any write
        total = len(items)
        if not total:
            self._emit_result(CommandResult(RunCommand.CREATE_POINT, None, None, True,
                                            "uploaded 0 of 0 points", {"uploaded": 0.0, "total": 0.0}))
            return
        self._leave_teach()
        self._upload = _UploadRun(self._request_id, items)
        self._note_upload_progress(self._upload, force=True)
        self._uploadStep.emit()

    @staticmethod
    def _check_upload_items(client: RobotClient, raw: Sequence[tuple[object, tuple[object, ...], object]],
                            ) -> list[UploadItem]:
        lo, hi = client.settings.point_id_min, client.settings.point_id_max
        items: list[UploadItem] = []
        for pid, pose, tool in raw:
            if isinstance(pid, bool) or not isinstance(pid, int) or not lo <= pid <= hi:
                raise InvalidInput(f"point id must be an integer in {lo}..{hi}, got {pid!r}")
            if isinstance(tool, bool) or not isinstance(tool, int) or not 0 <= tool <= registers.TOOL_NONE:
                raise InvalidInput(f"tool frame of point {pid} must be 0..{registers.TOOL_NONE}, "
                                   f"got {tool!r}")
            if len(pose) != 6:
                raise InvalidInput(f"pose of point {pid} needs 6 values, got {len(pose)}")
            values: list[float] = []
            for v in pose:
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                        or abs(v) > _FLOAT32_MAX:
                    raise InvalidInput(f"pose of point {pid}: {v!r} is not a finite float32")
                values.append(float(v))
            items.append((pid, tuple(values), tool))
        return items

    @Slot()
    def _upload_step(self) -> None:
        """One chunk of the running upload (at most UPLOAD_CHUNK_POINTS points of one tool frame, or
        UPLOAD_CHUNK_SECONDS), then the next chunk is queued behind whatever arrived meanwhile."""
        upload = self._upload
        if upload is None or self._closed:
            return
        if upload.end is None and upload.index < len(upload.items) and self._link_up:
            if time.monotonic() - self._last_poll >= 1.0 / self._poll_hz:
                self._poll()  # keep the monitor live even if the event loop favours queued calls
            self._run_urgent()
            if upload.end is None and self._link_up and self._upload is upload:
                self._upload_chunk(upload)
        if self._upload is not upload:
            return  # ended meanwhile (link lost, closed)
        if upload.end is not None or upload.index >= len(upload.items) or not self._link_up:
            self._finish_upload()
        else:
            self._uploadStep.emit()

    def _upload_chunk(self, upload: _UploadRun) -> None:
        client = self._client
        assert client is not None
        start = time.monotonic()
        items = upload.items
        first = upload.index
        tool = items[first][2]
        last = first
        while last < len(items) and last - first < UPLOAD_CHUNK_POINTS and items[last][2] == tool:
            last += 1

        def progress(done: int, total: int) -> bool:
            self._run_urgent()  # stop / pause / cancel / jog release between two points
            if upload.end is not None or not self._link_up or self._closed:
                return False
            if time.monotonic() - self._last_poll >= 1.0 / self._poll_hz:
                self._poll()
            return self._link_up and time.monotonic() - start < UPLOAD_CHUNK_SECONDS

        transport_error: str | None = None
        self._upload_busy = True
        outer_id, self._request_id = self._request_id, upload.request_id
        try:
            chunk = [(pid, pose) for pid, pose, _ in items[first:last]]
            results = client.upload_points(chunk, tool, progress, gv_start=UPLOAD_POSE_GV)
        except (LinkError, ResponseTimeout) as exc:  # before the first point (status read, mode)
            results, transport_error = [], str(exc)
        except TeachPadError as exc:
            results = []
            upload.end = upload.end or str(exc)
        finally:
            self._upload_busy = False
            self._request_id = outer_id
        for (point_id, _, _), result in zip(items[first:], results, strict=False):
            upload.index += 1
            if result.ok:
                upload.good += 1
                self.pointUploaded.emit(point_id, True, "")
            else:
                self.pointUploaded.emit(point_id, False, result.message or "failed")
                if result.status is None:  # the link failed during this point: its outcome is unknown
                    transport_error = result.message
        if transport_error is not None:
            upload.end = upload.end or transport_error
            self._transport_failed(transport_error)
        self._note_upload_progress(upload)

    def _note_upload_progress(self, upload: _UploadRun, *, force: bool = False) -> None:
        now = time.monotonic()
        due = force or now - upload.progress_at >= UPLOAD_PROGRESS_PERIOD
        if upload.index != upload.progress_done and due:
            upload.progress_at = now
            upload.progress_done = upload.index
            self.uploadProgress.emit(upload.index, len(upload.items))

    def _end_upload(self, reason: str) -> None:
        """Ask the running upload to end before its next point (at once when between chunks)."""
        upload = self._upload
        if upload is None:
            return
        if upload.end is None:
            upload.end = reason
        if not self._upload_busy:
            self._finish_upload()

    def _finish_upload(self) -> None:
        """The batch's final commandFinished (after every pointUploaded), with the upload's request id."""
        upload, self._upload = self._upload, None
        if upload is None:
            return
        total = len(upload.items)
        self._note_upload_progress(upload, force=True)
        text = f"uploaded {upload.good} of {total} points" + (f" ({upload.end})" if upload.end else "")
        details = {"uploaded": float(upload.good), "attempted": float(upload.index), "total": float(total)}
        result = CommandResult(RunCommand.CREATE_POINT, None, None, upload.good == total, text, details)
        self._emit_result(result, upload.request_id)

    # --- polling ------------------------------------------------------------------------
    @Slot()
    def _on_tick(self) -> None:
        if self._closed or not self._link_up:
            return
        self._run_jobs()
        if self._link_up and not self._closed:
            self._poll()

    def _poll(self) -> None:
        """One poll; results emitted from here belong to no request (even inside a job)."""
        outer_id, self._request_id = self._request_id, None
        try:
            self._poll_once()
        finally:
            self._request_id = outer_id

    def _poll_once(self) -> None:
        client = self._client
        if client is None:
            return
        now = time.monotonic()
        self._last_poll = now
        with_clock = now >= self._next_clock
        canary: float | None = None
        try:
            t0 = time.perf_counter()
            pose = client.read_pose()
            t1 = time.perf_counter()
            self._run_urgent()  # a stop goes out between the two reads
            if not self._link_up:
                return
            t2 = time.perf_counter()
            status = client.read_status(with_clock=with_clock)
            t3 = time.perf_counter()
            if with_clock and self._canary_token is not None and self._canary_gv is not None:
                canary = client.read_gv(self._canary_gv)[0]  # the restart canary, on the slow clock
        except (LinkError, ResponseTimeout) as exc:
            self._report_poll_error(str(exc))
            self._transport_failed(str(exc))
            return
        except TeachPadError as exc:
            self._report_poll_error(str(exc))
            return
        self._failures = 0
        self._poll_error = None
        if with_clock:
            self._next_clock = now + timing.CLOCK_POLL_PERIOD
        elif self._last_status is not None:
            status = dataclasses.replace(status, clock=self._last_status.clock)
        self._note_rtt((t1 - t0) + (t3 - t2), 2, now)
        self._publish(pose, status)
        self.pollSucceeded.emit(now)  # provided by the worker split
        if now - self._stats_sent >= 0.5:  # provided by the worker split
            self._stats_sent = now
            self.linkStatsChanged.emit(client.stats)
        if canary is not None and canary != self._canary_token:
            self._canary_changed(canary)
        self._after_status(status, pose, now)
        self._flush_traffic()

    def _report_poll_error(self, message: str) -> None:
        if message != self._poll_error:  # once per distinct error, not 50 times a second
            self._poll_error = message
            self._emit_error(Operation.POLL, message)

    def _publish(self, pose: Pose, status: ControllerStatus) -> None:
        if pose != self._last_pose:
            self._last_pose = pose
            self.poseChanged.emit(pose)
        if status != self._last_status:
            self._last_status = status
            self.statusChanged.emit(status)
        alarms = int(status.alarms)
        if alarms != self._last_alarms:
            self._last_alarms = alarms
            self.alarmsChanged.emit(alarms)

    def _after_status(self, status: ControllerStatus, pose: Pose, now: float) -> None:
        active = self._active
        if active is not None:
            result = active.completion.update(status, pose, now)
            if result is not None:
                self._active = None
                if active.operation == Operation.CREATE_POINT and result.ok:
                    details = dict(result.details)
                    details.update(zip(("x", "y", "z", "a", "b", "c"), pose.xyzabc, strict=True))
                    result = dataclasses.replace(result, details=details)
                self._emit_result(result, active.request_id)
        teach = self._teach
        if teach.enabled and status.mode != ControllerMode.MODBUS_TEACH \
                and now - teach.enabled_at > TEACH_MODE_GRACE:
            self._teach = _TeachState()  # e-stop, manual, go to zero, program... ended it
            if self._jog is not None:
                self._end_jog()
                mode = controller_mode_text(int(status.mode))
                message = f"the controller left teach mode (mode now: {mode})"
                self._emit_error(Operation.JOG, message)
        elif (teach.enabled or self._teach_dirty) and self._jog is None and self._active is None \
                and now - self._released_at >= TEACH_IDLE_DISABLE:
            try:
                self._stop_jog_and_teach()
            except TeachPadError as exc:
                self._emit_error(Operation.TEACH_DISABLE, str(exc))

    def _note_rtt(self, seconds: float, transactions: int, now: float) -> None:
        self._rtt_sum += seconds
        self._rtt_count += transactions
        if now - self._rtt_since < RTT_REPORT_PERIOD or not self._rtt_count:
            return
        rtt = round(1000.0 * self._rtt_sum / self._rtt_count, 2)
        self._rtt_sum, self._rtt_count, self._rtt_since = 0.0, 0, now
        if rtt != self._last_rtt:
            self._last_rtt = rtt
            self.rttChanged.emit(rtt)

    def _on_traffic(self, record: TrafficRecord) -> None:
        if self._capture:
            self._traffic.append(record)

    def _flush_traffic(self) -> None:
        if self._capture and self._traffic:
            batch, self._traffic = self._traffic, []
            self.trafficObserved.emit(batch)


# --------------------------------------------------------------------------------------------
# The GUI-thread facade
# --------------------------------------------------------------------------------------------
