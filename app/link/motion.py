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

import dataclasses
import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from app import timing
from app.errors import InvalidInput, MalformedResponse, ModbusExceptionError, Reason, ResponseTimeout
from app.link.client import RobotClient
from app.link.host import WorkerHost
from app.link.tracker import CommandTracker
from app.link.types import Operation, StepFrame
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import ProgramMotionMode

__all__ = ["ActiveCommand", "Completion", "MotionCommands", "MotionTracker"]

_log = logging.getLogger(__name__)

#: A status read that failed without the link going down (busy, no answer in time, a bad answer)
_READ_ERRORS = (ModbusExceptionError, ResponseTimeout, MalformedResponse)


class Completion(Protocol):
    @property
    def deadline(self) -> float: ...

    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None: ...

    def stopped(self, now: float) -> CommandResult: ...

    def unknown(
        self, now: float, cause: object = None, *, message: str | None = None, reason: Reason | None = None
    ) -> CommandResult: ...


@dataclass
class ActiveCommand:
    operation: str
    completion: Completion
    motion: bool  # a motion (blocks other motions) rather than a short command
    request_id: int | None = None


class MotionTracker:
    """The active command and its completion; fed by every good poll (worker thread only)."""

    def __init__(self) -> None:
        self.active: ActiveCommand | None = None

    @property
    def motion_under_way(self) -> str | None:
        """The operation of the motion under way (None when there is none)."""
        active = self.active
        return active.operation if active is not None and active.motion else None

    def track(self, operation: str, completion: Completion, *, motion: bool, request_id: int | None) -> None:
        self.active = ActiveCommand(operation, completion, motion, request_id)

    def take(self) -> ActiveCommand | None:
        """Forget the active command and return it (stop, link loss, close)."""
        active, self.active = self.active, None
        return active

    def update(
        self, status: ControllerStatus, pose: Pose, now: float
    ) -> tuple[CommandResult, int | None] | None:
        """Feed one poll (status read before pose); the result and its request id once it ended."""
        active = self.active
        if active is None:
            return None
        result = active.completion.update(status, pose, now)
        if result is None:
            return None
        self.active = None
        if active.operation == Operation.CREATE_POINT and result.ok:
            details = dict(result.details)
            details.update(zip(("x", "y", "z", "a", "b", "c"), pose.xyzabc, strict=True))
            result = dataclasses.replace(result, details=details)
        return result, active.request_id


class MotionCommands:
    """The job bodies of the long commands (worker thread; errors propagate to the executor)."""

    def __init__(self, host: WorkerHost) -> None:
        self._host = host

    def require_none(self, operation: str) -> None:
        """Refuse ``operation`` while a motion or an upload is under way."""
        host = self._host
        host.jog.require_no_halt(operation)
        busy = host.motion.motion_under_way
        if busy is not None:
            text = f"{busy} is still under way: wait for it or press Stop"
            raise InvalidInput(text, code="busy", params={"operation": busy})
        if host.uploader.run is not None:
            raise InvalidInput(
                f"{Operation.UPLOAD_POINTS} is still under way: wait for it, cancel it or press Stop",
                code="busy_upload",
                params={"operation": Operation.UPLOAD_POINTS},
            )

    def _begin(self, operation: str) -> RobotClient:
        self.require_none(operation)
        client = self._host.client_or_raise()
        self._host.jog.leave_teach(self._host.poller.last_status)
        return client

    def _track(self, operation: str, completion: Completion, *, motion: bool) -> None:
        self._host.motion.track(operation, completion, motion=motion, request_id=self._host.request_id)

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
            active = host.motion.active
            if active is None or active.completion is not tracker or not host.link_up:
                return
            time.sleep(tracker.poll_interval(now))

    def step(self, frame: StepFrame, offsets: Sequence[float], ext: Sequence[float], speed: float) -> None:
        client = self._begin(Operation.STEP)
        client.step(frame, offsets, ext, speed, wait=False)
        self._track_last(client, Operation.STEP, motion=True)

    def move_to_point(
        self,
        end_id: int,
        via_id: int | None,
        orientation_changes: bool,
        ignore_middle: bool,
        speed: float,
        tool: int,
    ) -> None:
        client = self._begin(Operation.MOVE_TO_POINT)
        client.move_to_point(
            end_id,
            via_id=via_id,
            orientation_changes=orientation_changes,
            ignore_middle=ignore_middle,
            speed=speed,
            tool=tool,
            wait=False,
        )
        self._track_last(client, Operation.MOVE_TO_POINT, motion=True)

    def go_zero(self, axis: int | None, switch_to_auto: bool = False) -> None:
        client = self._begin(Operation.GO_ZERO)
        before = self._host.poller.last_pose  # (the client reads it when there was no poll yet)
        self._track(
            Operation.GO_ZERO, client.go_zero(axis, before=before, switch_to_auto=switch_to_auto), motion=True
        )

    def run_program(
        self,
        program_id: int,
        mode: ProgramMotionMode,
        cycles: int,
        speed_ratio: int,
        switch_to_auto: bool = False,
    ) -> None:
        client = self._begin(Operation.RUN_PROGRAM)
        before = self._host.poller.last_pose
        watch = client.run_program(
            program_id, mode, cycles, speed_ratio, before=before, switch_to_auto=switch_to_auto
        )
        self._track(Operation.RUN_PROGRAM, watch, motion=True)

    def create_point(self, point_id: int, pose: Sequence[float] | None, tool: int) -> None:
        self.require_none(Operation.CREATE_POINT)
        client = self._host.client_or_raise()
        client.create_point(point_id, pose=pose, tool=tool, wait=False)
        self._track_last(client, Operation.CREATE_POINT, motion=False)
