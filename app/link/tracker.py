"""Command completion: when has the controller finished the command the host sent?

Decisions on the open questions of PROTOCOL.md section 7 that live here:

* **Completion detection** (the stale-0xFF problem) is :class:`CommandTracker`. A command is
  *acknowledged* once GV291 has shown a value different from its pre-command code, or -- for
  moves -- once the motion is visibly under way (program state running/paused, status
  "moving", or the pose left its starting value). A terminal code (0xFF or an error) ends the
  command only if GV291 has left the pre-command code since the command was sent; a code equal
  to the stale one never ends it as such. Two rules (``rule``), chosen per connection by the
  client (``ConnectionSettings.completion``):

  - ``"sentinel"`` (GV291 keeps what the host writes): the client writes
    :data:`~app.protocol.enums.STATUS_SENTINEL` into GV291 just before the command, so the
    pre-command code is the sentinel and the controller's own write of its result -- even
    straight to 0xFF within one scan -- is the proof. Confirmed results only.
  - ``"observe"`` (GV291 read-only): the pre-command code is whatever the controller showed.
    A controller that goes 0xFF -> 0 -> 0xFF between two reads shows no change. For the
    idempotent instant commands (create point, teach enable/disable), when the status stayed at
    the 0xFF (done) it had before for ``unconfirmed_after`` seconds the command ends *done,
    unconfirmed* (``ok=True, unconfirmed=True``): an error code would have been a visible
    change, so this is never a success over a reported error. When it stayed at an *error*
    code from before, the command ends refused (``unconfirmed=True``): the same error again, or
    not taken -- never a success. Teach enable/disable are confirmed by the controller mode
    (560 entering / leaving 2, Modbus teach) too. Moves never end unconfirmed: they confirm by
    motion as above, and a move that was seen moving and stopped while GV291 never left the
    stale code ends, after ``ACK_TIMEOUT``, as a :class:`CommandTimeout` saying the result is
    unknown (never as success).
* **Polling while waiting** backs off (:meth:`CommandTracker.poll_interval`): the first read
  follows the command at once, then ``ACK_BACKOFF_FIRST``, doubling, capped at
  ``ACK_BACKOFF_CAP`` (moves: ``MOVE_POLL_INTERVAL``), and never sleeping past the
  unconfirmed deadline. No spinning: a real controller is not hammered. For the instant
  commands a :class:`ResultPacer` (one per connection) times the second read: when this
  controller's results usually show, learned from the commands before, so a steady
  controller is read about twice per command (the first read, then the result) and a slow
  or jittery one backs off as before. A paced read that came too early is followed by one
  read a little later (``ResultPacer.retry_after``, at least ``RETRY_MIN``), then the backoff.
  The caller may fill the wait with a transaction that does not touch what the command reads
  (``CommandClient.wait(meanwhile=)``: an upload writes the next point's pose there).
* **After a stop** the wait ends when the host sent the stop itself (:meth:`CommandTracker.stopped`,
  at once, also for an instant command whose result has not shown yet: a controller that
  resets GV291 to 0 on a stop never shows it, and waiting for it would hold the host for the
  command's timeout; the command ends failed, *not confirmed*), or when a move that was
  seen under way shows program state *stopped* with GV291 at 0 (initial) for
  ``timing.STOP_SETTLE`` (a transient 0 just before 0xFF is not a stop).
"""

from __future__ import annotations

import math
from collections import deque
from typing import Literal

from app import timing
from app.errors import (
    AlarmRaised,
    CommandRefused,
    CommandStopped,
    CommandTimeout,
    OutcomeUnknown,
    Reason,
    TeachPadError,
)
from app.link.arrival import arrived, pose_moved
from app.link.foreign import ForeignMasterWatch, overlapped_text
from app.link.outcome import UNKNOWN_ADVICE, OutcomeHook
from app.link.pacer import ResultPacer
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import (
    RUN_COMMAND_TEXT,
    STATUS_DONE,
    CommandKind,
    CommandStatus,
    ControllerMode,
    ProgramState,
    RunCommand,
    alarm_names,
    controller_mode_text,
    decode_command_status,
)

__all__ = [
    "BACKOFF_DOUBLINGS_MAX",
    "CommandTracker",
    "CompletionRule",
    "backoff",
    "command_text",
]

CompletionRule = Literal["sentinel", "observe"]


# --------------------------------------------------------------------------------------------
# Completion detection
# --------------------------------------------------------------------------------------------


def command_text(command: RunCommand) -> str:
    return RUN_COMMAND_TEXT.get(command, f"command 0x{int(command):02X}")


#: Doublings after which a backoff is at its cap whatever its first pause (2**60 x 1 ns > 30 years):
#: the exponent stops there, so a wait of any length (a move read for minutes) never overflows.
BACKOFF_DOUBLINGS_MAX = 60


def backoff(first: float, cap: float, doublings: int) -> float:
    """``first`` doubled ``doublings`` times (none when negative), capped at ``cap``."""
    return min(cap, first * 2.0 ** min(max(0, doublings), BACKOFF_DOUBLINGS_MAX))


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
        rule: CompletionRule = "observe",
        pre_code: int | None = None,
        unconfirmed_after: float | None = None,
        pacer: ResultPacer | None = None,
    ) -> None:
        self.command = command
        # Move to point: the X Y Z this host sent for the end point, when it knows it. A move whose
        # GV291 never left the stale code, seen moving and now still at the target, ended there.
        self.target: tuple[float, float, float] | None = None
        self.target_joints: tuple[float, ...] | None = None  # a joint step: J1..J6 where it ends
        self.target_ext: tuple[float, ...] | None = None  # a step that moves external axes: E1..E5
        self.kind = CommandKind.of(command)
        self.before = before
        self.before_pose = before_pose
        self.rule: CompletionRule = rule
        # "sentinel": the code the host wrote into GV291 just before the command
        self.pre_code = before.command_status_code if pre_code is None else pre_code
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
        self.backoff_first = timing.ACK_BACKOFF_FIRST
        self.backoff_cap = timing.MOVE_POLL_INTERVAL if self.is_move else timing.ACK_BACKOFF_CAP
        # observe rule, instant commands only: when a stale 0xFF / error counts as this command's
        self.unconfirmed_after: float | None = None
        if rule == "observe" and not self.is_move:
            self.unconfirmed_after = (
                timing.UNCONFIRMED_AFTER if unconfirmed_after is None else unconfirmed_after
            )
        self.reads = 0
        # instant commands: the second read is timed by the pacer (see ResultPacer)
        self.pacer = None if self.is_move else pacer
        self._read_at = math.inf  # when the next read goes out (monotonic), planned by poll_interval
        # when the last two reads went out (monotonic), and the read that showed the command taken:
        # what the pacer needs, and no more (a move may be read for as long as it runs)
        self._sent: deque[float] = deque(maxlen=2)
        self._ack_sent = 0.0
        self._ack_read = 0  # how many reads it took to see the command taken (GV291 left the old code)
        self._stopped_since: float | None = None
        self._idle_since: float | None = None
        self._last_pose = before_pose
        self.last_status: ControllerStatus | None = None
        self.result: CommandResult | None = None
        self.error: TeachPadError | None = None
        self.note: OutcomeHook | None = None  # the audit's hook, called with the result (outcome.py)
        # the sending client's watch for another master (app/link/foreign.py): a "done" seen
        # while another master was seen cannot be told from its command's, it ends unknown
        self.foreign: ForeignMasterWatch | None = None

    # -- public --------------------------------------------------------------------------
    @property
    def finished(self) -> bool:
        return self.result is not None

    @property
    def text(self) -> str:
        return command_text(self.command)

    @property
    def deadline(self) -> float:
        """When the command's own time runs out (monotonic; a move making progress moves it on)."""
        return self._deadline

    def decode(self, code: int) -> CommandStatus:
        return decode_command_status(self.kind, code)

    def poll_interval(self, now: float) -> float:
        """How long to wait before the next status read: backoff from the command on.

        ``ACK_BACKOFF_FIRST`` after the first read, doubling with every read, capped at
        ``backoff_cap``; never past the moment an unchanged status counts as unconfirmed.
        """
        ack = self._ack_read  # reads up to the one that showed the command taken (0: not yet)
        if self.pacer is not None and ack and self.reads == ack:
            # taken, no result yet: the next read when this controller's results usually show
            interval = max(0.0, self._ack_sent + self.pacer.estimate - now)
        elif self.pacer is not None and ack and self.reads == ack + 1:
            # the paced read was early: once more a little later, then the backoff as before
            interval = self.pacer.retry_after(now - self._ack_sent, self.backoff_first)
        elif self.pacer is not None and ack:
            interval = backoff(self.backoff_first, self.backoff_cap, self.reads - ack - 2)
        else:
            interval = backoff(self.backoff_first, self.backoff_cap, self.reads - 1)
        if self.unconfirmed_after is not None and not self.acknowledged:
            left = self.started + self.unconfirmed_after - now
            if left > 0:
                interval = min(interval, left)
        self._read_at = now + interval
        return interval

    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None:
        """Take one status read; return the result once the command has ended."""
        if self.result is not None:
            return self.result
        code = self._note_read(status, now)
        if status.alarms:
            if self.before.alarms and code == self.pre_code and now - self.started < self.ack_timeout:
                return None  # sent during the alarm: the controller's own refusal code is on its way
            return self._alarm(status, code, now)
        self._note_code(code)
        progressed = self._note_motion(status, pose)
        if not self.acknowledged and (self.code_left_pre or self.motion_seen):
            self.acknowledged = True
            self.ack_time = now
        if self.acknowledged:
            result = self._judge_acknowledged(status, pose, code, progressed, now)
        else:
            result = self._judge_unacknowledged(status, code, now)
        if result is not None:
            return result
        return self._check_deadline(code, progressed, now)

    def _note_read(self, status: ControllerStatus, now: float) -> int:
        """Count the read and keep its status; GV291's code in it."""
        self.reads += 1
        self._sent.append(min(self._read_at, now))  # an unplanned read (a poll): its answer's time
        self._read_at = math.inf
        self.last_status = status
        return status.command_status_code

    def _note_code(self, code: int) -> None:
        """GV291 left the pre-command code (the first read that shows it is what the pacer learns from)."""
        if code != self.pre_code:
            if not self.code_left_pre:
                self._ack_read = self.reads
                self._ack_sent = self._sent[-1]
            self.code_left_pre = True

    def _judge_acknowledged(
        self, status: ControllerStatus, pose: Pose | None, code: int, progressed: bool, now: float
    ) -> CommandResult | None:
        """The command was taken: what the status word says, then a stop, then what the pose says."""
        said = self._judge_status_word(code, now)
        if said is not None:
            return said
        stopped = self._check_stopped(status, code, now)
        if stopped is not None:
            return stopped
        return self._judge_motion(status, pose, code, progressed, now)

    def _judge_status_word(self, code: int, now: float) -> CommandResult | None:
        """A terminal code (done or refused) ends the command, but only once GV291 has left the
        stale pre-command value."""
        decoded = self.decode(code)
        if self.code_left_pre and decoded.is_done:
            return self._finish(
                True,
                decoded,
                f"{self.text}: {decoded.text}",
                now,
                reason=Reason("done", self._args(status=code)),
            )
        if self.code_left_pre and decoded.is_error:
            err = CommandRefused(
                decoded, f"{self.text} refused: {decoded.text} (status {code})", params=self._args()
            )
            return self._fail(err, code, now)
        return None

    def _judge_motion(
        self, status: ControllerStatus, pose: Pose | None, code: int, progressed: bool, now: float
    ) -> CommandResult | None:
        """A move that moved and stopped while GV291 kept its stale code: done when the arm is at
        the target, else the result is unknown (never a success)."""
        at_target = self._at_target(pose)
        if not self._moved_without_status(status, progressed, now, at_target=at_target):
            return None
        if at_target:
            done = self.decode(STATUS_DONE)
            return self._finish(
                True,
                done,
                f"{self.text}: {done.text} (arrived at the point; the command status did not change)",
                now,
                reason=Reason("done", self._args(status=STATUS_DONE)),
            )
        text = self.decode(self.pre_code).text
        return self._fail(
            CommandTimeout(
                f"{self.text}: the arm moved and stopped, but the command status stayed "
                f"{self.pre_code} '{text}' from before the command; the result is unknown",
                code="result_unknown",
                params=self._args(status=self.pre_code),
            ),
            code,
            now,
        )

    def _judge_unacknowledged(self, status: ControllerStatus, code: int, now: float) -> CommandResult | None:
        """Not taken yet: proven by the controller mode (teach enable/disable), unconfirmed
        (observe rule), or not acknowledged in time."""
        if self._teach_mode_changed(status):
            decoded = self.decode(STATUS_DONE)
            return self._finish(
                True,
                decoded,
                f"{self.text}: {decoded.text} (seen in the controller mode, "
                f"now {controller_mode_text(int(status.mode))})",
                now,
                reason=Reason("done_by_mode", self._args(mode=int(status.mode))),
            )
        if (
            self.unconfirmed_after is not None
            and now - self.started >= self.unconfirmed_after
            and (self.decode(code).is_done or self.decode(code).is_error)
        ):
            return self._unconfirmed(code, now)
        if now - self.started >= self.ack_timeout:
            text = self.decode(self.pre_code).text
            return self._fail(
                CommandTimeout(
                    f"controller did not acknowledge {self.text} within {_seconds(self.ack_timeout)} s "
                    f"(command status stayed {self.pre_code} '{text}' from before the command)",
                    code="not_acknowledged",
                    params=self._args(seconds=round(self.ack_timeout, 3), status=self.pre_code),
                ),
                code,
                now,
            )
        return None

    def _check_deadline(self, code: int, progressed: bool, now: float) -> CommandResult | None:
        """The command's own time: a move making progress (no explicit timeout) moves it on."""
        if progressed and self.hard_timeout is None:
            self._deadline = now + self._budget
        if now >= self._deadline:
            decoded = self.decode(code)
            return self._fail(
                CommandTimeout(
                    f"{self.text} did not complete within {_seconds(self._budget)} s "
                    f"(last command status {code} '{decoded.text}')",
                    code="command_timeout",
                    params=self._args(seconds=round(self._budget, 3), status=code),
                ),
                code,
                now,
            )
        return None

    def unknown(
        self, now: float, cause: object = None, *, message: str | None = None, reason: Reason | None = None
    ) -> CommandResult:
        """The host cannot tell how it ended (its status reads failed, the link went down, it is
        no longer followed): ends *unknown* (unless it already ended). ``message``/``reason``
        replace the default words ("sent; the outcome is unknown -- check the robot ...")."""
        if self.result is not None:
            return self.result
        code = self.last_status.command_status_code if self.last_status else self.pre_code
        text = message or f"{self.text}: {UNKNOWN_ADVICE}" + (f" ({cause})" if cause else "")
        error = OutcomeUnknown(text, params=self._args())
        self.error = error
        return self._finish(False, self.decode(code), text, now, reason=reason or error.as_reason())

    def stopped(self, now: float) -> CommandResult:
        """The host sent stop itself: the command ends as stopped (unless it already ended)."""
        if self.result is not None:
            return self.result
        code = self.last_status.command_status_code if self.last_status else self.pre_code
        # an instant command (create point) stopped before its result showed: not confirmed either way
        unseen = "" if self.is_move else " before its result was seen (not confirmed)"
        return self._fail(
            CommandStopped(
                f"{self.text} stopped by the operator{unseen}",
                code="stopped_by_operator",
                params=self._args(),
            ),
            code,
            now,
        )

    # -- internals -----------------------------------------------------------------------
    def _alarm(self, status: ControllerStatus, code: int, now: float) -> CommandResult:
        """An alarm ends the wait. For a command sent during the alarm, GV291's refusal is the
        controller's own word for it (e.g. 2, emergency stop, for a step sent during one); an
        alarm raised after the command ended it (alarm while waiting)."""
        decoded = self.decode(code)
        if self.before.alarms and code != self.pre_code and decoded.is_error:
            err: TeachPadError = CommandRefused(
                decoded, f"{self.text} refused: {decoded.text} (status {code})", params=self._args()
            )
        else:
            names = ", ".join(alarm_names(int(status.alarms))) or str(int(status.alarms))
            err = AlarmRaised(
                int(status.alarms), f"{self.text}: alarm while waiting: {names}", params=self._args()
            )
        return self._fail(err, code, now)

    def _teach_mode_changed(self, status: ControllerStatus) -> bool:
        """Teach enable/disable proven by the controller mode (560) entering / leaving 2."""
        teach = ControllerMode.MODBUS_TEACH
        was, now_in = self.before.mode == teach, status.mode == teach
        if self.command is RunCommand.TEACH_ENABLE:
            return now_in and not was
        if self.command is RunCommand.TEACH_DISABLE:
            return was and not now_in
        return False

    def _unconfirmed(self, code: int, now: float) -> CommandResult:
        """Observe rule: GV291 never moved from its pre-command code (0xFF or an error)."""
        decoded = self.decode(code)
        waited = _seconds(now - self.started)
        if decoded.is_done:
            message = (
                f"{self.text}: done, unconfirmed (command status stayed {code} '{decoded.text}' "
                f"as before the command for {waited} s; the controller reported no error)"
            )
            return self._finish(
                True,
                decoded,
                message,
                now,
                unconfirmed=True,
                reason=Reason("done_unconfirmed", self._args(status=code)),
            )
        self.error = CommandRefused(
            decoded,
            f"{self.text} refused (unconfirmed): command status stayed {code} '{decoded.text}' "
            f"from the previous command for {waited} s",
            code="refused_unconfirmed",
            params=self._args(seconds=float(waited)),
        )
        return self._finish(
            False, decoded, str(self.error), now, unconfirmed=True, reason=self.error.as_reason()
        )

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
        if not (
            self.is_move
            and self.motion_seen
            and status.program_state == ProgramState.STOPPED
            and self.code_left_pre
            and self.decode(code).is_initial
        ):
            self._stopped_since = None
            return None
        if self._stopped_since is None:
            self._stopped_since = now
        if now - self._stopped_since < self.stop_settle:
            return None
        return self._fail(
            CommandStopped(
                f"{self.text} stopped: program state returned to stopped without 'done'", params=self._args()
            ),
            code,
            now,
        )

    def _moved_without_status(
        self, status: ControllerStatus, progressed: bool, now: float, *, at_target: bool = False
    ) -> bool:
        """A move seen under way has been still for a while and GV291 never left the stale code
        (still at its target: after ``stop_settle``; elsewhere: also after ``ack_timeout``)."""
        if not self.is_move or self.code_left_pre or not self.motion_seen:
            return False
        if status.program_state != ProgramState.STOPPED or progressed:
            self._idle_since = None
            return False
        if self._idle_since is None:
            self._idle_since = now
        settled = now - self._idle_since >= self.stop_settle
        return settled and (at_target or now - self.started >= self.ack_timeout)

    def _at_target(self, pose: Pose | None) -> bool:
        """The arm stands where this host sent it (see :func:`app.link.arrival.arrived`)."""
        return pose is not None and arrived(pose, self.target, self.target_joints, self.target_ext)

    def _details(self, now: float) -> dict[str, float]:
        details = {"elapsed": now - self.started}
        if self.ack_time is not None:
            details["ack_after"] = self.ack_time - self.started
        return details

    def _args(self, **extra: object) -> dict[str, object]:
        """A reason's arguments: the command (its number) and what the caller adds."""
        return {"command": int(self.command), **extra}

    def _finish(
        self,
        ok: bool,
        status: CommandStatus,
        message: str,
        now: float,
        *,
        unconfirmed: bool = False,
        reason: Reason | None = None,
    ) -> CommandResult:
        foreign = self.foreign
        if ok and foreign is not None and foreign.seen_since(self.started):
            message = overlapped_text(self.text)
            self.error = OutcomeUnknown(message, params=self._args(foreign=True))
            ok, reason = False, self.error.as_reason()
        details = self._details(now)
        details["reads"] = float(self.reads)
        ack = self._ack_read
        if self.pacer is not None and not unconfirmed and 0 < ack < self.reads:
            # a result seen after the read that showed the command taken: how long after it
            taken = self._ack_sent
            missed = self._sent[-2] - taken if self.reads > ack + 1 else None
            self.pacer.learn(missed, self._sent[-1] - taken)
        self.result = CommandResult(
            self.command, self.kind, status, ok, message, details, unconfirmed=unconfirmed, reason=reason
        )
        if self.note is not None:
            self.note(self.result)
        return self.result

    def _fail(self, error: TeachPadError, code: int, now: float) -> CommandResult:
        self.error = error
        return self._finish(False, self.decode(code), str(error), now, reason=error.as_reason())
