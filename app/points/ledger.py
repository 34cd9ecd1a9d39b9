"""Temp points: the host's ledger of the controller's temp points, and their CSV form.

The controller forgets every temp point when its system logs in again (PROTOCOL.md section 5,
function 2), so the host keeps the master copy here and re-creates points on the controller
when they are needed. Each :class:`TempPoint` records whether the controller is known to hold
it (:class:`SyncState`).

Design for the GUI: :class:`TempPoint` is frozen; :class:`PointLedger` is an ordered list
whose mutation methods validate first, then change, and return what they changed
(a row, the old point, a :class:`PointEdit`), so a ``QAbstractTableModel`` can announce the
change and a ``QUndoStack`` command can revert it with :meth:`PointLedger.insert`,
:meth:`PointLedger.remove`, :meth:`PointLedger.replace` or :meth:`PointLedger.move`.
The ledger is not thread-safe: one thread (the GUI's) owns it; workers get
:meth:`PointLedger.snapshot` tuples.

Sync rules: a new, duplicated or imported-and-different point is ``CHANGED`` (not yet on the
controller); editing ``id``, ``x``..``c`` or ``tool`` marks a point ``CHANGED``; ``name``,
``note`` and ``e1``..``e5`` are host-only (function 2 stores six pose values and a tool frame,
nothing else) and leave the state alone; :meth:`PointLedger.mark_all_unknown` is for a
controller restart or a reconnect.

CSV (documented in docs/PROJECT_FORMAT.md): header row with the columns
``id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note``; UTF-8, with or without a BOM; ``id`` and
``x``..``c`` are required, the others may be left out (defaults: empty name and note, external
axes 0, tool 200 = none). Rows are numbered as a spreadsheet shows them: the header is row 1.
"""

from __future__ import annotations

import csv
import enum
import io
import math
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Protocol

from app.errors import InvalidInput, LinkError, ResponseTimeout, TeachPadError
from app.models import CommandResult, Pose
from app.protocol.enums import QT_TRANSLATE_NOOP
from app.protocol.registers import TEMP_POINT_ID_MAX, TEMP_POINT_ID_MIN, TOOL_NONE

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

TOOL_MAX = 199  # tool frames 0..199 are "tool N+1"; TOOL_NONE (200) is "no tool frame"
NAME_MAX_CHARS = 200
NOTE_MAX_CHARS = 2000
ZERO_EXT: Ext5 = (0.0, 0.0, 0.0, 0.0, 0.0)


class FileFormatError(InvalidInput):
    """A points / project file the host refuses; names the row (or line) and the field.

    ``str(error)`` reads e.g. ``points.csv: row 7, column 'x': 'abc' is not a number``.
    """

    def __init__(
        self,
        reason: str,
        *,
        path: str | None = None,
        row: int | None = None,
        column: str | None = None,
        where: str | None = None,
    ) -> None:
        self.reason = reason
        self.path = path
        self.row = row
        self.column = column
        self.where = where
        super().__init__(self._text())

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
        return FileFormatError(self.reason, path=path, row=self.row, column=self.column, where=self.where)


class FieldError(InvalidInput):
    """One field's value refused; ``field`` names it, ``reason`` says why."""

    def __init__(self, field_name: str, reason: str) -> None:
        super().__init__(f"{field_name}: {reason}")
        self.field = field_name
        self.reason = reason


class SyncState(enum.Enum):
    """Whether the controller holds the host's copy of a point."""

    UNKNOWN = "unknown"  # e.g. after a reconnect: the controller may have restarted
    ON_CONTROLLER = "on-controller"  # created on the controller with exactly these values
    CHANGED = "changed"  # changed on the host (or new) since the last upload
    FAILED = "failed"  # the last upload failed; TempPoint.sync_error says why

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
}


@dataclass(frozen=True)
class PointLimits:
    """Accepted temp point ids (a setting; PROTOCOL.md section 7)."""

    id_min: int = TEMP_POINT_ID_MIN
    id_max: int = TEMP_POINT_ID_MAX

    def __post_init__(self) -> None:
        if self.id_min < 0 or self.id_max < self.id_min:
            raise InvalidInput(f"bad point id range {self.id_min}..{self.id_max}")


DEFAULT_LIMITS = PointLimits()


# --- field parsing (shared by the GUI editors, CSV and JSON) ------------------------------


def parse_float(field_name: str, value: object) -> float:
    """A finite float from a number or text; NaN and infinities are refused."""
    if isinstance(value, bool):
        raise FieldError(field_name, f"{value!r} is not a number")
    if isinstance(value, int | float):
        number = float(value)
    elif isinstance(value, str):
        text = value.strip()
        if not text:
            raise FieldError(field_name, "the value is empty")
        try:
            number = float(text)
        except ValueError:
            raise FieldError(field_name, f"{text!r} is not a number") from None
    else:
        raise FieldError(field_name, f"{value!r} is not a number")
    if not math.isfinite(number):
        raise FieldError(field_name, f"{value!r} is not a finite number")
    return number


def parse_int(field_name: str, value: object) -> int:
    """An integer from an int, an integral float or text (``"5"``, ``"5.0"``)."""
    if isinstance(value, bool):
        raise FieldError(field_name, f"{value!r} is not an integer")
    if isinstance(value, int):
        return value
    number = parse_float(field_name, value)
    if not number.is_integer():
        shown = value.strip() if isinstance(value, str) else value
        raise FieldError(field_name, f"{shown!r} is not an integer")
    return int(number)


def parse_point_id(value: object, limits: PointLimits = DEFAULT_LIMITS, field_name: str = "id") -> int:
    point_id = parse_int(field_name, value)
    if not limits.id_min <= point_id <= limits.id_max:
        raise FieldError(field_name, f"id {point_id} is outside {limits.id_min}..{limits.id_max}")
    return point_id


def parse_tool(value: object, field_name: str = "tool") -> int:
    """Tool frame: 0..199 (tool N+1) or 200 (none)."""
    tool = parse_int(field_name, value)
    if not (0 <= tool <= TOOL_MAX or tool == TOOL_NONE):
        raise FieldError(field_name, f"tool {tool} is not 0..{TOOL_MAX} or {TOOL_NONE} (none)")
    return tool


def parse_text(field_name: str, value: object, max_chars: int) -> str:
    if value is None:
        return ""
    if not isinstance(value, str):
        raise FieldError(field_name, f"{value!r} is not text")
    if len(value) > max_chars:
        raise FieldError(field_name, f"is longer than {max_chars} characters")
    if any(ch in value for ch in "\x00\r\n") and field_name == "name":
        raise FieldError(field_name, "must be one line")
    return value


def tool_text(tool: int) -> str:
    """How the GUI and CLI show a tool frame."""
    return "none" if tool == TOOL_NONE else f"tool {tool + 1} ({tool})"


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
        """True when the controller would hold the same data for both (id, pose, tool)."""
        return self.id == other.id and self.xyzabc == other.xyzabc and self.tool == other.tool


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
        x=x, y=y, z=z, a=a, b=b, c=c,
        ext=(e1, e2, e3, e4, e5),
        tool=parse_tool(tool),
        note=parse_text("note", note, NOTE_MAX_CHARS),
        sync=sync,
        sync_error=sync_error if sync is SyncState.FAILED else "",
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
            raise FieldError(required, "the value is missing")
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


# --- the ledger ------------------------------------------------------------------------------


@dataclass(frozen=True)
class PointEdit:
    """One row replaced: enough for ``dataChanged`` and for undo (``replace(row, old)``)."""

    row: int
    old: TempPoint
    new: TempPoint

    @property
    def changed_fields(self) -> tuple[str, ...]:
        """Fields of :data:`POINT_FIELDS` (plus ``sync``) whose value changed."""
        names = [f for f in POINT_FIELDS if self.old.get(f) != self.new.get(f)]
        if (self.old.sync, self.old.sync_error) != (self.new.sync, self.new.sync_error):
            names.append("sync")
        return tuple(names)


class ImportMode(enum.Enum):
    REPLACE = "replace"  # the ledger becomes the imported list
    MERGE = "merge"  # imported ids replace the same ids in place; new ids are appended


@dataclass(frozen=True)
class ImportReport:
    added: int
    updated: int
    unchanged: int
    removed: int

    @property
    def text(self) -> str:
        return (
            f"{self.added} added, {self.updated} updated, {self.unchanged} unchanged, {self.removed} removed"
        )


class PointLedger:
    """The host's ordered list of temp points, unique ids, validated on every change.

    Rows are 0-based positions in the list. Every mutation bumps :attr:`revision` (for dirty
    tracking and autosave) and returns what changed.
    """

    def __init__(self, points: Iterable[TempPoint] = (), limits: PointLimits = DEFAULT_LIMITS) -> None:
        self._limits = limits
        self._points: list[TempPoint] = []
        self._index: dict[int, int] | None = None
        self.revision = 0
        self.replace_all(points)
        self.revision = 0

    # --- reading
    @property
    def limits(self) -> PointLimits:
        return self._limits

    def set_limits(self, limits: PointLimits) -> None:
        """Change the accepted id range (a setting); refused while a point lies outside it."""
        outside = [p.id for p in self._points if not limits.id_min <= p.id <= limits.id_max]
        if outside:
            shown = ", ".join(map(str, outside[:10])) + (" ..." if len(outside) > 10 else "")
            raise InvalidInput(f"points outside {limits.id_min}..{limits.id_max}: {shown}")
        self._limits = limits

    def __len__(self) -> int:
        return len(self._points)

    def __iter__(self) -> Iterator[TempPoint]:
        return iter(tuple(self._points))

    def __getitem__(self, row: int) -> TempPoint:
        return self._points[row]

    def __contains__(self, point_id: object) -> bool:
        return isinstance(point_id, int) and point_id in self._ids()

    def __repr__(self) -> str:
        return f"PointLedger({len(self._points)} points, revision {self.revision})"

    def snapshot(self) -> tuple[TempPoint, ...]:
        """An immutable copy to hand to another thread or keep for undo."""
        return tuple(self._points)

    def ids(self) -> list[int]:
        return [p.id for p in self._points]

    def row_of(self, point_id: int) -> int | None:
        return self._ids().get(point_id)

    def get(self, point_id: int) -> TempPoint | None:
        row = self.row_of(point_id)
        return None if row is None else self._points[row]

    def point(self, point_id: int) -> TempPoint:
        """The point with ``point_id``; :class:`InvalidInput` if there is none."""
        found = self.get(point_id)
        if found is None:
            raise InvalidInput(f"there is no point with id {point_id}")
        return found

    def next_free_id(self, after: int | None = None) -> int:
        """The smallest unused id in range (greater than ``after`` when given)."""
        used = self._ids()
        start = self._limits.id_min if after is None else max(self._limits.id_min, after + 1)
        for candidate in range(start, self._limits.id_max + 1):
            if candidate not in used:
                return candidate
        raise InvalidInput(f"no free point id left in {start}..{self._limits.id_max}")

    def find(self, text: str) -> list[int]:
        """Rows matching ``text``: the point with that id first, then names containing it
        (case-insensitive). Empty text matches nothing."""
        needle = text.strip()
        if not needle:
            return []
        rows: list[int] = []
        try:
            row = self.row_of(int(needle))
        except ValueError:
            row = None
        if row is not None:
            rows.append(row)
        folded = needle.casefold()
        rows.extend(
            r for r, p in enumerate(self._points) if folded in p.name.casefold() and r not in rows
        )
        return rows

    def needing_upload(self) -> list[TempPoint]:
        return [p for p in self._points if p.needs_upload]

    # --- structural changes
    def insert(self, row: int, point: TempPoint) -> int:
        """Insert a point at ``row`` (clamped to 0..len); returns the row it landed on."""
        self._check_point(point, ignore_row=None)
        row = max(0, min(row, len(self._points)))
        self._points.insert(row, point)
        self._touch()
        return row

    def append(self, point: TempPoint) -> int:
        return self.insert(len(self._points), point)

    def add(
        self,
        name: str = "",
        pose: Sequence[float] = (0.0,) * 6,
        ext: Sequence[float] = ZERO_EXT,
        tool: int = TOOL_NONE,
        note: str = "",
        *,
        point_id: int | None = None,
        row: int | None = None,
    ) -> int:
        """A new point (next free id unless given) appended or inserted at ``row``."""
        new_id = self.next_free_id() if point_id is None else point_id
        point = make_point(new_id, name, pose, ext, tool, note, limits=self._limits)
        return self.insert(len(self._points) if row is None else row, point)

    def duplicate(self, row: int, new_id: int | None = None) -> int:
        """Copy the point at ``row`` right after it, under the next free id after its own."""
        source = self._points[row]
        point_id = self.next_free_id(after=source.id) if new_id is None else new_id
        copy = replace(source, id=point_id, sync=SyncState.CHANGED, sync_error="")
        return self.insert(row + 1, copy)

    def remove(self, row: int) -> TempPoint:
        """Remove the point at ``row``; returns it (undo: ``insert(row, point)``)."""
        point = self._points.pop(row)
        self._touch()
        return point

    def remove_rows(self, rows: Iterable[int]) -> list[tuple[int, TempPoint]]:
        """Remove several rows; returns ``(row, point)`` in ascending row order (undo: insert
        them in that order)."""
        unique = sorted(set(rows))
        for row in unique:
            if not 0 <= row < len(self._points):
                raise InvalidInput(f"no row {row}")
        removed = [(row, self._points[row]) for row in unique]
        for row in reversed(unique):
            del self._points[row]
        if removed:
            self._touch()
        return removed

    def move(self, src: int, dst: int) -> None:
        """Move the point at ``src`` so that it ends at index ``dst`` (undo: ``move(dst, src)``)."""
        if not (0 <= src < len(self._points) and 0 <= dst < len(self._points)):
            raise InvalidInput(f"cannot move row {src} to {dst} in {len(self._points)} rows")
        if src == dst:
            return
        self._points.insert(dst, self._points.pop(src))
        self._touch()

    def replace_all(self, points: Iterable[TempPoint]) -> None:
        """Swap the whole list after checking all of it (a bad list leaves the ledger as it was)."""
        new = list(points)
        seen: dict[int, int] = {}
        for row, point in enumerate(new):
            self._check_fields(point)
            if point.id in seen:
                raise InvalidInput(f"row {row}: id {point.id} is already used on row {seen[point.id]}")
            seen[point.id] = row
        self._points = new
        self._touch()

    def import_points(
        self, points: Sequence[TempPoint], mode: ImportMode = ImportMode.REPLACE
    ) -> ImportReport:
        """Import a parsed list. A point identical on the controller side to the one it
        replaces keeps that one's sync state; others become ``CHANGED``."""
        old = {p.id: p for p in self._points}
        seen: set[int] = set()
        for number, point in enumerate(points, start=1):
            if point.id in seen:
                raise InvalidInput(f"imported point {number}: id {point.id} appears twice")
            seen.add(point.id)
        incoming: list[TempPoint] = []
        added = updated = unchanged = 0
        for point in points:
            previous = old.get(point.id)
            if previous is None:
                added += 1
                incoming.append(replace(point, sync=SyncState.CHANGED, sync_error=""))
            elif previous.same_on_controller(point):
                if previous.name == point.name and previous.note == point.note and previous.ext == point.ext:
                    unchanged += 1
                else:
                    updated += 1
                incoming.append(replace(point, sync=previous.sync, sync_error=previous.sync_error))
            else:
                updated += 1
                incoming.append(replace(point, sync=SyncState.CHANGED, sync_error=""))
        if mode is ImportMode.REPLACE:
            incoming_ids = {p.id for p in incoming}
            removed = sum(1 for pid in old if pid not in incoming_ids)
            self.replace_all(incoming)
        else:
            removed = 0
            by_id = {p.id: p for p in incoming}
            merged = [by_id.pop(p.id, p) for p in self._points]
            merged.extend(p for p in incoming if p.id in by_id)
            self.replace_all(merged)
        return ImportReport(added=added, updated=updated, unchanged=unchanged, removed=removed)

    # --- edits of one row
    def replace(self, row: int, point: TempPoint) -> TempPoint:
        """Put ``point`` at ``row`` as it is (sync state included); returns the old point."""
        self._check_point(point, ignore_row=row)
        old = self._points[row]
        self._points[row] = point
        self._touch()
        return old

    def set_field(self, row: int, field_name: str, value: object) -> PointEdit:
        """Edit one field (text from an editor or a typed value), validated."""
        old = self._points[row]
        new = with_field(old, field_name, value, self._limits)
        if new != old:
            self.replace(row, new)
        return PointEdit(row, old, new)

    def set_pose(self, row: int, pose: Sequence[float], ext: Sequence[float] | None = None) -> PointEdit:
        """Set x..c (and e1..e5) at once, e.g. "touch up to the current pose"."""
        old = self._points[row]
        checked = make_point(
            old.id, old.name, pose, old.ext if ext is None else ext, old.tool, old.note,
            sync=old.sync, sync_error=old.sync_error, limits=self._limits,
        )
        new = _mark_changed(old, checked)
        if new != old:
            self.replace(row, new)
        return PointEdit(row, old, new)

    def set_sync(self, point_id: int, state: SyncState, reason: str = "") -> int:
        """Record the controller's side of a point; returns its row."""
        row = self.row_of(point_id)
        if row is None:
            raise InvalidInput(f"there is no point with id {point_id}")
        old = self._points[row]
        new = replace(old, sync=state, sync_error=reason if state is SyncState.FAILED else "")
        if new != old:
            self._points[row] = new
            self._touch(structural=False)
        return row

    def mark_all_unknown(self) -> list[int]:
        """After a controller restart or reconnect: nothing is known to be on the controller.
        ``CHANGED`` points stay ``CHANGED``. Returns the rows that changed."""
        known = (SyncState.ON_CONTROLLER, SyncState.FAILED)
        rows = [r for r, p in enumerate(self._points) if p.sync in known]
        for r in rows:
            self._points[r] = replace(self._points[r], sync=SyncState.UNKNOWN, sync_error="")
        if rows:
            self._touch(structural=False)
        return rows

    # --- internals
    def _ids(self) -> dict[int, int]:
        if self._index is None:
            self._index = {p.id: r for r, p in enumerate(self._points)}
        return self._index

    def _touch(self, structural: bool = True) -> None:
        if structural:
            self._index = None
        self.revision += 1

    def _check_fields(self, point: TempPoint) -> None:
        # Re-validate: a TempPoint may have been built directly.
        make_point(point.id, point.name, point.xyzabc, point.ext, point.tool, point.note, limits=self._limits)

    def _check_point(self, point: TempPoint, ignore_row: int | None) -> None:
        self._check_fields(point)
        row = self.row_of(point.id)
        if row is not None and row != ignore_row:
            raise FieldError("id", f"id {point.id} is already used by {self._points[row].label}")


# --- CSV ---------------------------------------------------------------------------------------


def _format_float(value: float) -> str:
    return repr(float(value))


def points_to_csv(points: Iterable[TempPoint]) -> str:
    """The CSV text (no BOM) of ``points``, header first."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\r\n")
    writer.writerow(CSV_COLUMNS)
    for p in points:
        writer.writerow(
            [str(p.id), p.name, *(_format_float(v) for v in p.xyzabc),
             *(_format_float(v) for v in p.ext), str(p.tool), p.note]
        )
    return out.getvalue()


def decode_text(data: bytes, path: str | None = None) -> str:
    """UTF-8 text, a leading BOM dropped; refuses other encodings with a hint."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise FileFormatError(
            f"not UTF-8 text (bad byte at offset {exc.start}); save the file as UTF-8", path=path
        ) from None


def parse_points_csv(
    text: str, limits: PointLimits = DEFAULT_LIMITS, *, path: str | None = None
) -> list[TempPoint]:
    """Parse CSV text fully; raises :class:`FileFormatError` naming the row and column."""
    if text.startswith("\ufeff"):
        text = text[1:]
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    rows: list[list[str]] = []
    try:
        rows.extend(reader)
    except csv.Error as exc:
        raise FileFormatError(f"not valid CSV ({exc})", path=path, row=len(rows) + 1) from None
    header_at = next((i for i, r in enumerate(rows) if any(cell.strip() for cell in r)), None)
    if header_at is None:
        raise FileFormatError("the file is empty (expected a header row)", path=path, row=1)
    header = [cell.strip().lower() for cell in rows[header_at]]
    header_row = header_at + 1
    for col, name in enumerate(header):
        if name not in CSV_COLUMNS:
            raise FileFormatError(
                f"unknown column {rows[header_at][col]!r} (expected: {','.join(CSV_COLUMNS)})",
                path=path, row=header_row,
            )
        if header.index(name) != col:
            raise FileFormatError("the column appears twice", path=path, row=header_row, column=name)
    for name in CSV_COLUMNS:
        if name in CSV_REQUIRED and name not in header:
            raise FileFormatError(
                "the column is missing from the header", path=path, row=header_row, column=name
            )
    points: list[TempPoint] = []
    seen: dict[int, int] = {}
    for number, cells in enumerate(rows[header_at + 1:], start=header_row + 1):
        if not any(cell.strip() for cell in cells):
            continue  # blank line
        if len(cells) != len(header):
            raise FileFormatError(
                f"has {len(cells)} cells, the header has {len(header)} (truncated or extra cells?)",
                path=path, row=number,
            )
        fields = dict(zip(header, cells, strict=True))
        try:
            point = point_from_fields(fields, limits)
        except FieldError as exc:
            raise FileFormatError(exc.reason, path=path, row=number, column=exc.field) from None
        if point.id in seen:
            raise FileFormatError(
                f"id {point.id} is already used on row {seen[point.id]}", path=path, row=number, column="id"
            )
        seen[point.id] = number
        points.append(point)
    return points


# --- upload (function 2) ------------------------------------------------------------------------


class PointUploader(Protocol):
    """The part of ``RobotClient`` an upload needs (duck-typed)."""

    def create_point(
        self, point_id: int, *, pose: Sequence[float] | None = ..., tool: int = ..., wait: bool = ...
    ) -> CommandResult: ...


@dataclass(frozen=True)
class UploadOutcome:
    point_id: int
    ok: bool
    reason: str = ""
    sent: TempPoint | None = None  # the values the controller now holds (ok only)
    unconfirmed: bool = False  # ok, but the controller's status never changed (CommandResult.unconfirmed)


@dataclass
class UploadReport:
    outcomes: list[UploadOutcome] = field(default_factory=list)
    aborted: str | None = None  # why the upload stopped early (link lost, stop requested)
    not_attempted: list[int] = field(default_factory=list)
    interrupted: bool = False  # ended by Ctrl-C

    @property
    def ok_count(self) -> int:
        return sum(1 for o in self.outcomes if o.ok)

    @property
    def failed(self) -> list[UploadOutcome]:
        return [o for o in self.outcomes if not o.ok]

    @property
    def all_ok(self) -> bool:
        return self.aborted is None and not self.failed


def upload_points(
    client: PointUploader,
    points: Sequence[TempPoint],
    *,
    progress: Callable[[int, int], bool | None] | None = None,
) -> UploadReport:
    """Create ``points`` on the controller one by one (function 2 from GVs).

    A point the controller refuses is recorded and the upload goes on; a lost link, Ctrl-C
    or ``progress`` returning False ends it, leaving the rest (the interrupted point included)
    in ``not_attempted``. Does not touch a ledger: apply the report with :func:`apply_upload`
    in the ledger's thread.
    """
    report = UploadReport()
    total = len(points)
    for done, point in enumerate(points):
        if progress is not None and progress(done, total) is False:
            report.aborted = "stopped on request"
            report.not_attempted = [p.id for p in points[done:]]
            return report
        try:
            result = client.create_point(point.id, pose=point.xyzabc, tool=point.tool, wait=True)
        except (LinkError, ResponseTimeout) as exc:
            report.aborted = str(exc) or type(exc).__name__
            report.not_attempted = [p.id for p in points[done:]]
            return report
        except KeyboardInterrupt:
            # Keep what was done: the caller records it and the ledger stays truthful.
            report.aborted = "interrupted"
            report.interrupted = True
            report.not_attempted = [p.id for p in points[done:]]
            return report
        except TeachPadError as exc:
            report.outcomes.append(UploadOutcome(point.id, False, str(exc) or type(exc).__name__))
            continue
        if result.ok:
            report.outcomes.append(UploadOutcome(point.id, True, sent=point, unconfirmed=result.unconfirmed))
        else:
            reason = result.message or (result.status.text if result.status else "failed")
            report.outcomes.append(UploadOutcome(point.id, False, reason))
    if progress is not None:
        progress(total, total)
    return report


def apply_upload(ledger: PointLedger, report: UploadReport) -> list[int]:
    """Record an upload's outcome in the ledger; returns the rows that changed.

    A point edited on the host while it was being uploaded stays ``CHANGED``."""
    rows: list[int] = []
    for outcome in report.outcomes:
        current = ledger.get(outcome.point_id)
        if current is None:
            continue
        if outcome.ok:
            if outcome.sent is not None and not current.same_on_controller(outcome.sent):
                continue
            rows.append(ledger.set_sync(outcome.point_id, SyncState.ON_CONTROLLER))
        else:
            rows.append(ledger.set_sync(outcome.point_id, SyncState.FAILED, outcome.reason))
    return rows


def parse_id_list(text: str) -> list[int]:
    """``"1,2,5-9"`` -> ``[1, 2, 5, 6, 7, 8, 9]`` (order kept, duplicates dropped)."""
    ids: list[int] = []
    seen: set[int] = set()
    for part in text.split(","):
        item = part.strip()
        if not item:
            continue
        lo_text, sep, hi_text = item.partition("-")
        try:
            if sep:
                lo, hi = int(lo_text), int(hi_text)
                if hi < lo:
                    raise InvalidInput(f"bad id range {item!r}: {hi} < {lo}")
                chunk = list(range(lo, hi + 1))
            else:
                chunk = [int(item)]
        except ValueError:
            raise InvalidInput(f"bad id list item {item!r} (use e.g. 1,2,5-9)") from None
        for i in chunk:
            if i not in seen:
                seen.add(i)
                ids.append(i)
    return ids
