"""The host's ledger of the controller's temp points.

Design for the GUI: :class:`~app.points.point.TempPoint` is frozen; :class:`PointLedger` is an
ordered list whose mutation methods validate first, then change, and return what they changed
(a row, the old point, a :class:`PointEdit`), so a ``QAbstractTableModel`` can announce the
change and a ``QUndoStack`` command can revert it with :meth:`PointLedger.insert`,
:meth:`PointLedger.remove`, :meth:`PointLedger.replace` or :meth:`PointLedger.move`.
The ledger is not thread-safe: one thread (the GUI's) owns it; workers get
:meth:`PointLedger.snapshot` tuples. :meth:`PointLedger.mark_all_unknown` is for a controller
restart, a reconnect or a loaded file.

The point itself lives in :mod:`app.points.point`, CSV in :mod:`app.points.csv_io`, uploads in
:mod:`app.points.upload`, importing a file's list in :mod:`app.points.ledger_import`.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, replace

from app.errors import InvalidInput
from app.points.fields import DEFAULT_LIMITS, FieldError, PointLimits
from app.points.ledger_import import ImportMode, ImportReport, merge_import
from app.points.point import (
    POINT_FIELDS,
    ZERO_EXT,
    SyncState,
    TempPoint,
    _mark_changed,
    is_valid_point,
    make_point,
    with_field,
)
from app.protocol.registers import TOOL_NONE


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


def _no_such_point(point_id: int) -> InvalidInput:
    return InvalidInput(
        f"there is no point with id {point_id}", code="no_such_point", params={"id": point_id}
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

    @classmethod
    def from_checked(cls, points: list[TempPoint], limits: PointLimits = DEFAULT_LIMITS) -> PointLedger:
        """A ledger over ``points`` that the caller has just validated (each built by
        ``make_point`` / ``point_from_fields`` with ``limits``, ids unique): nothing is checked
        twice. Project loading uses it; everything else goes through the checking constructor."""
        ledger = cls((), limits)
        ledger._points = points
        return ledger

    # --- reading
    @property
    def limits(self) -> PointLimits:
        return self._limits

    def set_limits(self, limits: PointLimits) -> None:
        """Change the accepted id range (a setting); refused while a point lies outside it."""
        outside = [p.id for p in self._points if not limits.id_min <= p.id <= limits.id_max]
        if outside:
            shown = ", ".join(map(str, outside[:10])) + (" ..." if len(outside) > 10 else "")
            raise InvalidInput(
                f"points outside {limits.id_min}..{limits.id_max}: {shown}",
                code="points_outside_range",
                params={"id_min": limits.id_min, "id_max": limits.id_max, "ids": shown},
            )
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
            raise _no_such_point(point_id)
        return found

    def next_free_id(self, after: int | None = None) -> int:
        """The smallest unused id in range (greater than ``after`` when given)."""
        used = self._ids()
        start = self._limits.id_min if after is None else max(self._limits.id_min, after + 1)
        for candidate in range(start, self._limits.id_max + 1):
            if candidate not in used:
                return candidate
        raise InvalidInput(
            f"no free point id left in {start}..{self._limits.id_max}",
            code="no_free_point_id",
            params={"start": start, "id_max": self._limits.id_max},
        )

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
        rows.extend(r for r, p in enumerate(self._points) if folded in p.name.casefold() and r not in rows)
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
                raise InvalidInput(f"no row {row}", code="no_such_row", params={"row": row})
        removed = [(row, self._points[row]) for row in unique]
        for row in reversed(unique):
            del self._points[row]
        if removed:
            self._touch()
        return removed

    def move(self, src: int, dst: int) -> None:
        """Move the point at ``src`` so that it ends at index ``dst`` (undo: ``move(dst, src)``)."""
        if not (0 <= src < len(self._points) and 0 <= dst < len(self._points)):
            raise InvalidInput(
                f"cannot move row {src} to {dst} in {len(self._points)} rows",
                code="cannot_move_row",
                params={"src": src, "dst": dst, "rows": len(self._points)},
            )
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
                raise InvalidInput(
                    f"row {row}: id {point.id} is already used on row {seen[point.id]}",
                    code="duplicate_row_id",
                    params={"row": row, "id": point.id, "other": seen[point.id]},
                )
            seen[point.id] = row
        self._points = new
        self._touch()

    def import_points(
        self, points: Sequence[TempPoint], mode: ImportMode = ImportMode.REPLACE, *, allow_empty: bool = False
    ) -> ImportReport:
        """Import a parsed list (see :func:`~app.points.ledger_import.merge_import`): a point
        identical on the controller side to the one it replaces keeps that one's sync state;
        others become ``CHANGED``. An empty list in replace mode raises :class:`EmptyImport`
        unless ``allow_empty``."""
        merged, report = merge_import(self._points, points, mode, allow_empty=allow_empty)
        self.replace_all(merged)
        return report

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
            old.id,
            old.name,
            pose,
            old.ext if ext is None else ext,
            old.tool,
            old.note,
            sync=old.sync,
            sync_error=old.sync_error,
            limits=self._limits,
        )
        new = _mark_changed(old, checked)
        if new != old:
            self.replace(row, new)
        return PointEdit(row, old, new)

    def set_sync(self, point_id: int, state: SyncState, reason: str = "") -> int:
        """Record the controller's side of a point; returns its row."""
        row = self.row_of(point_id)
        if row is None:
            raise _no_such_point(point_id)
        old = self._points[row]
        new = replace(old, sync=state, sync_error=reason if state is SyncState.FAILED else "")
        if new != old:
            self._points[row] = new
            self._touch(structural=False)
        return row

    def mark_all_unknown(self) -> list[int]:
        """After a controller restart or reconnect: nothing is known to be on the controller.
        ``CHANGED`` points stay ``CHANGED``. Returns the rows that changed."""
        known = (SyncState.ON_CONTROLLER, SyncState.UNCONFIRMED, SyncState.FAILED)
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
        # Re-validate: a TempPoint may have been built directly. The quick check passes the
        # usual point; make_point says what is wrong with the others.
        if is_valid_point(point, self._limits):
            return
        make_point(point.id, point.name, point.xyzabc, point.ext, point.tool, point.note, limits=self._limits)

    def _check_point(self, point: TempPoint, ignore_row: int | None) -> None:
        self._check_fields(point)
        row = self.row_of(point.id)
        if row is not None and row != ignore_row:
            taken = self._points[row].label
            raise FieldError(
                "id",
                f"id {point.id} is already used by {taken}",
                code="point_id_taken",
                params={"id": point.id, "point": taken},
            )


__all__ = [
    "PointEdit",
    "PointLedger",
]
