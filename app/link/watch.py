"""How a command without a GV291 result ended (run program, go to zero): told by motion.

The controller answers a run program (440 <- 0x01) or a go to zero (445) only through its state:
:class:`MotionWatch` decides from the status and pose reads after the command, for the GUI's
worker (fed by its polls) and the CLI (fed by :meth:`~app.link.command_client.CommandClient.follow`)
alike. Its results sort into the outcomes of :mod:`app.link.outcome`:

* an alarm before anything moved: refused, with the alarm in words; after: ended by the alarm;
* nothing moved within ``timing.ACK_TIMEOUT``: refused (no such program; for go to zero, unless
  the joints already read zero: then done, "already at zero");
* moved, then program state stopped with the pose standing still: done -- for go to zero only
  when the joints asked for read zero (when the controller reports joints), else stopped short;
* the host's own stop: stopped; reads that fail or a link that goes down: unknown;
* seen done while another Modbus master was seen since it was sent (:mod:`app.link.foreign`): unknown
  -- the motion and the stop seen may be the other master's doing (issue 19).

A command sent while the controller already runs a program cannot be told by motion: the client
does not send it (:class:`~app.errors.ControllerBusy`, in :mod:`app.link.client`).
"""

from __future__ import annotations

from collections.abc import Callable

from app import timing
from app.errors import AlarmRaised, CommandStopped, OutcomeUnknown, Reason, TeachPadError
from app.link.arrival import pose_moved
from app.link.foreign import ForeignMasterWatch, overlapped_text
from app.link.outcome import UNKNOWN_ADVICE, OutcomeHook
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import JOINT_AXIS_NAMES, ProgramState, RunCommand, alarm_names

__all__ = ["ZERO_TOLERANCE", "MotionWatch", "StateCheck", "joints_off_zero"]

ZERO_TOLERANCE = 0.05  # degrees (or mm for linear axes): a joint this close to 0 is at zero


def joints_off_zero(pose: Pose | None, axes: tuple[int, ...]) -> tuple[int, float] | None:
    """The first of ``axes`` (0..10 = J1..J11) not at zero in ``pose`` and its value; None when
    all are at zero. Raises LookupError when the pose does not report the joints (J1..J6 are a
    project extension; J7..J11 are the external axes)."""
    if pose is None or pose.joints is None:
        raise LookupError("the controller does not report its joints")
    values = (*pose.joints, *pose.ext)
    for axis in axes:
        if abs(values[axis]) > ZERO_TOLERANCE:
            return axis, values[axis]
    return None


class MotionWatch:
    """Program state and pose decide how a program run / go to zero ended (GV291 is not used).

    Started once the program state shows running/paused or the pose moves; done once it reads
    stopped with the pose standing still. No sign of motion within ``timing.ACK_TIMEOUT`` means
    the controller did not start it. ``zero_axes``: a go to zero's joints (0..10), checked at the
    end when the controller reports joints. ``program``: a run's program id (for its words).
    """

    def __init__(
        self,
        command: RunCommand | None,
        text: str,
        before_pose: Pose | None,
        now: float,
        *,
        operation: str = "",
        zero_axes: tuple[int, ...] | None = None,
        program: int | None = None,
    ) -> None:
        self.command = command
        self.text = text
        self.operation = operation or text
        self.zero_axes = zero_axes
        self.program = program
        self.started = now
        self.ack_timeout = timing.ACK_TIMEOUT
        self._last_pose = before_pose
        self.seen = False  # motion (or a running program) was seen: the controller took it
        self._moved = False  # the pose itself was seen to move (not only a running program state)
        # go to zero on joints already at zero: a controller may still report its program running for
        # a moment; with no pose moved it was "already at zero", whichever the polls caught
        self._zero_at_start = zero_axes is not None and _reads_zero(before_pose, zero_axes)
        self._start_pose = before_pose
        self.result: CommandResult | None = None
        self.error: TeachPadError | None = None
        self.note: OutcomeHook | None = None  # the audit's hook (app/link/outcome.py)
        # the sending client's watch for another master (app/link/foreign.py): what was seen done
        # while another master was seen cannot be told from its doing, it ends unknown
        self.foreign: ForeignMasterWatch | None = None

    @property
    def finished(self) -> bool:
        return self.result is not None

    @property
    def deadline(self) -> float:
        """Until when a run of failed status reads does not yet make the outcome unknown."""
        return self.started + (self.ack_timeout if not self.seen else 0.0)

    def _args(self, **extra: object) -> dict[str, object]:
        args: dict[str, object] = {"operation": self.operation}
        if self.command is not None:
            args["command"] = int(self.command)
        if self.program is not None:
            args["program"] = self.program
        return {**args, **extra}

    def _end(
        self, ok: bool, message: str, now: float, reason: Reason, error: TeachPadError | None = None
    ) -> CommandResult:
        foreign = self.foreign
        if ok and foreign is not None and foreign.seen_since(self.started):
            # what it was seen to do (moved and stood still, at zero) may be the other master's
            message = overlapped_text(self.text)
            error = OutcomeUnknown(message, params=self._args(foreign=True))
            ok, reason = False, error.as_reason()
        self.error = error
        self.result = CommandResult(
            self.command, None, None, ok, message, {"elapsed": now - self.started}, reason=reason
        )
        if self.note is not None:
            self.note(self.result)
        return self.result

    def _fail(self, error: TeachPadError, now: float) -> CommandResult:
        return self._end(False, str(error), now, error.as_reason(), error)

    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None:
        if self.result is not None:
            return self.result
        if status.alarms:
            return self._alarm(int(status.alarms), now)
        running = status.program_state in (ProgramState.RUNNING, ProgramState.PAUSED)
        moved = _away(pose, self._last_pose)
        if pose is not None:
            self._last_pose = pose
        # moved since the last read, or crept away from where it was when sent (slower than a read's step)
        self._moved = self._moved or moved or _away(pose, self._start_pose)
        if not self.seen:
            if running or moved:
                self.seen = True
            elif now - self.started >= self.ack_timeout:
                return self._not_started(now)
            return None
        if not running and not moved:
            return self._stood_still(now)
        return None

    def _alarm(self, mask: int, now: float) -> CommandResult:
        names = ", ".join(alarm_names(mask))
        if self.seen:
            text, code = f"{self.text}: ended by an alarm: {names}", "alarm_while_waiting"
        else:
            text, code = f"{self.text} refused by the controller: {names}", "refused_alarm"
        error = AlarmRaised(mask, text, params=self._args())
        error.code = code
        return self._fail(error, now)

    def _not_started(self, now: float) -> CommandResult:
        seconds = round(self.ack_timeout, 3)
        if self.zero_axes is not None and _reads_zero(self._last_pose, self.zero_axes):
            return self._already_at_zero(now)
        if self.program is not None:
            text = (
                f"{self.text} refused: the program did not start within {seconds:g} s (no such "
                "program, or the controller refused it)"
            )
            return self._fail(TeachPadError(text, code="program_not_started", params=self._args()), now)
        text = (
            f"{self.text} refused: nothing moved within {seconds:g} s "
            "(refused by the controller, or already there)"
        )
        return self._fail(TeachPadError(text, code="no_motion", params=self._args(seconds=seconds)), now)

    def _stood_still(self, now: float) -> CommandResult:
        if self.zero_axes is not None:
            try:
                off = joints_off_zero(self._last_pose, self.zero_axes)
            except LookupError:
                off = None  # no joints reported: stood still is all that can be seen
            if off is not None:
                axis, value = off
                text = f"{self.text}: the arm stopped before zero ({JOINT_AXIS_NAMES[axis]} at {value:.3f})"
                params = self._args(axis=JOINT_AXIS_NAMES[axis], value=round(value, 3))
                return self._fail(CommandStopped(text, code="zero_stopped_short", params=params), now)
            if self._zero_at_start and not self._moved:
                return self._already_at_zero(now)
        return self._end(True, f"{self.text}: done", now, Reason("done", self._args()))

    def _already_at_zero(self, now: float) -> CommandResult:
        return self._end(
            True, f"{self.text}: done (already at zero)", now, Reason("zero_already", self._args())
        )

    def stopped(self, now: float) -> CommandResult:
        """The host sent stop itself."""
        if self.result is not None:
            return self.result
        error = CommandStopped(
            f"{self.text} stopped by the operator", code="stopped_by_operator", params=self._args()
        )
        return self._fail(error, now)

    def unknown(
        self, now: float, cause: object = None, *, message: str | None = None, reason: Reason | None = None
    ) -> CommandResult:
        """Its outcome cannot be told (status reads failed, the link went down): ends unknown."""
        if self.result is not None:
            return self.result
        text = message or f"{self.text}: {UNKNOWN_ADVICE}" + (f" ({cause})" if cause else "")
        error = OutcomeUnknown(text, params=self._args())
        return self._end(False, text, now, reason or error.as_reason(), error)


class StateCheck:
    """How a plain command without a result register ended (work mode, stop, pause, resume):
    done once the status shows what it asked for (``expect``), refused when it still does not
    after ``timing.ACK_TIMEOUT`` (``describe`` says what the status shows instead). The CLI's
    plain commands are judged by it (:meth:`~app.link.command_client.CommandClient.follow`)."""

    seen = False  # (a state check has no "started")

    def __init__(
        self,
        text: str,
        expect: Callable[[ControllerStatus], bool],
        describe: Callable[[ControllerStatus], str],
        now: float,
        *,
        operation: str = "",
    ) -> None:
        self.text = text
        self.expect = expect
        self.describe = describe
        self.operation = operation or text
        self.started = now
        self.ack_timeout = timing.ACK_TIMEOUT
        self.result: CommandResult | None = None
        self.error: TeachPadError | None = None
        self.note: OutcomeHook | None = None

    @property
    def finished(self) -> bool:
        return self.result is not None

    @property
    def deadline(self) -> float:
        return self.started + self.ack_timeout

    def _end(
        self, ok: bool, message: str, now: float, reason: Reason, error: TeachPadError | None = None
    ) -> CommandResult:
        self.error = error
        self.result = CommandResult(
            None, None, None, ok, message, {"elapsed": now - self.started}, reason=reason
        )
        if self.note is not None:
            self.note(self.result)
        return self.result

    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None:
        if self.result is not None:
            return self.result
        args = {"operation": self.operation}
        if self.expect(status):
            return self._end(True, f"{self.text}: done ({self.describe(status)})", now, Reason("done", args))
        if now - self.started < self.ack_timeout:
            return None
        seconds = round(self.ack_timeout, 3)
        text = f"{self.text} not taken: {self.describe(status)} after {seconds:g} s"
        error = TeachPadError(text, code="state_not_reached", params={**args, "seconds": seconds})
        return self._end(False, text, now, error.as_reason(), error)

    def stopped(self, now: float) -> CommandResult:
        return self.unknown(now)

    def unknown(
        self, now: float, cause: object = None, *, message: str | None = None, reason: Reason | None = None
    ) -> CommandResult:
        if self.result is not None:
            return self.result
        text = message or f"{self.text}: {UNKNOWN_ADVICE}" + (f" ({cause})" if cause else "")
        error = OutcomeUnknown(text, params={"operation": self.operation})
        return self._end(False, text, now, reason or error.as_reason(), error)


def _reads_zero(pose: Pose | None, axes: tuple[int, ...]) -> bool:
    """The joints ``axes`` of ``pose`` read zero (False when unknown: no pose, no joints)."""
    try:
        return joints_off_zero(pose, axes) is None
    except LookupError:
        return False


def _away(pose: Pose | None, start: Pose | None) -> bool:
    """``pose`` is not where ``start`` was (False when either is unknown)."""
    return pose is not None and start is not None and pose_moved(pose, start)
