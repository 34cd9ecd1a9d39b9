"""The point ledger as a Qt table model; every edit is a ``QUndoCommand``.

:class:`PointsModel` shows the :class:`~app.points.ledger.PointLedger` of a
:class:`~app.points.project.Project` (one row per temp point) and changes it only through commands
pushed on a ``QUndoStack``: cell edits, add, duplicate, delete, reorder, teach and CSV import
are all undoable. Editing a point's id follows the id in every plan of the project (undo puts
the plans back too). Refused input raises :class:`~app.errors.InvalidInput` from the
``edit_*`` methods; ``setData`` turns it into :attr:`PointsModel.editRejected` and leaves the
model unchanged.

Sync states are not undoable: they describe the controller, not the operator's edits. The
model keeps what it knows each id holds on the controller (``_on_controller``: set by uploads
and teach, cleared by a reconnect) and derives the sync state of every point an undo or redo
puts back from it, so undoing an edit after an upload never claims a point is on the
controller when it is not.

The generic undoable list model and its commands are in :mod:`ui.models.undo_list`, this
model's own (import, id follow) in :mod:`ui.models.point_commands`; the filter proxy is
:class:`ui.models.point_filter.PointFilterProxy`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import replace
from typing import Any

from PySide6.QtCore import (
    QModelIndex,
    QPersistentModelIndex,
    Qt,
    Signal,
)
from PySide6.QtGui import QBrush, QColor, QUndoStack

from app.errors import InvalidInput
from app.points.fields import FieldError
from app.points.ledger import PointLedger
from app.points.ledger_import import ImportMode, ImportReport
from app.points.point import SyncState, TempPoint, make_point, point_from_pose, with_field
from app.points.project_model import Project
from app.points.provenance import Origin
from app.points.upload import UploadReport, apply_upload
from app.protocol.registers import TOOL_NONE
from ui.messages import refusal_text
from ui.models.point_columns import (
    COL_C,
    COL_ID,
    COL_SYNC,
    COL_TOOL,
    COL_X,
    COLUMNS,
    EXT_COLUMNS,
    NUMBER_COLUMNS,
    POINT_ID_ROLE,
    SYNC_COLOURS,
    SYNC_ROLE,
    TOOL_NONE_WORDS,
    edit_text,
    format_number,
    sync_text,
    tool_display,
)
from ui.models.point_commands import ReplaceAllCommand, follow_id
from ui.models.point_provenance import ProvenanceStamps, provenance_tip
from ui.models.undo_list import (
    InsertRowsCommand,
    MoveRowsCommand,
    RemoveRowsCommand,
    ReplaceRowCommand,
    UndoableListModel,
)

ModelIndex = QModelIndex | QPersistentModelIndex


class PointsModel(UndoableListModel):
    """Table model over ``project.ledger``; see the module docstring.

    Signals: ``editRejected(str)``, ``listEdited(object)`` (inherited), ``planReferencesChanged()``
    (an id edit, or its undo, changed segments of plans), ``syncChanged()`` (sync states changed
    without an edit: upload, teach, reconnect).
    """

    planReferencesChanged = Signal()
    syncChanged = Signal()

    def __init__(self, project: Project, undo_stack: QUndoStack, parent: Any = None) -> None:
        super().__init__(undo_stack, parent)
        self._project = project
        self._on_controller: dict[int, TempPoint] = {}
        self._headers: tuple[str, ...] = ()
        self._header_tips: dict[int, str] = {}
        self._brushes: dict[SyncState, tuple[QBrush, QBrush]] = {}  # made by the first row drawn
        #: how the points made here are stamped (the window tells it the controller the link reaches)
        self.stamps = ProvenanceStamps()
        self._seed_controller_copy()
        self.retranslate()

    # --- project
    @property
    def project(self) -> Project:
        return self._project

    @property
    def ledger(self) -> PointLedger:
        return self._project.ledger

    def set_project(self, project: Project) -> None:
        """Show another project (open, new, recover). The caller clears the undo stack."""
        self.beginResetModel()
        self._project = project
        self._seed_controller_copy()
        self.endResetModel()

    def _sync_brushes(self, state: SyncState) -> tuple[QBrush, QBrush]:
        """(text, background) of a sync state's cell. Made by the first row drawn, not with the
        model: PySide6 readies QGradient, QImage and QPixmap for the first QBrush(QColor), ~3 ms
        that the window's first paint does not need (the points table is built after it)."""
        if not self._brushes:
            self._brushes = {
                state: (QBrush(QColor(fg)), QBrush(QColor(bg))) for state, (fg, bg) in SYNC_COLOURS.items()
            }
        return self._brushes[state]

    def _seed_controller_copy(self) -> None:
        self._on_controller = {p.id: p for p in self.ledger if p.sync is SyncState.ON_CONTROLLER}

    def retranslate(self) -> None:
        names = {
            "id": self.tr("ID"),
            "name": self.tr("Name"),
            "tool": self.tr("Tool"),
            "sync": self.tr("Sync"),
            "note": self.tr("Note"),
            # external axes: J7..J11 as the jog panel, go to zero and the monitor name them (the
            # CSV's columns keep their names e1..e5, the header tip says which)
            **{f"e{n}": f"J{n + 6}" for n in range(1, 6)},
        }
        self._headers = tuple(names.get(c, c.upper()) for c in COLUMNS)
        self._header_tips = {
            COL_ID: self.tr("Temp point id on the controller"),
            COL_TOOL: self.tr("Tool frame (200 = none)"),
            COL_SYNC: self.tr("Whether the controller holds this point"),
            **{c: self.tr("mm, base frame") for c in range(COL_X, COL_X + 3)},
            **{c: self.tr("degrees") for c in range(COL_X + 3, COL_C + 1)},
            **{
                c: self.tr(
                    "External axis (recorded only: the controller does not store it); CSV column {column}"
                ).format(column=f"e{n}")
                for n, c in enumerate(EXT_COLUMNS, start=1)
            },
        }
        self.headerDataChanged.emit(Qt.Orientation.Horizontal, 0, len(COLUMNS) - 1)

    # --- reading
    def rowCount(self, parent: ModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(self.ledger)

    def columnCount(self, parent: ModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(COLUMNS)

    def point_at(self, row: int) -> TempPoint:
        return self.ledger[row]

    def row_of(self, point_id: int) -> int | None:
        return self.ledger.row_of(point_id)

    def headerData(
        self, section: int, orientation: Qt.Orientation, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        if orientation == Qt.Orientation.Horizontal and 0 <= section < len(COLUMNS):
            if role == Qt.ItemDataRole.DisplayRole:
                return self._headers[section]
            if role == Qt.ItemDataRole.ToolTipRole:
                return self._header_tips.get(section)
        elif orientation == Qt.Orientation.Vertical and role == Qt.ItemDataRole.DisplayRole:
            return section + 1
        return None

    def data(self, index: ModelIndex, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
        if not index.isValid() or not 0 <= index.row() < len(self.ledger):
            return None
        point = self.ledger[index.row()]
        column = index.column()
        if not 0 <= column < len(COLUMNS):
            return None
        by_role = _DATA_BY_ROLE.get(role)
        return None if by_role is None else by_role(self, point, column)

    def _display(self, point: TempPoint, column: int) -> str:
        name = COLUMNS[column]
        if name in ("id",):
            return str(point.id)
        if name in ("name", "note"):
            return str(point.get(name)).replace("\n", " ⏎ ") if name == "note" else point.name
        if name == "tool":
            return tool_display(point.tool)
        if name == "sync":
            return sync_text(point.sync)
        value = point.get(name)
        return format_number(float(value), name) if isinstance(value, float | int) else str(value)

    def _edit_value(self, point: TempPoint, column: int) -> str:
        name = COLUMNS[column]
        if name == "sync":
            return point.sync.value
        value = point.get(name)
        if isinstance(value, float):
            return edit_text(value, name)
        return str(value)

    def _tooltip(self, point: TempPoint, column: int) -> str | None:
        name = COLUMNS[column]
        if name == "sync":
            if point.sync is SyncState.FAILED:
                reason = point.sync_error or self.tr("no reason given")
                return self.tr("Upload failed: {reason}").format(reason=reason)
            return {
                SyncState.UNKNOWN: self.tr(
                    "Not known whether the controller holds this point (it restarted, it is "
                    "another controller, or the arm did not arrive there): a move to it creates "
                    "it again first"
                ),
                SyncState.ON_CONTROLLER: self.tr("The controller holds this point with these values"),
                SyncState.CHANGED: self.tr("Changed on the host (or new) since the last upload"),
                SyncState.UNCONFIRMED: self.tr(
                    "Sent without an error, but the controller's status never "
                    "changed: most likely there, not proven; upload it again "
                    "before moving to it"
                ),
            }[point.sync]
        if name == "note" and point.note:
            return point.note
        if name == "tool":
            return self.tr("Tool frame {value}").format(value=point.tool)
        return provenance_tip(point.made)  # the id, name, pose and axes cells: how it was made

    def _alignment(self, _point: TempPoint, column: int) -> int:
        if column in NUMBER_COLUMNS:
            return int(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        return int(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter)

    def _sync_foreground(self, point: TempPoint, column: int) -> QBrush | None:
        return self._sync_brushes(point.sync)[0] if column == COL_SYNC else None

    def _sync_background(self, point: TempPoint, column: int) -> QBrush | None:
        return self._sync_brushes(point.sync)[1] if column == COL_SYNC else None

    def _point_id(self, point: TempPoint, _column: int) -> int:
        return point.id

    def _sync_state(self, point: TempPoint, _column: int) -> SyncState:
        return point.sync

    def flags(self, index: ModelIndex) -> Qt.ItemFlag:
        if not index.isValid():
            return Qt.ItemFlag.NoItemFlags
        base = Qt.ItemFlag.ItemIsSelectable | Qt.ItemFlag.ItemIsEnabled
        if index.column() != COL_SYNC:
            base |= Qt.ItemFlag.ItemIsEditable
        return base

    # --- editing through the view
    def setData(self, index: ModelIndex, value: Any, role: int = Qt.ItemDataRole.EditRole) -> bool:
        if role != Qt.ItemDataRole.EditRole or not index.isValid() or value is None:
            return False
        if not 0 <= index.row() < len(self.ledger) or not 0 <= index.column() < len(COLUMNS):
            return False
        name = COLUMNS[index.column()]
        if name == "sync":
            return False
        try:
            self.edit_field(index.row(), name, value)
        except InvalidInput as exc:
            self.editRejected.emit(self.refusal_text(self.ledger[index.row()], name, exc))
            return False
        return True

    def refusal_text(self, point: TempPoint, name: str, exc: InvalidInput) -> str:
        reason = refusal_text(exc)
        column = self._headers[COLUMNS.index(name)] if name in COLUMNS else name
        return self.tr("{point}, {column}: refused, {reason}").format(
            point=point.label, column=column, reason=reason
        )

    # --- edits (each pushes one undo command; raise InvalidInput when refused)
    def edit_field(self, row: int, name: str, value: object) -> bool:
        """Set one field of the point at ``row``; False when nothing changed."""
        old = self.ledger[row]
        if name == "tool" and isinstance(value, str) and value.strip().lower() in TOOL_NONE_WORDS:
            value = TOOL_NONE
        new = with_field(old, name, value, self.ledger.limits)
        if new == old:
            return False
        new = replace(new, made=self.stamps.edited(old.made))
        if name == "id":
            other = self.ledger.row_of(new.id)
            if other is not None and other != row:
                taken = self.ledger[other].label
                raise FieldError(
                    "id",
                    f"id {new.id} is already used by {taken}",
                    code="point_id_taken",
                    params={"id": new.id, "point": taken},
                )
        after = (
            follow_id(lambda: self._project.plans, old.id, new.id, self.planReferencesChanged.emit)
            if old.id != new.id
            else None
        )
        column = self._headers[COLUMNS.index(name)] if name in COLUMNS else name
        text = self.tr("Edit {point} {column}").format(point=old.label, column=column)
        self._stack.push(ReplaceRowCommand(self, self.ledger, row, old, new, text, after=after))
        return True

    def add_point(
        self,
        row: int | None = None,
        *,
        name: str = "",
        pose: Sequence[float] | None = None,
        tool: int = TOOL_NONE,
    ) -> int:
        """A new point (next free id) at ``row`` (default: the end); returns its row."""
        point = make_point(self.next_id(), name, pose or (0.0,) * 6, tool=tool, limits=self.ledger.limits)
        point = replace(point, made=self.stamps.made(Origin.TYPED))
        row = len(self.ledger) if row is None else max(0, min(row, len(self.ledger)))
        self._stack.push(
            InsertRowsCommand(
                self, self.ledger, [(row, point)], self.tr("Add {point}").format(point=point.label)
            )
        )
        return row

    def next_id(self) -> int:
        """The id for a new point: one more than the highest (1 for an empty list), or the
        smallest free id when the highest is at the limit."""
        limits = self.ledger.limits
        ids = self.ledger.ids()
        candidate = max(ids) + 1 if ids else max(1, limits.id_min)
        if limits.id_min <= candidate <= limits.id_max:
            return candidate
        return self.ledger.next_free_id()

    def duplicate_rows(self, rows: Iterable[int]) -> list[int]:
        """Copy each row right after the block it belongs to, under new ids; returns new rows."""
        chosen = sorted(set(rows))
        if not chosen:
            return []
        used = set(self.ledger.ids())
        copies: list[tuple[int, TempPoint]] = []
        for offset, row in enumerate(chosen):
            source = self.ledger[row]
            new_id = self._free_id_after(source.id, used)
            used.add(new_id)
            # a copy's values were made as its source's were: its history, edited now
            made = self.stamps.edited(source.made)
            copy = replace(source, id=new_id, sync=SyncState.CHANGED, sync_error="", made=made)
            copies.append((row + 1 + offset, copy))
        text = (
            self.tr("Duplicate {point}").format(point=self.ledger[chosen[0]].label)
            if len(chosen) == 1
            else self.tr("Duplicate {n} points").format(n=len(chosen))
        )
        self._stack.push(InsertRowsCommand(self, self.ledger, copies, text))
        return [row for row, _ in copies]

    def _free_id_after(self, after: int, used: set[int]) -> int:
        limits = self.ledger.limits
        for start in (after + 1, limits.id_min):
            for candidate in range(max(start, limits.id_min), limits.id_max + 1):
                if candidate not in used:
                    return candidate
        raise InvalidInput(f"no free point id left in {limits.id_min}..{limits.id_max}")

    def remove_rows(self, rows: Iterable[int]) -> int:
        """Delete rows (one undo step); returns how many."""
        chosen = sorted({r for r in rows if 0 <= r < len(self.ledger)})
        if not chosen:
            return 0
        text = (
            self.tr("Delete {point}").format(point=self.ledger[chosen[0]].label)
            if len(chosen) == 1
            else self.tr("Delete {n} points").format(n=len(chosen))
        )
        self._stack.push(RemoveRowsCommand(self, self.ledger, chosen, text))
        return len(chosen)

    def can_move(self, rows: Iterable[int], delta: int) -> bool:
        chosen = sorted(set(rows))
        if not chosen:
            return False
        return chosen[0] + delta >= 0 if delta < 0 else chosen[-1] + delta < len(self.ledger)

    def move_rows(self, rows: Iterable[int], delta: int) -> list[int]:
        """Move rows one place up (-1) or down (+1); returns their new rows (unchanged if at an end)."""
        chosen = sorted(set(rows))
        if not self.can_move(chosen, delta):
            return chosen
        text = self.tr("Move up") if delta < 0 else self.tr("Move down")
        command = MoveRowsCommand(self, self.ledger, chosen, delta, text)
        self._stack.push(command)
        return list(command.new_rows)

    def add_taught_point(self, point_id: int, pose: Any, *, name: str = "", tool: int = TOOL_NONE) -> int:
        """A point the controller just created from its current pose (``pose``: a ``Pose``).

        It is on the controller by construction. Returns its row."""
        point = point_from_pose(point_id, pose, name, tool=tool, limits=self.ledger.limits)
        point = replace(point, sync=SyncState.ON_CONTROLLER, made=self.stamps.made(Origin.TAUGHT))
        if self.ledger.row_of(point_id) is not None:
            taken = self.ledger.point(point_id).label
            raise FieldError(
                "id",
                f"id {point_id} is already used by {taken}",
                code="point_id_taken",
                params={"id": point_id, "point": taken},
            )
        self._on_controller[point_id] = point
        row = len(self.ledger)
        self._stack.push(
            InsertRowsCommand(
                self, self.ledger, [(row, point)], self.tr("Teach {point}").format(point=point.label)
            )
        )
        return row

    def import_points(
        self,
        points: Sequence[TempPoint],
        mode: ImportMode = ImportMode.REPLACE,
        *,
        allow_empty: bool = False,
        check: Callable[[PointLedger], None] | None = None,
    ) -> ImportReport:
        """Import parsed points (one undo step); the ledger is untouched when refused (an empty
        list in replace mode too, unless ``allow_empty``; ``check`` raising on the ledger the
        import would give -- a project too large to be read back)."""
        scratch = PointLedger(self.ledger.snapshot(), self.ledger.limits)
        report = scratch.import_points(points, mode, allow_empty=allow_empty)
        if check is not None:
            check(scratch)
        text = self.tr("Import {n} points").format(n=len(points))
        self._stack.push(
            ReplaceAllCommand(self._apply_replace_all, self.ledger.snapshot(), scratch.snapshot(), text)
        )
        return report

    # --- sync state (not undoable)
    def mark_all_unknown(self) -> int:
        """The controller restarted or reconnected: nothing is known to be on it any more."""
        self._on_controller.clear()
        rows = self.ledger.mark_all_unknown()
        self._sync_rows_changed(rows)
        return len(rows)

    def apply_upload(self, report: UploadReport) -> list[int]:
        """Record an upload (see :func:`app.points.ledger.apply_upload`); returns the rows changed."""
        for outcome in report.outcomes:
            if outcome.ok and outcome.sent is not None and not outcome.unconfirmed:
                self._on_controller[outcome.point_id] = outcome.sent
            else:  # failed, or not proven to be there
                self._on_controller.pop(outcome.point_id, None)
        rows = apply_upload(self.ledger, report)
        self._sync_rows_changed(rows)
        return rows

    def set_sync(self, point_id: int, state: SyncState, reason: str = "") -> None:
        """Record the controller's side of one point (e.g. a teach that overwrote it)."""
        if state is not SyncState.ON_CONTROLLER:
            self._on_controller.pop(point_id, None)
        else:
            self._on_controller[point_id] = self.ledger.point(point_id)
        self._sync_rows_changed([self.ledger.set_sync(point_id, state, reason)])

    def _sync_rows_changed(self, rows: Sequence[int]) -> None:
        if rows:
            self.dataChanged.emit(self.index(min(rows), 0), self.index(max(rows), len(COLUMNS) - 1))
            self.syncChanged.emit()

    # --- command hooks
    def _show(self, target: Any) -> None:
        if target is not self.ledger:
            raise RuntimeError("undo command for a ledger that is no longer shown")

    def _prepare(self, target: Any, item: Any) -> Any:
        return self.settle(item)

    def settle(self, point: TempPoint) -> TempPoint:
        """``point`` with the sync state that what the controller is known to hold implies."""
        known = self._on_controller.get(point.id)
        if known is not None:
            if known.same_on_controller(point):
                return replace(point, sync=SyncState.ON_CONTROLLER, sync_error="")
            return replace(point, sync=SyncState.CHANGED, sync_error="")
        if point.sync is SyncState.ON_CONTROLLER:
            return replace(point, sync=SyncState.UNKNOWN, sync_error="")
        return point

    def _apply_replace_all(self, points: Sequence[TempPoint]) -> None:
        self.beginResetModel()
        self.ledger.replace_all([self.settle(p) for p in points])
        self.endResetModel()
        self._after_change(self.ledger)


# what data() answers for each role: the cell's point and column in, the value out
_DATA_BY_ROLE: dict[int, Callable[[PointsModel, TempPoint, int], Any]] = {
    Qt.ItemDataRole.DisplayRole: PointsModel._display,
    Qt.ItemDataRole.EditRole: PointsModel._edit_value,
    Qt.ItemDataRole.ToolTipRole: PointsModel._tooltip,
    Qt.ItemDataRole.TextAlignmentRole: PointsModel._alignment,
    Qt.ItemDataRole.ForegroundRole: PointsModel._sync_foreground,
    Qt.ItemDataRole.BackgroundRole: PointsModel._sync_background,
    POINT_ID_ROLE: PointsModel._point_id,
    SYNC_ROLE: PointsModel._sync_state,
}
