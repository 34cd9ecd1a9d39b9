"""The safety envelope the pendant enforces before the controller has to.

An :class:`Envelope` holds, per robot profile: joint limits, a Cartesian keep-in box, keep-out
boxes, a maximum jog ratio, a maximum TCP speed for moves and plans, and the caps of reduced-
speed mode. The checks here are pure functions of XYZ (mm, base frame) and joint angles
(degrees); they answer with an :class:`EnvelopeViolation` (a code plus its arguments, so the
GUI can translate it, and a plain English ``message``) or None.

* :func:`check_target` — a step or move target; :func:`check_path` — sampled XYZ;
* :func:`check_segment` — one plan segment from a start pose, lines and arcs sampled through
  :mod:`app.plan.geometry`; every chord between samples is tested against the boxes exactly
  (slab test), so a thin keep-out box between two samples is not missed;
* :func:`plan_violations` — every segment of a plan, for :func:`app.plan.checks.check_plan`.

Speeds: a step, move or segment faster than ``max_speed`` is a violation in every mode. Reduced-
speed mode does not refuse a faster one: it caps it (:meth:`Envelope.motion_caps`, applied by the
client to every speed it writes), so the speed checks here do not depend on the mode.

The jog guard lives in :mod:`app.safety.jog_guard`; the boxes (:class:`Box`, their slab test)
in :mod:`app.safety.box`.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from app.errors import InvalidInput, TeachPadError
from app.lazy_numpy import FloatArray
from app.models import Pose
from app.plan.geometry import PointLike, segment_length, segment_path, xyz_of
from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.safety.box import Box
from app.safety.caps import MotionCaps

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np

__all__ = [
    "ARC_SAMPLE_STEP_MM",
    "AXIS_NAMES",
    "MAX_SAMPLES_PER_SEGMENT",
    "REDUCED_SPEED_DEFAULT",
    "Envelope",
    "EnvelopeRefused",
    "EnvelopeViolation",
    "ViolationCode",
    "check_jog_ratio",
    "check_joints",
    "check_path",
    "check_point",
    "check_segment",
    "check_speed",
    "check_step",
    "check_target",
    "plan_violations",
    "require_target",
]

AXIS_NAMES = ("X", "Y", "Z")
#: Longest chord (mm) between the samples of an arc; lines are tested exactly.
ARC_SAMPLE_STEP_MM = 2.0
MAX_SAMPLES_PER_SEGMENT = 4000
#: ISO 10218-1's reduced speed for the TCP; the default cap of reduced-speed mode.
REDUCED_SPEED_DEFAULT = 250.0


class ViolationCode(enum.Enum):
    KEEP_IN = "keep_in"  # outside the keep-in box
    KEEP_OUT = "keep_out"  # inside a keep-out box
    JOINT_LIMIT = "joint_limit"  # a joint beyond its limit
    SPEED = "speed"  # a move or segment faster than allowed
    JOG_RATIO = "jog_ratio"  # a jog ratio above the cap


@dataclass(frozen=True)
class EnvelopeViolation:
    """Why a target, a path or a jog leaves the envelope.

    ``axis`` is "X"/"Y"/"Z" (or "J1".."J6"), ``value`` what was asked or reached, ``limit`` the
    bound it passed; ``box`` names a keep-out box; ``segment`` is 0-based (None: not a plan).
    """

    code: ViolationCode
    value: float
    limit: float
    axis: str = ""
    box: str = ""
    segment: int | None = None
    reduced: bool = False  # the limit is reduced-speed mode's
    approaching: bool = False  # not past the limit yet: within the stopping distance (jog guard)

    @property
    def message(self) -> str:
        where = "" if self.segment is None else f"segment {self.segment + 1}: "
        unit = "°" if self.code is ViolationCode.JOINT_LIMIT else "mm"
        if self.approaching:
            joint = self.code is ViolationCode.JOINT_LIMIT
            edge = "its limit" if joint else "the edge of the allowed work space"
            zone = f"the keep-out zone '{self.box}'" if self.box else edge
            return (
                f"{where}{self.axis} = {self.value:.1f} {unit} is within stopping distance of {zone} "
                f"at {self.limit:.1f} {unit}"
            )
        if self.code is ViolationCode.KEEP_IN:
            side = "below" if self.value < self.limit else "above"
            text = (
                f"{self.axis} = {self.value:.1f} {unit} is outside the allowed work space "
                f"({side} its limit {self.limit:.1f} {unit})"
            )
        elif self.code is ViolationCode.KEEP_OUT:
            text = (
                f"the path enters the keep-out zone '{self.box}' ({self.axis} = {self.value:.1f} {unit}, "
                f"its face is at {self.limit:.1f} {unit})"
            )
        elif self.code is ViolationCode.JOINT_LIMIT:
            side = "below" if self.value < self.limit else "above"
            text = f"{self.axis} = {self.value:.1f}° is {side} its limit {self.limit:.1f}°"
        elif self.code is ViolationCode.SPEED:
            mode = " in reduced-speed mode" if self.reduced else ""
            text = f"speed {self.value:g} mm/s is above the {self.limit:g} mm/s allowed{mode}"
        else:
            mode = " in reduced-speed mode" if self.reduced else ""
            text = f"jog speed {self.value:g}% is above the {self.limit:g}% allowed{mode}"
        return where + text

    def at_segment(self, index: int) -> EnvelopeViolation:
        return replace(self, segment=index)

    def __str__(self) -> str:
        return self.message


class EnvelopeRefused(TeachPadError):
    """An action was refused before the wire because it would leave the safety envelope."""

    code = "envelope_refused"

    def __init__(self, violation: EnvelopeViolation, action: str = "") -> None:
        prefix = f"{action} refused: " if action else "refused: "
        v = violation
        super().__init__(
            prefix + violation.message,
            params={
                "violation": v.code.value,
                "value": v.value,
                "limit": v.limit,
                "axis": v.axis,
                "box": v.box,
                "segment": v.segment,
                "reduced": v.reduced,
                "approaching": v.approaching,
            },
        )
        self.violation = violation


def _check_pair(lo: float, hi: float, what: str) -> tuple[float, float]:
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise InvalidInput(f"{what}: the lower limit must be below the upper limit (finite numbers)")
    return (float(lo), float(hi))


def _positive(value: float, what: str, hi: float | None = None) -> float:
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise InvalidInput(f"{what} must be a number > 0")
    if hi is not None and value > hi:
        raise InvalidInput(f"{what} must be at most {hi:g}")
    return float(value)


@dataclass(frozen=True)
class Envelope:
    """The limits of one robot profile. Empty ``joint_limits`` / no ``keep_in``: not checked."""

    joint_limits: tuple[tuple[float, float], ...] = ()  # J1.. in degrees
    keep_in: Box | None = None
    keep_out: tuple[Box, ...] = ()
    max_jog_ratio: float = 100.0  # %
    max_speed: float = 1000.0  # mm/s, moves and plan segments
    reduced_jog_ratio: float = 10.0  # % cap in reduced-speed mode
    reduced_speed: float = REDUCED_SPEED_DEFAULT  # mm/s cap in reduced-speed mode

    def __post_init__(self) -> None:
        limits = tuple(
            _check_pair(lo, hi, f"J{i + 1} limits") for i, (lo, hi) in enumerate(self.joint_limits)
        )
        object.__setattr__(self, "joint_limits", limits)
        object.__setattr__(self, "keep_out", tuple(self.keep_out))
        _positive(self.max_jog_ratio, "the maximum jog speed (%)", 100.0)
        _positive(self.reduced_jog_ratio, "the reduced-mode jog speed (%)", 100.0)
        _positive(self.max_speed, "the maximum speed (mm/s)")
        _positive(self.reduced_speed, "the reduced-mode speed (mm/s)")
        names = [b.name for b in self.keep_out]
        if len(set(names)) != len(names):
            raise InvalidInput("two keep-out zones have the same name")

    def jog_ratio_cap(self, reduced: bool = False) -> float:
        return min(self.max_jog_ratio, self.reduced_jog_ratio) if reduced else self.max_jog_ratio

    def speed_cap(self, reduced: bool = False) -> float:
        return min(self.max_speed, self.reduced_speed) if reduced else self.max_speed

    def cap_jog_ratio(self, ratio: float, reduced: bool = False) -> float:
        """The ratio to send: ``ratio`` capped (reduced mode caps silently, as a mode should)."""
        return min(ratio, self.jog_ratio_cap(reduced))

    def motion_caps(self, reach: float) -> MotionCaps:
        """Reduced-speed mode's caps for the client: the ratio cap (jog, programs), the TCP speed
        cap (steps, moves), and ``reach`` (mm, the robot model's reach bound: joint steps)."""
        return MotionCaps(self.jog_ratio_cap(True), self.speed_cap(True), reach)

    def clearance(self, p: FloatArray) -> float:
        """Signed distance (mm) to the Cartesian boundary: > 0 inside the allowed space."""
        best = math.inf
        if self.keep_in is not None:
            best = self.keep_in.clearance_inside(p)
        for box in self.keep_out:
            best = min(best, -box.clearance_inside(p))
        return best


# --- checks ---------------------------------------------------------------------------------


def _outside_keep_in(box: Box, p: FloatArray) -> EnvelopeViolation:
    lo, hi = box.lo_array, box.hi_array
    i = int(np.argmax(np.maximum(lo - p, p - hi)))
    limit = float(lo[i] if p[i] < lo[i] else hi[i])
    return EnvelopeViolation(ViolationCode.KEEP_IN, float(p[i]), limit, AXIS_NAMES[i])


def _inside_keep_out(zone: Box, p: FloatArray) -> EnvelopeViolation:
    i, value, face = zone.depth(p)
    return EnvelopeViolation(ViolationCode.KEEP_OUT, value, face, AXIS_NAMES[i], zone.name)


def check_point(envelope: Envelope, xyz: FloatArray) -> EnvelopeViolation | None:
    """The Cartesian checks of one XYZ (mm)."""
    p = np.asarray(xyz, dtype=np.float64)
    box = envelope.keep_in
    if box is not None and not box.contains(p):
        return _outside_keep_in(box, p)
    for zone in envelope.keep_out:
        if zone.contains(p):
            return _inside_keep_out(zone, p)
    return None


def check_joints(envelope: Envelope, joints: Sequence[float]) -> EnvelopeViolation | None:
    for i, ((lo, hi), q) in enumerate(zip(envelope.joint_limits, joints, strict=False)):
        if not lo <= q <= hi:
            return EnvelopeViolation(ViolationCode.JOINT_LIMIT, float(q), lo if q < lo else hi, f"J{i + 1}")
    return None


def check_speed(envelope: Envelope, speed: float) -> EnvelopeViolation | None:
    """Above ``max_speed``: refused in every mode (reduced-speed mode caps, it does not refuse)."""
    if speed > envelope.max_speed:
        return EnvelopeViolation(ViolationCode.SPEED, float(speed), envelope.max_speed)
    return None


def check_jog_ratio(envelope: Envelope, ratio: float, reduced: bool = False) -> EnvelopeViolation | None:
    cap = envelope.jog_ratio_cap(reduced)
    if ratio > cap:
        return EnvelopeViolation(ViolationCode.JOG_RATIO, float(ratio), cap, reduced=reduced)
    return None


def check_target(
    envelope: Envelope,
    pose: PointLike,
    joints: Sequence[float] | None = None,
    *,
    speed: float | None = None,
) -> EnvelopeViolation | None:
    """A step or move target (and its joints, its speed, when known): the first violation."""
    return (
        check_point(envelope, xyz_of(pose))
        or (check_joints(envelope, joints) if joints is not None else None)
        or (check_speed(envelope, speed) if speed is not None else None)
    )


def require_target(
    envelope: Envelope,
    pose: PointLike,
    joints: Sequence[float] | None = None,
    *,
    speed: float | None = None,
    action: str = "",
) -> None:
    """:func:`check_target`, raising :class:`EnvelopeRefused` for a violation."""
    violation = check_target(envelope, pose, joints, speed=speed)
    if violation is not None:
        raise EnvelopeRefused(violation, action)


def check_step(
    envelope: Envelope,
    pose: Pose,
    offsets: Sequence[float],
    *,
    joint: bool,
    speed: float | None = None,
) -> EnvelopeViolation | None:
    """An incremental move (function 1) from ``pose``: base frame (``joint`` False) X Y Z
    offsets in mm, a straight line checked whole, and its speed (mm/s); joint frame J1..J6
    offsets in degrees against the joint limits (needs ``pose.joints``; the TCP's path of a
    joint move needs the arm's kinematics and is the controller's to check)."""
    if joint:
        if pose.joints is None:
            return None
        target = [q + d for q, d in zip(pose.joints, offsets, strict=False)]
        return check_joints(envelope, target)
    if speed is not None and (too_fast := check_speed(envelope, speed)) is not None:
        return too_fast
    start = np.array((pose.x, pose.y, pose.z), dtype=np.float64)
    end = start + np.asarray(list(offsets)[:3], dtype=np.float64)
    return check_path(envelope, np.vstack((start, end)))


def check_path(envelope: Envelope, xyz: FloatArray) -> EnvelopeViolation | None:
    """A polyline through the rows of ``xyz`` (n, 3): every vertex in the keep-in box (convex,
    so every chord is too), no chord touching a keep-out box."""
    pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    if pts.shape[0] == 0:
        return None
    box = envelope.keep_in
    if box is not None:
        outside = np.flatnonzero(~box.inside_mask(pts))
        if outside.size:
            return _outside_keep_in(box, pts[outside[0]])
    if pts.shape[0] == 1:
        for zone in envelope.keep_out:
            if zone.contains(pts[0]):
                return _inside_keep_out(zone, pts[0])
        return None
    a, b = pts[:-1], pts[1:]
    pmin, pmax = pts.min(axis=0), pts.max(axis=0)
    for zone in envelope.keep_out:
        if np.any(pmax < zone.lo_array) or np.any(pmin > zone.hi_array):
            continue  # the path's bounding box misses the zone
        k = zone.segments_hit(a, b)
        if k is not None:
            return _inside_keep_out(zone, zone.entry_point(a[k], b[k]))
    return None


def _samples_for(start: PointLike, segment: Segment, ledger: PointLedger) -> int:
    if not segment.is_arc:
        return 3  # a line is tested exactly by its chords
    length = segment_length(start, segment, ledger)
    return int(min(MAX_SAMPLES_PER_SEGMENT, max(16, math.ceil(length / ARC_SAMPLE_STEP_MM) + 1)))


def check_segment(
    envelope: Envelope, start: PointLike, segment: Segment, ledger: PointLedger
) -> EnvelopeViolation | None:
    """One plan segment from ``start``: its speed, then its path (arcs sampled finely).

    Raises :class:`InvalidInput` for a missing point or an arc that defines no circle (the
    plan checks report those themselves)."""
    speed = check_speed(envelope, segment.speed)
    if speed is not None:
        return speed
    path = segment_path(start, segment, ledger, samples=_samples_for(start, segment, ledger))
    return check_path(envelope, path)


def plan_violations(
    plan: Plan,
    ledger: PointLedger,
    envelope: Envelope,
    current_pose: PointLike | None = None,
    *,
    start_index: int = 0,
    loops: int | None = None,
) -> list[EnvelopeViolation]:
    """The first violation of each segment that leaves the envelope (``segment`` set).

    Segments start where they will run from: ``start_index`` at ``current_pose`` (only its end
    point and speed are checked when the pose is unknown), the others at the previous end;
    with more than one loop, segment 0 also from the last end. Segments with missing points
    or degenerate arcs are left to the plan's own checks.
    """
    loops = plan.loops if loops is None else loops
    out: list[EnvelopeViolation] = []
    for i, seg in enumerate(plan.segments):
        starts = _segment_starts(plan.segments, i, ledger, current_pose, start_index, loops)
        if starts:
            found = _first_violation(envelope, starts, seg, ledger)
        else:
            found = _violation_without_start(envelope, seg, ledger)
        if found is not None:
            out.append(found.at_segment(i))
    return out


def _segment_starts(
    segs: list[Segment],
    i: int,
    ledger: PointLedger,
    current_pose: PointLike | None,
    start_index: int,
    loops: int,
) -> list[PointLike]:
    """Where segment ``i`` may run from: the pose (the first segment run), the previous segment's
    end (when that runs before it), the last segment's end (segment 0 of a further loop)."""
    starts: list[PointLike] = []
    if i == start_index and current_pose is not None:
        starts.append(current_pose)
    if i > 0 and (i > start_index or loops != 1):
        prev = ledger.get(segs[i - 1].end_id)
        if prev is not None:
            starts.append(prev)
    if i == 0 and loops != 1 and len(segs) > 1:
        last = ledger.get(segs[-1].end_id)
        if last is not None:
            starts.append(last)
    return starts


def _first_violation(
    envelope: Envelope, starts: list[PointLike], seg: Segment, ledger: PointLedger
) -> EnvelopeViolation | None:
    """The segment's first violation from the first start that has one (a segment its points
    cannot make is left to the plan's checks)."""
    for start in starts:
        try:
            found = check_segment(envelope, start, seg, ledger)
        except InvalidInput:
            found = None
        if found is not None:
            return found
    return None


def _violation_without_start(
    envelope: Envelope, seg: Segment, ledger: PointLedger
) -> EnvelopeViolation | None:
    """A segment whose start is unknown: its speed, end point and middle point are checked."""
    end = ledger.get(seg.end_id)
    via = ledger.get(seg.via_id) if seg.via_id is not None else None
    return (
        check_speed(envelope, seg.speed)
        or (check_point(envelope, xyz_of(end)) if end is not None else None)
        or (check_point(envelope, xyz_of(via)) if via is not None else None)
    )
