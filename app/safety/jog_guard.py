"""The jog guard: stop a teach jog before the TCP crosses the envelope, allow jogging back out.

The controller jogs until told otherwise, so the host decides on every pose poll:
:meth:`JogGuard.decide` takes the pose just read and the jog under way and answers
:class:`JogDecision` — ``allow`` or stop now (write ratio 0). The margin is the distance the arm
can cover before the *next* decision takes effect: ``speed x horizon + extra``, where ``speed``
is the arm's jog speed at 100 % times the ratio. The nominal horizon is ``poll period +
latency``; the worker passes a measured one (:class:`GuardTiming`: the real age of the pose
judged, the longest recent gap between two decisions, the longest recent answer) whenever that
is longer -- a loaded PC polls late, and a keep-in face must hold then too. A jog is stopped when
the point that far ahead along the jog direction (the chord to it, exactly) leaves the allowed
space; a jog whose look-ahead point is *further inside* than the pose is always allowed, so
the operator can jog back out of a boundary (or out of a zone entered some other way), and
only back out.

Directions: base-frame X/Y/Z are known; tool-frame X/Y/Z follow the pose's A B C; user-frame
and joint jogs move the TCP in a direction the host cannot know (the user frame lives in the
controller; joint jogs need the real arm's kinematics), so for them the look-ahead is a sphere:
allowed while the pose is more than the margin from every boundary. Near a boundary, jog out in
the base or tool frame. Rotations about the TCP (A/B/C) do not move it. Joint jogs also respect
the joint limits, with the same look-ahead in degrees.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Protocol

from app.geometry import abc_to_matrix
from app.lazy_numpy import FloatArray
from app.models import Pose
from app.protocol.enums import TeachFrame
from app.safety.envelope import (
    AXIS_NAMES,
    Envelope,
    EnvelopeViolation,
    ViolationCode,
    check_jog_ratio,
    check_path,
    check_point,
)

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np

#: Host-side delay (s) from a pose sample to a ratio-0 write landing: read + write round trips
#: and the controller's reaction. The worker may pass its measured figure instead.
JOG_GUARD_LATENCY = 0.05
JOG_GUARD_EXTRA_MM = 1.0  # fixed extra margin (mm): deceleration, pose noise
JOG_GUARD_EXTRA_DEG = 0.5  # the same for joint limits (degrees)
#: How long (s) a late decision or a slow answer, once seen, keeps widening the look-ahead.
JOG_GUARD_WINDOW = 5.0


class GuardTiming:
    """The look-ahead's time, measured on the worker (pure: the caller passes the clock readings,
    all from one clock, ``time.perf_counter``).

    A decision at ``now`` on a pose whose read was *sent* at ``read_at`` lets the arm run until
    the next decision's stop lands, so the horizon is the sum of

    * the pose's age, ``now - read_at`` (it may have been sampled as early as the request left);
    * the time to the next decision: the longest gap between two decisions of a held jog seen in
      the last :data:`JOG_GUARD_WINDOW` s, at least the nominal poll period plus two reads (the
      next poll's status and pose) -- a worker descheduled or held up by a slow answer decides
      late, and on a loaded PC it happens again;
    * the stop write's trip: the longest read seen in the window.

    :meth:`horizon` never answers less than the guard's nominal ``poll period + latency``; for a
    standing arm (a press) never less than the horizons its recent decisions used
    (:meth:`note_horizon`), so a press toward a boundary right after a stop there is refused,
    not started and stopped again.
    """

    def __init__(self, window: float = JOG_GUARD_WINDOW) -> None:
        self.window = window
        self._gaps: deque[tuple[float, float]] = deque()  # (when, gap s) between two decisions
        self._trips: deque[tuple[float, float]] = deque()  # (when, s) of one read
        self._used: deque[tuple[float, float]] = deque()  # (when, s) horizons of decisions
        self._last_decision: float | None = None

    def note_read(self, read_at: float, answered_at: float) -> None:
        """A pose read sent at ``read_at`` and answered at ``answered_at``."""
        self._trips.append((answered_at, max(0.0, answered_at - read_at)))
        self._forget(answered_at)

    def note_decision(self, now: float, *, jogging: bool) -> None:
        """A poll's decision point; the gap since the previous one counts while a jog is held."""
        if jogging and self._last_decision is not None:
            self._gaps.append((now, max(0.0, now - self._last_decision)))
        self._last_decision = now if jogging else None
        self._forget(now)

    def note_horizon(self, now: float, horizon: float) -> None:
        """A decision on a moving arm used ``horizon``."""
        self._used.append((now, horizon))
        self._forget(now)

    def horizon(self, guard: JogGuard, now: float, read_at: float | None) -> float:
        """Seconds the arm may run, from the pose read at ``read_at`` (None: the arm stands still,
        its pose's age does not matter), before a stop decided at the next poll lands."""
        self._forget(now)
        age = 0.0 if read_at is None else max(0.0, now - read_at)
        gap = max((g for _, g in self._gaps), default=0.0)
        trip = max((t for _, t in self._trips), default=0.0)
        next_poll = guard.poll_period + 2 * trip  # the timer, then its status and pose reads
        seconds = max(guard.horizon, age + max(next_poll, gap) + trip)
        if read_at is None:
            seconds = max(seconds, max((h for _, h in self._used), default=0.0))
        return seconds

    def _forget(self, now: float) -> None:
        for items in (self._gaps, self._trips, self._used):
            while items and now - items[0][0] > self.window:
                items.popleft()


@dataclass(frozen=True)
class ArmSpeeds:
    """How fast the arm jogs at ratio 100 (the controller's settings; the simulator's defaults)."""

    linear: float = 250.0  # mm/s, Cartesian X/Y/Z jog
    joint: float = 30.0  # deg/s, joint jog
    tcp_in_joint_jog: float = 600.0  # mm/s, an upper bound of the TCP's speed in a joint jog


class JogLike(Protocol):
    """A jog: :class:`JogMotion`, or the worker's :class:`app.link.types.JogRequest` as it is."""

    @property
    def frame(self) -> TeachFrame: ...
    @property
    def axis(self) -> int: ...
    @property
    def direction(self) -> int: ...
    @property
    def ratio(self) -> float: ...


def _sign(motion: JogLike) -> float:
    return 1.0 if motion.direction else -1.0


@dataclass(frozen=True)
class JogMotion:
    """The jog under way (or about to start): as :class:`app.link.types.JogRequest`."""

    frame: TeachFrame
    axis: int  # 0-5 X Y Z A B C; joint frame 0-10 J1..J11
    direction: int  # 0 negative, 1 positive
    ratio: float  # %

    @property
    def sign(self) -> float:
        return 1.0 if self.direction else -1.0


@dataclass(frozen=True)
class JogDecision:
    allow: bool
    violation: EnvelopeViolation | None = None  # why it stops (None when allowed)
    margin: float = 0.0  # look-ahead used (mm, or degrees for a joint limit)
    clearance: float = math.inf  # distance (mm) from the pose to the nearest Cartesian boundary
    backing_out: bool = False  # allowed only because it moves away from a boundary

    @property
    def message(self) -> str:
        if self.violation is None:
            return ""
        return f"jog stopped before the limit: {self.violation.message}"


def nearest_boundary(envelope: Envelope, p: FloatArray) -> EnvelopeViolation | None:
    """The boundary closest to ``p`` as a violation (axis, value, face), or None (no boundary)."""
    best: tuple[float, EnvelopeViolation] | None = None
    if envelope.keep_in is not None:
        outside = check_point(Envelope(keep_in=envelope.keep_in), p)
        if outside is not None:
            return outside
        box = envelope.keep_in
        for i in range(3):
            for face in (box.lo[i], box.hi[i]):
                d = abs(float(p[i]) - face)
                if best is None or d < best[0]:
                    best = (d, EnvelopeViolation(ViolationCode.KEEP_IN, float(p[i]), face, AXIS_NAMES[i]))
    for zone in envelope.keep_out:
        d = -zone.clearance_inside(p)
        if best is None or d < best[0]:
            q = np.clip(p, zone.lo, zone.hi)
            i = int(np.argmax(np.abs(p - q))) if d > 0 else zone.depth(p)[0]
            face = float(q[i]) if d > 0 else zone.depth(p)[2]
            best = (d, EnvelopeViolation(ViolationCode.KEEP_OUT, float(p[i]), face, AXIS_NAMES[i], zone.name))
    return None if best is None else best[1]


class JogGuard:
    """Decides, on every poll during a jog, whether it may go on. Pure: no I/O, no clock."""

    def __init__(
        self,
        envelope: Envelope,
        *,
        poll_period: float,
        latency: float = JOG_GUARD_LATENCY,
        speeds: ArmSpeeds | None = None,
        reduced: bool = False,
    ) -> None:
        if not (poll_period > 0 and latency >= 0):
            raise ValueError("poll period must be > 0 and latency >= 0")
        self.envelope = envelope
        self.poll_period = poll_period
        self.latency = latency
        self.speeds = speeds or ArmSpeeds()
        self.reduced = reduced

    @property
    def horizon(self) -> float:
        """Seconds until a stop decided at the next poll takes effect."""
        return self.poll_period + self.latency

    def margin(self, motion: JogLike, horizon: float | None = None) -> float:
        """Look-ahead (mm) for ``motion`` over ``horizon`` s (None: the nominal :attr:`horizon`)."""
        frac = max(0.0, motion.ratio) / 100.0
        seconds = self.horizon if horizon is None else max(self.horizon, horizon)
        if motion.frame is TeachFrame.JOINT:
            return self.speeds.tcp_in_joint_jog * frac * seconds + JOG_GUARD_EXTRA_MM
        return self.speeds.linear * frac * seconds + JOG_GUARD_EXTRA_MM

    def decide(self, pose: Pose, motion: JogLike, horizon: float | None = None) -> JogDecision:
        """Allow the jog ``motion`` from ``pose``, or say why to stop it now. ``horizon``: the
        measured seconds until a stop decided next would land (:meth:`GuardTiming.horizon`);
        never less than the nominal one."""
        env = self.envelope
        p = np.array((pose.x, pose.y, pose.z), dtype=np.float64)
        clearance = env.clearance(p)
        too_fast = check_jog_ratio(env, motion.ratio, self.reduced)
        if too_fast is not None:
            return JogDecision(False, too_fast, clearance=clearance)
        if motion.ratio <= 0:
            return JogDecision(True, clearance=clearance)
        if motion.frame is TeachFrame.JOINT:
            joint = self._joint_decision(pose, motion, horizon)
            if joint is not None:
                return joint
        margin = self.margin(motion, horizon)
        direction = self._direction(pose, motion)
        if direction is None:  # the TCP does not move (rotation about it)
            return JogDecision(True, margin=margin, clearance=clearance)
        if direction.size == 0:  # unknown direction: a sphere of radius margin
            if clearance > margin:
                return JogDecision(True, margin=margin, clearance=clearance)
            return JogDecision(False, _approaching(env, p, nearest_boundary(env, p)), margin, clearance)
        ahead = p + direction * margin
        violation = check_path(env, np.vstack((p, ahead)))
        if violation is None:
            return JogDecision(True, margin=margin, clearance=clearance)
        if env.clearance(ahead) > clearance + 1e-9:
            return JogDecision(True, margin=margin, clearance=clearance, backing_out=True)
        return JogDecision(False, _approaching(env, p, violation), margin, clearance)

    def _direction(self, pose: Pose, motion: JogLike) -> FloatArray | None:
        """Unit vector of the TCP's motion; None: it does not move; empty: not known."""
        if motion.frame is TeachFrame.JOINT or motion.frame is TeachFrame.USER:
            return np.empty(0)
        if motion.axis >= 3:
            return None
        if motion.frame is TeachFrame.TOOL:
            column = abc_to_matrix(pose.a, pose.b, pose.c)[:, motion.axis]
            return np.asarray(column * _sign(motion), dtype=np.float64)
        unit = np.zeros(3)
        unit[motion.axis] = _sign(motion)
        return unit

    def _joint_decision(self, pose: Pose, motion: JogLike, horizon: float | None) -> JogDecision | None:
        limits = self.envelope.joint_limits
        ax = motion.axis
        if pose.joints is None or ax >= len(limits) or ax >= len(pose.joints):
            return None
        lo, hi = limits[ax]
        q = pose.joints[ax]
        seconds = self.horizon if horizon is None else max(self.horizon, horizon)
        step = self.speeds.joint * motion.ratio / 100.0 * seconds + JOG_GUARD_EXTRA_DEG
        ahead = q + _sign(motion) * step
        if lo <= ahead <= hi:
            return None
        inward = (q > hi and _sign(motion) < 0) or (q < lo and _sign(motion) > 0)
        if inward:
            return None
        limit = hi if _sign(motion) > 0 else lo
        past = q > hi or q < lo
        return JogDecision(
            False,
            EnvelopeViolation(ViolationCode.JOINT_LIMIT, q, limit, f"J{ax + 1}", approaching=not past),
            step,
        )


def _approaching(
    env: Envelope, p: FloatArray, violation: EnvelopeViolation | None
) -> EnvelopeViolation | None:
    """Mark a stop before the boundary as such (the pose itself is still inside)."""
    if violation is None or check_point(env, p) is not None:
        return violation
    value = float(p[AXIS_NAMES.index(violation.axis)]) if violation.axis in AXIS_NAMES else violation.value
    return replace(violation, value=value, approaching=True)
