"""What the worker's jobs do: the plain, urgent and long commands of the worker.

A mixin of :class:`~app.link.worker.RobotWorker` (kept apart from the worker's lifecycle, job
execution and signals, like :mod:`app.link.requests`): every method runs in the worker thread as
the body of one job, reports through ``emit_result`` and raises typed errors that
:meth:`RobotWorker._execute` turns into signals.
"""

from __future__ import annotations

import logging
import time
from typing import TYPE_CHECKING, Protocol

from app.errors import LinkError, MalformedResponse, Reason, ResponseTimeout, TeachPadError, WriteBlocked
from app.link.ops import (
    CancelUpload,
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
from app.link.stop_line import stop_on_a_fresh_connection
from app.link.types import Operation
from app.link.upload import RawItem
from app.models import CommandResult
from app.protocol.enums import WorkMode

if TYPE_CHECKING:
    from app.link.capture import TrafficCapture
    from app.link.client import RobotClient
    from app.link.jobs import Job, JobQueue
    from app.link.jog import JogMachine
    from app.link.motion import MotionCommands, MotionTracker
    from app.link.stop_line import StopLine, StopSent
    from app.link.supervisor import LinkSupervisor
    from app.link.upload import Uploader
    from app.safety.audit import AuditLog

__all__ = ["WorkerCommands"]

_log = logging.getLogger(__name__)

#: The main link's stop failed because the link did (not the controller's refusal).
_LINK_FAILURES = (LinkError, ResponseTimeout, MalformedResponse)


class _Step(Protocol):
    def emit(self) -> None: ...


class WorkerCommands:
    """The ``_do_*`` job bodies of :class:`~app.link.worker.RobotWorker` (worker thread)."""

    if TYPE_CHECKING:  # provided by RobotWorker
        audit: AuditLog | None
        capture: TrafficCapture
        jog: JogMachine
        motion: MotionTracker
        motions: MotionCommands
        stop_line: StopLine
        supervisor: LinkSupervisor
        uploader: Uploader
        _jobs: JobQueue
        _current_job: Job | None
        _current_seq: int
        _uploadStep: _Step  # noqa: N815

        def client_or_raise(self) -> RobotClient: ...
        def emit_result(self, result: CommandResult, request_id: int | None = -1) -> None: ...

    def _done(self, text: str, operation: str) -> None:
        """A request the controller answered (its outcome is not watched): *sent*, named by its
        operation (the GUI says "pause: sent.", never a nameless "The command: done.")."""
        reason = Reason("request_done", {"operation": operation})
        self.emit_result(CommandResult(None, None, None, True, text, reason=reason))

    def _failed(self, text: str, request_id: int | None = -1, reason: Reason | None = None) -> None:
        self.emit_result(CommandResult(None, None, None, False, text, reason=reason), request_id)

    # --- plain and urgent commands ------------------------------------------------------
    def _do_stop(self, _op: Stop) -> None:
        job = self._current_job
        on_line = job.on_line if job is not None else None  # already written on the stop line
        client = self.supervisor.client
        if client is None or not self.supervisor.link_up:
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
                and not self.jog.jogging
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
            self.uploader.end("stopped")
            self.jog.stop_refused(exc)  # sent again at every poll until the controller takes it
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
        supervisor = self.supervisor
        settings = supervisor.settings
        if settings is None:  # TeachPad knows no controller: nothing to stop
            raise LinkError("not connected to a controller", code="not_connected")
        prior = supervisor.client  # the link that went (None after a disconnect): its unanswered writes
        jog = self.jog
        try:
            sent = stop_on_a_fresh_connection(
                settings,
                audit=self.audit,
                capture=self.capture,
                ratio_zero=jog.jogging or jog.teach_dirty or jog.halting,
                again_after=prior.write_lost_until if prior is not None else 0.0,
            )
        except WriteBlocked:
            raise
        except TeachPadError as exc:
            self._cancel_motions_before_stop()
            self.uploader.end("stopped")
            self._end_jog_after_a_failed_stop()
            cause = exc.as_reason()
            raise LinkError(
                f"stop: could not reach the controller at {settings.endpoint} ({exc}): check the robot",
                code="stop_unreachable",
                params={"endpoint": settings.endpoint, "cause": cause.code, "cause_args": dict(cause.args)},
            ) from None
        if prior is not None:  # its writes (stop, ratio 0) are ours, not another master's
            prior.foreign.note_write(time.monotonic())
        job = self._current_job
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
            self.supervisor.transport_failed(main_failure)

    def _report_stop_line(self, on_line: StopSent | None) -> bool:
        """The stop line's answer: checked, audited, shown in the traffic. True when the
        controller took the stop there."""
        return on_line is not None and self.stop_line.report(self.capture, self.audit, on_line)

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
            self.supervisor.transport_failed(exc)

    def _after_stop(
        self, now: float, text: str, reason: Reason | None = None, *, main_link_failed: bool = False
    ) -> None:
        """The controller took the stop: end the upload, cancel the motions queued before the Stop
        (first: whatever fails after, none of them runs after it), end the jog and the motion in
        flight; then the Stop's own result."""
        job = self._current_job
        if job is not None and job.sent is not None:
            job.sent.set()  # the poster (the GUI thread) may go on
        self.uploader.end("stopped")
        self._cancel_motions_before_stop()
        # no jog held, or its speed 0 went on the other connection: nothing to say if this fails
        if main_link_failed:
            self._end_jog_after_a_failed_stop()
        else:
            self.jog.on_stop()  # speed 0; a failure here is the Stop's error, as before
        active = self.motion.take()
        if active is not None:
            self.emit_result(active.completion.stopped(now), active.request_id)
        self.emit_result(CommandResult(None, None, None, True, text, reason=reason))

    def _end_jog_after_a_failed_stop(self) -> None:
        """The stop line's stop was taken, the main link failed: the held jog ends (a jog sequence
        still starting gives way before its ratio goes out), and speed 0 is tried; if that fails
        too, teach mode counts as unknown (speed 0 and teach off before anything else)."""
        try:
            self.jog.on_stop()
        except TeachPadError:
            self.jog.teach_dirty = True

    def _cancel_motions_before_stop(self) -> None:
        stop_seq = self._current_seq
        for job in self._jobs.cancel(lambda j: j.kind is JobKind.MOTION and j.seq < stop_seq):
            self._failed(
                f"{job.operation}: cancelled by Stop",
                job.request_id,
                Reason("cancelled_by_stop", {"operation": str(job.operation)}),
            )

    def _do_cancel_upload(self, _op: CancelUpload) -> None:
        """No controller stop: the upload ends after the point in progress; queued uploads are dropped."""
        for job in self._jobs.cancel(lambda j: j.operation == Operation.UPLOAD_POINTS):
            self._failed(
                f"{job.operation}: cancelled",
                job.request_id,
                Reason("upload_cancelled", {"operation": str(job.operation)}),
            )
        if self.uploader.run is None:
            self._done(f"{Operation.CANCEL_UPLOAD}: no upload under way", Operation.CANCEL_UPLOAD)
            return
        self.uploader.end("cancelled")
        ends = f"{Operation.CANCEL_UPLOAD}: the upload ends after the current point"
        self._done(ends, Operation.CANCEL_UPLOAD)

    def _do_pause(self, _op: Pause) -> None:
        self.client_or_raise().pause()
        self._done("pause: sent", Operation.PAUSE)

    def _do_resume(self, _op: Resume) -> None:
        self.client_or_raise().resume()
        self._done("resume: sent", Operation.RESUME)

    def _do_set_mode(self, op: SetMode) -> None:
        mode = WorkMode(op.mode)
        client = self.client_or_raise()
        if mode is WorkMode.MANUAL:
            self.jog.stop_jog_and_teach()
        client.set_work_mode(mode)
        self._done(f"work mode: {mode.name.lower()}", Operation.SET_MODE)

    def _do_jog_press(self, op: JogPress) -> None:
        self.motions.require_none(Operation.JOG)
        self.jog.press(op.request)

    def _do_jog_release(self, _op: JogRelease) -> None:
        self.jog.release()

    def _do_jog_ratio(self, op: SetJogRatio) -> None:
        self.jog.set_ratio(op.ratio)

    # --- long commands ------------------------------------------------------------------
    def _do_upload_points(self, op: UploadPoints) -> None:
        """Case 2.2 for many points, tool by tool; runs in chunks, see :class:`Uploader`."""
        self.motions.require_none(Operation.UPLOAD_POINTS)
        raw: list[RawItem] = list(op.items)
        if self.uploader.start(raw):
            self._uploadStep.emit()
