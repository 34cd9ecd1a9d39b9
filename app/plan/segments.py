"""Trajectories on the host: plans of LINE / ARC segments, their checks, geometry and timing.

A :class:`Plan` is an ordered list of :class:`Segment` run one after the other with function 3
(move to temp point). A segment names its end point (and, for an arc, its middle point) by id
in a :class:`~app.points.ledger.PointLedger`; it starts wherever the previous one ended. The first
segment starts at the robot's pose when the run begins, and on every loop after the first at
the end of the last segment.

Geometry: a LINE is straight; an ARC is the true circle through its start S, middle M and end
E (centre = circumcentre, in the plane of the three points), travelled S -> M -> E. Segment
fields that the controller interprets but that don't move the XYZ path (orientation kept or
changing, ignore-middle, tool frame) are carried, not modelled: "ignore the middle point"
(GV203) is taken to concern the middle point's orientation only, so the path still passes
through M (the seed does not say more; see docs/PROJECT_FORMAT.md).

Indices are 0-based in the API (``PlanIssue.segment``, ``PlanRunner`` positions); texts meant
for people count segments from 1.

Mutation methods of :class:`Plan` return what they changed so a Qt model and an undo stack
can wrap them (same conventions as :class:`~app.points.ledger.PointLedger`).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from app import timing
from app.errors import InvalidInput
from app.models import Pose
from app.points.ledger import (
    FieldError,
    PointLedger,
    SyncState,
    TempPoint,
    parse_float,
    parse_int,
    parse_tool,
    tool_text,
)
from app.protocol.enums import QT_TRANSLATE_NOOP
from app.protocol.registers import TOOL_NONE

FloatArray = NDArray[np.float64]

TR_CONTEXT = "Plan"

#: Time added per segment to length / speed: command round trip, acceleration, settling (s).
SEGMENT_OVERHEAD_S = 0.3
DEFAULT_SPEED = 50.0  # mm/s
DEFAULT_SAMPLES = 32  # samples per segment for drawing
MAX_LOOPS = 1_000_000
PLAN_NAME_MAX_CHARS = 100

#: Editable fields of a segment, in table column order.
SEGMENT_FIELDS: tuple[str, ...] = ("kind", "via", "end", "speed", "orientation", "ignore_middle", "tool")


class SegmentKind(enum.Enum):
    LINE = "line"
    ARC = "arc"

    @property
    def text(self) -> str:
        return SEGMENT_KIND_TEXT[self]


SEGMENT_KIND_TEXT: dict[SegmentKind, str] = {
    SegmentKind.LINE: QT_TRANSLATE_NOOP("Plan", "line"),
    SegmentKind.ARC: QT_TRANSLATE_NOOP("Plan", "arc"),
}

ORIENTATION_CHANGES = "changes"
ORIENTATION_KEPT = "kept"


def _parse_bool(field_name: str, value: object) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, int) and value in (0, 1):
        return bool(value)
    if isinstance(value, str):
        key = value.strip().lower()
        if key in ("1", "true", "yes", "on"):
            return True
        if key in ("0", "false", "no", "off"):
            return False
    raise FieldError(field_name, f"{value!r} is not yes/no")


def parse_kind(value: object) -> SegmentKind:
    if isinstance(value, SegmentKind):
        return value
    if isinstance(value, str):
        key = value.strip().lower()
        for kind in SegmentKind:
            if kind.value == key:
                return kind
    raise FieldError("kind", f"{value!r} is not 'line' or 'arc'")


def parse_orientation(value: object) -> bool:
    """``orientation_changes`` from ``"changes"``/``"kept"`` (or a bool)."""
    if isinstance(value, str):
        key = value.strip().lower()
        if key in (ORIENTATION_CHANGES, "change", "changing"):
            return True
        if key in (ORIENTATION_KEPT, "keep", "constant"):
            return False
    if isinstance(value, bool):
        return value
    raise FieldError("orientation", f"{value!r} is not '{ORIENTATION_CHANGES}' or '{ORIENTATION_KEPT}'")


def _parse_ref(field_name: str, value: object) -> int:
    point_id = parse_int(field_name, value)
    if point_id < 0:
        raise FieldError(field_name, f"point id {point_id} is negative")
    return point_id


@dataclass(frozen=True)
class Segment:
    """One move to a temp point (function 3).

    A LINE never carries a middle point (``via_id`` is dropped); an ARC without one is kept
    (so an editor can switch kind first) and reported by :func:`check_plan`.
    """

    kind: SegmentKind
    end_id: int
    via_id: int | None = None
    speed: float = DEFAULT_SPEED  # mm/s (GV225)
    orientation_changes: bool = True  # GV202: 1 changes, 0 kept constant
    ignore_middle: bool = False  # GV203
    tool: int = TOOL_NONE  # GV245

    def __post_init__(self) -> None:
        object.__setattr__(self, "kind", parse_kind(self.kind))
        object.__setattr__(self, "end_id", _parse_ref("end", self.end_id))
        if self.kind is SegmentKind.LINE:
            object.__setattr__(self, "via_id", None)
        elif self.via_id is not None:
            object.__setattr__(self, "via_id", _parse_ref("via", self.via_id))
        object.__setattr__(self, "speed", parse_float("speed", self.speed))
        object.__setattr__(self, "orientation_changes", _parse_bool("orientation", self.orientation_changes))
        object.__setattr__(self, "ignore_middle", _parse_bool("ignore_middle", self.ignore_middle))
        object.__setattr__(self, "tool", parse_tool(self.tool))

    @classmethod
    def line(cls, end_id: int, speed: float = DEFAULT_SPEED, **kwargs: object) -> Segment:
        return cls(SegmentKind.LINE, end_id, None, speed, **kwargs)  # type: ignore[arg-type]

    @classmethod
    def arc(cls, via_id: int, end_id: int, speed: float = DEFAULT_SPEED, **kwargs: object) -> Segment:
        return cls(SegmentKind.ARC, end_id, via_id, speed, **kwargs)  # type: ignore[arg-type]

    @property
    def is_arc(self) -> bool:
        return self.kind is SegmentKind.ARC

    @property
    def orientation(self) -> str:
        return ORIENTATION_CHANGES if self.orientation_changes else ORIENTATION_KEPT

    @property
    def point_ids(self) -> tuple[int, ...]:
        return (self.end_id,) if self.via_id is None else (self.via_id, self.end_id)

    def get(self, field_name: str) -> object:
        """Value of a field of :data:`SEGMENT_FIELDS`."""
        values: dict[str, object] = {
            "kind": self.kind, "via": self.via_id, "end": self.end_id, "speed": self.speed,
            "orientation": self.orientation, "ignore_middle": self.ignore_middle, "tool": self.tool,
        }
        if field_name not in values:
            raise FieldError(field_name, "no such field")
        return values[field_name]

    def with_field(self, field_name: str, value: object) -> Segment:
        """A copy with one field set from an editor's value (validated)."""
        if field_name == "kind":
            return replace(self, kind=parse_kind(value))
        if field_name == "via":
            blank = value is None or (isinstance(value, str) and not value.strip())
            return replace(self, via_id=None if blank else _parse_ref("via", value))
        if field_name == "end":
            return replace(self, end_id=_parse_ref("end", value))
        if field_name == "speed":
            return replace(self, speed=parse_float("speed", value))
        if field_name == "orientation":
            return replace(self, orientation_changes=parse_orientation(value))
        if field_name == "ignore_middle":
            return replace(self, ignore_middle=_parse_bool("ignore_middle", value))
        if field_name == "tool":
            return replace(self, tool=parse_tool(value))
        raise FieldError(field_name, "no such field")

    @property
    def text(self) -> str:
        """E.g. ``arc via P2 to P3, 100 mm/s``."""
        path = f"arc via P{self.via_id} to P{self.end_id}" if self.is_arc else f"line to P{self.end_id}"
        return f"{path}, {self.speed:g} mm/s"


def validate_plan_name(name: object) -> str:
    if not isinstance(name, str) or not name.strip():
        raise FieldError("name", "a plan needs a name")
    text = name.strip()
    if len(text) > PLAN_NAME_MAX_CHARS or any(ch in text for ch in "\r\n\x00"):
        raise FieldError("name", f"must be one line of at most {PLAN_NAME_MAX_CHARS} characters")
    return text


def validate_loops(value: object) -> int:
    loops = parse_int("loops", value)
    if not 0 <= loops <= MAX_LOOPS:
        raise FieldError("loops", f"{loops} is not 0 (endless) .. {MAX_LOOPS}")
    return loops


@dataclass(frozen=True)
class SegmentEdit:
    row: int
    old: Segment
    new: Segment


@dataclass(eq=False)
class Plan:
    """A named, ordered list of segments run ``loops`` times (0 = until stopped)."""

    name: str
    segments: list[Segment] = field(default_factory=list)
    loops: int = 1
    revision: int = 0

    def __post_init__(self) -> None:
        self.name = validate_plan_name(self.name)
        self.loops = validate_loops(self.loops)
        self.segments = list(self.segments)
        for seg in self.segments:
            if not isinstance(seg, Segment):
                raise InvalidInput(f"not a Segment: {seg!r}")

    def __len__(self) -> int:
        return len(self.segments)

    def __getitem__(self, row: int) -> Segment:
        return self.segments[row]

    def point_ids(self) -> set[int]:
        return {pid for seg in self.segments for pid in seg.point_ids}

    def copy(self, name: str | None = None) -> Plan:
        return Plan(self.name if name is None else name, list(self.segments), self.loops)

    # --- mutations (each returns what an undo needs)
    def insert(self, row: int, segment: Segment) -> int:
        row = max(0, min(row, len(self.segments)))
        self.segments.insert(row, segment)
        self.revision += 1
        return row

    def append(self, segment: Segment) -> int:
        return self.insert(len(self.segments), segment)

    def remove(self, row: int) -> Segment:
        seg = self.segments.pop(row)
        self.revision += 1
        return seg

    def move(self, src: int, dst: int) -> None:
        """Move segment ``src`` so that it ends at index ``dst`` (undo: ``move(dst, src)``)."""
        n = len(self.segments)
        if not (0 <= src < n and 0 <= dst < n):
            raise InvalidInput(f"cannot move segment {src} to {dst} in {n} segments")
        if src != dst:
            self.segments.insert(dst, self.segments.pop(src))
            self.revision += 1

    def replace(self, row: int, segment: Segment) -> Segment:
        old = self.segments[row]
        self.segments[row] = segment
        self.revision += 1
        return old

    def set_field(self, row: int, field_name: str, value: object) -> SegmentEdit:
        old = self.segments[row]
        new = old.with_field(field_name, value)
        if new != old:
            self.replace(row, new)
        return SegmentEdit(row, old, new)

    def set_loops(self, loops: object) -> int:
        old, self.loops = self.loops, validate_loops(loops)
        if old != self.loops:
            self.revision += 1
        return old

    def rename(self, name: object) -> str:
        """Rename (the project checks that names stay unique); returns the old name."""
        old, self.name = self.name, validate_plan_name(name)
        if old != self.name:
            self.revision += 1
        return old

    def replace_point_id(self, old_id: int, new_id: int) -> list[int]:
        """Follow a renumbered point; returns the rows that changed."""
        rows: list[int] = []
        for row, seg in enumerate(self.segments):
            new = replace(
                seg,
                end_id=new_id if seg.end_id == old_id else seg.end_id,
                via_id=new_id if seg.via_id == old_id else seg.via_id,
            )
            if new != seg:
                self.segments[row] = new
                rows.append(row)
        if rows:
            self.revision += 1
        return rows


# --- checks ----------------------------------------------------------------------------------


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


class IssueKind(enum.Enum):
    ERROR = "error"  # the plan cannot run as it is
    NEEDS_UPLOAD = "needs-upload"  # a point must be (re)created on the controller first
    WARNING = "warning"  # it can run, but look


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


@dataclass(frozen=True)
class PlanIssue:
    """One problem of a plan. ``segment`` is the 0-based index (None: the whole plan)."""

    segment: int | None
    kind: IssueKind
    code: IssueCode
    message: str  # plain English, already says which segment
    point_id: int | None = None

    @property
    def is_error(self) -> bool:
        return self.kind is IssueKind.ERROR

    def __str__(self) -> str:
        return f"{self.kind.value}: {self.message}"


def has_errors(issues: Sequence[PlanIssue]) -> bool:
    return any(i.kind is IssueKind.ERROR for i in issues)


def ids_needing_upload(issues: Sequence[PlanIssue]) -> list[int]:
    return sorted({i.point_id for i in issues if i.kind is IssueKind.NEEDS_UPLOAD and i.point_id is not None})


PointLike = Pose | TempPoint | Sequence[float] | FloatArray


def xyz_of(obj: PointLike) -> FloatArray:
    """XYZ (mm) of a pose, a point, or a sequence / array whose first three values are XYZ."""
    if isinstance(obj, Pose | TempPoint):
        return np.array((obj.x, obj.y, obj.z), dtype=np.float64)
    arr = np.asarray(obj, dtype=np.float64).reshape(-1)
    if arr.size < 3:
        raise InvalidInput(f"a start pose needs at least x y z, got {arr.size} values")
    return arr[:3].copy()


def _seg_name(index: int) -> str:
    return f"segment {index + 1}"


def _arc_issue(
    s: FloatArray, m: FloatArray, e: FloatArray, limits: PlanLimits
) -> tuple[IssueCode, str] | None:
    """Why S, M, E define no usable circle, or None."""
    d_sm, d_me, d_se = (float(np.linalg.norm(p - q)) for p, q in ((m, s), (e, m), (e, s)))
    tol = limits.min_point_distance
    if min(d_sm, d_me, d_se) < tol:
        which = "start and middle" if d_sm < tol else ("middle and end" if d_me < tol else "start and end")
        return IssueCode.ARC_POINTS_COINCIDE, (
            f"the arc's {which} points coincide (closer than {tol:g} mm): three distinct points are needed"
        )
    # distance of M from the line S-E
    off = float(np.linalg.norm(np.cross(m - s, e - s))) / d_se
    if off < limits.collinear_tolerance:
        return IssueCode.ARC_COLLINEAR, (
            f"the arc's three points are (nearly) on one line: the middle point is {off:.3g} mm off the "
            f"start-end line (at least {limits.collinear_tolerance:g} mm needed); use a line instead"
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
) -> list[PlanIssue]:
    """Everything to fix (or know) before running ``plan`` from segment ``start_index``.

    ``current_pose`` is where the robot is now: the start of segment ``start_index``.
    Without it, an arc starting there is reported as unchecked (warning). With ``loops``
    other than 1, the first segment is also checked from the end of the last one.
    Issues come sorted by segment; "needs upload" is reported once per point.
    """
    limits = limits or PlanLimits()
    loops = plan.loops if loops is None else loops
    issues: list[PlanIssue] = []
    n = len(plan.segments)
    if n == 0:
        return [PlanIssue(None, IssueKind.ERROR, IssueCode.EMPTY_PLAN, f"plan '{plan.name}' has no segments")]
    if not 0 <= start_index < n:
        return [PlanIssue(None, IssueKind.ERROR, IssueCode.BAD_START,
                          f"cannot start at segment {start_index + 1}: the plan has {n} segments")]
    ends: list[FloatArray | None] = []
    upload_reported: set[int] = set()
    for i, seg in enumerate(plan.segments):
        name = _seg_name(i)
        end = ledger.get(seg.end_id)
        via = ledger.get(seg.via_id) if seg.via_id is not None else None
        ends.append(None if end is None else xyz_of(end))
        if not 0 < seg.speed <= limits.max_speed:
            issues.append(PlanIssue(i, IssueKind.ERROR, IssueCode.BAD_SPEED,
                                    f"{name}: speed {seg.speed:g} mm/s is not in "
                                    f"(0, {limits.max_speed:g}] mm/s"))
        if seg.is_arc and seg.via_id is None:
            issues.append(PlanIssue(i, IssueKind.ERROR, IssueCode.ARC_NO_MIDDLE,
                                    f"{name}: the arc has no middle point"))
        for role, pid, point in (("middle", seg.via_id, via), ("end", seg.end_id, end)):
            if pid is None:
                continue
            if point is None:
                issues.append(PlanIssue(i, IssueKind.ERROR, IssueCode.MISSING_POINT,
                                        f"{name}: {role} point P{pid} does not exist", pid))
                continue
            if point.needs_upload and pid not in upload_reported:
                upload_reported.add(pid)
                why = point.sync.text + (f": {point.sync_error}" if point.sync is SyncState.FAILED else "")
                issues.append(PlanIssue(i, IssueKind.NEEDS_UPLOAD, IssueCode.NEEDS_UPLOAD,
                                        f"{name}: {point.label} is not on the controller ({why}); upload it",
                                        pid))
            if point.tool != seg.tool:
                issues.append(PlanIssue(i, IssueKind.WARNING, IssueCode.TOOL_MISMATCH,
                                        f"{name}: {point.label} was taught with {tool_text(point.tool)}, "
                                        f"the segment moves with {tool_text(seg.tool)}", pid))
    # Geometry, from where each segment starts when it runs: segment start_index from the
    # current pose, the others from the previous end; with more loops, segment 0 also from
    # the last end, and the segments before start_index run on later loops.
    start_pose = None if current_pose is None else xyz_of(current_pose)
    more_loops = loops != 1
    for i, seg in enumerate(plan.segments):
        starts: list[tuple[FloatArray | None, str]] = []
        if i == start_index:
            starts.append((start_pose, "from the current pose"))
        if i > 0 and (i > start_index or more_loops):
            later = "" if i > start_index else f"on loops after the first, starting at the end of segment {i}"
            starts.append((ends[i - 1], later))
        if i == 0 and more_loops:
            starts.append((ends[n - 1], f"on loops after the first, starting at the end of segment {n}"))
        end_xyz = ends[i]
        via_pt = ledger.get(seg.via_id) if seg.via_id is not None else None
        for start, context in starts:
            suffix = f" ({context})" if context else ""
            if seg.is_arc:
                if via_pt is None or end_xyz is None:
                    continue
                if start is None:
                    if i == start_index and current_pose is None:
                        issues.append(PlanIssue(i, IssueKind.WARNING, IssueCode.ARC_START_UNKNOWN,
                                                f"{_seg_name(i)}: the arc starts at the robot's current "
                                                "pose, which is not known: its shape is not checked"))
                    continue
                problem = _arc_issue(start, xyz_of(via_pt), end_xyz, limits)
                if problem is not None:
                    issues.append(PlanIssue(i, IssueKind.ERROR, problem[0],
                                            f"{_seg_name(i)}: {problem[1]}{suffix}"))
                elif i == start_index and i > 0 and (planned_start := ends[i - 1]) is not None:
                    detour = _arc_detour(start, planned_start, xyz_of(via_pt), end_xyz)
                    if detour is not None:
                        issues.append(PlanIssue(i, detour[0], IssueCode.ARC_RESUME_PAST_MIDDLE,
                                                f"{_seg_name(i)}: {detour[1]}"))
            elif start is not None and end_xyz is not None:
                length = float(np.linalg.norm(end_xyz - start))
                if length < limits.zero_length:
                    issues.append(PlanIssue(i, IssueKind.WARNING, IssueCode.ZERO_LENGTH,
                                            f"{_seg_name(i)}: the line goes nowhere "
                                            f"(start and end {length:.3g} mm apart){suffix}"))
    order = {IssueKind.ERROR: 0, IssueKind.NEEDS_UPLOAD: 1, IssueKind.WARNING: 2}
    issues.sort(key=lambda it: (-1 if it.segment is None else it.segment, order[it.kind]))
    return issues


def _arc_detour(start: FloatArray, planned_start: FloatArray, via: FloatArray,
                end: FloatArray) -> tuple[IssueKind, str] | None:
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
    swing = (f"sent from here the arc would swing {math.degrees(sweep_now):.0f}° round through the "
             f"middle point (planned {math.degrees(sweep_planned):.0f}°)")
    if past_middle:
        return IssueKind.ERROR, (f"the arm stopped past the arc's middle point: {swing}; move to the "
                                 "end point with a line, or run from the segment before")
    return IssueKind.WARNING, f"{swing}; check the preview before running from here"


# --- geometry ------------------------------------------------------------------------------


@dataclass(frozen=True)
class ArcGeometry:
    """Circles through (S, M, E) triples, one row per arc; NaN rows where degenerate.

    A point of the circle at angle t is ``centre + radius * (cos t * u + sin t * v)``; S is at
    t = 0, M at ``via_angle``, E at ``sweep`` (0 < via_angle < sweep < 2 pi).
    """

    centre: FloatArray  # (n, 3)
    radius: FloatArray  # (n,)
    normal: FloatArray  # (n, 3) unit, S -> M -> E counter-clockwise about it
    u: FloatArray  # (n, 3) unit, centre -> S
    v: FloatArray  # (n, 3) unit, normal x u
    via_angle: FloatArray  # (n,) rad
    sweep: FloatArray  # (n,) rad

    @property
    def length(self) -> FloatArray:
        return np.asarray(self.radius * self.sweep, dtype=np.float64)

    def rows(self, mask: NDArray[np.bool_]) -> ArcGeometry:
        """The arcs selected by a boolean mask."""
        return ArcGeometry(self.centre[mask], self.radius[mask], self.normal[mask], self.u[mask],
                           self.v[mask], self.via_angle[mask], self.sweep[mask])

    def masked(self, keep: NDArray[np.bool_]) -> ArcGeometry:
        """Same rows, NaN where ``keep`` is False."""
        k1, k2 = keep, keep[:, None]
        return ArcGeometry(np.where(k2, self.centre, np.nan), np.where(k1, self.radius, np.nan),
                           np.where(k2, self.normal, np.nan), np.where(k2, self.u, np.nan),
                           np.where(k2, self.v, np.nan), np.where(k1, self.via_angle, np.nan),
                           np.where(k1, self.sweep, np.nan))


def _rows_dot(p: FloatArray, q: FloatArray) -> FloatArray:
    return np.asarray(np.einsum("ij,ij->i", p, q), dtype=np.float64)


def arc_geometry(s: FloatArray, m: FloatArray, e: FloatArray, eps: float = 1e-9) -> ArcGeometry:
    """Circumcircles of the triangles (S, M, E), vectorised over rows of (n, 3) arrays.

    Rows whose points are (nearly) collinear or coincide — triangle area below ``eps`` times
    the squared size — are NaN.
    """
    s, m, e = (np.atleast_2d(np.asarray(x, dtype=np.float64)) for x in (s, m, e))
    b = m - s
    c = e - s
    w = np.cross(b, c)
    ww = _rows_dot(w, w)
    scale = np.maximum(_rows_dot(b, b), _rows_dot(c, c))
    ok = ww > (eps * scale) ** 2  # |w| (twice the triangle's area) against size^2
    ww_safe = np.where(ok, ww, 1.0)
    # circumcentre relative to S: (|b|^2 (c x w) + |c|^2 (w x b)) / (2 |w|^2)
    rel = (_rows_dot(b, b)[:, None] * np.cross(c, w) + _rows_dot(c, c)[:, None] * np.cross(w, b)) / (
        2.0 * ww_safe[:, None]
    )
    centre = s + rel
    radius = np.linalg.norm(rel, axis=1)
    normal = w / np.sqrt(ww_safe)[:, None]
    u = -rel / np.where(radius > 0, radius, 1.0)[:, None]
    v = np.cross(normal, u)
    two_pi = 2.0 * math.pi

    def angle(p: FloatArray) -> FloatArray:
        d = p - centre
        return np.asarray(np.mod(np.arctan2(_rows_dot(d, v), _rows_dot(d, u)), two_pi), dtype=np.float64)

    via_angle = angle(m)
    sweep = angle(e)
    return ArcGeometry(centre, radius, normal, u, v, via_angle, sweep).masked(ok)


def _sample_arcs(
    s: FloatArray, m: FloatArray, e: FloatArray, geo: ArcGeometry, samples: int
) -> FloatArray:
    """(n, samples, 3) points along each arc, with S, M and E themselves among them.

    The angle is piecewise linear in the sample number so that sample ``j`` is exactly M;
    degenerate rows (NaN geometry) become the polyline S -> M -> E."""
    n = s.shape[0]
    k = samples
    t = np.linspace(0.0, 1.0, k)
    frac = np.where(np.isfinite(geo.sweep), geo.via_angle / np.where(geo.sweep > 0, geo.sweep, 1.0), 0.5)
    j = np.clip(np.rint(frac * (k - 1)), 1, k - 2).astype(np.intp)
    t_m = (j / (k - 1))[:, None]
    first = t[None, :] <= t_m
    # fraction along each half (0..1)
    h1 = np.where(first, t[None, :] / t_m, 0.0)
    h2 = np.where(first, 0.0, (t[None, :] - t_m) / (1.0 - t_m))
    theta = np.where(first, geo.via_angle[:, None] * h1,
                     geo.via_angle[:, None] + (geo.sweep - geo.via_angle)[:, None] * h2)
    pts = geo.centre[:, None, :] + geo.radius[:, None, None] * (
        np.cos(theta)[:, :, None] * geo.u[:, None, :] + np.sin(theta)[:, :, None] * geo.v[:, None, :]
    )
    bad = ~np.isfinite(geo.radius)
    if bad.any():
        poly = np.where(
            first[:, :, None],
            s[:, None, :] + h1[:, :, None] * (m - s)[:, None, :],
            m[:, None, :] + h2[:, :, None] * (e - m)[:, None, :],
        )
        pts[bad] = poly[bad]
    rows = np.arange(n)
    pts[:, 0] = s
    pts[rows, j] = m
    pts[:, -1] = e
    return np.asarray(pts, dtype=np.float64)


def _sample_lines(s: FloatArray, e: FloatArray, samples: int) -> FloatArray:
    t = np.linspace(0.0, 1.0, samples)
    pts = s[:, None, :] + t[None, :, None] * (e - s)[:, None, :]
    pts[:, -1] = e
    return np.asarray(pts, dtype=np.float64)


def _resolve(seg: Segment, ledger: PointLedger) -> tuple[FloatArray, FloatArray | None]:
    end = ledger.get(seg.end_id)
    if end is None:
        raise InvalidInput(f"point P{seg.end_id} does not exist")
    if not seg.is_arc:
        return xyz_of(end), None
    if seg.via_id is None:
        raise InvalidInput("the arc has no middle point")
    via = ledger.get(seg.via_id)
    if via is None:
        raise InvalidInput(f"point P{seg.via_id} does not exist")
    return xyz_of(end), xyz_of(via)


def segment_path(start_pose: PointLike, segment: Segment, ledger: PointLedger,
                 samples: int = DEFAULT_SAMPLES) -> FloatArray:
    """(samples, 3) XYZ along one segment from ``start_pose``, both ends included.

    Raises :class:`InvalidInput` for a missing point or an arc whose points define no circle
    (:func:`plan_path` draws those as a polyline instead)."""
    if samples < 3:
        raise InvalidInput("at least 3 samples per segment")
    s = xyz_of(start_pose)[None, :]
    end, via = _resolve(segment, ledger)
    if via is None:
        return np.asarray(_sample_lines(s, end[None, :], samples)[0], dtype=np.float64)
    geo = arc_geometry(s, via[None, :], end[None, :])
    if not np.isfinite(geo.radius[0]):
        raise InvalidInput("the arc's three points define no circle (they coincide or are collinear)")
    return np.asarray(_sample_arcs(s, via[None, :], end[None, :], geo, samples)[0], dtype=np.float64)


def segment_length(start_pose: PointLike, segment: Segment, ledger: PointLedger) -> float:
    """Path length (mm) of one segment from ``start_pose``."""
    s = xyz_of(start_pose)
    end, via = _resolve(segment, ledger)
    if via is None:
        return float(np.linalg.norm(end - s))
    geo = arc_geometry(s[None, :], via[None, :], end[None, :])
    if not np.isfinite(geo.radius[0]):
        raise InvalidInput("the arc's three points define no circle (they coincide or are collinear)")
    return float(geo.length[0])


def estimate_time(length: float, speed: float, overhead: float = SEGMENT_OVERHEAD_S) -> float:
    """Seconds for one segment: length / speed plus a fixed per-segment overhead."""
    if not speed > 0:
        raise InvalidInput(f"speed {speed:g} mm/s: must be > 0")
    return length / speed + overhead


def move_timeout(estimate: float) -> float:
    """Timeout for waiting on one move: 3 x its estimate, at least ``timing.MOVE_TIMEOUT_MIN``."""
    if not math.isfinite(estimate):
        return float(timing.MOVE_TIMEOUT_MIN)
    return max(float(timing.MOVE_TIMEOUT_MIN), 3.0 * estimate)


@dataclass(frozen=True)
class PlanGeometry:
    """Per-segment geometry of a plan, vectorised; NaN where unknown (missing point, no start)."""

    starts: FloatArray  # (n, 3)
    vias: FloatArray  # (n, 3), NaN for lines
    ends: FloatArray  # (n, 3)
    is_arc: NDArray[np.bool_]  # (n,)
    arcs: ArcGeometry  # rows for every segment (NaN for lines)
    lengths: FloatArray  # (n,) mm; degenerate arcs count as the polyline S-M-E

    def __len__(self) -> int:
        return int(self.lengths.shape[0])


def plan_geometry(
    plan: Plan | Sequence[Segment], ledger: PointLedger, start: PointLike | None = None
) -> PlanGeometry:
    """Geometry of all segments at once; segment 0 starts at ``start`` (NaN if None)."""
    segments = plan.segments if isinstance(plan, Plan) else list(plan)
    n = len(segments)
    nan3 = np.full(3, np.nan)

    def pos(pid: int | None) -> FloatArray:
        if pid is None:
            return nan3
        p = ledger.get(pid)
        return nan3 if p is None else np.array((p.x, p.y, p.z), dtype=np.float64)

    ends = np.array([pos(seg.end_id) for seg in segments], dtype=np.float64).reshape(n, 3)
    vias = np.array([pos(seg.via_id) for seg in segments], dtype=np.float64).reshape(n, 3)
    is_arc = np.array([seg.is_arc for seg in segments], dtype=bool)
    starts = np.empty((n, 3))
    if n:
        starts[0] = nan3 if start is None else xyz_of(start)
        starts[1:] = ends[:-1]
    with np.errstate(invalid="ignore"):
        arcs = arc_geometry(starts, vias, ends).masked(is_arc)
    line_len = np.linalg.norm(ends - starts, axis=1)
    poly_len = np.linalg.norm(vias - starts, axis=1) + np.linalg.norm(ends - vias, axis=1)
    arc_len = np.where(np.isfinite(arcs.radius), arcs.length, poly_len)
    lengths = np.where(is_arc, arc_len, line_len)
    return PlanGeometry(starts, vias, ends, is_arc, arcs, np.asarray(lengths, dtype=np.float64))


@dataclass(frozen=True)
class PlanPath:
    """Sampled XYZ of a whole plan for drawing: NaN rows where a segment is unknown (draw with
    ``connect="finite"``); ``segment[i]`` is the segment index of row ``i``."""

    xyz: FloatArray  # (n * samples, 3)
    segment: NDArray[np.intp]  # (n * samples,)


def plan_path(plan: Plan | Sequence[Segment], ledger: PointLedger, start: PointLike | None = None,
              samples: int = DEFAULT_SAMPLES) -> PlanPath:
    """Sample every segment (vectorised). Arcs are true circles; an arc whose points define
    no circle is drawn as the polyline through them."""
    if samples < 3:
        raise InvalidInput("at least 3 samples per segment")
    geo = plan_geometry(plan, ledger, start)
    n = len(geo)
    pts = np.full((n, samples, 3), np.nan)
    lines = ~geo.is_arc
    if lines.any():
        pts[lines] = _sample_lines(geo.starts[lines], geo.ends[lines], samples)
    arcs = geo.is_arc
    if arcs.any():
        pts[arcs] = _sample_arcs(
            geo.starts[arcs], geo.vias[arcs], geo.ends[arcs], geo.arcs.rows(arcs), samples
        )
    unknown = ~np.isfinite(pts).all(axis=(1, 2))
    pts[unknown] = np.nan
    return PlanPath(pts.reshape(n * samples, 3), np.repeat(np.arange(n, dtype=np.intp), samples))


@dataclass(frozen=True)
class PlanEstimate:
    """Lengths (mm) and times (s) of a plan.

    ``lengths``/``times`` are the first loop's (segment 0 from the start pose); on later loops
    segment 0 starts at the last segment's end, which ``next_loop_*`` accounts for.
    ``unknown`` lists segments whose length could not be computed (left out of the sums).
    With ``loops == 0`` (endless) the totals are infinite.
    """

    lengths: FloatArray
    times: FloatArray
    loop_length: float
    loop_time: float
    next_loop_length: float
    next_loop_time: float
    wrap_length: float  # segment 0 on loops after the first (NaN if unknown)
    wrap_time: float
    loops: int
    total_length: float
    total_time: float
    unknown: tuple[int, ...]


def estimate_plan(plan: Plan, ledger: PointLedger, start: PointLike | None = None, *,
                  loops: int | None = None, overhead: float = SEGMENT_OVERHEAD_S) -> PlanEstimate:
    loops = plan.loops if loops is None else loops
    geo = plan_geometry(plan, ledger, start)
    speeds = np.array([seg.speed for seg in plan.segments], dtype=np.float64)
    safe = np.where(speeds > 0, speeds, np.nan)
    times = geo.lengths / safe + overhead
    known = np.isfinite(times)
    loop_length = float(np.nansum(np.where(known, geo.lengths, np.nan)))
    loop_time = float(np.nansum(times))
    next_length, next_time = loop_length, loop_time
    wrap_length = wrap_time = math.nan
    if len(geo):
        wrap = plan_geometry(plan.segments[:1], ledger, geo.ends[-1])
        wrap_length = float(wrap.lengths[0])
        wrap_time = wrap_length / float(safe[0]) + overhead
        if math.isfinite(wrap_time):
            next_length = loop_length - (float(geo.lengths[0]) if known[0] else 0.0) + wrap_length
            next_time = loop_time - (float(times[0]) if known[0] else 0.0) + wrap_time
    if loops == 0:
        total_length = total_time = math.inf
    else:
        total_length = loop_length + (loops - 1) * next_length
        total_time = loop_time + (loops - 1) * next_time
    return PlanEstimate(
        lengths=geo.lengths, times=np.asarray(times, dtype=np.float64), loop_length=loop_length,
        loop_time=loop_time, next_loop_length=next_length, next_loop_time=next_time,
        wrap_length=wrap_length, wrap_time=wrap_time, loops=loops,
        total_length=total_length, total_time=total_time,
        unknown=tuple(int(i) for i in np.flatnonzero(~known)),
    )


def segment_timeouts(plan: Plan, ledger: PointLedger, start: PointLike | None = None) -> list[float | None]:
    """Per-segment wait timeouts (s) for the runner (see :func:`move_timeout`); None where the
    length is unknown (the client then uses its own default). Segment 0 gets the longer of its
    first-loop and later-loop estimates."""
    est = estimate_plan(plan, ledger, start)
    out: list[float | None] = [move_timeout(float(t)) if math.isfinite(t) else None for t in est.times]
    if len(plan) and plan.loops != 1 and math.isfinite(est.wrap_time):
        first = float(est.times[0])
        out[0] = move_timeout(max(est.wrap_time, first) if math.isfinite(first) else est.wrap_time)
    return out
