"""The rules of a segment edit in the planner's table (:class:`ui.models.segment_model.SegmentTableModel`):
what a cell accepts, and the segment a new row starts with. Refusals are typed
(:class:`~app.points.ledger.FieldError`, :class:`~app.errors.InvalidInput`) and say why in
words; the model turns them into undoable commands or an ``editRejected`` sentence.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from PySide6.QtCore import Qt

from app.errors import InvalidInput
from app.plan.segments import DEFAULT_SPEED, Plan, Segment, SegmentKind
from app.points.fields import FieldError, parse_point_id
from app.points.ledger import PointLedger
from app.protocol.registers import TOOL_NONE
from ui.models.point_columns import TOOL_NONE_WORDS


def edited_segment(old: Segment, name: str, value: object, ledger: PointLedger) -> Segment:
    """``old`` with field ``name`` set to ``value`` as the operator typed it (``P5``, ``none``);
    FieldError when the value is refused (a point that does not exist, a speed ≤ 0, an arc whose
    middle point is its end point)."""
    if name in ("via", "end"):
        blank = value is None or (isinstance(value, str) and not value.strip())
        if not (name == "via" and blank):
            value = parse_point_id(strip_p(value), ledger.limits, name)
            if value not in ledger:  # a segment only picks points that exist
                raise FieldError(
                    name,
                    f"point P{value} does not exist: pick one of the list",
                    code="segment_point_missing",
                    params={"id": value},
                )
    if name == "tool" and isinstance(value, str) and value.strip().lower() in TOOL_NONE_WORDS:
        value = TOOL_NONE
    new = old.with_field(name, value)
    if new.speed <= 0:
        raise FieldError(
            "speed",
            f"{new.speed:g} mm/s: the speed must be > 0",
            code="speed_not_positive",
            params={"speed": f"{new.speed:g}"},
        )
    if new.is_arc and new.via_id is not None and new.via_id == new.end_id:
        raise FieldError(name, "an arc's middle point must differ from its end point", code="arc_same_points")
    return new


def default_segment(plan: Plan, ids: Sequence[int], at: int, kind: SegmentKind) -> Segment:
    """A new segment at row ``at`` of ``plan``, over the point ids ``ids`` (the ledger's, in
    order): see :meth:`ui.models.segment_model.SegmentTableModel.default_segment`."""
    previous = plan[at - 1] if 0 < at <= len(plan) else None
    if len(ids) < (2 if kind is SegmentKind.ARC else 1):
        raise InvalidInput(
            "an arc needs two points: add or teach points first"
            if ids
            else "there are no points yet: add or teach a point first"
        )

    def after(pid: int | None) -> int:
        if pid is None or pid not in ids:
            return ids[0]
        return ids[(ids.index(pid) + 1) % len(ids)]

    speed = previous.speed if previous else DEFAULT_SPEED
    tool = previous.tool if previous else TOOL_NONE
    start = previous.end_id if previous else None
    if kind is SegmentKind.ARC:
        via = after(start)
        end = after(via)
        return Segment.arc(via, end, speed, tool=tool)
    return Segment.line(after(start), speed, tool=tool)


def strip_p(value: object) -> object:
    """Accept ``P5`` / ``p5`` / ``5 circle W`` (what the cell shows) for a point id."""
    if isinstance(value, str):
        text = value.strip()
        if text[:1] in ("P", "p"):
            text = text[1:]
        return text.split()[0] if text.split() else text
    return value


def is_checked(value: Any) -> bool:
    """A check-state cell's value (Qt.CheckState, bool or its int) as a bool; FieldError else."""
    if isinstance(value, Qt.CheckState):
        return value == Qt.CheckState.Checked
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        return value == Qt.CheckState.Checked.value
    raise FieldError(
        "ignore_middle",
        f"{value!r} is not a check state",
        code="not_yes_no",
        params={"value": repr(value)[:40]},
    )
