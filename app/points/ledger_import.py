"""Importing a parsed point list into the ledger: modes, the report, the merge rule.

:meth:`app.points.ledger.PointLedger.import_points` uses :func:`merge_import` and then swaps
its list.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass, replace

from app.errors import InvalidInput
from app.points.point import SyncState, TempPoint


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


class EmptyImport(InvalidInput):
    """A replace-mode import without a single point: it would delete every point; refused
    unless the caller asks for it explicitly (``allow_empty=True``)."""

    code = "empty_import"

    def __init__(self, existing: int) -> None:
        self.existing = existing
        super().__init__(
            f"the file has no points: replacing with it would remove all {existing} point(s) "
            "of the project (merge it, or ask explicitly for an empty import)",
            params={"existing": existing},
        )


def merge_import(
    current: Sequence[TempPoint],
    points: Sequence[TempPoint],
    mode: ImportMode = ImportMode.REPLACE,
    *,
    allow_empty: bool = False,
) -> tuple[list[TempPoint], ImportReport]:
    """The list the ledger becomes when ``points`` are imported over ``current``, and the
    report. A point identical on the controller side to the one it replaces keeps that one's
    sync state (and, when nothing at all changed, its provenance); others become ``CHANGED``.
    An empty list in replace mode raises :class:`EmptyImport` unless ``allow_empty``. Fields are
    not checked here: the ledger's ``replace_all`` checks the result."""
    if not points and mode is ImportMode.REPLACE and not allow_empty:
        raise EmptyImport(len(current))
    old = {p.id: p for p in current}
    seen: set[int] = set()
    for number, point in enumerate(points, start=1):
        if point.id in seen:
            raise InvalidInput(
                f"imported point {number}: id {point.id} appears twice",
                code="import_duplicate_id",
                params={"number": number, "id": point.id},
            )
        seen.add(point.id)
    incoming: list[TempPoint] = []
    added = updated = unchanged = 0
    for point in points:
        previous = old.get(point.id)
        if previous is None:
            added += 1
            incoming.append(replace(point, sync=SyncState.CHANGED, sync_error=""))
        elif previous.same_on_controller(point):
            same = previous.name == point.name and previous.note == point.note and previous.ext == point.ext
            unchanged += same
            updated += not same
            # an unchanged point keeps its history too (the import did not make it)
            made = previous.made if same else point.made
            incoming.append(replace(point, sync=previous.sync, sync_error=previous.sync_error, made=made))
        else:
            updated += 1
            incoming.append(replace(point, sync=SyncState.CHANGED, sync_error=""))
    if mode is ImportMode.REPLACE:
        incoming_ids = {p.id for p in incoming}
        removed = sum(1 for pid in old if pid not in incoming_ids)
        result = incoming
    else:
        removed = 0
        by_id = {p.id: p for p in incoming}
        result = [by_id.pop(p.id, p) for p in current]
        result.extend(p for p in incoming if p.id in by_id)
    return result, ImportReport(added=added, updated=updated, unchanged=unchanged, removed=removed)
