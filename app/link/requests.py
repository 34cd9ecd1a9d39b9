"""The worker's request API (any thread): each request becomes a job in the worker's queue.

A mixin of :class:`~app.link.worker.RobotWorker` (kept apart so the worker stays readable):
every method returns the request id that the job's results and errors will carry.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING, Protocol

from app.link.jobs import JOG_PRESS, JOG_RATIO, Job, JobKind, JobQueue
from app.link.types import JogRequest, Operation, StepFrame
from app.link.upload import RawItem
from app.protocol.enums import ProgramMotionMode, WorkMode

if TYPE_CHECKING:
    from app.link.jog import JogMachine
    from app.link.motion import MotionCommands
    from app.link.stop_line import StopLine, StopSent

__all__ = ["STOP_HANDOFF_WAIT", "WorkerRequests"]

#: How long a thread that posts a Stop waits (GIL released) for the worker to send it (s). While
#: it waits, the poster (the GUI thread) cannot hold the GIL the worker needs to write the stop:
#: measured, that wait was most of a Stop's latency (the worker waiting for a busy GUI thread's
#: GIL, the in-flight poll finishing in slow motion). A rare event: a short freeze is the price.
STOP_HANDOFF_WAIT = 0.005


class _Wake(Protocol):
    def emit(self) -> None: ...


class WorkerRequests:
    """``post`` and the ``request_*`` methods of :class:`~app.link.worker.RobotWorker`."""

    if TYPE_CHECKING:  # provided by RobotWorker
        stop_line: StopLine
        _jobs: JobQueue
        _wake: _Wake
        _worker_ident: int | None  # threading.get_ident() of the worker thread while it runs
        jog: JogMachine
        motions: MotionCommands

        def _do_stop(self, on_line: StopSent | None = None) -> None: ...
        def _do_pause(self) -> None: ...
        def _do_resume(self) -> None: ...
        def _do_cancel_upload(self) -> None: ...
        def _do_set_mode(self, mode: WorkMode) -> None: ...
        def _do_jog_press(self, request: JogRequest) -> None: ...
        def _do_upload_points(self, raw: list[RawItem]) -> None: ...

    def post(
        self,
        operation: str,
        run: Callable[[], None],
        kind: JobKind = JobKind.PLAIN,
        *,
        coalesce: str | None = None,
        needs_link: bool = True,
        cancels: tuple[str, ...] = (),
        sent: threading.Event | None = None,
    ) -> int:
        """Queue a job and wake the worker; returns the request id its results will carry."""
        request_id = self._jobs.put(
            Job(operation, run, kind, coalesce=coalesce, needs_link=needs_link, cancels=cancels, sent=sent)
        )
        self._wake.emit()
        return request_id

    def request_stop(self) -> int:
        """Write the stop now on the stop line when there is one (app/link/stop_line.py), then queue
        the stop job first in line (the main link's stop, the line's answer, the bookkeeping).
        Without a stop line, from another thread, wait (GIL released) until the worker has written
        it, at most :data:`STOP_HANDOFF_WAIT`, so nothing of the caller's runs first. The job runs
        whatever the link's state: without a link it goes over a fresh connection to the last
        controller (:meth:`~app.link.commands.WorkerCommands._do_stop`)."""
        on_line = self.stop_line.send_stop()
        sent = threading.Event()
        # needs no link: without one the job stops the last controller over a fresh connection
        request_id = self.post(
            Operation.STOP, lambda: self._do_stop(on_line), JobKind.URGENT, needs_link=False, sent=sent
        )
        worker = self._worker_ident
        if on_line is None and worker is not None and worker != threading.get_ident():
            sent.wait(STOP_HANDOFF_WAIT)
        return request_id

    def request_pause(self) -> int:
        return self.post(Operation.PAUSE, self._do_pause, JobKind.URGENT)

    def request_resume(self) -> int:
        return self.post(Operation.RESUME, self._do_resume, JobKind.URGENT)

    def request_jog_press(self, request: JogRequest) -> int:
        return self.post(
            Operation.JOG, lambda: self._do_jog_press(request), JobKind.MOTION, coalesce=JOG_PRESS
        )

    def request_jog_release(self) -> int:
        return self.post(
            Operation.JOG_RELEASE,
            self.jog.release,
            JobKind.URGENT,
            needs_link=False,
            cancels=(JOG_PRESS, JOG_RATIO),
        )

    def request_jog_ratio(self, ratio: float) -> int:
        return self.post(
            Operation.JOG_SPEED, lambda: self.jog.set_ratio(ratio), JobKind.MOTION, coalesce=JOG_RATIO
        )

    def request_step(
        self, frame: StepFrame, offsets: Sequence[float], ext_offsets: Sequence[float], speed: float
    ) -> int:
        offs, ext = tuple(offsets), tuple(ext_offsets)
        return self.post(Operation.STEP, lambda: self.motions.step(frame, offs, ext, speed), JobKind.MOTION)

    def request_set_mode(self, mode: WorkMode) -> int:
        return self.post(Operation.SET_MODE, lambda: self._do_set_mode(mode))

    def request_go_zero(self, axis: int | None, switch_to_auto: bool = False) -> int:
        return self.post(
            Operation.GO_ZERO, lambda: self.motions.go_zero(axis, switch_to_auto), JobKind.MOTION
        )

    def request_run_program(
        self,
        program_id: int,
        mode: ProgramMotionMode,
        cycles: int,
        speed_ratio: int,
        switch_to_auto: bool = False,
    ) -> int:
        return self.post(
            Operation.RUN_PROGRAM,
            lambda: self.motions.run_program(program_id, mode, cycles, speed_ratio, switch_to_auto),
            JobKind.MOTION,
        )

    def request_create_point(self, point_id: int, pose: Sequence[float] | None, tool: int) -> int:
        values = None if pose is None else tuple(pose)
        return self.post(Operation.CREATE_POINT, lambda: self.motions.create_point(point_id, values, tool))

    def request_move_to_point(
        self,
        end_id: int,
        via_id: int | None,
        orientation_changes: bool,
        ignore_middle: bool,
        speed: float,
        tool: int,
    ) -> int:
        return self.post(
            Operation.MOVE_TO_POINT,
            lambda: self.motions.move_to_point(
                end_id, via_id, orientation_changes, ignore_middle, speed, tool
            ),
            JobKind.MOTION,
        )

    def request_upload_points(self, points: Iterable[tuple[int, Sequence[float], int]]) -> int:
        """Items (id, pose6, tool); copied here, checked in the worker before the first write."""
        items: list[RawItem] = [(pid, tuple(pose), tool) for pid, pose, tool in points]
        return self.post(Operation.UPLOAD_POINTS, lambda: self._do_upload_points(items), JobKind.MOTION)

    def request_cancel_upload(self) -> int:
        """End the running upload after the point in progress, without a controller stop."""
        return self.post(Operation.CANCEL_UPLOAD, self._do_cancel_upload, JobKind.URGENT, needs_link=False)
