"""The jog state machine (PROTOCOL.md case 4) and the dead-man around it, on the worker thread.

Release writes ratio 0 and keeps teach enabled; teach is disabled after
:data:`app.timing.TEACH_IDLE_DISABLE` s without a jog, before any other motion, on disconnect and
on shutdown. When the link comes back after a loss, ratio 0 and teach disable go out before
anything else (a real controller keeps jogging when its master goes away); when a silent
controller answers again, ratio 0 goes out at once if a jog was under way.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

from app import timing
from app.errors import CommandRefused, InvalidInput, LinkError, Reason, TeachPadError
from app.link.host import WorkerHost
from app.link.tracker import CommandTracker
from app.link.types import JogRequest, Operation
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import ControllerMode, TeachFrame, controller_mode_text
from app.safety.envelope import EnvelopeRefused, EnvelopeViolation
from app.safety.jog_guard import GuardTiming, JogGuard

__all__ = ["JogMachine", "PreemptedError", "TeachState"]


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

    def __init__(self, host: WorkerHost) -> None:
        self._host = host
        self.teach = TeachState()
        self.teach_dirty = False  # teach may be on at the controller though we could not switch it off
        self.jog: JogRequest | None = None
        self._serial = 0
        self.released_at = 0.0
        self.ratio_zero_pending = False  # the controller went silent while jogging: ratio 0 on return
        self.guard: JogGuard | None = None  # the safety envelope's jog guard (immutable; set by the GUI)
        self.guard_timing = GuardTiming()  # the guard's look-ahead, measured (perf_counter clock)
        self._pose_read_at: float | None = None  # when the read of the poller's last pose was sent

    # --- state ----------------------------------------------------------------------------
    @property
    def jogging(self) -> bool:
        """A jog is held, or a speed written for one is still in force."""
        return self.jog is not None or self.teach.moving

    def reset(self) -> None:
        """A new connection (new settings): nothing is known about teach mode."""
        self.teach = TeachState()
        self.teach_dirty = False
        self.ratio_zero_pending = False

    def end_jog(self) -> None:
        """Forget the held jog; a jog sequence still running for it gives way."""
        if self.jog is not None:
            self.released_at = time.monotonic()
        self.jog = None
        self._serial += 1

    def link_lost(self) -> None:
        if self.teach.enabled or self.jog is not None:
            self.teach_dirty = True  # a real controller keeps jogging: switch it off on return
        self.end_jog()
        self.teach = TeachState()
        self.ratio_zero_pending = False

    def controller_silent(self) -> None:
        """The controller stopped answering: drop the held jog (ratio 0 goes out on its return).
        When a jog was under way the operator is told (an error with its reason, code
        ``jog_stopped_silent``)."""
        jogging = self.jogging
        self.end_jog()
        if not jogging:
            return
        self.ratio_zero_pending = True
        note = "jog stopped: the controller is not answering (speed 0 is sent as soon as it answers)"
        self._host.emit_error(Operation.JOG, note, None, Reason("jog_stopped_silent"))

    def controller_answers(self) -> None:
        """The dead-man after a silence: ratio 0 before anything else, if a jog was under way."""
        if not self.ratio_zero_pending:
            return
        self.ratio_zero_pending = False
        client = self._host.client
        if client is None or client.settings.monitor_only:
            return
        client.teach_set_ratio(0.0)
        self.teach.ratio = 0.0

    # --- sequences without urgent jobs in between (connect, close, idle) -------------------
    def make_teach_safe(self, status: ControllerStatus, ever_connected: bool) -> None:
        """On (re)connection: a jog left running by a lost link is stopped before anything else."""
        client = self._host.client
        assert client is not None
        self.ratio_zero_pending = False
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
        client.teach_set_ratio(0.0)
        self.teach.ratio = 0.0
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
            and idle
            and now - self.released_at >= timing.TEACH_IDLE_DISABLE
        ):
            try:
                self.stop_jog_and_teach()
            except TeachPadError as exc:
                self._host.emit_exception(Operation.TEACH_DISABLE, exc)

    def on_stop(self) -> None:
        """A stop went out: the jog ends, ratio 0 if teach is on and moving."""
        self.end_jog()
        if self.teach.moving:
            self._host.client_or_raise().teach_set_ratio(0.0)
            self.teach.ratio = 0.0

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
        if not self._host.supervisor.answering:  # refused before the wire; not a link failure
            raise TeachPadError("the controller is not answering: jog not started", code="jog_not_answering")
        if not 0.0 < request.ratio <= 100.0:
            raise InvalidInput(
                f"jog speed must be 1..100 %, got {request.ratio:g}",
                code="bad_jog_ratio",
                params={"value": f"{request.ratio:g}"},
            )
        self._require_guard(request)  # refused before teach mode is even switched on
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
                client.teach_set_ratio(request.ratio)
                teach.ratio = request.ratio
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
        client.teach_set_ratio(request.ratio)
        self.teach.ratio = request.ratio

    # --- the jog guard (the safety envelope) ---------------------------------------------
    def _require_guard(self, request: JogRequest) -> None:
        """Raise :class:`EnvelopeRefused` (nothing written) when the guard would stop this jog now.
        Without a pose yet there is nothing to decide on: the first poll decides."""
        guard, pose = self.guard, self._host.poller.last_pose
        if guard is None or pose is None:
            return
        # A standing arm's last pose is still where it is; a moving one's has aged since its read.
        moving = self.teach.moving
        read_at = self._pose_read_at if moving else None
        horizon = self.guard_timing.horizon(guard, time.perf_counter(), read_at)
        decision = guard.decide(pose, request, horizon)
        if not decision.allow and decision.violation is not None:
            self.end_jog()
            if self.teach.moving:  # a jog under way stops too
                self._host.client_or_raise().teach_set_ratio(0.0)
                self.teach.ratio = 0.0
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
        jog, guard, client = self.jog, self.guard, self._host.client
        measured.note_decision(now, jogging=jog is not None)
        if jog is None or guard is None or client is None or jog.ratio <= 0:
            return None
        horizon = measured.horizon(guard, now, read_at)
        measured.note_horizon(now, horizon)
        decision = guard.decide(pose, jog, horizon)
        if decision.allow or decision.violation is None:
            return None
        if self.teach.enabled and not client.settings.monitor_only:
            client.teach_set_ratio(0.0)
            self.teach.ratio = 0.0
        self.end_jog()
        return decision.violation

    def release(self) -> None:
        """The dead-man: ratio 0, teach stays enabled (disabled later when idle)."""
        self.end_jog()
        self.released_at = time.monotonic()
        client = self._host.client
        if not self._host.link_up or client is None:
            return
        if self.teach.enabled:
            client.teach_set_ratio(0.0)
            self.teach.ratio = 0.0

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
        self.end_jog()
        self._host.client_or_raise().teach_set_ratio(0.0)
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
