"""The jog state machine (PROTOCOL.md case 4) and the dead-man around it, on the worker thread.

Release writes ratio 0 and keeps teach enabled; teach is disabled after
:data:`app.timing.TEACH_IDLE_DISABLE` s without a jog, before any other motion, on disconnect and
on shutdown. When the link comes back after a loss, ratio 0 and teach disable go out before
anything else (a real controller keeps jogging when its master goes away); when a silent
controller answers again, ratio 0 goes out at once if a jog was under way.

A jog is over only when the controller has answered its speed 0 (or a Stop) and the pose is
seen still (:class:`~app.link.halt.HaltWatch`, app/link/halt.py): a refused or unanswered speed 0
is sent again at every poll (:meth:`JogMachine.settle_halt`), escalates to Stop, the envelope
guard keeps deciding on the jog being released, and the GUI is told (``publish_halt``). A Stop
the controller refused is followed the same way, and so is a Pause it refused
(:meth:`JogMachine.pause_refused`; the Pause's request ends with the outcome). No new jog or
motion starts meanwhile.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass

from app import timing
from app.errors import (
    CommandRefused,
    InvalidInput,
    LinkError,
    ModbusExceptionError,
    OutcomeUnknown,
    Reason,
    TeachPadError,
)
from app.link.active import MotionTracker
from app.link.halt import HaltWatch, HaltWrite, follow_refused_stop, halt_refusal, settle, write_halt_stop
from app.link.host import PartLink
from app.link.outcome import UNKNOWN_ADVICE
from app.link.tracker import CommandTracker
from app.link.types import HaltKind, JogRequest, Operation, UnconfirmedHalt
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import ControllerMode, ProgramState, TeachFrame, controller_mode_text
from app.protocol.exceptions import exception_text, not_carried_out
from app.safety.envelope import EnvelopeRefused, EnvelopeViolation
from app.safety.jog_guard import GuardTiming, JogGuard

__all__ = ["JogMachine", "PreemptedError", "TeachState"]

#: The operation a halt's unconfirmed / escalated notice is said under.
_HALT_OPERATION = {
    HaltKind.RELEASE: Operation.JOG_RELEASE,
    HaltKind.STOP: Operation.STOP,
    HaltKind.PAUSE: Operation.PAUSE,
}


@dataclass
class TeachState:
    enabled: bool = False  # we enabled teach mode and have not seen it end
    frame_key: tuple[TeachFrame, int, int] | None = None
    axis: tuple[int, int] | None = None  # (axis, direction) last written
    ratio: float = 0.0  # last GV203 we wrote
    enabled_at: float = 0.0

    @property
    def moving(self) -> bool:
        """Teach is on with a nonzero speed written: the arm may be jogging."""
        return self.enabled and self.ratio != 0.0


class PreemptedError(Exception):
    """A jog sequence gave way to an urgent job (release / stop) or to a link loss."""


class JogMachine:
    """Teach mode and the held jog; every write goes through the host's client."""

    def __init__(
        self,
        host: PartLink,
        tracker: MotionTracker,
        *,
        last_pose: Callable[[], Pose | None],
        answering: Callable[[], bool],
    ) -> None:
        """``tracker``: the command under way (a stop ends it); ``last_pose``: the polls' last
        pose (the jog guard's start); ``answering``: the controller answers the polls."""
        self._host = host
        self._tracker = tracker
        self._last_pose = last_pose
        self._answering = answering
        self.teach = TeachState()
        self.teach_dirty = False  # teach may be on at the controller though we could not switch it off
        self.jog: JogRequest | None = None
        self._serial = 0
        self.released_at = 0.0
        self.halt: HaltWatch | None = None  # a jog / Stop being stopped, until the controller confirms
        self._shown: UnconfirmedHalt | None = None  # what the GUI was last told of it
        self._pause_requests: list[int | None] = []  # the Pause requests a PAUSE watch ends
        self._program_state: int | None = None  # the last poll's program state (None: not read yet)
        self.guard: JogGuard | None = None  # the safety envelope's jog guard (immutable; set by the GUI)
        self.guard_timing = GuardTiming()  # the guard's look-ahead, measured (perf_counter clock)
        self._pose_read_at: float | None = None  # when the read of the poller's last pose was sent

    # --- state ----------------------------------------------------------------------------
    @property
    def jogging(self) -> bool:
        """A jog is held, or a speed written for one is still in force."""
        return self.jog is not None or self.teach.moving

    @property
    def halting(self) -> bool:
        """A jog or a Stop is being stopped and the controller has not confirmed it yet."""
        return self.halt is not None

    def reset(self) -> None:
        """A new connection (new settings): nothing is known about teach mode."""
        self.teach = TeachState()
        self.teach_dirty = False
        self._drop_halt("the connection was made again")

    def end_jog(self) -> None:
        """Forget the held jog; a jog sequence still running for it gives way."""
        if self.jog is not None:
            self.released_at = time.monotonic()
        self.jog = None
        self._serial += 1

    def link_lost(self) -> None:
        """The link is down. A jog being stopped stays watched (and shown): the reconnection's
        speed 0 and the polls after it confirm it."""
        if self.teach.enabled or self.jog is not None:
            self.teach_dirty = True  # a real controller keeps jogging: switch it off on return
        jog = self.jog
        if jog is not None:
            self._begin_halt(HaltKind.RELEASE, jog).silent = True
            self._publish_halt(quiet=True)  # the link's state says why
        self.end_jog()
        self.teach = TeachState()

    def controller_silent(self) -> None:
        """The controller stopped answering: drop the held jog (ratio 0 goes out on its return).
        When a jog was under way the operator is told (an error with its reason, code
        ``jog_stopped_silent``)."""
        jog, jogging = self.jog, self.jogging
        self.end_jog()
        if not jogging:
            return
        self._begin_halt(HaltKind.RELEASE, jog).silent = True
        self._publish_halt(quiet=True)  # the sentence below says it
        note = "jog stopped: the controller is not answering (speed 0 is sent as soon as it answers)"
        self._host.emit_error(Operation.JOG, note, None, Reason("jog_stopped_silent"))

    def controller_answers(self) -> None:
        """The dead-man after a silence: ratio 0 before anything else, if a jog was under way."""
        halt = self.halt
        if halt is not None and halt.answered_at is None:
            halt.answering_again(time.monotonic())
            self.settle_halt()

    # --- sequences without urgent jobs in between (connect, close, idle) -------------------
    def make_teach_safe(self, status: ControllerStatus, ever_connected: bool) -> None:
        """On (re)connection: a jog left running by a lost link is stopped before anything else."""
        self._program_state = int(status.program_state)  # (a Pause refused now: anything to pause?)
        client = self._host.client
        assert client is not None
        if not (ever_connected or status.mode == ControllerMode.MODBUS_TEACH):
            return
        maybe_on = self.teach.enabled or self.teach_dirty or status.mode == ControllerMode.MODBUS_TEACH
        self.end_jog()
        if not maybe_on or client.settings.monitor_only:
            return
        self.teach_dirty = True
        self.stop_jog_and_teach()

    def stop_jog_and_teach(self) -> None:
        """Jog ratio 0 and teach disable, if we may have teach on."""
        self.end_jog()
        if not (self.teach.enabled or self.teach_dirty):
            return
        client = self._host.client  # also while connecting, before the link is declared up
        if client is None:
            raise LinkError("not connected to a controller", code="not_connected")
        self._speed_zero()
        client.teach_disable(wait=False)
        self.teach = TeachState()
        self.teach_dirty = False
        tracker = client.last_tracker
        assert tracker is not None
        result = self.await_short(tracker, urgent=False)
        if not result.ok:
            self._host.emit_result(result)

    def after_status(self, status: ControllerStatus, now: float, *, idle: bool) -> None:
        """Per good poll: teach mode ended by the controller, or idle long enough to switch it off."""
        self._program_state = int(status.program_state)
        self._pause_status(status)
        teach = self.teach
        if (
            teach.enabled
            and status.mode != ControllerMode.MODBUS_TEACH
            and now - teach.enabled_at > timing.TEACH_MODE_GRACE
        ):
            self.teach = TeachState()  # e-stop, manual, go to zero, program... ended it
            if self.jog is not None:
                self.end_jog()
                mode = controller_mode_text(int(status.mode))
                self._host.emit_error(
                    Operation.JOG,
                    f"the controller left teach mode (mode now: {mode})",
                    reason=Reason("left_teach_mode", {"mode": int(status.mode)}),
                )
        elif (
            (teach.enabled or self.teach_dirty)
            and self.jog is None
            and not (self.halt is not None and self.halt.unconfirmed)  # its own writes go on first
            and idle
            and now - self.released_at >= timing.TEACH_IDLE_DISABLE
        ):
            try:
                self.stop_jog_and_teach()
            except TeachPadError as exc:
                self._host.emit_exception(Operation.TEACH_DISABLE, exc)

    def on_stop(self) -> None:
        """The controller took a Stop: the jog ends, and a jog or Stop being stopped is answered
        (it is over once the pose is seen still). Ratio 0 if teach is on and moving; if the
        controller refuses that, the Stop stopped the arm: teach mode counts as unknown (switched
        off before the next jog)."""
        self.end_jog()
        halt = self.halt
        if halt is not None:
            halt.took(HaltWrite.STOP, time.monotonic())
        if self.teach.moving:
            try:
                self._speed_zero()
            except ModbusExceptionError:
                self.teach = TeachState()
                self.teach_dirty = True

    def stop_refused(self, exc: TeachPadError) -> None:
        """The operator's Stop was refused or not answered: it goes out again at every poll (with
        speed 0 if a jog was under way) until the controller takes it."""
        jog = self.jog
        self.end_jog()
        if not halt_refusal(exc):
            if jog is not None or self.teach.moving:
                self.teach_dirty = True  # the link failed: speed 0 and teach off on its return
            return
        self._end_pause_requests("superseded by the Stop, which is sent again at every poll")
        self.halt = follow_refused_stop(self.halt, jog, exc, time.monotonic())
        self._publish_halt()

    # --- a Pause until the controller confirms it (app/link/halt.py) ----------------------
    def pause_refused(self, exc: TeachPadError, request_id: int | None) -> bool:
        """The operator's Pause (request ``request_id``) was refused or not answered: it is sent
        again at every poll until the controller answers it (or a Stop after
        :data:`app.timing.PAUSE_ESCALATE_AFTER` s); the request ends with the outcome. True: the
        watch follows it. False: not a refusal it follows (the link failed), nothing is under way
        to pause (no motion of ours, and the last poll read the program stopped or paused), or a
        jog's stop or a Stop is under way already (stronger than a Pause): the Pause fails as it is."""
        halt = self.halt
        if not halt_refusal(exc) or (halt is not None and halt.kind is not HaltKind.PAUSE):
            return False
        idle = self._program_state is not None and self._program_state != ProgramState.RUNNING
        if halt is None and idle and self._tracker.motion_under_way is None:
            return False
        if halt is None:
            halt = self.halt = HaltWatch(HaltKind.PAUSE, None, time.monotonic())
        halt.refused(HaltWrite.PAUSE, exc)
        self._pause_requests.append(request_id)
        self._publish_halt()
        return True

    def pause_answered(self) -> None:
        """The controller answered a Pause: a Pause being followed is answered too."""
        halt = self.halt
        if halt is not None and halt.kind is HaltKind.PAUSE:
            halt.took(HaltWrite.PAUSE, time.monotonic())

    def drop_pause(self, why: str) -> None:
        """A Pause being followed is dropped (the operator resumed): not sent again."""
        if self.halt is not None and self.halt.kind is HaltKind.PAUSE:
            self._drop_halt(why)

    def _pause_status(self, status: ControllerStatus) -> None:
        """Per good poll: a Pause being followed is confirmed by the program state reading
        paused, or ends once it reads stopped and the pose is still (nothing left to pause)."""
        halt = self.halt
        if halt is None or halt.kind is not HaltKind.PAUSE:
            return
        state = status.program_state
        if halt.program_seen(state == ProgramState.PAUSED, state == ProgramState.STOPPED):
            self._halt_over(halt)

    def _pause_over(self, halt: HaltWatch) -> None:
        """A Pause's watch is over: each of its requests ends with what happened."""
        seconds = round(time.monotonic() - halt.since, 1)
        args: dict[str, object] = {"seconds": seconds}
        if halt.paused:
            ok, code = True, "pause_confirmed"
            text = f"pause: confirmed by the controller after {seconds:.1f} s (the arm is paused)"
        elif halt.answered_by is HaltWrite.STOP:
            ok, code = False, "pause_stopped"
            text = (
                f"pause: not confirmed by the controller within {seconds:.1f} s: Stop was sent instead "
                "and the arm stands still"
            )
        else:
            ok, code = True, "pause_nothing_running"
            text = "pause: nothing left to pause (the motion ended before the controller took the pause)"
        self._emit_pause_requests(CommandResult(None, None, None, ok, text, reason=Reason(code, args)))

    def _end_pause_requests(self, why: str) -> None:
        """A Pause's watch ends unconfirmed (dropped or superseded): its requests fail, saying why."""
        halt = self.halt
        if halt is None or halt.kind is not HaltKind.PAUSE:
            return
        text = f"pause: not confirmed by the controller ({why})"
        reason = Reason("pause_dropped", {"why": why})
        self._emit_pause_requests(CommandResult(None, None, None, False, text, reason=reason))

    def _emit_pause_requests(self, result: CommandResult) -> None:
        requests, self._pause_requests = self._pause_requests, []
        for request_id in requests:
            self._host.emit_result(result, request_id)

    # --- jobs ----------------------------------------------------------------------------
    def _check(self, serial: int) -> None:
        """Between two steps of a jog sequence: let urgent jobs in; stop if one ended this jog."""
        host = self._host
        host.run_urgent()
        if serial != self._serial or not host.link_up or host.closed:
            raise PreemptedError

    def press(self, request: JogRequest) -> None:
        """The jog state machine (PROTOCOL.md case 4).

        * teach enabled with the same frame: same axis/direction -> only the ratio;
          other axis/direction -> ratio 0, GV201-202, ratio.
        * teach off, or another frame -> ratio 0 and disable (if it was on), then
          GV200-203 = (frame, axis, direction, 0), 0x80 (auto mode first if needed), wait for
          GV291 while servicing urgent jobs, then the ratio.
        A release or stop arriving in between ends the sequence before the ratio is written.
        """
        client = self._host.client_or_raise()
        if not self._answering():  # refused before the wire; not a link failure
            raise TeachPadError("the controller is not answering: jog not started", code="jog_not_answering")
        if not 0.0 < request.ratio <= 100.0:
            raise InvalidInput(
                f"jog speed must be 1..100 %, got {request.ratio:g}",
                code="bad_jog_ratio",
                params={"value": f"{request.ratio:g}"},
            )
        self.require_no_halt(Operation.JOG)
        self._require_guard(request)  # refused before teach mode is even switched on
        self._drop_halt("superseded by a jog")  # a release answered, not seen still yet: superseded
        self.jog = request
        self._serial += 1
        serial = self._serial
        teach = self.teach
        if teach.enabled and teach.frame_key == request.frame_key:
            if teach.axis != (request.axis, request.direction):
                client.teach_set_axis(request.axis, request.direction)  # ratio 0 first, then GV201-202
                teach.ratio = 0.0
                teach.axis = (request.axis, request.direction)
                self._check(serial)
            if teach.ratio != request.ratio:
                self._require_guard(request)
                self._start(request.ratio)
            return
        if teach.enabled or self.teach_dirty:
            client.teach_set_ratio(0.0)
            teach.ratio = 0.0
            self._check(serial)
            self.disable_teach()
            self._check(serial)
        client.teach_enable(
            request.frame,
            request.axis,
            request.direction,
            user_frame=request.user,
            tool_frame=request.tool,
            wait=False,
        )
        self.teach = TeachState(
            True, request.frame_key, (request.axis, request.direction), 0.0, time.monotonic()
        )
        tracker = client.last_tracker
        assert tracker is not None
        result = self.await_short(tracker, urgent=True)  # a release meanwhile writes ratio 0
        if not result.ok:
            self.teach = TeachState()
            # Refused: teach is off for sure. Stopped / timed out: it may be on, switch it off later.
            self.teach_dirty = not isinstance(tracker.error, CommandRefused)
            self.end_jog()
            self._host.emit_result(result)
            return
        self._check(serial)
        self._require_guard(request)  # the pose may have moved on while teach mode came up
        self._start(request.ratio)

    def _start(self, ratio: float) -> None:
        """GV203 <- ``ratio`` (> 0: the arm moves). An answer that does not say the write was not
        carried out (a Modbus exception other than :data:`~app.protocol.exceptions.NOT_CARRIED_OUT`)
        leaves the arm maybe jogging: the jog counts as under way (the envelope guard watches it,
        a release or Stop halts it) and the operator reads "outcome unknown", never "refused"."""
        client = self._host.client_or_raise()
        try:
            client.teach_set_ratio(ratio)
        except ModbusExceptionError as exc:
            if not_carried_out(exc.exception_code):
                raise
            self.teach.ratio = ratio
            code = exc.exception_code
            answer = exception_text(code, "a code the standard does not define")
            raise OutcomeUnknown(
                f"jog at {ratio:g} %: {UNKNOWN_ADVICE} (the speed write was answered Modbus exception "
                f"{code}, {answer}, which does not say it was not carried out: the arm may be jogging)",
                params={"operation": Operation.JOG},
            ) from exc
        self.teach.ratio = ratio

    # --- the jog guard (the safety envelope) ---------------------------------------------
    def _require_guard(self, request: JogRequest) -> None:
        """Raise :class:`EnvelopeRefused` (nothing written) when the guard would stop this jog now.
        Without a pose yet there is nothing to decide on: the first poll decides."""
        guard, pose = self.guard, self._last_pose()
        if guard is None or pose is None:
            return
        # A standing arm's last pose is still where it is; a moving one's has aged since its read.
        moving = self.teach.moving
        read_at = self._pose_read_at if moving else None
        horizon = self.guard_timing.horizon(guard, time.perf_counter(), read_at)
        decision = guard.decide(pose, request, horizon)
        if not decision.allow and decision.violation is not None:
            jog = self.jog
            self.end_jog()
            if self.teach.moving:  # a jog under way stops too, until the controller confirms it
                self._halt_now(HaltKind.RELEASE, jog)
            raise EnvelopeRefused(decision.violation, "jog")

    def guard_pose(
        self, pose: Pose, read_at: float | None = None, answered_at: float | None = None
    ) -> EnvelopeViolation | None:
        """Per poll, right after the pose is read (its request sent at ``read_at``, answered at
        ``answered_at``, ``time.perf_counter``; None: just now): stop a jog heading over a boundary
        (ratio 0 first, the jog ends; teach stays on, as after a release). Returns why it stopped.

        The look-ahead covers the measured time until the next poll's stop could land
        (:class:`~app.safety.jog_guard.GuardTiming`), not the nominal poll period: a late poll
        on a loaded PC must not carry the arm over the boundary."""
        now = time.perf_counter()
        read_at = now if read_at is None else read_at
        self._pose_read_at = read_at
        measured = self.guard_timing
        measured.note_read(read_at, now if answered_at is None else answered_at)
        jog, guard, client, halt = self.jog, self.guard, self._host.client, self.halt
        releasing = halt.request if jog is None and halt is not None and halt.unconfirmed else None
        watched = jog if jog is not None else releasing  # the guard keeps watching a jog being stopped
        measured.note_decision(now, jogging=watched is not None)
        if watched is None or guard is None or client is None or watched.ratio <= 0:
            return None
        horizon = measured.horizon(guard, now, read_at)
        measured.note_horizon(now, horizon)
        decision = guard.decide(pose, watched, horizon)
        if decision.allow or decision.violation is None:
            return None
        if halt is not None and jog is None:
            if not halt.escalate():  # speed 0 not confirmed, the arm heads over a boundary: Stop now
                return None
            self.settle_halt()
            return decision.violation
        self.end_jog()
        if self.teach.enabled and not client.settings.monitor_only:
            self._halt_now(HaltKind.RELEASE, jog)
        return decision.violation

    def release(self) -> None:
        """The dead-man: ratio 0, teach stays enabled (disabled later when idle). The jog is over
        once the controller has answered and the pose is seen still (see the module docstring)."""
        jog = self.jog
        self.end_jog()
        self.released_at = time.monotonic()
        client = self._host.client
        if not self._host.link_up or client is None:
            return
        if self.teach.enabled:
            self._halt_now(HaltKind.RELEASE, jog)

    # --- a halt until the controller confirms it (app/link/halt.py) ------------------------
    def require_no_halt(self, operation: str) -> None:
        """Refuse ``operation`` while a jog's stop or a Stop is not confirmed by the controller."""
        halt = self.halt
        if halt is not None and halt.unconfirmed:
            what = {
                HaltKind.RELEASE: "the last jog's stop",
                HaltKind.STOP: "the Stop",
                HaltKind.PAUSE: "the Pause",
            }[halt.kind]
            raise TeachPadError(
                f"{operation} refused: the controller has not confirmed {what} yet (it is sent again "
                "at every poll; press Stop, or wait until the arm is seen still)",
                code="halt_unconfirmed",
                params={"operation": operation},
            )

    def settle_halt(self) -> None:
        """Per poll (before its reads) while a halt is watched: send what it asks for now. A
        refusal or no answer is counted (and tried again at the next poll); a link failure is
        raised after that (the poll fails as it would have)."""
        halt = self.halt
        client = self._host.client
        if halt is None or client is None or client.settings.monitor_only:
            return
        # each write waits the poll timeout at most: a controller that does not answer it gets it
        # again at the next poll, it does not hold the worker for the request timeout
        now = time.monotonic()
        halt.due(now)  # a Stop due now (escalated): the GUI hears it before the Stop's own results
        self._publish_halt()
        with client.io_timeout(client.settings.effective_poll_timeout):
            failure = settle(self._send, halt, now)
        self._publish_halt()
        if failure is not None:
            raise failure

    def halt_pose(self, pose: Pose) -> None:
        """Per poll, after the pose: the halt is over once answered and the pose is still."""
        halt = self.halt
        if halt is None or not halt.pose_seen(pose):
            return
        self._halt_over(halt)

    def _halt_over(self, halt: HaltWatch) -> None:
        """The halt is over: forgotten, and the operator told if they were told it went wrong."""
        self.halt = None
        if halt.kind is HaltKind.PAUSE:
            self._pause_over(halt)  # its requests say it (the GUI's Pause waits for them)
            self._publish_halt()
            return
        if not halt.speed_zero_answered and self.teach.moving:
            # stopped by a Stop while GV203 still holds the jog's speed: teach mode counts as
            # unknown, so the next jog writes speed 0 and switches teach off and on first
            self.teach = TeachState()
            self.teach_dirty = True
        if self._shown is None:
            return  # answered at once and seen still: nothing to say
        seconds = time.monotonic() - halt.since
        what = "jog stopped" if halt.kind is HaltKind.RELEASE else "stop"
        self._host.emit_result(
            CommandResult(
                None,
                None,
                None,
                True,
                f"{what}: confirmed by the controller after {seconds:.1f} s (the arm stands still)",
                reason=Reason(f"{halt.kind.value}_confirmed", {"seconds": round(seconds, 1)}),
            ),
            None,
        )
        self._publish_halt()

    def _begin_halt(self, kind: HaltKind, request: JogRequest | None) -> HaltWatch:
        halt = self.halt
        if halt is None or halt.over:
            halt = self.halt = HaltWatch(kind, request, time.monotonic())
        elif halt.request is None:
            halt.request = request
        return halt

    def _halt_now(self, kind: HaltKind, request: JogRequest | None) -> None:
        """Begin (or go on with) a halt and send its writes at once."""
        self._begin_halt(kind, request)
        self.settle_halt()

    def _drop_halt(self, why: str = "superseded") -> None:
        self._end_pause_requests(why)
        self.halt = None
        self._publish_halt()

    def _speed_zero(self) -> None:
        """GV203 <- 0 (also while connecting, before the link is declared up); a halt being
        watched counts it as answered."""
        client = self._host.client
        if client is None:
            raise LinkError("not connected to a controller", code="not_connected")
        client.teach_set_ratio(0.0)
        self.teach.ratio = 0.0
        if self.halt is not None:
            self.halt.took(HaltWrite.SPEED_ZERO, time.monotonic())

    def _send(self, write: HaltWrite) -> None:
        if write is HaltWrite.SPEED_ZERO:
            self._speed_zero()
            return
        client = self._host.client
        if client is None:
            raise LinkError("not connected to a controller", code="not_connected")
        if write is HaltWrite.PAUSE:
            client.pause()
            self.pause_answered()
            return
        write_halt_stop(client, self.halt, self._tracker, self._host.emit_result)

    def _publish_halt(self, *, quiet: bool = False) -> None:
        """Tell the GUI what changed (and, the first time it goes wrong, why, unless ``quiet``)."""
        halt = self.halt
        state = None if halt is None else halt.state()
        if state == self._shown:
            return
        before, self._shown = self._shown, state
        self._host.publish_halt(state)
        if state is None or halt is None or quiet:
            return
        now = time.monotonic()
        goes_on = halt.kind is not HaltKind.STOP  # a release or a Pause: a Stop may follow
        if before is None or (goes_on and state.escalated and not before.escalated):
            # release_unconfirmed, release_escalated (Stop sent too), stop_unconfirmed,
            # pause_unconfirmed, pause_escalated (Stop sent instead)
            step = "escalated" if goes_on and state.escalated else "unconfirmed"
            operation = _HALT_OPERATION[halt.kind]
            reason = Reason(f"{halt.kind.value}_{step}", {"seconds": round(now - halt.since, 1)})
            self._host.emit_error(operation, halt.words(now), None, reason)

    def set_ratio(self, ratio: float) -> None:
        """Speed slider moved while jogging: GV203 changes the speed live."""
        jog = self.jog
        if jog is None:
            return
        if not 0.0 < ratio <= 100.0:
            raise InvalidInput(
                f"jog speed must be 1..100 %, got {ratio:g}",
                code="bad_jog_ratio",
                params={"value": f"{ratio:g}"},
            )
        self.jog = dataclasses.replace(jog, ratio=ratio)
        if self.teach.moving and self.teach.ratio != ratio:
            self._require_guard(self.jog)
            self._host.client_or_raise().teach_set_ratio(ratio)
            self.teach.ratio = ratio

    def disable_teach(self) -> None:
        """0x81 and wait for its GV291 (servicing urgent jobs); a refusal is reported and ends the job."""
        client = self._host.client_or_raise()
        client.teach_disable(wait=False)
        self.teach = TeachState()
        self.teach_dirty = False
        tracker = client.last_tracker
        assert tracker is not None
        result = self.await_short(tracker, urgent=True)
        if not result.ok:
            self.teach_dirty = True
            self._host.emit_result(result)
            raise PreemptedError

    def leave_teach(self, last_status: ControllerStatus | None) -> None:
        """Before a motion of another kind: ratio 0 and teach disable (the controller refuses otherwise)."""
        if not (
            self.teach.enabled
            or self.teach_dirty
            or (last_status is not None and last_status.mode == ControllerMode.MODBUS_TEACH)
        ):
            return
        # the motion's own commands take over (a halt not confirmed refused it before)
        self._drop_halt("superseded by a motion")
        self.end_jog()
        self._speed_zero()
        self.disable_teach()

    def await_short(self, tracker: CommandTracker, *, urgent: bool) -> CommandResult:
        """Status reads until a short command (teach enable/disable) ends -- the tracker's own
        timeouts bound this to a few seconds at worst; with ``urgent`` the urgent jobs (stop,
        release) run between two reads, so they are never held up."""
        host = self._host
        client = host.client
        if client is None:
            raise LinkError("not connected to a controller", code="not_connected")
        while True:
            now = time.monotonic()
            result = tracker.update(client.read_status(), None, now)
            if result is not None:
                return result
            if urgent:
                host.run_urgent()
                if not host.link_up or host.closed:
                    raise PreemptedError
            time.sleep(tracker.poll_interval(now))  # backoff: no tight polling of a real controller
