"""Trajectories on the host: plans of LINE / ARC segments, the model.

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

The checks are in :mod:`app.plan.checks`, the arc geometry and sampling in
:mod:`app.plan.geometry`, the time estimates in :mod:`app.plan.estimates`.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field, replace

from app.errors import InvalidInput
from app.points.fields import FieldError, parse_float, parse_int, parse_tool, shown
from app.protocol.enums import QT_TRANSLATE_NOOP
from app.protocol.registers import TOOL_NONE

TR_CONTEXT = "Plan"

DEFAULT_SPEED = 50.0  # mm/s
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
    raise FieldError(
        field_name, f"{value!r} is not yes/no", code="not_yes_no", params={"value": shown(value)}
    )


def parse_kind(value: object) -> SegmentKind:
    if isinstance(value, SegmentKind):
        return value
    if isinstance(value, str):
        key = value.strip().lower()
        for kind in SegmentKind:
            if kind.value == key:
                return kind
    raise FieldError(
        "kind", f"{value!r} is not 'line' or 'arc'", code="not_segment_kind", params={"value": shown(value)}
    )


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
    raise FieldError(
        "orientation",
        f"{value!r} is not '{ORIENTATION_CHANGES}' or '{ORIENTATION_KEPT}'",
        code="not_orientation",
        params={"value": shown(value)},
    )


def _parse_ref(field_name: str, value: object) -> int:
    point_id = parse_int(field_name, value)
    if point_id < 0:
        raise FieldError(
            field_name, f"point id {point_id} is negative", code="negative_point_id", params={"id": point_id}
        )
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
            "kind": self.kind,
            "via": self.via_id,
            "end": self.end_id,
            "speed": self.speed,
            "orientation": self.orientation,
            "ignore_middle": self.ignore_middle,
            "tool": self.tool,
        }
        if field_name not in values:
            raise FieldError(field_name, "no such field", code="no_such_field", params={"name": field_name})
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
        raise FieldError(field_name, "no such field", code="no_such_field", params={"name": field_name})

    @property
    def text(self) -> str:
        """E.g. ``arc via P2 to P3, 100 mm/s``."""
        path = f"arc via P{self.via_id} to P{self.end_id}" if self.is_arc else f"line to P{self.end_id}"
        return f"{path}, {self.speed:g} mm/s"


def validate_plan_name(name: object) -> str:
    if not isinstance(name, str) or not name.strip():
        raise FieldError("name", "a plan needs a name", code="plan_name_empty")
    text = name.strip()
    if len(text) > PLAN_NAME_MAX_CHARS or any(ch in text for ch in "\r\n\x00"):
        raise FieldError(
            "name",
            f"must be one line of at most {PLAN_NAME_MAX_CHARS} characters",
            code="plan_name_format",
            params={"max": PLAN_NAME_MAX_CHARS},
        )
    return text


def validate_loops(value: object) -> int:
    loops = parse_int("loops", value)
    if not 0 <= loops <= MAX_LOOPS:
        raise FieldError(
            "loops",
            f"{loops} is not 0 (endless) .. {MAX_LOOPS}",
            code="bad_loops",
            params={"value": loops, "max": MAX_LOOPS},
        )
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
            raise InvalidInput(
                f"cannot move segment {src} to {dst} in {n} segments",
                code="cannot_move_segment",
                params={"src": src, "dst": dst, "segments": n},
            )
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
