"""The short commands' handlers (pause, resume, set mode, cancel upload, the jog's press,
release and speed, the upload's start): a part of the worker, composed by
:class:`~app.link.worker.RobotWorker`, which registers each in its one table (operation type ->
handler, :mod:`app.link.ops`). Every handler runs in the worker thread as the body of one job,
reports through ``emit_result`` and raises typed errors that the worker's executor turns into
signals. What a handler uses of the worker is :class:`CommandsHost`. The Stop is not here:
everything a Stop does is :mod:`app.link.halt` (its job: :class:`~app.link.halt.StopJob`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from app.errors import ModbusExceptionError, Reason, TeachPadError
from app.link.client import RobotClient
from app.link.jobs import Job
from app.link.jog import JogMachine
from app.link.motion import MotionCommands
from app.link.ops import (
    CancelUpload,
    Handlers,
    JogPress,
    JogRelease,
    Pause,
    Resume,
    SetJogRatio,
    SetMode,
    UploadPoints,
)
from app.link.types import Operation
from app.link.upload import RawItem, Uploader
from app.models import CommandResult
from app.protocol.enums import WorkMode

__all__ = ["CommandsHost", "WorkerCommands"]


class CommandsHost(Protocol):
    """What the short commands use of the worker (worker thread); the parts they drive (the
    jog, the motions, the upload) are given to :class:`WorkerCommands` one by one."""

    @property
    def request_id(self) -> int | None:
        """The request id of the job being executed."""
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

    def __init__(
        self, host: CommandsHost, *, jog: JogMachine, motions: MotionCommands, uploader: Uploader
    ) -> None:
        self._host = host
        self._jog = jog
        self._motions = motions
        self._uploader = uploader

    def register(self, handlers: Handlers) -> None:
        """The operations these handlers run, in the worker's one table."""
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

    # --- plain and urgent commands (the Stop is app/link/halt.py's StopJob) -----------------
    def cancel_upload(self, _op: CancelUpload) -> None:
        """No controller stop: the upload ends after the point in progress; queued uploads are dropped."""
        for job in self._host.cancel_queued(lambda j: j.operation == Operation.UPLOAD_POINTS):
            self._failed(
                f"{job.operation}: cancelled",
                job.request_id,
                Reason("upload_cancelled", {"operation": str(job.operation)}),
            )
        if self._uploader.run is None:
            self._done(f"{Operation.CANCEL_UPLOAD}: no upload under way", Operation.CANCEL_UPLOAD)
            return
        self._uploader.end("cancelled")
        ends = f"{Operation.CANCEL_UPLOAD}: the upload ends after the current point"
        self._done(ends, Operation.CANCEL_UPLOAD)

    def pause(self, _op: Pause) -> None:
        """442 <- 1. Refused or not answered: the Pause is followed (sent again at every poll,
        app/link/halt.py) and this request ends when it is over: paused, stopped instead, or
        nothing left to pause."""
        client = self._host.client_or_raise()
        try:
            client.pause()
        except TeachPadError as exc:
            if not self._jog.pause_refused(exc, self._host.request_id):
                raise
            return
        self._jog.pause_answered()
        self._done("pause: sent", Operation.PAUSE)

    def resume(self, _op: Resume) -> None:
        self._jog.drop_pause("superseded by Resume")  # the operator no longer wants it
        self._host.client_or_raise().resume()
        self._done("resume: sent", Operation.RESUME)

    def set_mode(self, op: SetMode) -> None:
        mode = WorkMode(op.mode)
        client = self._host.client_or_raise()
        if mode is WorkMode.MANUAL:
            self._jog.stop_jog_and_teach()
        try:
            client.set_work_mode(mode)
        except ModbusExceptionError as exc:
            exc.params["mode"] = int(mode)  # the refusal names the mode asked for
            raise
        self._done(f"work mode: {mode.name.lower()}", Operation.SET_MODE)

    def jog_press(self, op: JogPress) -> None:
        self._motions.require_none(Operation.JOG)
        self._jog.press(op.request)

    def jog_release(self, _op: JogRelease) -> None:
        self._jog.release()

    def jog_ratio(self, op: SetJogRatio) -> None:
        self._jog.set_ratio(op.ratio)

    # --- long commands ------------------------------------------------------------------
    def upload_points(self, op: UploadPoints) -> None:
        """Case 2.2 for many points, tool by tool; runs in chunks, see :class:`Uploader`."""
        self._motions.require_none(Operation.UPLOAD_POINTS)
        raw: list[RawItem] = list(op.items)
        if self._uploader.start(raw):
            self._host.next_upload_step()
