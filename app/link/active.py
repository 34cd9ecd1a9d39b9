"""The command under way and its completion, fed by every good poll (worker thread only).

:class:`MotionTracker` holds the one active command: a :class:`~app.link.tracker.CommandTracker`
(commands with GV291) or a :class:`~app.link.watch.MotionWatch` (run program, go to zero) until
a :class:`CommandResult` comes out. It imports no worker part, so every part (and
:mod:`app.link.host`) can name it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Protocol

from app.errors import Reason
from app.link.types import Operation
from app.models import CommandResult, ControllerStatus, Pose

__all__ = ["ActiveCommand", "Completion", "MotionTracker"]


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
