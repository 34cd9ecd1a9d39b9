"""The points model's own undo pieces, beside the generic ones of :mod:`ui.models.undo_list`.

:class:`ReplaceAllCommand` swaps the whole list (a CSV import); :func:`follow_id` is the
``after`` hook of an id edit that renumbers the plans' references and puts them back on undo.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

from PySide6.QtGui import QUndoCommand

from app.plan.segments import Plan, Segment
from app.points.point import TempPoint


class ReplaceAllCommand(QUndoCommand):
    """The whole list swapped (CSV import): ``apply`` puts a list in place (redo: ``after``,
    undo: ``before``)."""

    def __init__(
        self,
        apply: Callable[[Sequence[TempPoint]], None],
        before: Sequence[TempPoint],
        after: Sequence[TempPoint],
        text: str,
    ) -> None:
        super().__init__(text)
        self._apply = apply
        self._before = tuple(before)
        self._after = tuple(after)

    def redo(self) -> None:
        self._apply(self._after)

    def undo(self) -> None:
        self._apply(self._before)


def follow_id(
    plans: Callable[[], Iterable[Plan]], old_id: int, new_id: int, changed: Callable[[], None]
) -> Callable[[bool], None]:
    """Renumber references in the plans (redo) and put them back exactly (undo); ``changed``
    is called when some segment was touched. ``plans`` is read when the step runs."""
    saved: list[tuple[Plan, list[tuple[int, Segment]]]] = []

    def apply(forward: bool) -> None:
        if forward:
            saved.clear()
            for plan in plans():
                before = list(plan.segments)
                touched = plan.replace_point_id(old_id, new_id)
                if touched:
                    saved.append((plan, [(r, before[r]) for r in touched]))
        else:
            for plan, originals in saved:
                for r, seg in originals:
                    plan.replace(r, seg)
        if saved:
            changed()

    return apply
