"""The temp point panel: the ledger table, teach, upload / restore, move to a point.

The widget: the action bar (primary buttons, edit toolbar, filter by id / name, E1..E5), the
reconnect banner, upload progress, the table and a status line; those widgets are built in
:mod:`ui.panels.points_parts`, this module holds the actions and decides what is enabled. The
robot side (teach, upload, restore, move and their outcomes) is a
:class:`~ui.controllers.point_sync.PointSyncController`, shared with the planner.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from PySide6.QtCore import QEvent, QModelIndex, Qt, Signal, Slot
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QLabel, QSizePolicy, QVBoxLayout, QWidget

from app.errors import InvalidInput
from app.points.upload import UploadReport
from app.safety.caps import MotionCaps
from ui.controllers.point_sync import LEVEL_ERROR, LEVEL_INFO, LEVEL_WARN, PointSyncController
from ui.controllers.safety import lock_editing
from ui.dialogs.confirm import ConfirmFn, ask_confirmation
from ui.messages import refusal_text
from ui.models.point_filter import PointFilterProxy
from ui.models.points_model import PointsModel
from ui.palette import COLOR_ERROR, COLOR_OK
from ui.panels.points_parts import PointsActionBar, PointsTable, RestoreBanner, UploadProgressRow


class PointsPanel(QWidget):
    """Point ledger panel; see the module docstring.

    Public: the ``action_*`` QActions (teach Ctrl+T, add, duplicate, delete, move up/down,
    upload selected / all / needed, restore all, cancel upload, move to point, show E1..E5,
    find Ctrl+F), ``selected_rows()`` / ``select_rows()``, ``set_run_active(bool)`` (disables
    motion while a plan runs), signal ``statusMessage(str)``.
    """

    statusMessage = Signal(str)

    def __init__(
        self,
        model: PointsModel,
        controller: PointSyncController | None = None,
        parent: QWidget | None = None,
        *,
        confirm: ConfirmFn | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("PointsPanel")
        self._model = model
        self._controller = controller or PointSyncController(model, parent=self)
        self._confirm = confirm or ask_confirmation(self)
        self._run_active = False
        self._alarm_hold = False  # an e-stop / servo alarm: no move-to (MotionController.alarmHoldChanged)
        self._edit_reason: str | None = None  # why the role may not edit points (None: it may)
        self.move_check: Callable[[int, float], str | None] | None = None  # the envelope: why not (None: go)

        self.proxy = PointFilterProxy(self)
        self.proxy.setSourceModel(model)

        self._make_actions()
        self._build()
        self.retranslate()

        model.editRejected.connect(self._on_rejected)
        model.modelReset.connect(self._update_actions)
        model.rowsInserted.connect(self._update_actions)
        model.rowsRemoved.connect(self._update_actions)
        model.rowsMoved.connect(self._update_actions)
        c = self._controller
        c.statusMessage.connect(self.show_message)
        c.busyChanged.connect(self._update_actions)
        c.connectedChanged.connect(self._update_actions)
        c.restoreOffered.connect(self._on_restore_offered)
        c.uploadProgress.connect(self._on_upload_progress)
        c.uploadFinished.connect(self._on_upload_finished)
        c.pointTaught.connect(self._on_taught)
        self.table.selectionModel().selectionChanged.connect(self._update_actions)
        self._on_restore_offered(c.restore_offered)
        self._update_actions()

    # --- construction
    def _make_actions(self) -> None:
        def act(
            shortcut: QKeySequence | QKeySequence.StandardKey | str | None = None,
            slot: Callable[[], Any] | None = None,
            checkable: bool = False,
        ) -> QAction:
            action = QAction(self)
            if shortcut is not None:
                action.setShortcut(QKeySequence(shortcut))
                action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.setCheckable(checkable)
            if slot is not None:
                action.triggered.connect(slot)
            self.addAction(action)
            return action

        self.action_teach = act("Ctrl+T", self.teach)
        self.action_teach.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        self.action_add = act("Ctrl+Shift+N", self.add_point)
        self.action_duplicate = act("Ctrl+D", self.duplicate_selected)
        self.action_delete = act(QKeySequence.StandardKey.Delete, self.delete_selected)
        self.action_move_up = act("Alt+Up", lambda: self.move_selected(-1))
        self.action_move_down = act("Alt+Down", lambda: self.move_selected(1))
        self.action_upload_selected = act(None, self.upload_selected)
        self.action_upload_all = act(None, self.upload_all)
        self.action_upload_needed = act(None, self._controller.upload_needed)
        self.action_restore_all = act(None, self._controller.restore_all)
        self.action_cancel_upload = act(None, self._controller.cancel_upload)
        self.action_move_to = act("Ctrl+M", self.move_to_selected)
        self.action_show_ext = act(None, None, checkable=True)
        self.action_show_ext.toggled.connect(self._show_ext)
        self.action_find = act(QKeySequence.StandardKey.Find, self._focus_find)

    def _build(self) -> None:
        bar = PointsActionBar(
            self,
            teach=self.action_teach,
            upload_selected=self.action_upload_selected,
            upload_needed=self.action_upload_needed,
            upload_all=self.action_upload_all,
            restore_all=self.action_restore_all,
            move_to=self.action_move_to,
            show_ext=self.action_show_ext,
            edits=(
                self.action_add,
                self.action_duplicate,
                self.action_delete,
                self.action_move_up,
                self.action_move_down,
            ),
        )
        self.action_bar = bar
        self.primary_row, self.toolbar = bar.primary_row, bar.toolbar
        self.teach_button, self.upload_button = bar.teach_button, bar.upload_button
        self.restore_all_button, self.move_to_button = bar.restore_all_button, bar.move_to_button
        self.speed, self.find_edit = bar.speed, bar.find_edit
        self.speed_cap = bar.speed_cap
        self._caps: MotionCaps | None = None  # reduced-speed mode's caps, None: off
        self.speed.valueChanged.connect(self._show_move_cap)
        self.find_edit.textChanged.connect(self.proxy.set_filter_text)

        self.banner = RestoreBanner(self._controller.restore_all, self)
        self.restore_button = self.banner.restore_button
        self.progress_row = UploadProgressRow(self._controller.cancel_upload, self)
        self.progress, self.cancel_button = self.progress_row.progress, self.progress_row.cancel_button

        self.table = PointsTable(
            (
                self.action_move_to,
                self.action_upload_selected,
                None,
                self.action_teach,
                self.action_add,
                self.action_duplicate,
                self.action_delete,
            ),
            self,
        )
        self.table.setModel(self.proxy)
        self.table.size_columns()
        self.table.doubleClicked.connect(self._say_why_not_editable)
        self._show_ext(False)

        self.status = QLabel(self)
        self.status.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.status.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)

        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.setSpacing(4)
        for widget in (bar.primary_row, bar.edit_row, self.banner, self.progress_row):
            layout.addWidget(widget)
        layout.addWidget(self.table, 1)
        layout.addWidget(self.status)

    def retranslate(self) -> None:
        texts = {
            self.action_teach: (
                self.tr("Teach"),
                self.tr(
                    "Create the next temp point on the controller from the robot's current pose (Ctrl+T)"
                ),
            ),
            self.action_add: (self.tr("Add"), self.tr("Add a point on the host (not on the controller yet)")),
            self.action_duplicate: (self.tr("Duplicate"), self.tr("Copy the selected points under new ids")),
            self.action_delete: (
                self.tr("Delete"),
                self.tr("Delete the selected points from the host's list"),
            ),
            self.action_move_up: ("▲", self.tr("Move the selected points up (Alt+Up)")),
            self.action_move_down: ("▼", self.tr("Move the selected points down (Alt+Down)")),
            self.action_upload_selected: (
                self.tr("Upload selected"),
                self.tr("Create the selected points on the controller"),
            ),
            self.action_upload_needed: (
                self.tr("Upload changed"),
                self.tr("Upload every point not known to be on the controller"),
            ),
            self.action_upload_all: (self.tr("Upload all"), self.tr("Create every point on the controller")),
            self.action_restore_all: (
                self.tr("Restore all"),
                self.tr("Re-create all points after a controller restart"),
            ),
            self.action_cancel_upload: (self.tr("Cancel upload"), ""),
            self.action_move_to: (
                self.tr("Move to point"),
                self.tr("Move the robot in a line to the selected point (asks first)"),
            ),
            self.action_show_ext: (self.tr("J7–J11"), self.tr("Show the external axes columns (J7–J11)")),
            self.action_find: (self.tr("Find"), ""),
        }
        for action, (text, tip) in texts.items():
            action.setText(text)
            action.setToolTip(tip or text)
        for part in (self.action_bar, self.banner, self.progress_row):
            part.retranslate()
        self._model.retranslate()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- public
    @property
    def model(self) -> PointsModel:
        return self._model

    @property
    def controller(self) -> PointSyncController:
        return self._controller

    def selected_rows(self) -> list[int]:
        """Selected rows of the model (not of the filtered view), ascending."""
        rows = {self.proxy.mapToSource(index).row() for index in self.table.selectionModel().selectedRows()}
        return sorted(r for r in rows if r >= 0)

    def select_rows(self, rows: Iterable[int]) -> None:
        selection = self.table.selectionModel()
        selection.clearSelection()
        first: QModelIndex | None = None
        for row in rows:
            index = self.proxy.mapFromSource(self._model.index(row, 0))
            if not index.isValid():
                continue
            selection.select(index, selection.SelectionFlag.Select | selection.SelectionFlag.Rows)
            first = first or index
        if first is not None:
            selection.setCurrentIndex(first, selection.SelectionFlag.NoUpdate)
            self.table.scrollTo(first)

    def set_confirm(self, confirm: ConfirmFn) -> None:
        """Replace the operator's yes/no question (tests answer without a dialog)."""
        self._confirm = confirm

    def set_edit_permission(self, reason: str | None) -> None:
        """Role gating: add / duplicate / delete / reorder / cell edits only while ``reason`` is
        None; else disabled (not hidden) with ``reason`` as the tooltip."""
        self._edit_reason = reason
        lock_editing(self.table, reason is not None)
        self.retranslate()  # the usual tooltips back; _update_actions puts the reason on top
        self._update_actions()

    @Slot()
    def _say_why_not_editable(self) -> None:
        """A double click on a cell the role may not edit says why (it opened nothing)."""
        if self._edit_reason is not None:
            text = self.tr("This cell cannot be edited: {why}").format(why=self._edit_reason)
            self.show_message(text, LEVEL_WARN)

    def set_run_active(self, active: bool) -> None:
        """A plan is running: no teach / upload / move from here."""
        self._run_active = active
        self._update_actions()

    def set_alarm_hold(self, hold: bool) -> None:
        """An emergency stop or servo alarm is set: no move-to (teach and upload move nothing)."""
        self._alarm_hold = bool(hold)
        self._update_actions()

    @Slot(str, str)
    def show_message(self, text: str, level: str = LEVEL_INFO) -> None:
        colour = {LEVEL_ERROR: COLOR_ERROR, LEVEL_WARN: "#8a5300", LEVEL_INFO: COLOR_OK}.get(level, "")
        self.status.setStyleSheet(f"color: {colour};" if colour else "")
        self.status.setText(text)
        self.status.setToolTip(text)
        self.statusMessage.emit(text)

    # --- slots of the actions
    @Slot()
    def teach(self) -> None:
        self._controller.teach()

    @Slot()
    def add_point(self) -> None:
        """A new point after the selection, at the robot's current pose when the link is fresh;
        else a copy of the selected (or last) point's pose, or zeros, and the status says so."""
        rows = self.selected_rows()
        at = rows[-1] + 1 if rows else None
        start = self._controller.new_point_pose(rows[-1] if rows else None)
        try:
            row = self._model.add_point(at, pose=start.pose, tool=start.tool)
        except InvalidInput as exc:
            self.show_message(refusal_text(exc), LEVEL_ERROR)
            return
        self._clear_filter_for(row)
        self.select_rows([row])
        label = self._model.ledger[row].label
        if start.live:
            self.show_message(
                self.tr("Added {point} at the robot's current pose").format(point=label), LEVEL_INFO
            )
            return
        why = (
            self.tr("pose copied from P{id}").format(id=start.copied_from)
            if start.copied_from is not None
            else self.tr("pose set to zeros")
        )
        self.show_message(
            self.tr("Added {point}, not from the controller: no live pose ({why})").format(
                point=label, why=why
            ),
            LEVEL_WARN,
        )

    @Slot()
    def duplicate_selected(self) -> None:
        try:
            rows = self._model.duplicate_rows(self.selected_rows())
        except InvalidInput as exc:
            self.show_message(refusal_text(exc), LEVEL_ERROR)
            return
        self.select_rows(rows)

    @Slot()
    def delete_selected(self) -> None:
        rows = self.selected_rows()
        if not rows:
            return
        used = [
            (p.label, ref)
            for r in rows
            for p in [self._model.point_at(r)]
            for ref in self._model.project.references(p.id)
        ]
        n = self._model.remove_rows(rows)
        text = self.tr("Deleted {n} points (Ctrl+Z to undo)").format(n=n)
        if used:
            label, (plan, segment) = used[0]
            text += " — " + self.tr("{point} is used by plan '{plan}' segment {k}").format(
                point=label, plan=plan, k=segment + 1
            )
            self.show_message(text, LEVEL_WARN)
        else:
            self.show_message(text, LEVEL_INFO)

    def move_selected(self, delta: int) -> None:
        rows = self._model.move_rows(self.selected_rows(), delta)
        self.select_rows(rows)

    @Slot()
    def upload_selected(self) -> None:
        ids = [self._model.point_at(r).id for r in self.selected_rows()]
        self._controller.upload(ids)

    @Slot()
    def upload_all(self) -> None:
        self._controller.upload(self._model.ledger.ids())

    @Slot()
    def move_to_selected(self) -> None:
        if self._alarm_hold:
            return  # the action is disabled; a call that still arrives moves nothing
        rows = self.selected_rows()
        if len(rows) != 1:
            self.show_message(self.tr("Select one point to move to"), LEVEL_WARN)
            return
        point = self._model.point_at(rows[0])
        speed = self.sent_speed()
        refused = self.move_check(point.id, speed) if self.move_check is not None else None
        if refused:
            self.show_message(refused, LEVEL_ERROR)
            return
        question = self.tr(
            "Move the robot in a straight line to {point}?\n\n"
            "X {x:.3f}  Y {y:.3f}  Z {z:.3f}\nA {a:.3f}  B {b:.3f}  C {c:.3f}\n"
            "Speed {v} mm/s"
        ).format(
            point=point.label,
            x=point.x,
            y=point.y,
            z=point.z,
            a=point.a,
            b=point.b,
            c=point.c,
            v=f"{speed:g}",
        )
        # whatever its sync state: the move creates the point again from this pose first
        if self._confirm(self.tr("Move to point"), question):
            self._controller.move_to(point.id, speed)

    @Slot(object)
    def set_caps(self, caps: MotionCaps | None) -> None:
        """Reduced-speed mode's caps (None: off): the TCP cap is shown beside the speed, and is the
        speed a move to a point goes out at (the link's client caps it too)."""
        self._caps = caps
        self._show_move_cap()

    def sent_speed(self) -> float:
        """The speed of Move to point as it goes out: the field's, capped in reduced-speed mode."""
        speed = float(self.speed.value())
        return speed if self._caps is None else self._caps.linear_speed(speed)

    @Slot()
    def _show_move_cap(self) -> None:
        sent = self.sent_speed()
        capped = sent < self.speed.value()
        self.speed_cap.setVisible(capped)
        if capped:
            self.speed_cap.setText(self.tr("→ {cap} mm/s (reduced speed)").format(cap=f"{sent:g}"))

    # --- internals
    def _clear_filter_for(self, row: int) -> None:
        if not self.proxy.mapFromSource(self._model.index(row, 0)).isValid():
            self.find_edit.clear()

    def _focus_find(self) -> None:
        self.action_bar.focus_find()

    @Slot(bool)
    def _show_ext(self, shown: bool) -> None:
        self.table.show_ext(shown)

    @Slot(str)
    def _on_rejected(self, text: str) -> None:
        self.show_message(text, LEVEL_ERROR)

    @Slot(bool)
    def _on_restore_offered(self, offered: bool) -> None:
        self.banner.setVisible(offered)

    @Slot(int, int)
    def _on_upload_progress(self, done: int, total: int) -> None:
        self.progress_row.show_progress(done, total)

    @Slot(object)
    def _on_upload_finished(self, report: UploadReport) -> None:
        self.progress_row.hide()

    @Slot(int)
    def _on_taught(self, point_id: int) -> None:
        row = self._model.row_of(point_id)
        if row is not None:
            self._clear_filter_for(row)
            self.select_rows([row])

    @Slot()
    def _update_actions(self, *_args: Any) -> None:
        rows = self.selected_rows()
        c = self._controller
        link_ok = c.link is not None and c.connected and not c.busy and not self._run_active
        has_points = len(self._model.ledger) > 0
        self.action_teach.setEnabled(link_ok)
        self.action_duplicate.setEnabled(bool(rows))
        self.action_delete.setEnabled(bool(rows))
        self.action_move_up.setEnabled(self._model.can_move(rows, -1))
        self.action_move_down.setEnabled(self._model.can_move(rows, 1))
        self.action_upload_selected.setEnabled(link_ok and bool(rows))
        self.action_upload_all.setEnabled(link_ok and has_points)
        self.action_upload_needed.setEnabled(link_ok and has_points)
        self.action_restore_all.setEnabled(link_ok and has_points)
        self.restore_button.setEnabled(link_ok and has_points)
        self.action_cancel_upload.setEnabled(c.operation == "upload")
        self.cancel_button.setEnabled(c.operation == "upload")
        self.action_move_to.setEnabled(link_ok and len(rows) == 1 and not self._alarm_hold)
        self.upload_button.setEnabled(link_ok and has_points)
        edits = (
            self.action_add,
            self.action_duplicate,
            self.action_delete,
            self.action_move_up,
            self.action_move_down,
        )
        self.action_add.setEnabled(True)
        for action in edits:
            action.setEnabled(action.isEnabled() and self._edit_reason is None)
            if self._edit_reason:
                action.setToolTip(self._edit_reason)
