"""The short commands' handlers (stop, pause, resume, set mode, cancel upload, the jog's press,
release and speed, the upload's start): a part of the worker, composed by
:class:`~app.link.worker.RobotWorker`, which registers each in its one table (operation type ->
handler, :mod:`app.link.ops`). Every handler runs in the worker thread as the body of one job,
reports through ``emit_result`` and raises typed errors that the worker's executor turns into
signals. What a handler uses of the worker is :class:`CommandsHost`.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import Protocol

from app.errors import (
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    Reason,
    ResponseTimeout,
    TeachPadError,
    WriteBlocked,
)
from app.link.active import MotionTracker
from app.link.capture import TrafficCapture
from app.link.client import RobotClient
from app.link.jobs import Job
from app.link.jog import JogMachine
from app.link.motion import MotionCommands
from app.link.ops import (
    CancelUpload,
    Handlers,
    JobKind,
    JogPress,
    JogRelease,
    Pause,
    Resume,
    SetJogRatio,
    SetMode,
    Stop,
    UploadPoints,
)
from app.link.stop_line import StopLine, StopSent, stop_on_a_fresh_connection
from app.link.supervisor import LinkSupervisor
from app.link.types import Operation
from app.link.upload import RawItem, Uploader
from app.models import CommandResult
from app.protocol.enums import WorkMode
from app.safety.audit import AuditLog

__all__ = ["CommandsHost", "WorkerCommands"]

_log = logging.getLogger(__name__)

#: The main link's stop failed because the link did (not the controller's refusal).
_LINK_FAILURES = (LinkError, ResponseTimeout, MalformedResponse)


class CommandsHost(Protocol):
    """What the short commands use of the worker (worker thread)."""

    supervisor: LinkSupervisor
    jog: JogMachine
    motion: MotionTracker
    motions: MotionCommands
    uploader: Uploader
    capture: TrafficCapture
    stop_line: StopLine
    audit: AuditLog | None

    @property
    def current_job(self) -> Job | None:
        """The job being executed (a Stop's: its place in the queue, its stop-line write)."""
        ...

    def client_or_raise(self) -> RobotClient: ...

    def emit_result(self, result: CommandResult, request_id: int | None = -1) -> None: ...

    def cancel_queued(self, predicate: Callable[[Job], bool]) -> list[Job]:
        """Remove and return the queued (not urgent) jobs that match."""
        ...

    def next_upload_step(self) -> None:
        """The upload's next chunk, one event-loop turn later."""
        ...


class WorkerCommands:
    """The short commands' handlers (see the module docstring); worker thread only."""

    def __init__(self, host: CommandsHost) -> None:
        self._host = host

    def register(self, handlers: Handlers) -> None:
        """The operations these handlers run, in the worker's one table."""
        handlers.add(Stop, self.stop)
        handlers.add(Pause, self.pause)
        handlers.add(Resume, self.resume)
        handlers.add(SetMode, self.set_mode)
        handlers.add(CancelUpload, self.cancel_upload)
        handlers.add(JogPress, self.jog_press)
        handlers.add(JogRelease, self.jog_release)
        handlers.add(SetJogRatio, self.jog_ratio)
        handlers.add(UploadPoints, self.upload_points)

    def _done(self, text: str, operation: str) -> None:
        """A request the controller answered (its outcome is not watched): *sent*, named by its
        operation (the GUI says "pause: sent.", never a nameless "The command: done.")."""
        reason = Reason("request_done", {"operation": operation})
        self._host.emit_result(CommandResult(None, None, None, True, text, reason=reason))

    def _failed(self, text: str, request_id: int | None = -1, reason: Reason | None = None) -> None:
        self._host.emit_result(CommandResult(None, None, None, False, text, reason=reason), request_id)

    # --- plain and urgent commands ------------------------------------------------------
    def stop(self, _op: Stop) -> None:
        job = self._host.current_job
        on_line = job.on_line if job is not None else None  # already written on the stop line
        client = self._host.supervisor.client
        if client is None or not self._host.supervisor.link_up:
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
            took = self._report_stop_line(on_line)  # ... and the controller took it on the stop line
            if (
                took
                and on_line is not None
                and client.writes_settled_before(on_line.sent_mono)
                and not self._host.jog.jogging
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
            self._host.uploader.end("stopped")
            self._host.jog.stop_refused(exc)  # sent again at every poll until the controller takes it
            raise
        except BaseException:
            self._report_stop_line(on_line)
            raise
        self._report_stop_line(on_line)
        self._after_stop(time.monotonic(), "stop: sent")

    def _stop_on_a_fresh_connection(self, main_failure: TeachPadError | None) -> None:
        """The Stop over a new connection to the last controller (app/link/stop_line.py): the
        link is not up (``main_failure`` None) or its own stop failed (``main_failure``). Sent:
        the Stop's result says so, naming the controller (a warning); the command in flight ends
        as stopped. Not sent: a :class:`LinkError` (code ``stop_unreachable``) naming the
        controller and why, and everything queued before the Stop is cancelled all the same."""
        supervisor = self._host.supervisor
        settings = supervisor.settings
        if settings is None:  # TeachPad knows no controller: nothing to stop
            raise LinkError("not connected to a controller", code="not_connected")
        prior = supervisor.client  # the link that went (None after a disconnect): its unanswered writes
        jog = self._host.jog
        try:
            sent = stop_on_a_fresh_connection(
                settings,
                audit=self._host.audit,
                capture=self._host.capture,
                ratio_zero=jog.jogging or jog.teach_dirty or jog.halting,
                again_after=prior.write_lost_until if prior is not None else 0.0,
            )
        except WriteBlocked:
            raise
        except TeachPadError as exc:
            self._cancel_motions_before_stop()
            self._host.uploader.end("stopped")
            self._end_jog_after_a_failed_stop()
            cause = exc.as_reason()
            raise LinkError(
                f"stop: could not reach the controller at {settings.endpoint} ({exc}): check the robot",
                code="stop_unreachable",
                params={"endpoint": settings.endpoint, "cause": cause.code, "cause_args": dict(cause.args)},
            ) from None
        if prior is not None:  # its writes (stop, ratio 0) are ours, not another master's
            prior.foreign.note_write(time.monotonic())
        job = self._host.current_job
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
            self._host.supervisor.transport_failed(main_failure)

    def _report_stop_line(self, on_line: StopSent | None) -> bool:
        """The stop line's answer: checked, audited, shown in the traffic. True when the
        controller took the stop there."""
        host = self._host
        return on_line is not None and host.stop_line.report(host.capture, host.audit, on_line)

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
        if isinstance(exc, LinkError | ResponseTimeout | MalformedResponse):
            self._host.supervisor.transport_failed(exc)

    def _after_stop(
        self, now: float, text: str, reason: Reason | None = None, *, main_link_failed: bool = False
    ) -> None:
        """The controller took the stop: end the upload, cancel the motions queued before the Stop
        (first: whatever fails after, none of them runs after it), end the jog and the motion in
        flight; then the Stop's own result."""
        job = self._host.current_job
        if job is not None and job.sent is not None:
            job.sent.set()  # the poster (the GUI thread) may go on
        self._host.uploader.end("stopped")
        self._cancel_motions_before_stop()
        # no jog held, or its speed 0 went on the other connection: nothing to say if this fails
        if main_link_failed:
            self._end_jog_after_a_failed_stop()
        else:
            self._host.jog.on_stop()  # speed 0; a failure here is the Stop's error, as before
        active = self._host.motion.take()
        if active is not None:
            self._host.emit_result(active.completion.stopped(now), active.request_id)
        self._host.emit_result(CommandResult(None, None, None, True, text, reason=reason))

    def _end_jog_after_a_failed_stop(self) -> None:
        """The stop line's stop was taken, the main link failed: the held jog ends (a jog sequence
        still starting gives way before its ratio goes out), and speed 0 is tried; if that fails
        too, teach mode counts as unknown (speed 0 and teach off before anything else)."""
        try:
            self._host.jog.on_stop()
        except TeachPadError:
            self._host.jog.teach_dirty = True

    def _cancel_motions_before_stop(self) -> None:
        """The motions queued before the Stop (its place in the queue) get "cancelled by Stop"."""
        stop = self._host.current_job
        stop_seq = stop.seq if stop is not None else 0
        for job in self._host.cancel_queued(lambda j: j.kind is JobKind.MOTION and j.seq < stop_seq):
            self._failed(
                f"{job.operation}: cancelled by Stop",
                job.request_id,
                Reason("cancelled_by_stop", {"operation": str(job.operation)}),
            )

    def cancel_upload(self, _op: CancelUpload) -> None:
        """No controller stop: the upload ends after the point in progress; queued uploads are dropped."""
        for job in self._host.cancel_queued(lambda j: j.operation == Operation.UPLOAD_POINTS):
            self._failed(
                f"{job.operation}: cancelled",
                job.request_id,
                Reason("upload_cancelled", {"operation": str(job.operation)}),
            )
        if self._host.uploader.run is None:
            self._done(f"{Operation.CANCEL_UPLOAD}: no upload under way", Operation.CANCEL_UPLOAD)
            return
        self._host.uploader.end("cancelled")
        ends = f"{Operation.CANCEL_UPLOAD}: the upload ends after the current point"
        self._done(ends, Operation.CANCEL_UPLOAD)

    def pause(self, _op: Pause) -> None:
        self._host.client_or_raise().pause()
        self._done("pause: sent", Operation.PAUSE)

    def resume(self, _op: Resume) -> None:
        self._host.client_or_raise().resume()
        self._done("resume: sent", Operation.RESUME)

    def set_mode(self, op: SetMode) -> None:
        mode = WorkMode(op.mode)
        client = self._host.client_or_raise()
        if mode is WorkMode.MANUAL:
            self._host.jog.stop_jog_and_teach()
        try:
            client.set_work_mode(mode)
        except ModbusExceptionError as exc:
            exc.params["mode"] = int(mode)  # the refusal names the mode asked for
            raise
        self._done(f"work mode: {mode.name.lower()}", Operation.SET_MODE)

    def jog_press(self, op: JogPress) -> None:
        self._host.motions.require_none(Operation.JOG)
        self._host.jog.press(op.request)

    def jog_release(self, _op: JogRelease) -> None:
        self._host.jog.release()

    def jog_ratio(self, op: SetJogRatio) -> None:
        self._host.jog.set_ratio(op.ratio)

    # --- long commands ------------------------------------------------------------------
    def upload_points(self, op: UploadPoints) -> None:
        """Case 2.2 for many points, tool by tool; runs in chunks, see :class:`Uploader`."""
        self._host.motions.require_none(Operation.UPLOAD_POINTS)
        raw: list[RawItem] = list(op.items)
        if self._host.uploader.start(raw):
            self._host.next_upload_step()
