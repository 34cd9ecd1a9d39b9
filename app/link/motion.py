"""The long commands (step, move to point, go to zero, run program, create point): their start
and the completion tracking of the one under way.

:class:`MotionCommands` starts them without waiting (teach mode is left first); the regular
polls then feed the active command through :class:`MotionTracker`: a :class:`CommandTracker`
(commands with GV291) or a :class:`~app.link.watch.MotionWatch` (run program and go to zero,
which do not use GV291; the client makes it, as for the CLI) until a :class:`CommandResult`
comes out. Only one motion at a time: a motion requested while another one or an upload is
under way is refused.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

from app import timing
from app.errors import InvalidInput, MalformedResponse, ModbusExceptionError, ResponseTimeout
from app.link.active import Completion, MotionTracker
from app.link.client import RobotClient
from app.link.host import PartLink, Readings, TeachGate
from app.link.ops import CreatePoint, GoZero, Handlers, MoveToPoint, RunProgram, Step
from app.link.tracker import CommandTracker
from app.link.types import Operation

__all__ = ["MotionCommands"]

_log = logging.getLogger(__name__)

#: A status read that failed without the link going down (busy, no answer in time, a bad answer)
_READ_ERRORS = (ModbusExceptionError, ResponseTimeout, MalformedResponse)


class MotionCommands:
    """The handlers of the long commands' operations (:mod:`app.link.ops`; worker thread;
    errors propagate to the executor)."""

    def __init__(
        self,
        host: PartLink,
        tracker: MotionTracker,
        teach: TeachGate,
        readings: Readings,
        uploading: Callable[[], bool],
    ) -> None:
        """``teach``: the jog (a stop unconfirmed refuses, teach mode is left first);
        ``readings``: the polls' last pose and status; ``uploading``: an upload is under way."""
        self._host = host
        self._tracker = tracker
        self._teach = teach
        self._readings = readings
        self._uploading = uploading

    def register(self, handlers: Handlers) -> None:
        """The operations these handlers run, in the worker's one table."""
        handlers.add(Step, self.step)
        handlers.add(GoZero, self.go_zero)
        handlers.add(RunProgram, self.run_program)
        handlers.add(MoveToPoint, self.move_to_point)
        handlers.add(CreatePoint, self.create_point)

    def require_none(self, operation: str) -> None:
        """Refuse ``operation`` while a motion or an upload is under way."""
        self._teach.require_no_halt(operation)
        busy = self._tracker.motion_under_way
        if busy is not None:
            text = f"{busy} is still under way: wait for it or press Stop"
            raise InvalidInput(text, code="busy", params={"operation": busy})
        if self._uploading():
            raise InvalidInput(
                f"{Operation.UPLOAD_POINTS} is still under way: wait for it, cancel it or press Stop",
                code="busy_upload",
                params={"operation": Operation.UPLOAD_POINTS},
            )

    def _begin(self, operation: str) -> RobotClient:
        self.require_none(operation)
        client = self._host.client_or_raise()
        self._teach.leave_teach(self._readings.last_status)
        return client

    def _track(self, operation: str, completion: Completion, *, motion: bool) -> None:
        self._tracker.track(operation, completion, motion=motion, request_id=self._host.request_id)

    def _track_last(self, client: RobotClient, operation: str, *, motion: bool) -> None:
        tracker = client.last_tracker
        assert tracker is not None
        self._track(operation, tracker, motion=motion)
        self._acknowledge(client, tracker)

    def _acknowledge(self, client: RobotClient, tracker: CommandTracker) -> None:
        """GV291 read at once after the command, then with the tracker's backoff (1, 2, 4 ...
        ms) for at most ``timing.ACK_SPIN``, until it leaves the pre-command code. The polls
        alone could miss the whole 0xFF -> moving -> 0xFF window of a short command when the
        worker thread is late (a loaded machine): the tracker could then never tell the new 0xFF
        from the stale one. A result found here is kept by the tracker and published by the next
        poll, after that poll's pose and status."""
        host = self._host
        deadline = time.monotonic() + timing.ACK_SPIN
        while True:
            try:
                status = client.read_status(timeout=client.settings.effective_poll_timeout)
            except _READ_ERRORS as exc:
                # the command was taken (its write answered): a status read that fails does not
                # make it failed; the polls follow it (retried, and the link's own rules for a
                # controller that stays silent or busy: unknown when the link goes down)
                _log.info(
                    "%s: status read after the command failed (%s); the polls follow it", tracker.text, exc
                )
                return
            now = time.monotonic()
            if tracker.update(status, None, now) is not None or tracker.code_left_pre or now >= deadline:
                return
            host.run_urgent()  # a stop goes out at once
            active = self._tracker.active
            if active is None or active.completion is not tracker or not host.link_up:
                return
            time.sleep(tracker.poll_interval(now))

    def step(self, op: Step) -> None:
        client = self._begin(Operation.STEP)
        client.step(op.frame, op.offsets, op.ext_offsets, op.speed, wait=False)
        self._track_last(client, Operation.STEP, motion=True)

    def move_to_point(self, op: MoveToPoint) -> None:
        client = self._begin(Operation.MOVE_TO_POINT)
        client.move_to_point(
            op.end_id,
            via_id=op.via_id,
            orientation_changes=op.orientation_changes,
            ignore_middle=op.ignore_middle,
            speed=op.speed,
            tool=op.tool,
            wait=False,
        )
        self._track_last(client, Operation.MOVE_TO_POINT, motion=True)

    def go_zero(self, op: GoZero) -> None:
        client = self._begin(Operation.GO_ZERO)
        before = self._readings.last_pose  # (the client reads it when there was no poll yet)
        completion = client.go_zero(op.axis, before=before, switch_to_auto=op.switch_to_auto)
        self._track(Operation.GO_ZERO, completion, motion=True)

    def run_program(self, op: RunProgram) -> None:
        client = self._begin(Operation.RUN_PROGRAM)
        before = self._readings.last_pose
        watch = client.run_program(
            op.program_id, op.mode, op.cycles, op.speed_ratio, before=before, switch_to_auto=op.switch_to_auto
        )
        self._track(Operation.RUN_PROGRAM, watch, motion=True)

    def create_point(self, op: CreatePoint) -> None:
        self.require_none(Operation.CREATE_POINT)
        client = self._host.client_or_raise()
        client.create_point(op.point_id, pose=op.pose, tool=op.tool, wait=False)
        self._track_last(client, Operation.CREATE_POINT, motion=False)
