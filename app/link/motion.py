"""Completion tracking of the one command under way (step, move, go to zero, run program, ...).

The regular polls feed the active command: a :class:`CommandTracker` (commands with GV291) or a
:class:`MotionWatch` (run program and go to zero, which do not use GV291) until a
:class:`CommandResult` comes out. Only one command is tracked at a time.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Protocol

from app import timing
from app.link.tracker import pose_moved
from app.link.types import Operation
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import ProgramState, RunCommand, alarm_names

__all__ = ["ActiveCommand", "Completion", "MotionTracker", "MotionWatch"]


class Completion(Protocol):
    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None: ...

    def stopped(self, now: float) -> CommandResult: ...


class MotionWatch:
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

    def update(self, status: ControllerStatus, pose: Pose,
               now: float) -> tuple[CommandResult, int | None] | None:
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
