"""Checks of a plan before it runs: missing or unsent points, arcs that define no circle,
speeds, tools, and an arc resumed past its middle point.

Messages are plain English and already name the segment (counted from 1). Beside each message
an issue carries its ``code`` and ``args`` (numbers, point ids and labels, the role of a point,
where the segment starts -- never English sentences): the GUI words them in the operator's
language (``ui/messages.issue_text``).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from app.errors import InvalidInput
from app.lazy_numpy import FloatArray
from app.plan.geometry import PointLike, arc_geometry, xyz_of
from app.plan.issue_kind import IssueKind
from app.plan.segments import Plan, Segment
from app.points.fields import tool_text
from app.points.ledger import PointLedger
from app.points.point import SyncState
from app.safety.envelope import Envelope, EnvelopeRefused, plan_violations

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np


@dataclass(frozen=True)
class PlanLimits:
    """Settings the checks use."""

    max_speed: float = 1000.0  # mm/s
    collinear_tolerance: float = 0.1  # mm: an arc's middle point must be this far off the chord line
    min_point_distance: float = 0.1  # mm: an arc's three points must be this far apart
    zero_length: float = 0.01  # mm: a shorter line is reported (warning)

    def __post_init__(self) -> None:
        for name in ("max_speed", "collinear_tolerance", "min_point_distance", "zero_length"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise InvalidInput(f"{name} must be a finite number >= 0")
        if self.max_speed <= 0:
            raise InvalidInput("max_speed must be > 0")


# An arc resumed from a pose this far from its planned start is checked for a detour.
ARC_RESUME_TOLERANCE_MM = 1.0
ARC_RESUME_TOLERANCE_DEG = 2.0


class IssueCode(enum.Enum):
    EMPTY_PLAN = "empty-plan"
    MISSING_POINT = "missing-point"
    NEEDS_UPLOAD = "needs-upload"
    ARC_NO_MIDDLE = "arc-no-middle"
    ARC_POINTS_COINCIDE = "arc-points-coincide"
    ARC_COLLINEAR = "arc-collinear"
    ARC_START_UNKNOWN = "arc-start-unknown"
    BAD_SPEED = "bad-speed"
    ZERO_LENGTH = "zero-length"
    TOOL_MISMATCH = "tool-mismatch"
    BAD_START = "bad-start"
    ARC_RESUME_PAST_MIDDLE = "arc-resume-past-middle"
    OUTSIDE_ENVELOPE = "outside-envelope"  # an error: the segment leaves the safety envelope
    UNREACHABLE = "unreachable"  # the robot model's IK finds no solution (app.view3d.reach)
    JOINT_LIMIT = "joint-limit"  # reachable only past a joint limit of the robot model
    MODEL_DISAGREES = "model-disagrees"  # the model's FK is not the controller's pose (view3d.agreement)
    SPEED_CAPPED = "speed-capped"  # a warning: reduced-speed mode sends the segment at its cap


@dataclass(frozen=True)
class PlanIssue:
    """One problem of a plan. ``segment`` is the 0-based index (None: the whole plan)."""

    segment: int | None
    kind: IssueKind
    code: IssueCode
    message: str  # plain English, already says which segment
    point_id: int | None = None
    # the message's values for the GUI's sentence (see the module docstring)
    args: Mapping[str, Any] = field(default_factory=dict, compare=False, hash=False)

    @property
    def is_error(self) -> bool:
        return self.kind is IssueKind.ERROR

    def __str__(self) -> str:
        return f"{self.kind.value}: {self.message}"


#: Reachability of a plan by a robot model: (plan, ledger, current pose) -> issues.
ReachCheck = Callable[[Plan, PointLedger, PointLike | None], Sequence[PlanIssue]]


def has_errors(issues: Sequence[PlanIssue]) -> bool:
    return any(i.kind is IssueKind.ERROR for i in issues)


def ids_needing_upload(issues: Sequence[PlanIssue]) -> list[int]:
    return sorted({i.point_id for i in issues if i.kind is IssueKind.NEEDS_UPLOAD and i.point_id is not None})


def _seg_name(index: int) -> str:
    return f"segment {index + 1}"


def _arc_issue(
    s: FloatArray, m: FloatArray, e: FloatArray, limits: PlanLimits
) -> tuple[IssueCode, str, dict[str, Any]] | None:
    """Why S, M, E define no usable circle (code, English, args), or None."""
    d_sm, d_me, d_se = (float(np.linalg.norm(p - q)) for p, q in ((m, s), (e, m), (e, s)))
    tol = limits.min_point_distance
    if min(d_sm, d_me, d_se) < tol:
        pair = "start-middle" if d_sm < tol else ("middle-end" if d_me < tol else "start-end")
        which = pair.replace("-", " and ")
        return (
            IssueCode.ARC_POINTS_COINCIDE,
            (f"the arc's {which} points coincide (closer than {tol:g} mm): three distinct points are needed"),
            {"pair": pair, "tolerance": tol},
        )
    # distance of M from the line S-E
    off = float(np.linalg.norm(np.cross(m - s, e - s))) / d_se
    if off < limits.collinear_tolerance:
        return (
            IssueCode.ARC_COLLINEAR,
            (
                f"the arc's three points are (nearly) on one line: the middle point is {off:.3g} mm off the "
                f"start-end line (at least {limits.collinear_tolerance:g} mm needed); use a line instead"
            ),
            {"offset": float(f"{off:.3g}"), "tolerance": limits.collinear_tolerance},
        )
    return None


def check_plan(
    plan: Plan,
    ledger: PointLedger,
    limits: PlanLimits | None = None,
    current_pose: PointLike | None = None,
    *,
    start_index: int = 0,
    loops: int | None = None,
    envelope: Envelope | None = None,
    reduced_speed: bool = False,
    reach: ReachCheck | None = None,
) -> list[PlanIssue]:
    """Everything to fix (or know) before running ``plan`` from segment ``start_index``.

    ``current_pose`` is where the robot is now: the start of segment ``start_index``.
    Without it, an arc starting there is reported as unchecked (warning). With ``loops``
    other than 1, the first segment is also checked from the end of the last one.
    Issues come sorted by segment; "needs upload" is reported once per point. With an
    ``envelope``, a segment that leaves it (sampled, arcs too) or runs faster than its maximum
    speed is an error (:data:`IssueCode.OUTSIDE_ENVELOPE`), which blocks Run; with
    ``reduced_speed`` a segment faster than the reduced-speed cap is a warning
    (:data:`IssueCode.SPEED_CAPPED`): it runs at the cap (the client caps every speed it writes).
    ``reach`` (e.g. :meth:`app.view3d.reach.ReachChecker.plan_issues`) adds the robot model's
    reachability issues (:data:`IssueCode.UNREACHABLE`, :data:`IssueCode.JOINT_LIMIT`).
    """
    limits = limits or PlanLimits()
    loops = plan.loops if loops is None else loops
    issues: list[PlanIssue] = []
    n = len(plan.segments)
    if n == 0:
        return [
            PlanIssue(
                None,
                IssueKind.ERROR,
                IssueCode.EMPTY_PLAN,
                f"plan '{plan.name}' has no segments",
                args={"plan": plan.name},
            )
        ]
    if not 0 <= start_index < n:
        return [
            PlanIssue(
                None,
                IssueKind.ERROR,
                IssueCode.BAD_START,
                f"cannot start at segment {start_index + 1}: the plan has {n} segments",
                args={"start": start_index + 1, "segments": n},
            )
        ]
    ends = [None if (end := ledger.get(seg.end_id)) is None else xyz_of(end) for seg in plan.segments]
    issues.extend(_point_issues(plan, ledger, limits))
    # Geometry, from where each segment starts when it runs: segment start_index from the
    # current pose, the others from the previous end; with more loops, segment 0 also from
    # the last end, and the segments before start_index run on later loops.
    start_pose = None if current_pose is None else xyz_of(current_pose)
    for i, seg in enumerate(plan.segments):
        for start, context in _segment_starts(i, n, start_index, loops != 1, start_pose, ends):
            issues.extend(
                _geometry_issues(
                    i,
                    seg,
                    start,
                    context,
                    ends,
                    ledger,
                    limits,
                    pose_unknown=i == start_index and current_pose is None,
                    resumed=i == start_index,
                )
            )
    if envelope is not None:
        if reduced_speed:
            issues.extend(_capped_speeds(plan, envelope))
        for v in plan_violations(plan, ledger, envelope, current_pose, start_index=start_index, loops=loops):
            issues.append(
                PlanIssue(
                    v.segment,
                    IssueKind.ERROR,
                    IssueCode.OUTSIDE_ENVELOPE,
                    v.message,
                    args=EnvelopeRefused(v).as_reason().args,
                )
            )
    if reach is not None:
        issues.extend(reach(plan, ledger, current_pose))
    order = {IssueKind.ERROR: 0, IssueKind.NEEDS_UPLOAD: 1, IssueKind.WARNING: 2}
    issues.sort(key=lambda it: (-1 if it.segment is None else it.segment, order[it.kind]))
    return issues


def _capped_speeds(plan: Plan, envelope: Envelope) -> list[PlanIssue]:
    """Reduced-speed mode: the segments that will run at the cap, not at their own speed."""
    cap = envelope.speed_cap(reduced=True)
    return [
        PlanIssue(
            i,
            IssueKind.WARNING,
            IssueCode.SPEED_CAPPED,
            f"{_seg_name(i)}: runs at {cap:g} mm/s, the reduced-speed cap (planned {seg.speed:g} mm/s)",
            args={"speed": seg.speed, "cap": cap},
        )
        for i, seg in enumerate(plan.segments)
        if cap < seg.speed <= envelope.max_speed
    ]


def _point_issues(plan: Plan, ledger: PointLedger, limits: PlanLimits) -> list[PlanIssue]:
    """Speeds, arcs without a middle, missing points, points to upload, tool mismatches."""
    issues: list[PlanIssue] = []
    upload_reported: set[int] = set()
    for i, seg in enumerate(plan.segments):
        name = _seg_name(i)
        end = ledger.get(seg.end_id)
        via = ledger.get(seg.via_id) if seg.via_id is not None else None
        if not 0 < seg.speed <= limits.max_speed:
            issues.append(
                PlanIssue(
                    i,
                    IssueKind.ERROR,
                    IssueCode.BAD_SPEED,
                    f"{name}: speed {seg.speed:g} mm/s is not in (0, {limits.max_speed:g}] mm/s",
                    args={"speed": seg.speed, "max": limits.max_speed},
                )
            )
        if seg.is_arc and seg.via_id is None:
            issues.append(
                PlanIssue(i, IssueKind.ERROR, IssueCode.ARC_NO_MIDDLE, f"{name}: the arc has no middle point")
            )
        for role, pid, point in (("middle", seg.via_id, via), ("end", seg.end_id, end)):
            if pid is None:
                continue
            if point is None:
                issues.append(
                    PlanIssue(
                        i,
                        IssueKind.ERROR,
                        IssueCode.MISSING_POINT,
                        f"{name}: {role} point P{pid} does not exist",
                        pid,
                        args={"role": role, "id": pid},
                    )
                )
                continue
            if point.needs_upload and pid not in upload_reported:
                upload_reported.add(pid)
                why = point.sync.text + (f": {point.sync_error}" if point.sync is SyncState.FAILED else "")
                issues.append(
                    PlanIssue(
                        i,
                        IssueKind.NEEDS_UPLOAD,
                        IssueCode.NEEDS_UPLOAD,
                        f"{name}: {point.label} is not on the controller ({why}); upload it",
                        pid,
                        args={"point": point.label, "sync": point.sync.value},
                    )
                )
            if point.tool != seg.tool:
                issues.append(
                    PlanIssue(
                        i,
                        IssueKind.WARNING,
                        IssueCode.TOOL_MISMATCH,
                        f"{name}: {point.label} was taught with {tool_text(point.tool)}, "
                        f"the segment moves with {tool_text(seg.tool)}",
                        pid,
                        args={"point": point.label, "point_tool": point.tool, "segment_tool": seg.tool},
                    )
                )
    return issues


# Where a segment starts, for the message: (English, args the GUI words). None: no context.
Context = tuple[str, dict[str, Any]] | None


def _segment_starts(
    i: int,
    n: int,
    start_index: int,
    more_loops: bool,
    start_pose: FloatArray | None,
    ends: Sequence[FloatArray | None],
) -> list[tuple[FloatArray | None, Context]]:
    """Where segment ``i`` starts when it runs, each with the context for the message."""
    starts: list[tuple[FloatArray | None, Context]] = []
    if i == start_index:
        starts.append((start_pose, ("from the current pose", {"from": "current_pose"})))
    if i > 0 and (i > start_index or more_loops):
        later: Context = (
            None
            if i > start_index
            else (
                f"on loops after the first, starting at the end of segment {i}",
                {"from": "later_loops", "after": i},
            )
        )
        starts.append((ends[i - 1], later))
    if i == 0 and more_loops:
        starts.append(
            (
                ends[n - 1],
                (
                    f"on loops after the first, starting at the end of segment {n}",
                    {"from": "later_loops", "after": n},
                ),
            )
        )
    return starts


def _geometry_issues(
    i: int,
    seg: Segment,
    start: FloatArray | None,
    context: Context,
    ends: Sequence[FloatArray | None],
    ledger: PointLedger,
    limits: PlanLimits,
    *,
    pose_unknown: bool,
    resumed: bool,
) -> list[PlanIssue]:
    """The shape of segment ``i`` run from ``start``: a usable arc, a line that goes somewhere."""
    suffix = f" ({context[0]})" if context else ""
    where: dict[str, Any] = context[1] if context else {}
    end_xyz = ends[i]
    if not seg.is_arc:
        if start is None or end_xyz is None:
            return []
        length = float(np.linalg.norm(end_xyz - start))
        if length >= limits.zero_length:
            return []
        return [
            PlanIssue(
                i,
                IssueKind.WARNING,
                IssueCode.ZERO_LENGTH,
                f"{_seg_name(i)}: the line goes nowhere (start and end {length:.3g} mm apart){suffix}",
                args={"length": float(f"{length:.3g}"), **where},
            )
        ]
    via_pt = ledger.get(seg.via_id) if seg.via_id is not None else None
    if via_pt is None or end_xyz is None:
        return []
    if start is None:
        if not pose_unknown:
            return []
        return [
            PlanIssue(
                i,
                IssueKind.WARNING,
                IssueCode.ARC_START_UNKNOWN,
                f"{_seg_name(i)}: the arc starts at the robot's current "
                "pose, which is not known: its shape is not checked",
            )
        ]
    problem = _arc_issue(start, xyz_of(via_pt), end_xyz, limits)
    if problem is not None:
        return [
            PlanIssue(
                i,
                IssueKind.ERROR,
                problem[0],
                f"{_seg_name(i)}: {problem[1]}{suffix}",
                args={**problem[2], **where},
            )
        ]
    if resumed and i > 0 and (planned_start := ends[i - 1]) is not None:
        detour = _arc_detour(start, planned_start, xyz_of(via_pt), end_xyz)
        if detour is not None:
            return [
                PlanIssue(
                    i,
                    detour[0],
                    IssueCode.ARC_RESUME_PAST_MIDDLE,
                    f"{_seg_name(i)}: {detour[1]}",
                    args=detour[2],
                )
            ]
    return []


def _arc_detour(
    start: FloatArray, planned_start: FloatArray, via: FloatArray, end: FloatArray
) -> tuple[IssueKind, str, dict[str, Any]] | None:
    """Why an arc sent from ``start`` would not follow the planned arc, or None.

    An arc interrupted past its middle point and sent again from where the arm stopped goes
    through the middle point again: the circle through (here, M, E) runs almost all the way
    round. That is an error when the arm stands on the planned arc past M; from elsewhere a
    sweep clearly larger than planned is a warning.
    """
    if float(np.linalg.norm(start - planned_start)) < ARC_RESUME_TOLERANCE_MM:
        return None
    planned = arc_geometry(planned_start, via, end)
    now = arc_geometry(start, via, end)
    sweep_now, sweep_planned = float(now.sweep[0]), float(planned.sweep[0])
    if not (math.isfinite(sweep_now) and math.isfinite(sweep_planned)):
        return None
    rel = start - planned.centre[0]
    off_plane = abs(float(np.dot(rel, planned.normal[0])))
    in_plane = rel - np.dot(rel, planned.normal[0]) * planned.normal[0]
    off_circle = abs(float(np.linalg.norm(in_plane)) - float(planned.radius[0]))
    at = math.atan2(float(np.dot(rel, planned.v[0])), float(np.dot(rel, planned.u[0]))) % (2.0 * math.pi)
    on_arc = max(off_plane, off_circle) < ARC_RESUME_TOLERANCE_MM
    past_middle = on_arc and float(planned.via_angle[0]) < at < sweep_planned
    larger = sweep_now > sweep_planned + math.radians(ARC_RESUME_TOLERANCE_DEG)
    if not (past_middle or larger):
        return None
    swing = (
        f"sent from here the arc would swing {math.degrees(sweep_now):.0f}° round through the "
        f"middle point (planned {math.degrees(sweep_planned):.0f}°)"
    )
    args = {
        "sweep": round(math.degrees(sweep_now)),
        "planned": round(math.degrees(sweep_planned)),
        "past_middle": past_middle,
    }
    if past_middle:
        return (
            IssueKind.ERROR,
            (
                f"the arm stopped past the arc's middle point: {swing}; move to the "
                "end point with a line, or run from the segment before"
            ),
            args,
        )
    return IssueKind.WARNING, f"{swing}; check the preview before running from here", args
