"""The project in memory: points (a :class:`~app.points.ledger.PointLedger`), plans and a little
metadata, with a revision counter for dirty tracking. The file format (JSON, load and save)
lives in :mod:`app.points.project`."""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterable
from dataclasses import dataclass, field

from app.errors import InvalidInput
from app.plan.segments import Plan, validate_plan_name
from app.points.ledger import PointLedger
from app.watchlist.entry import WatchEntry

HISTORY_TEXT_MAX = 200  # longest upload time / endpoint text kept as history


def now_iso() -> str:
    return dt.datetime.now(dt.UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z")


@dataclass(frozen=True)
class LastUpload:
    """History: when this host last uploaded a point, and to which controller. Never proof that
    the controller still holds it (it may have restarted, another tool may have overwritten it)."""

    time: str
    endpoint: str


@dataclass(eq=False)
class Project:
    """Points, plans and metadata. Plan names are unique (compared after stripping)."""

    name: str = "untitled"
    ledger: PointLedger = field(default_factory=PointLedger)
    plans: list[Plan] = field(default_factory=list)
    description: str = ""
    created: str = field(default_factory=now_iso)
    modified: str = ""
    #: point id -> the last upload of that point (history only; see :class:`LastUpload`)
    upload_history: dict[int, LastUpload] = field(default_factory=dict)
    #: the GVs and registers watched (View -> Watch list), saved with the project
    watch_list: tuple[WatchEntry, ...] = ()
    _revision: int = field(default=0, init=False, repr=False)

    def __post_init__(self) -> None:
        seen: set[str] = set()  # one pass: 20,000 plans are checked in milliseconds, not seconds
        for plan in self.plans:
            if plan.name in seen:
                raise InvalidInput(f"two plans are named {plan.name!r}")
            seen.add(plan.name)

    @property
    def revision(self) -> int:
        """Changes whenever the project, its ledger or a plan changes (dirty tracking)."""
        return self._revision + self.ledger.revision + sum(p.revision for p in self.plans)

    def touch(self) -> None:
        """Count a metadata change."""
        self._revision += 1

    def record_upload(self, point_ids: Iterable[int], endpoint: str, when: str | None = None) -> None:
        """Note in the history that ``point_ids`` were just uploaded to ``endpoint``."""
        stamp = when or now_iso()
        ids = list(point_ids)
        for point_id in ids:
            self.upload_history[point_id] = LastUpload(stamp, endpoint[:HISTORY_TEXT_MAX])
        if ids:
            self._revision += 1

    def set_watch_list(self, entries: Iterable[WatchEntry]) -> None:
        """Replace the watch list (a change of the project when it differs)."""
        new = tuple(entries)
        if new != self.watch_list:
            self.watch_list = new
            self._revision += 1

    # --- plans
    def plan_names(self) -> list[str]:
        return [p.name for p in self.plans]

    def plan(self, name: str) -> Plan:
        for p in self.plans:
            if p.name == name.strip():
                return p
        raise InvalidInput(f"no plan named {name!r} (plans: {', '.join(self.plan_names()) or 'none'})")

    def add_plan(self, plan: Plan, row: int | None = None) -> int:
        if plan.name in self.plan_names():
            raise InvalidInput(f"a plan named {plan.name!r} already exists")
        row = len(self.plans) if row is None else max(0, min(row, len(self.plans)))
        self.plans.insert(row, plan)
        self._revision += 1
        return row

    def remove_plan(self, row: int) -> Plan:
        plan = self.plans.pop(row)
        self._revision += 1
        return plan

    def rename_plan(self, row: int, name: str) -> str:
        new = validate_plan_name(name)
        if any(p.name == new for i, p in enumerate(self.plans) if i != row):
            raise InvalidInput(f"a plan named {new!r} already exists")
        return self.plans[row].rename(new)

    def unique_plan_name(self, base: str = "plan") -> str:
        names = set(self.plan_names())
        if base not in names:
            return base
        k = 2
        while f"{base} {k}" in names:
            k += 1
        return f"{base} {k}"

    # --- cross references
    def references(self, point_id: int) -> list[tuple[str, int]]:
        """``(plan name, segment index)`` of every segment that uses ``point_id``."""
        return [
            (p.name, i) for p in self.plans for i, seg in enumerate(p.segments) if point_id in seg.point_ids
        ]

    def renumber_point(self, row: int, new_id: int) -> list[tuple[str, list[int]]]:
        """Change a point's id and follow it in every plan; returns ``(plan, rows)`` changed."""
        old_id = self.ledger[row].id
        self.ledger.set_field(row, "id", new_id)
        changed: list[tuple[str, list[int]]] = []
        for p in self.plans:
            rows = p.replace_point_id(old_id, new_id)
            if rows:
                changed.append((p.name, rows))
        return changed
