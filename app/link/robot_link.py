"""RobotLink: the GUI-thread facade of the worker (owns the thread, plain methods, shutdown)."""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence

from PySide6.QtCore import QCoreApplication, QObject, Qt, QThread, Signal, Slot

from app import timing
from app.link.client import ConnectionSettings, StepFrame
from app.link.types import ConnectionState, JogRequest, LinkState, WorkerError
from app.link.worker import DEFAULT_CANARY_GV, RobotWorker
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, TeachFrame, WorkMode

__all__ = ["RobotLink", "wait_for_detached_threads"]

_log = logging.getLogger(__name__)


class RobotLink(QObject):
    """Owns the worker thread; plain methods that never block on the network (except shutdown)."""

    poseChanged = Signal(Pose)  # noqa: N815
    statusChanged = Signal(ControllerStatus)  # noqa: N815
    alarmsChanged = Signal(int)  # noqa: N815
    connectionChanged = Signal(ConnectionState)  # noqa: N815
    rttChanged = Signal(float)  # noqa: N815
    commandFinished = Signal(CommandResult)  # noqa: N815
    errorOccurred = Signal(WorkerError)  # noqa: N815
    trafficObserved = Signal(list)  # noqa: N815
    controllerReconnected = Signal()  # noqa: N815
    controllerRestarted = Signal()  # noqa: N815
    uploadProgress = Signal(int, int)  # noqa: N815
    pointUploaded = Signal(int, bool, str)  # noqa: N815

    _connectRequested = Signal(object)  # noqa: N815
    _disconnectRequested = Signal()  # noqa: N815
    _shutdownRequested = Signal()  # noqa: N815
    _pollRateRequested = Signal(float)  # noqa: N815
    _captureRequested = Signal(bool)  # noqa: N815

    def __init__(self, parent: QObject | None = None, *, poll_hz: float = timing.POLL_HZ_DEFAULT,
                 canary_gv: int | None = DEFAULT_CANARY_GV) -> None:
        super().__init__(parent)
        self._settings: ConnectionSettings | None = None
        self._state = ConnectionState(LinkState.DISCONNECTED)
        self._shut = False
        self._capture_users = 0
        self._thread = QThread()
        self._thread.setObjectName("RobotWorker")
        self._worker = RobotWorker(poll_hz, canary_gv=canary_gv)
        self._worker.moveToThread(self._thread)
        self._thread.started.connect(self._worker.start)
        w = self._worker
        for name in ("poseChanged", "statusChanged", "alarmsChanged", "rttChanged", "commandFinished",
                     "errorOccurred", "trafficObserved", "controllerReconnected", "controllerRestarted",
                     "uploadProgress", "pointUploaded"):
            getattr(w, name).connect(getattr(self, name))
        w.connectionChanged.connect(self._on_connection)
        self._connectRequested.connect(w.connect_to)
        self._disconnectRequested.connect(w.disconnect_link)
        self._pollRateRequested.connect(w.set_poll_rate)
        self._captureRequested.connect(w.set_traffic_capture)
        self._shutdownRequested.connect(w.shutdown, Qt.ConnectionType.QueuedConnection)
        app = QCoreApplication.instance()
        if app is not None:
            app.aboutToQuit.connect(self.shutdown)
        self._thread.start()

    # --- state --------------------------------------------------------------------------
    @property
    def state(self) -> ConnectionState:
        return self._state

    @property
    def settings(self) -> ConnectionSettings | None:
        return self._settings

    @property
    def monitor_only(self) -> bool:
        return bool(self._settings and self._settings.monitor_only)

    @property
    def is_running(self) -> bool:
        return self._thread.isRunning()

    @Slot(object)
    def _on_connection(self, state: ConnectionState) -> None:
        self._state = state
        self.connectionChanged.emit(state)

    # --- connection ---------------------------------------------------------------------
    def connect_to(self, settings: ConnectionSettings) -> None:
        if self._shut:
            return
        self._settings = settings
        self._connectRequested.emit(settings)

    def disconnect(self) -> None:  # type: ignore[override]  # QObject.disconnect is not used on links
        if not self._shut:
            self._disconnectRequested.emit()

    def set_poll_rate(self, hz: float) -> None:
        if not self._shut:
            self._pollRateRequested.emit(float(hz))

    def set_traffic_capture(self, on: bool) -> None:
        """Reference-counted: capture runs while at least one user asked for it."""
        if self._shut:
            return
        self._capture_users = max(0, self._capture_users + (1 if on else -1))
        self._captureRequested.emit(self._capture_users > 0)

    # --- commands (queued; results come back as signals) -------------------------------
    # Each returns the request id that its CommandResult / WorkerError will carry (0 after shutdown:
    # nothing was queued).
    def stop(self) -> int:
        return 0 if self._shut else self._worker.request_stop()

    def pause(self) -> int:
        return 0 if self._shut else self._worker.request_pause()

    def resume(self) -> int:
        return 0 if self._shut else self._worker.request_resume()

    def jog_press(self, frame: TeachFrame, axis: int, direction: int, ratio: float, user: int = 0,
                  tool: int = 0) -> int:
        if self._shut:
            return 0
        request = JogRequest(TeachFrame(frame), axis, direction, ratio, user, tool)
        return self._worker.request_jog_press(request)

    def jog_release(self) -> int:
        return 0 if self._shut else self._worker.request_jog_release()

    def set_jog_ratio(self, ratio: float) -> int:
        return 0 if self._shut else self._worker.request_jog_ratio(ratio)

    def step(self, frame: StepFrame, offsets: Sequence[float],
             ext_offsets: Sequence[float] = (0.0,) * registers.NUM_EXTERNAL_AXES,
             speed: float = 10.0) -> int:
        return 0 if self._shut else self._worker.request_step(frame, offsets, ext_offsets, speed)

    def set_mode(self, mode: WorkMode) -> int:
        return 0 if self._shut else self._worker.request_set_mode(mode)

    def go_zero(self, axis: int | None) -> int:
        return 0 if self._shut else self._worker.request_go_zero(axis)

    def run_program(self, program_id: int, mode: ProgramMotionMode = ProgramMotionMode.SINGLE_RUN,
                    cycles: int = 1, speed_ratio: int = 100) -> int:
        return 0 if self._shut else self._worker.request_run_program(program_id, mode, cycles, speed_ratio)

    def create_point(self, point_id: int, pose: Sequence[float] | None = None,
                     tool: int = registers.TOOL_NONE) -> int:
        return 0 if self._shut else self._worker.request_create_point(point_id, pose, tool)

    def move_to_point(self, end_id: int, via_id: int | None = None, *, orientation_changes: bool = True,
                      ignore_middle: bool = False, speed: float = 50.0,
                      tool: int = registers.TOOL_NONE) -> int:
        if self._shut:
            return 0
        return self._worker.request_move_to_point(end_id, via_id, orientation_changes, ignore_middle, speed,
                                                  tool)

    def upload_points(self, points: Iterable[tuple[int, Sequence[float], int] | tuple[int, Sequence[float]]],
                      tool: int = registers.TOOL_NONE) -> int:
        """Create temp points from (id, pose6, tool) items ((id, pose6) items take ``tool``).

        The worker groups them by tool frame (GV245 written once per group) and reports each
        point with ``pointUploaded``, progress with ``uploadProgress`` and the batch with one
        ``commandFinished`` carrying the returned id. Stop or :meth:`cancel_upload` end it
        between two points."""
        if self._shut:
            return 0
        items = [(item[0], item[1], item[2] if len(item) > 2 else tool) for item in points]
        return self._worker.request_upload_points(items)

    def cancel_upload(self) -> int:
        """End the running upload after the current point; sends no stop to the controller."""
        return 0 if self._shut else self._worker.request_cancel_upload()

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
        thread = self._thread
        if not thread.isRunning():
            return
        self._shutdownRequested.emit()  # queued: runs once the transaction in flight is over
        wait_ms = max(1, round(timing.SHUTDOWN_WAIT * 1000))
        if not thread.wait(wait_ms):
            _log.warning("the robot worker is still inside a network call after %d ms; "
                         "it ends on its own in the background", wait_ms)
            _keep_until_finished(thread, self._worker)


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
