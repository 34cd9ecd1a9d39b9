"""Command completion: when has the controller finished the command the host sent?

Decisions on the open questions of PROTOCOL.md section 7 that live here:

* **Completion detection** (the stale-0xFF problem) is :class:`CommandTracker`. A command is
  *acknowledged* once GV291 has shown a value different from the code it held before the
  command was sent, or — for moves — once the motion is visibly under way (program state
  running/paused, status "moving", or the pose left its starting value). A terminal code
  (0xFF or an error) ends the command only if GV291 has left the pre-command code at some
  point since the command was sent; a code equal to the stale one never ends it. So an old
  0xFF is never taken for the new command's, at the price that a controller which goes
  0xFF -> 0 -> 0xFF faster than the host can read looks unacknowledged
  (-> :class:`CommandTimeout` after ``timing.ACK_TIMEOUT``). To keep that window small the
  first status read follows the command at once and, until GV291 has changed, reads follow
  every ``timing.ACK_POLL_INTERVAL`` (for at most ``ACK_TIMEOUT``). A move that was seen
  moving and has stopped while GV291 never left the stale code ends, after ``ACK_TIMEOUT``,
  as a :class:`CommandTimeout` saying the result is unknown (never as success).
* **After a stop** the wait ends when the host sent the stop itself, or when a move that was
  seen under way shows program state *stopped* with GV291 at 0 (initial) for
  ``timing.STOP_SETTLE`` (a transient 0 just before 0xFF is not a stop).
"""

from __future__ import annotations

from app import timing
from app.errors import AlarmRaised, CommandRefused, CommandStopped, CommandTimeout, TeachPadError
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import (
    RUN_COMMAND_TEXT,
    CommandKind,
    CommandStatus,
    ProgramState,
    RunCommand,
    alarm_names,
    decode_command_status,
)

__all__ = ["POSE_EPSILON", "CommandTracker", "command_text", "pose_moved"]

# A pose component that changed by more than this (mm or degrees) counts as motion.
POSE_EPSILON = 1e-3


# --------------------------------------------------------------------------------------------
# Completion detection
# --------------------------------------------------------------------------------------------


def command_text(command: RunCommand) -> str:
    return RUN_COMMAND_TEXT.get(command, f"command 0x{int(command):02X}")


def _pose_values(pose: Pose) -> tuple[float, ...]:
    return pose.xyzabc + tuple(pose.ext) + tuple(pose.joints or ())


def pose_moved(a: Pose, b: Pose) -> bool:
    va, vb = _pose_values(a), _pose_values(b)
    return len(va) != len(vb) or any(abs(x - y) > POSE_EPSILON for x, y in zip(va, vb, strict=True))


def _seconds(value: float) -> str:
    return str(round(value, 3))


class CommandTracker:
    """Decides how a command ended from successive status reads (see the module docstring).

    Feed it every status read (and, for moves, the pose) with :meth:`update`; it returns
    ``None`` while the command is under way and a :class:`CommandResult` when it ended. A
    result with ``ok=False`` has the matching typed error in :attr:`error` (CommandRefused,
    AlarmRaised, CommandTimeout, CommandStopped). Timing constants are read when the tracker
    is created, so tests can shrink them.
    """

    def __init__(
        self,
        command: RunCommand,
        before: ControllerStatus,
        before_pose: Pose | None,
        now: float,
        *,
        timeout: float | None = None,
    ) -> None:
        self.command = command
        self.kind = CommandKind.of(command)
        self.before = before
        self.before_pose = before_pose
        self.pre_code = before.command_status_code
        self.started = now
        self.is_move = self.kind is CommandKind.MOVE
        self.ack_timeout = timing.ACK_TIMEOUT
        self.stop_settle = timing.STOP_SETTLE
        self.hard_timeout = timeout
        # Without an explicit timeout a move may run as long as it makes progress.
        if timeout is not None:
            self._budget = timeout
        elif self.is_move:
            self._budget = timing.MOVE_TIMEOUT_MIN
        else:
            self._budget = timing.CREATE_POINT_TIMEOUT
        self._deadline = now + self._budget
        self.acknowledged = False
        self.ack_time: float | None = None
        self.code_left_pre = False
        self.motion_seen = False
        self.ack_poll_interval = timing.ACK_POLL_INTERVAL
        self.poll_interval_after_ack = (timing.MOVE_POLL_INTERVAL if self.is_move
                                        else timing.STATUS_POLL_INTERVAL)
        self._stopped_since: float | None = None
        self._idle_since: float | None = None
        self._last_pose = before_pose
        self.last_status: ControllerStatus | None = None
        self.result: CommandResult | None = None
        self.error: TeachPadError | None = None

    # -- public --------------------------------------------------------------------------
    @property
    def finished(self) -> bool:
        return self.result is not None

    @property
    def text(self) -> str:
        return command_text(self.command)

    def decode(self, code: int) -> CommandStatus:
        return decode_command_status(self.kind, code)

    def poll_interval(self, now: float) -> float:
        """How long to wait before the next status read.

        Fast until GV291 has left the pre-command code (the controller may show 0, "received",
        only briefly before the new final code), and for short commands until they end, for at
        most the acknowledgement timeout.
        """
        # short commands (create point, teach) finish within a controller cycle or two once
        # taken: keep reading fast after the acknowledgement too
        short = self.kind is not CommandKind.MOVE
        if short and now - self.started < timing.SHORT_COMMAND_SPIN:
            return 0.0  # back to back: the round trip itself paces the reads
        fast = not self.code_left_pre or short
        if fast and now - self.started < self.ack_timeout:
            return self.ack_poll_interval
        return self.poll_interval_after_ack

    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None:
        """Take one status read; return the result once the command has ended."""
        if self.result is not None:
            return self.result
        self.last_status = status
        code = status.command_status_code
        if status.alarms:
            names = ", ".join(alarm_names(int(status.alarms))) or str(int(status.alarms))
            return self._fail(
                AlarmRaised(int(status.alarms), f"{self.text}: alarm while waiting: {names}"),
                code, now,
            )
        if code != self.pre_code:
            self.code_left_pre = True
        progressed = self._note_motion(status, pose)
        if not self.acknowledged and (self.code_left_pre or self.motion_seen):
            self.acknowledged = True
            self.ack_time = now
        if self.acknowledged:
            decoded = self.decode(code)
            # A terminal code counts only once GV291 has left the stale pre-command value.
            if self.code_left_pre and decoded.is_done:
                return self._finish(True, decoded, f"{self.text}: {decoded.text}", now)
            if self.code_left_pre and decoded.is_error:
                err = CommandRefused(decoded, f"{self.text} refused: {decoded.text} (status {code})")
                return self._fail(err, code, now)
            stopped = self._check_stopped(status, code, now)
            if stopped is not None:
                return stopped
            if self._moved_without_status(status, progressed, now):
                text = self.decode(self.pre_code).text
                return self._fail(
                    CommandTimeout(
                        f"{self.text}: the arm moved and stopped, but the command status stayed "
                        f"{self.pre_code} '{text}' from before the command; the result is unknown"
                    ),
                    code, now,
                )
        elif now - self.started >= self.ack_timeout:
            text = self.decode(self.pre_code).text
            return self._fail(
                CommandTimeout(
                    f"controller did not acknowledge {self.text} within {_seconds(self.ack_timeout)} s "
                    f"(command status stayed {self.pre_code} '{text}' from before the command)"
                ),
                code, now,
            )
        if progressed and self.hard_timeout is None:
            self._deadline = now + self._budget
        if now >= self._deadline:
            decoded = self.decode(code)
            return self._fail(
                CommandTimeout(
                    f"{self.text} did not complete within {_seconds(self._budget)} s "
                    f"(last command status {code} '{decoded.text}')"
                ),
                code, now,
            )
        return None

    def stopped(self, now: float) -> CommandResult:
        """The host sent stop itself: the command ends as stopped (unless it already ended)."""
        if self.result is not None:
            return self.result
        code = self.last_status.command_status_code if self.last_status else self.pre_code
        return self._fail(CommandStopped(f"{self.text} stopped by the host"), code, now)

    # -- internals -----------------------------------------------------------------------
    def _note_motion(self, status: ControllerStatus, pose: Pose | None) -> bool:
        """Update ``motion_seen``; True when this read shows progress (for the stall timer)."""
        if not self.is_move:
            return False
        progressed = False
        state = status.program_state
        if state in (ProgramState.RUNNING, ProgramState.PAUSED):
            self.motion_seen = True
            progressed = state == ProgramState.PAUSED  # a paused move is alive, not stalled
        code = status.command_status_code
        if self.decode(code).is_moving and (self.code_left_pre or self.pre_code != code):
            self.motion_seen = True
        if pose is not None:
            if self.before_pose is not None and pose_moved(pose, self.before_pose):
                self.motion_seen = True
            if self._last_pose is not None and pose_moved(pose, self._last_pose):
                progressed = True
            self._last_pose = pose
        return progressed

    def _check_stopped(self, status: ControllerStatus, code: int, now: float) -> CommandResult | None:
        if not (self.is_move and self.motion_seen and status.program_state == ProgramState.STOPPED
                and self.code_left_pre and self.decode(code).is_initial):
            self._stopped_since = None
            return None
        if self._stopped_since is None:
            self._stopped_since = now
        if now - self._stopped_since < self.stop_settle:
            return None
        return self._fail(
            CommandStopped(f"{self.text} stopped: program state returned to stopped without 'done'"),
            code, now,
        )

    def _moved_without_status(self, status: ControllerStatus, progressed: bool, now: float) -> bool:
        """A move seen under way has been still for a while and GV291 never left the stale code."""
        if not self.is_move or self.code_left_pre or not self.motion_seen:
            return False
        if status.program_state != ProgramState.STOPPED or progressed:
            self._idle_since = None
            return False
        if self._idle_since is None:
            self._idle_since = now
        return now - self._idle_since >= self.stop_settle and now - self.started >= self.ack_timeout

    def _details(self, now: float) -> dict[str, float]:
        details = {"elapsed": now - self.started}
        if self.ack_time is not None:
            details["ack_after"] = self.ack_time - self.started
        return details

    def _finish(self, ok: bool, status: CommandStatus, message: str, now: float) -> CommandResult:
        self.result = CommandResult(self.command, self.kind, status, ok, message, self._details(now))
        return self.result

    def _fail(self, error: TeachPadError, code: int, now: float) -> CommandResult:
        self.error = error
        return self._finish(False, self.decode(code), str(error), now)
