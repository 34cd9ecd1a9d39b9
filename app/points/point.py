"""A temp point as the host keeps it: fields, validation and sync states.

The controller forgets every temp point when its system logs in again (PROTOCOL.md section 5,
function 2), and another tool may overwrite one at any time, so the host keeps the master
copy (:mod:`app.points.ledger`) and re-creates points on the controller when they are needed.
Each :class:`TempPoint` records whether the controller is known to hold it (:class:`SyncState`).

Sync rules: a new, duplicated or imported-and-different point is ``CHANGED`` (not yet on the
controller); editing ``id``, ``x``..``c`` or ``tool`` marks a point ``CHANGED``; ``name``,
``note`` and ``e1``..``e5`` are host-only (function 2 stores six pose values and a tool frame,
nothing else) and leave the state alone. A loaded file never says ``ON_CONTROLLER``: a file
cannot know what a controller holds.

Values from files and editors go through the ``parse_*`` functions of
:mod:`app.points.fields`, which refuse with a :class:`FieldError` naming the
field and quote at most :data:`QUOTE_CHARS` characters of a bad value (:func:`shown`).
"""

from __future__ import annotations

import enum
import math
import os
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

from app.errors import InvalidInput, Reason
from app.models import Pose
from app.points.fields import (
    DEFAULT_LIMITS,
    NAME_MAX_CHARS,
    NOTE_MAX_CHARS,
    TOOL_MAX,
    FieldError,
    PointLimits,
    has_surrogates,
    parse_float,
    parse_point_id,
    parse_text,
    parse_tool,
)
from app.points.provenance import UNKNOWN_PROVENANCE, Provenance
from app.protocol.enums import QT_TRANSLATE_NOOP
from app.protocol.registers import TOOL_NONE

_POSE32 = struct.Struct("<6f")

__all__ = [
    "CONTROLLER_FIELDS",
    "CSV_COLUMNS",
    "CSV_REQUIRED",
    "EXT_FIELDS",
    "POINT_FIELDS",
    "POSE_FIELDS",
    "SYNC_STATE_TEXT",
    "ZERO_EXT",
    "FileFormatError",
    "SyncState",
    "TempPoint",
    "fast_point_from_fields",
    "is_valid_point",
    "make_point",
    "point_from_fields",
    "point_from_pose",
    "with_field",
    "with_provenance",
]

TR_CONTEXT = "Points"

Pose6 = tuple[float, float, float, float, float, float]
Ext5 = tuple[float, float, float, float, float]

POSE_FIELDS: tuple[str, ...] = ("x", "y", "z", "a", "b", "c")
EXT_FIELDS: tuple[str, ...] = ("e1", "e2", "e3", "e4", "e5")
#: The editable fields of a point, in table / CSV column order.
POINT_FIELDS: tuple[str, ...] = ("id", "name", *POSE_FIELDS, *EXT_FIELDS, "tool", "note")
CSV_COLUMNS = POINT_FIELDS
CSV_REQUIRED: frozenset[str] = frozenset(("id", *POSE_FIELDS))
#: Fields the controller stores: editing one of them makes the point "changed on host".
CONTROLLER_FIELDS: frozenset[str] = frozenset(("id", *POSE_FIELDS, "tool"))

ZERO_EXT: Ext5 = (0.0, 0.0, 0.0, 0.0, 0.0)


REASON_MAX_CHARS = 300


class FileFormatError(InvalidInput):
    """A points / project file the host refuses; names the row (or line) and the field.

    ``str(error)`` reads e.g. ``points.csv: row 7, column 'x': 'abc' is not a number``.
    ``problem`` is the reason as a code and its arguments (None: only the English ``reason``);
    ``place`` is ``where`` as a code and its arguments (``place_point`` {index, id}, ...); the
    error's own reason (code ``file_format``) adds the file name, row and column.
    """

    code = "file_format"

    def __init__(
        self,
        reason: str,
        *,
        path: str | None = None,
        row: int | None = None,
        column: str | None = None,
        where: str | None = None,
        problem: Reason | None = None,
        place: Reason | None = None,
    ) -> None:
        if len(reason) > REASON_MAX_CHARS:  # a safety net: a message never carries a whole bad value
            reason = reason[:REASON_MAX_CHARS] + "..."
        self.reason = reason
        self.path = path
        self.row = row
        self.column = column
        self.where = where
        self.problem = problem
        self.place = place
        super().__init__(
            self._text(),
            params={
                "file": os.path.basename(path) if path else None,
                "row": row,
                "column": column,
                "where": where,
                "problem": problem,
                "place": place,
            },
        )

    def _text(self) -> str:
        parts: list[str] = []
        if self.where is not None:
            parts.append(self.where)
        elif self.row is not None:
            parts.append(f"row {self.row}")
        if self.column is not None:
            parts.append(f"column '{self.column}'" if self.where is None else f"field '{self.column}'")
        location = ", ".join(parts)
        text = f"{location}: {self.reason}" if location else self.reason
        return f"{self.path}: {text}" if self.path else text

    def with_path(self, path: str) -> FileFormatError:
        return FileFormatError(
            self.reason,
            path=path,
            row=self.row,
            column=self.column,
            where=self.where,
            problem=self.problem,
            place=self.place,
        )


class SyncState(enum.Enum):
    """Whether the controller holds the host's copy of a point."""

    UNKNOWN = "unknown"  # e.g. after a reconnect: the controller may have restarted
    ON_CONTROLLER = "on-controller"  # created on the controller with exactly these values
    CHANGED = "changed"  # changed on the host (or new) since the last upload
    FAILED = "failed"  # the last upload failed; TempPoint.sync_error says why
    #: Sent without an error, but the controller's status never changed (observe rule): most
    #: likely on the controller, not proven. Still needs an upload before a move relies on it.
    UNCONFIRMED = "unconfirmed"

    @property
    def text(self) -> str:
        return SYNC_STATE_TEXT[self]

    @classmethod
    def parse(cls, text: str) -> SyncState:
        for member in cls:
            if member.value == text:
                return member
        raise ValueError(f"unknown sync state {text!r} (expected one of: {', '.join(m.value for m in cls)})")


SYNC_STATE_TEXT: dict[SyncState, str] = {
    SyncState.UNKNOWN: QT_TRANSLATE_NOOP("Points", "unknown"),
    SyncState.ON_CONTROLLER: QT_TRANSLATE_NOOP("Points", "on controller"),
    SyncState.CHANGED: QT_TRANSLATE_NOOP("Points", "changed on host"),
    SyncState.FAILED: QT_TRANSLATE_NOOP("Points", "upload failed"),
    SyncState.UNCONFIRMED: QT_TRANSLATE_NOOP("Points", "on controller, unconfirmed"),
}


# --- the point -------------------------------------------------------------------------------


@dataclass(frozen=True)
class TempPoint:
    """One temp point as the host keeps it. Build through :func:`make_point` to validate."""

    id: int
    name: str = ""
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    a: float = 0.0
    b: float = 0.0
    c: float = 0.0
    ext: Ext5 = ZERO_EXT
    tool: int = TOOL_NONE
    note: str = ""
    sync: SyncState = SyncState.CHANGED
    sync_error: str = ""  # why the last upload failed (FAILED only)
    #: how, when, where the point was made (history: not compared, the controller never holds it)
    made: Provenance = field(default=UNKNOWN_PROVENANCE, compare=False)

    @property
    def xyzabc(self) -> Pose6:
        return (self.x, self.y, self.z, self.a, self.b, self.c)

    @property
    def xyz(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)

    @property
    def needs_upload(self) -> bool:
        return self.sync is not SyncState.ON_CONTROLLER

    @property
    def label(self) -> str:
        """``P5`` or ``P5 'pick'`` for messages."""
        return f"P{self.id} '{self.name}'" if self.name else f"P{self.id}"

    def get(self, field_name: str) -> object:
        """Value of a field of :data:`POINT_FIELDS` (``e1``..``e5`` from ``ext``)."""
        if field_name in EXT_FIELDS:
            return self.ext[EXT_FIELDS.index(field_name)]
        if field_name in POINT_FIELDS:
            value: object = getattr(self, field_name)
            return value
        raise FieldError(field_name, "no such field")

    def same_on_controller(self, other: TempPoint) -> bool:
        """True when the controller would hold the same data for both (id, pose, tool): the pose
        as the float32 values it holds (a CSV's shortest text of a float32 reads back as the
        same float32, not the same float64)."""
        return (
            self.id == other.id
            and _float32s(self.xyzabc) == _float32s(other.xyzabc)
            and self.tool == other.tool
        )


def _float32s(values: Sequence[float]) -> tuple[float, ...] | Sequence[float]:
    """``values`` rounded to float32 as the controller holds them (as they are if one does not fit)."""
    try:
        return _POSE32.unpack(_POSE32.pack(*values))
    except (OverflowError, struct.error):
        return values


def make_point(
    point_id: object,
    name: object = "",
    pose: Sequence[object] = (0.0,) * 6,
    ext: Sequence[object] = ZERO_EXT,
    tool: object = TOOL_NONE,
    note: object = "",
    *,
    sync: SyncState = SyncState.CHANGED,
    sync_error: str = "",
    limits: PointLimits = DEFAULT_LIMITS,
) -> TempPoint:
    """A validated :class:`TempPoint`; raises :class:`FieldError` naming the bad field."""
    if len(pose) != 6:
        raise FieldError("pose", f"needs 6 values (x y z a b c), got {len(pose)}")
    if len(ext) != 5:
        raise FieldError("ext", f"needs 5 values (e1..e5), got {len(ext)}")
    x, y, z, a, b, c = (parse_float(f, v) for f, v in zip(POSE_FIELDS, pose, strict=True))
    e1, e2, e3, e4, e5 = (parse_float(f, v) for f, v in zip(EXT_FIELDS, ext, strict=True))
    return TempPoint(
        id=parse_point_id(point_id, limits),
        name=parse_text("name", name, NAME_MAX_CHARS),
        x=x,
        y=y,
        z=z,
        a=a,
        b=b,
        c=c,
        ext=(e1, e2, e3, e4, e5),
        tool=parse_tool(tool),
        note=parse_text("note", note, NOTE_MAX_CHARS),
        sync=sync,
        sync_error=sync_error if sync is SyncState.FAILED else "",
    )


def fast_point_from_fields(
    fields: Mapping[str, object], limits: PointLimits = DEFAULT_LIMITS, *, sync: SyncState = SyncState.CHANGED
) -> TempPoint | None:
    """The point of :func:`point_from_fields` for well-formed decoded JSON, or None.

    Accepts only what :func:`point_from_fields` accepts and builds the same point: plain
    ``float`` pose / ext values (finite), an ``int`` id in ``limits`` and tool, one-line text
    within its length. Anything else (ints as coordinates, text numbers, blanks, bad values)
    returns None and the caller takes :func:`point_from_fields`, which says what is wrong.
    """
    get = fields.get
    pid = get("id")
    x, y, z, a, b, c = get("x"), get("y"), get("z"), get("a"), get("b"), get("c")
    e1, e2, e3, e4, e5 = get("e1", 0.0), get("e2", 0.0), get("e3", 0.0), get("e4", 0.0), get("e5", 0.0)
    tool = get("tool", TOOL_NONE)
    name = get("name", "")
    note = get("note", "")
    if (
        type(pid) is not int
        or type(tool) is not int
        or type(name) is not str
        or type(note) is not str
        or type(x) is not float
        or type(y) is not float
        or type(z) is not float
        or type(a) is not float
        or type(b) is not float
        or type(c) is not float
        or type(e1) is not float
        or type(e2) is not float
        or type(e3) is not float
        or type(e4) is not float
        or type(e5) is not float
    ):
        return None
    # one sum checks all eleven: NaN / inf propagate; an overflowing sum only sends a valid
    # point down the slow path
    if not math.isfinite(x + y + z + a + b + c + e1 + e2 + e3 + e4 + e5):
        return None
    if not limits.id_min <= pid <= limits.id_max or not (0 <= tool <= TOOL_MAX or tool == TOOL_NONE):
        return None
    if len(name) > NAME_MAX_CHARS or len(note) > NOTE_MAX_CHARS:
        return None
    if "\n" in name or "\r" in name or "\x00" in name:
        return None
    if (not name.isascii() and has_surrogates(name)) or (not note.isascii() and has_surrogates(note)):
        return None
    # The frozen dataclass's __init__ sets 13 fields one by one through object.__setattr__
    # (a third of a load's time); filling __dict__ at once builds the same, equal object.
    point: TempPoint = _new(TempPoint)
    _set(
        point,
        "__dict__",
        {
            "id": pid,
            "name": name,
            "x": x,
            "y": y,
            "z": z,
            "a": a,
            "b": b,
            "c": c,
            "ext": (e1, e2, e3, e4, e5),
            "tool": tool,
            "note": note,
            "sync": sync,
            "sync_error": "",
            "made": UNKNOWN_PROVENANCE,
        },
    )
    return point


_new = object.__new__
_set = object.__setattr__


def with_provenance(point: TempPoint, made: Provenance) -> TempPoint:
    """``point`` with its provenance set (copied the way :func:`fast_point_from_fields` builds a
    point: a project load sets it on every point)."""
    copy: TempPoint = _new(TempPoint)
    _set(copy, "__dict__", {**point.__dict__, "made": made})
    return copy


def is_valid_point(point: TempPoint, limits: PointLimits = DEFAULT_LIMITS) -> bool:
    """True when ``point`` holds values :func:`make_point` would accept (a quick check; False
    means: run :func:`make_point` for the message)."""
    return (
        fast_point_from_fields(
            {
                "id": point.id,
                "name": point.name,
                "x": point.x,
                "y": point.y,
                "z": point.z,
                "a": point.a,
                "b": point.b,
                "c": point.c,
                "e1": point.ext[0],
                "e2": point.ext[1],
                "e3": point.ext[2],
                "e4": point.ext[3],
                "e5": point.ext[4],
                "tool": point.tool,
                "note": point.note,
            },
            limits,
        )
        is not None
        if len(point.ext) == 5
        else False
    )


def point_from_pose(
    point_id: int, pose: Pose, name: str = "", *, tool: int = TOOL_NONE, limits: PointLimits = DEFAULT_LIMITS
) -> TempPoint:
    """A new point at a live pose (e.g. "teach here")."""
    return make_point(point_id, name, pose.xyzabc, pose.ext, tool, limits=limits)


def point_from_fields(
    fields: Mapping[str, object], limits: PointLimits = DEFAULT_LIMITS, *, sync: SyncState = SyncState.CHANGED
) -> TempPoint:
    """A point from a column -> value mapping (CSV row or JSON object); missing optional
    fields take their defaults, empty optional text cells too."""

    def optional(name: str, default: object) -> object:
        value = fields.get(name, default)
        blank = isinstance(value, str) and not value.strip()
        return default if blank and name not in ("name", "note") else value

    for required in CSV_REQUIRED:
        if required not in fields:
            raise FieldError(required, "the value is missing", code="value_missing")
    return make_point(
        fields["id"],
        optional("name", ""),
        [fields[f] for f in POSE_FIELDS],
        [optional(f, 0.0) for f in EXT_FIELDS],
        optional("tool", TOOL_NONE),
        optional("note", ""),
        sync=sync,
        limits=limits,
    )


def with_field(
    point: TempPoint, field_name: str, value: object, limits: PointLimits = DEFAULT_LIMITS
) -> TempPoint:
    """``point`` with one field set (validated); applies the sync rules of the module doc."""
    new: TempPoint
    if field_name == "id":
        new = replace(point, id=parse_point_id(value, limits))
    elif field_name == "name":
        new = replace(point, name=parse_text("name", value, NAME_MAX_CHARS))
    elif field_name == "note":
        new = replace(point, note=parse_text("note", value, NOTE_MAX_CHARS))
    elif field_name in POSE_FIELDS:
        pose = list(point.xyzabc)
        pose[POSE_FIELDS.index(field_name)] = parse_float(field_name, value)
        x, y, z, a, b, c = pose
        new = replace(point, x=x, y=y, z=z, a=a, b=b, c=c)
    elif field_name in EXT_FIELDS:
        ext = list(point.ext)
        ext[EXT_FIELDS.index(field_name)] = parse_float(field_name, value)
        new = replace(point, ext=(ext[0], ext[1], ext[2], ext[3], ext[4]))
    elif field_name == "tool":
        new = replace(point, tool=parse_tool(value))
    else:
        raise FieldError(field_name, "no such field (or not editable)")
    return _mark_changed(point, new)


def _mark_changed(old: TempPoint, new: TempPoint) -> TempPoint:
    if new.sync is not SyncState.CHANGED and not old.same_on_controller(new):
        return replace(new, sync=SyncState.CHANGED, sync_error="")
    return new
