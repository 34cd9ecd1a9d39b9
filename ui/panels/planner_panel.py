"""Trajectory planner panel: plans of the project, their segments, checks, preview and runs.

Layout: on the left the plan list (name, loops, segments; add / duplicate / delete, rename
and loops edited in place) and the run controls (Run, Run from here, Step, Pause, Resume,
Stop, Resume from k; progress "segment k of n, loop i of m"); in the middle the segment table
(editable, undoable) with the checks on their rows and a summary line; on the right the
preview (top / front / side) with lengths and times.

Checks (:func:`app.plan.segments.check_plan`), estimates and the preview are recomputed whenever the
plan, the points or the selection change. Before a run the checks are made again from the
robot's current pose: errors refuse the run, points that need an upload are offered for upload
("1 point needs upload — Upload now?") and the run starts when the upload succeeded.

The robot is driven by a :class:`~ui.controllers.plan_run_controller.PlanRunController`; uploads go through
a :class:`~ui.panels.points_panel.PointSyncController`. Questions to the operator go through the
injectable ``confirm(title, text) -> bool`` callable.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from PySide6.QtCore import QAbstractItemModel, QEvent, QModelIndex, QPersistentModelIndex, Qt, Signal, Slot
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QProgressBar,
    QPushButton,
    QSizePolicy,
    QSplitter,
    QStyledItemDelegate,
    QStyleOptionViewItem,
    QTableView,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.errors import InvalidInput, TeachPadError
from app.models import Pose
from app.plan.runner import RunEvent, RunOutcome, RunProgress, RunState
from app.plan.segments import (
    IssueKind,
    Plan,
    PlanIssue,
    PlanLimits,
    SegmentKind,
    check_plan,
    estimate_plan,
    ids_needing_upload,
    plan_path,
)
from app.points.ledger import UploadReport
from ui.controllers.plan_run_controller import PlanRunController
from ui.controllers.point_sync import PointSyncController
from ui.dialogs.confirm import ConfirmFn, ask_confirmation
from ui.models.plan_model import (
    COL_END,
    COL_IGNORE,
    COL_INDEX,
    COL_KIND,
    COL_LENGTH,
    COL_ORIENTATION,
    COL_SPEED,
    COL_TOOL,
    COL_VIA,
    PLAN_COL_NAME,
    PlanListModel,
    SegmentTableModel,
    kind_text,
    orientation_text,
)
from ui.models.points_model import PointsModel
from ui.panels.plan_preview import PlanPreview
from ui.widgets_common import COLOR_ERROR, COLOR_INFO, COLOR_OK, COLOR_WARN

ModelIndex = QModelIndex | QPersistentModelIndex


# --------------------------------------------------------------------------------------------
# Delegates
# --------------------------------------------------------------------------------------------


class ChoiceDelegate(QStyledItemDelegate):
    """A combo box of fixed choices: ``choices()`` gives ``(value, text)`` pairs."""

    def __init__(self, choices: Callable[[], Sequence[tuple[str, str]]],
                 parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._choices = choices

    def createEditor(self, parent: QWidget, option: QStyleOptionViewItem, index: ModelIndex) -> QWidget:
        combo = QComboBox(parent)
        for value, text in self._choices():
            combo.addItem(text, value)
        return combo

    def setEditorData(self, editor: QWidget, index: ModelIndex) -> None:
        assert isinstance(editor, QComboBox)
        found = editor.findData(index.data(Qt.ItemDataRole.EditRole))
        editor.setCurrentIndex(max(found, 0))

    def setModelData(self, editor: QWidget, model: QAbstractItemModel, index: ModelIndex) -> None:
        assert isinstance(editor, QComboBox)
        model.setData(index, editor.currentData(), Qt.ItemDataRole.EditRole)


class PointRefDelegate(QStyledItemDelegate):
    """An editable combo box of the ledger's points (``P5  name``); typing an id works too."""

    def __init__(self, points: PointsModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._points = points

    def createEditor(self, parent: QWidget, option: QStyleOptionViewItem, index: ModelIndex) -> QWidget:
        combo = QComboBox(parent)
        combo.setEditable(True)
        combo.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        for point in self._points.ledger:
            combo.addItem(f"P{point.id}  {point.name}".rstrip(), str(point.id))
        return combo

    def setEditorData(self, editor: QWidget, index: ModelIndex) -> None:
        assert isinstance(editor, QComboBox)
        value = str(index.data(Qt.ItemDataRole.EditRole) or "")
        found = editor.findData(value)
        if found >= 0:
            editor.setCurrentIndex(found)
        else:
            editor.setEditText(value)

    def setModelData(self, editor: QWidget, model: QAbstractItemModel, index: ModelIndex) -> None:
        assert isinstance(editor, QComboBox)
        text = editor.currentText()
        found = editor.findText(text)
        model.setData(index, editor.itemData(found) if found >= 0 else text, Qt.ItemDataRole.EditRole)


# --------------------------------------------------------------------------------------------
# The panel
# --------------------------------------------------------------------------------------------


class PlannerPanel(QWidget):
    """Plans, segments, checks, preview and run controls (see the module docstring).

    Public: ``action_*`` QActions (add / duplicate / delete plan, add line / arc, delete /
    move segment, run, run from here, step, pause, resume, stop, resume from k, upload now,
    check); :meth:`select_plan`, :meth:`current_plan`, :meth:`selected_segments`,
    :meth:`recheck`, :meth:`run`; ``segments`` (the :class:`SegmentTableModel`),
    ``preview``; signal ``statusMessage(str)``.
    """

    statusMessage = Signal(str)

    def __init__(self, plans: PlanListModel, points: PointsModel,
                 run_controller: PlanRunController | None = None,
                 point_sync: PointSyncController | None = None, parent: QWidget | None = None, *,
                 confirm: ConfirmFn | None = None, limits: PlanLimits | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("PlannerPanel")
        self._plans = plans
        self._points = points
        self._runner = run_controller or PlanRunController(parent=self)
        self._sync = point_sync
        self._confirm = confirm or ask_confirmation(self)
        self.limits = limits or PlanLimits()
        self._issues: list[PlanIssue] = []
        self._pending_run: tuple[int, bool, bool] | None = None  # (start, single, resume) after an upload
        self._next_step: tuple[int, int] | None = None
        self._run_plan: Plan | None = None
        self._run_revision = -1  # the run plan's revision when the run started
        self._summary_text = ""
        self._previewed: Plan | None = None  # the plan the preview's view range was fitted to
        self._pose_known = False

        self.segments = SegmentTableModel(plans.undo_stack, points.ledger, self)
        self._make_actions()
        self._build()
        self.retranslate()

        plans.modelReset.connect(self._on_plans_reset)
        plans.rowsInserted.connect(self._on_plans_inserted)
        plans.rowsRemoved.connect(self._on_plans_removed)
        plans.planChanged.connect(self._on_plan_changed)
        plans.editRejected.connect(lambda text: self.show_message(text, "error"))
        self.segments.listEdited.connect(self._on_segments_edited)
        self.segments.modelReset.connect(self.recheck)
        self.segments.planShown.connect(self._on_plan_shown)
        self.segments.editRejected.connect(lambda text: self.show_message(text, "error"))
        for signal in (points.dataChanged, points.rowsInserted, points.rowsRemoved, points.rowsMoved,
                       points.modelReset, points.planReferencesChanged):
            signal.connect(self._on_points_changed)
        points.modelReset.connect(lambda: self.segments.set_ledger(points.ledger))
        self.plan_view.selectionModel().currentRowChanged.connect(self._on_plan_row)
        self.segment_view.selectionModel().selectionChanged.connect(self._on_segment_selection)

        r = self._runner
        r.runningChanged.connect(self._on_running)
        r.pausedChanged.connect(self._update_actions)
        r.connectedChanged.connect(self._update_actions)
        r.progressChanged.connect(self._on_progress)
        r.runFinished.connect(self._on_run_finished)
        r.poseChanged.connect(self.preview.on_pose)
        r.poseChanged.connect(self._on_pose)
        if point_sync is not None:
            r.pointsMissing.connect(point_sync.points_missing)
            point_sync.busyChanged.connect(self._update_actions)
            point_sync.uploadFinished.connect(self._on_upload_finished)

        if plans.rowCount():
            self.select_plan(0)
        self._update_actions()

    # --- construction
    def _make_actions(self) -> None:
        def act(slot: Callable[[], Any], shortcut: str | None = None) -> QAction:
            action = QAction(self)
            if shortcut:
                action.setShortcut(QKeySequence(shortcut))
                action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.triggered.connect(slot)
            self.addAction(action)
            return action

        self.action_add_plan = act(self.add_plan)
        self.action_rename_plan = act(self.rename_plan, "F2")
        self.action_duplicate_plan = act(self.duplicate_plan)
        self.action_delete_plan = act(self.delete_plan)
        self.action_add_line = act(lambda: self.add_segment(SegmentKind.LINE), "Ctrl+L")
        self.action_add_arc = act(lambda: self.add_segment(SegmentKind.ARC), "Ctrl+Shift+A")
        self.action_delete_segment = act(self.delete_segments)
        self.action_segment_up = act(lambda: self.move_segments(-1), "Alt+Up")
        self.action_segment_down = act(lambda: self.move_segments(1), "Alt+Down")
        self.action_check = act(self.recheck)
        self.action_upload_now = act(self.upload_needed)
        self.action_run = act(lambda: self.run(0), "F5")
        self.action_run_from = act(self.run_from_selected, "Shift+F5")
        self.action_step = act(self.step, "F10")
        self.action_pause = act(self._runner.pause)
        self.action_resume = act(self._runner.resume)
        self.action_stop = act(self.stop)
        self.action_resume_from = act(self.resume_from)

    @staticmethod
    def _button(action: QAction, *, bold: bool = False) -> QToolButton:
        button = QToolButton()
        button.setDefaultAction(action)
        button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        button.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        button.setMinimumHeight(28)
        if bold:
            font = button.font()
            font.setBold(True)
            button.setFont(font)
        return button

    def _build(self) -> None:
        # left: plans + run controls
        self.plan_view = QTableView(self)
        self.plan_view.setModel(self._plans)
        self.plan_view.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.plan_view.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.plan_view.verticalHeader().setVisible(False)
        self.plan_view.verticalHeader().setDefaultSectionSize(24)
        header = self.plan_view.horizontalHeader()
        header.setSectionResizeMode(PLAN_COL_NAME, QHeaderView.ResizeMode.Stretch)
        header.setSectionResizeMode(1, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(2, QHeaderView.ResizeMode.ResizeToContents)
        plan_buttons = QHBoxLayout()
        for action in (self.action_add_plan, self.action_rename_plan, self.action_duplicate_plan,
                       self.action_delete_plan):
            plan_buttons.addWidget(self._button(action))
        plan_buttons.setSpacing(3)
        self.plans_box = QGroupBox(self)
        plans_layout = QVBoxLayout(self.plans_box)
        plans_layout.addWidget(self.plan_view, 1)
        plans_layout.addLayout(plan_buttons)

        self.run_box = QGroupBox(self)
        run_layout = QVBoxLayout(self.run_box)
        row1 = QHBoxLayout()
        row1.addWidget(self._button(self.action_run, bold=True))
        row1.addWidget(self._button(self.action_run_from))
        row1.addWidget(self._button(self.action_step))
        row2 = QHBoxLayout()
        row2.addWidget(self._button(self.action_pause))
        row2.addWidget(self._button(self.action_resume))
        stop = self._button(self.action_stop, bold=True)
        stop.setStyleSheet(f"QToolButton:enabled {{ color: {COLOR_ERROR}; }}")
        row2.addWidget(stop)
        self.resume_from_button = self._button(self.action_resume_from)
        self.run_label = QLabel(self)
        self.run_label.setWordWrap(True)
        self.run_progress = QProgressBar(self)
        self.run_progress.setTextVisible(False)
        self.run_progress.setMaximumHeight(10)
        run_layout.addLayout(row1)
        run_layout.addLayout(row2)
        run_layout.addWidget(self.resume_from_button)
        run_layout.addWidget(self.run_progress)
        run_layout.addWidget(self.run_label)

        left = QWidget(self)
        left_layout = QVBoxLayout(left)
        left_layout.setContentsMargins(0, 0, 0, 0)
        left_layout.addWidget(self.plans_box, 1)
        left_layout.addWidget(self.run_box)

        # middle: segments
        self.segment_view = QTableView(self)
        view = self.segment_view
        view.setModel(self.segments)
        view.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        view.setSelectionMode(QAbstractItemView.SelectionMode.ExtendedSelection)
        view.setEditTriggers(QAbstractItemView.EditTrigger.DoubleClicked
                             | QAbstractItemView.EditTrigger.EditKeyPressed
                             | QAbstractItemView.EditTrigger.SelectedClicked)
        view.verticalHeader().setDefaultSectionSize(24)
        view.verticalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Fixed)
        view.setWordWrap(False)
        view.setAlternatingRowColors(True)
        self._kind_delegate = ChoiceDelegate(
            lambda: [(k.value, kind_text(k)) for k in SegmentKind], view)
        self._orientation_delegate = ChoiceDelegate(
            lambda: [("changes", orientation_text(True)), ("kept", orientation_text(False))], view)
        self._point_delegate = PointRefDelegate(self._points, view)
        view.setItemDelegateForColumn(COL_KIND, self._kind_delegate)
        view.setItemDelegateForColumn(COL_ORIENTATION, self._orientation_delegate)
        view.setItemDelegateForColumn(COL_VIA, self._point_delegate)
        view.setItemDelegateForColumn(COL_END, self._point_delegate)
        seg_header = view.horizontalHeader()
        seg_header.setStretchLastSection(True)
        widths = {COL_INDEX: 50, COL_KIND: 50, COL_VIA: 104, COL_END: 104, COL_SPEED: 78, COL_ORIENTATION: 78,
                  COL_IGNORE: 84, COL_TOOL: 60, COL_LENGTH: 76}
        for column in range(self.segments.columnCount()):
            view.setColumnWidth(column, widths.get(column, 60))

        seg_buttons = QHBoxLayout()
        for action in (self.action_add_line, self.action_add_arc, self.action_delete_segment,
                       self.action_segment_up, self.action_segment_down):
            seg_buttons.addWidget(self._button(action))
        seg_buttons.addStretch(1)
        self.summary = QLabel(self)
        self.summary.setWordWrap(True)
        self.summary.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.upload_button = QPushButton(self)
        self.upload_button.clicked.connect(self.upload_needed)
        self.check_button = QPushButton(self)
        self.check_button.clicked.connect(self.recheck)
        summary_row = QHBoxLayout()
        summary_row.addWidget(self.summary, 1)
        summary_row.addWidget(self.upload_button)
        summary_row.addWidget(self.check_button)
        self.segments_box = QGroupBox(self)
        seg_layout = QVBoxLayout(self.segments_box)
        seg_layout.addLayout(seg_buttons)
        seg_layout.addWidget(view, 1)
        seg_layout.addLayout(summary_row)

        # right: preview
        self.preview = PlanPreview(self)
        self.preview_box = QGroupBox(self)
        preview_layout = QVBoxLayout(self.preview_box)
        preview_layout.addWidget(self.preview)

        # plans and segments side by side on top, the preview across the full width below:
        # the three projections stay readable on a 1280 px screen
        top = QSplitter(Qt.Orientation.Horizontal, self)
        top.addWidget(left)
        top.addWidget(self.segments_box)
        top.setStretchFactor(0, 0)
        top.setStretchFactor(1, 1)
        top.setSizes([230, 1050])
        top.setChildrenCollapsible(False)
        self.splitter = top
        outer = QSplitter(Qt.Orientation.Vertical, self)
        outer.addWidget(top)
        outer.addWidget(self.preview_box)
        outer.setStretchFactor(0, 1)
        outer.setStretchFactor(1, 1)
        outer.setSizes([340, 400])
        outer.setChildrenCollapsible(False)
        self.outer_splitter = outer

        self.status = QLabel(self)
        self.status.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.addWidget(outer, 1)
        layout.addWidget(self.status)

    def retranslate(self) -> None:
        texts = {
            self.action_add_plan: (self.tr("Add"), self.tr("Add an empty plan")),
            self.action_rename_plan: (self.tr("Rename"), self.tr("Rename the selected plan (F2)")),
            self.action_duplicate_plan: (self.tr("Duplicate"), self.tr("Copy the selected plan")),
            self.action_delete_plan: (self.tr("Delete"),
                                      self.tr("Delete the selected plan (Ctrl+Z to undo)")),
            self.action_add_line: (self.tr("+ Line"),
                                   self.tr("Add a line segment after the selection (Ctrl+L)")),
            self.action_add_arc: (self.tr("+ Arc"), self.tr("Add an arc segment after the selection")),
            self.action_delete_segment: (self.tr("Delete"), self.tr("Delete the selected segments")),
            self.action_segment_up: ("▲", self.tr("Move the selected segments up (Alt+Up)")),
            self.action_segment_down: ("▼", self.tr("Move the selected segments down (Alt+Down)")),
            self.action_check: (self.tr("Check"), self.tr("Check the plan from the robot's current pose")),
            self.action_upload_now: (self.tr("Upload now"), self.tr("Upload the points the plan needs")),
            self.action_run: (self.tr("Run"), self.tr("Run the plan from the first segment (F5)")),
            self.action_run_from: (self.tr("Run from here"),
                                   self.tr("Run from the selected segment (Shift+F5)")),
            self.action_step: (self.tr("Step"), self.tr("Run one segment, then stop (F10)")),
            self.action_pause: (self.tr("Pause"), self.tr("Pause the motion")),
            self.action_resume: (self.tr("Resume"), self.tr("Resume the paused motion")),
            self.action_stop: (self.tr("Stop"), self.tr("Stop the robot and the run")),
            self.action_resume_from: (self.tr("Resume from segment"), self.tr("Continue the stopped run")),
        }
        for action, (text, tip) in texts.items():
            action.setText(text)
            action.setToolTip(tip)
        self.plans_box.setTitle(self.tr("Plans"))
        self.run_box.setTitle(self.tr("Run"))
        self.segments_box.setTitle(self.tr("Segments"))
        self.preview_box.setTitle(self.tr("Preview"))
        self.upload_button.setText(self.tr("Upload now"))
        self.check_button.setText(self.tr("Check"))
        self._plans.retranslate()
        self.segments.retranslate()
        self._update_resume_text()
        self.recheck()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- public
    @property
    def run_controller(self) -> PlanRunController:
        return self._runner

    @property
    def point_sync(self) -> PointSyncController | None:
        return self._sync

    @property
    def issues(self) -> list[PlanIssue]:
        return list(self._issues)

    @property
    def summary_text(self) -> str:
        return self._summary_text

    def current_plan(self) -> Plan | None:
        return self.segments.plan

    def select_plan(self, row: int) -> None:
        if 0 <= row < self._plans.rowCount():
            self.plan_view.selectRow(row)
            self.plan_view.setCurrentIndex(self._plans.index(row, PLAN_COL_NAME))
        self.segments.set_plan(self._plans.plan_at(row) if 0 <= row < self._plans.rowCount() else None)

    def selected_segments(self) -> list[int]:
        return sorted({i.row() for i in self.segment_view.selectionModel().selectedRows()})

    def select_segments(self, rows: Sequence[int]) -> None:
        selection = self.segment_view.selectionModel()
        selection.clearSelection()
        for row in rows:
            selection.select(self.segments.index(row, 0),
                             selection.SelectionFlag.Select | selection.SelectionFlag.Rows)
        if rows:
            selection.setCurrentIndex(self.segments.index(rows[0], 0), selection.SelectionFlag.NoUpdate)
            self.segment_view.scrollTo(self.segments.index(rows[0], 0))

    def set_confirm(self, confirm: ConfirmFn) -> None:
        """Replace the operator's yes/no question (tests answer without a dialog)."""
        self._confirm = confirm

    @Slot(str, str)
    def show_message(self, text: str, level: str = "info") -> None:
        colour = {"error": COLOR_ERROR, "warn": "#8a5300", "info": COLOR_OK}.get(level, "")
        self.status.setStyleSheet(f"color: {colour};" if colour else "")
        self.status.setText(text)
        self.status.setToolTip(text)
        self.statusMessage.emit(text)

    # --- plans and segments
    @Slot()
    def add_plan(self) -> None:
        row = self._plans.add_plan()
        self.select_plan(row)

    @Slot()
    def rename_plan(self) -> None:
        """Edit the selected plan's name in place (undoable like every edit)."""
        row = self.plan_view.currentIndex().row()
        if row >= 0:
            self.plan_view.setFocus()
            self.plan_view.edit(self._plans.index(row, PLAN_COL_NAME))

    @Slot()
    def duplicate_plan(self) -> None:
        row = self.plan_view.currentIndex().row()
        if row >= 0:
            self.select_plan(self._plans.duplicate_plan(row))

    @Slot()
    def delete_plan(self) -> None:
        row = self.plan_view.currentIndex().row()
        if row < 0:
            return
        name = self._plans.plan_at(row).name
        self._plans.remove_plan(row)
        self.select_plan(min(row, self._plans.rowCount() - 1))
        self.show_message(self.tr("Deleted plan {name} (Ctrl+Z to undo)").format(name=name))

    def add_segment(self, kind: SegmentKind) -> None:
        if self.current_plan() is None:
            self.add_plan()
        rows = self.selected_segments()
        at = rows[-1] + 1 if rows else None
        try:
            row = self.segments.insert_segment(at, kind)
        except InvalidInput as exc:
            self.show_message(str(exc), "error")
            return
        self.select_segments([row])

    @Slot()
    def delete_segments(self) -> None:
        rows = self.selected_segments()
        try:
            n = self.segments.remove_rows(rows)
        except InvalidInput as exc:
            self.show_message(str(exc), "error")
            return
        if n:
            left = min(rows[0], self.segments.rowCount() - 1)
            self.select_segments([left] if left >= 0 else [])

    def move_segments(self, delta: int) -> None:
        try:
            rows = self.segments.move_rows(self.selected_segments(), delta)
        except InvalidInput as exc:
            self.show_message(str(exc), "error")
            return
        self.select_segments(rows)

    # --- checks, estimates, preview
    def _pose(self) -> Pose | None:
        return self._runner.last_pose

    @Slot()
    def recheck(self) -> None:
        """Checks, estimates and preview of the plan on display."""
        plan = self.current_plan()
        ledger = self._points.ledger
        if plan is None:
            self._issues = []
            self.preview.clear()
            self._set_summary([], None)
            self.preview.set_info("")
            return
        pose = self._pose()
        start, assumed = self._start_of(plan)
        self._issues = check_plan(plan, ledger, self.limits, pose, loops=plan.loops)
        self.segments.set_issues(self._issues)
        estimate = estimate_plan(plan, ledger, start)
        self.segments.set_estimate(estimate.lengths, estimate.times)
        self.preview.set_path(plan_path(plan, ledger, start), keep_view=plan is self._previewed)
        self._previewed = plan
        ids = sorted(plan.point_ids())
        used = [ledger.get(pid) for pid in ids]
        present = [p for p in used if p is not None]
        self.preview.set_points(np.array([p.xyz for p in present], dtype=np.float64).reshape(-1, 3),
                                [f"P{p.id}" for p in present])
        self.preview.set_start(start)
        self.preview.set_selected(self._selected_index())
        self._set_summary(self._issues, plan)
        self._set_info(plan, estimate, assumed)

    def _start_of(self, plan: Plan) -> tuple[Any, bool]:
        pose = self._pose()
        if pose is not None:
            return (pose.x, pose.y, pose.z), False
        if len(plan):
            last = self._points.ledger.get(plan[len(plan) - 1].end_id)
            if last is not None:
                return last.xyz, True
        return None, True

    def _selected_index(self) -> int | None:
        rows = self.selected_segments()
        return rows[0] if rows else None

    def _set_summary(self, issues: Sequence[PlanIssue], plan: Plan | None) -> None:
        errors = sum(1 for i in issues if i.kind is IssueKind.ERROR)
        warnings = sum(1 for i in issues if i.kind is IssueKind.WARNING)
        uploads = len(ids_needing_upload(issues))
        parts: list[str] = []
        if errors:
            parts.append(self.tr("%n error(s)", "", errors))
        if uploads:
            parts.append(self.tr("%n point(s) need upload", "", uploads))
        if warnings:
            parts.append(self.tr("%n warning(s)", "", warnings))
        if plan is None:
            text, colour = "", ""
        elif not parts:
            text, colour = self.tr("Checks passed: ready to run"), COLOR_OK
        else:
            text = ", ".join(parts)
            colour = COLOR_ERROR if errors else (COLOR_INFO if uploads else COLOR_WARN)
            if uploads and self._sync is not None:
                text += " — " + self.tr("Upload now?")
            row_errors = [i for i in issues if i.kind is IssueKind.ERROR and i.segment is not None]
            if row_errors:
                text += "\n" + row_errors[0].message
        whole = [i.message for i in issues if i.segment is None]
        if whole:
            text += "\n" + "\n".join(whole)
        self._summary_text = text
        self.summary.setText(text)
        self.summary.setStyleSheet(f"color: {colour};" if colour else "")
        self.summary.setToolTip("\n".join(str(i) for i in issues))
        self.upload_button.setVisible(bool(uploads) and self._sync is not None)
        self._update_actions()

    def _set_info(self, plan: Plan, estimate: Any, assumed: bool) -> None:
        def fmt_len(v: float) -> str:
            return "∞" if math.isinf(v) else f"{v:,.1f} mm"

        def fmt_time(v: float) -> str:
            if math.isinf(v):
                return "∞"
            minutes, seconds = divmod(v, 60.0)
            return f"{int(minutes)} min {seconds:04.1f} s" if minutes else f"{seconds:.1f} s"

        loops = self.tr("endless") if plan.loops == 0 else str(plan.loops)
        lines = [
            self.tr("<b>{name}</b>: {n} segments, loops: {loops}").format(name=plan.name, n=len(plan),
                                                                         loops=loops),
            self.tr("One loop: {length}, {time}").format(length=fmt_len(estimate.loop_length),
                                                        time=fmt_time(estimate.loop_time)),
            self.tr("Total: {length}, {time}").format(length=fmt_len(estimate.total_length),
                                                     time=fmt_time(estimate.total_time)),
        ]
        if estimate.unknown:
            lines.append(self.tr("Not counted (unknown length): segments {list}").format(
                list=", ".join(str(i + 1) for i in estimate.unknown[:10])))
        index = self._selected_index()
        if index is not None and index < len(plan):
            length, time = float(estimate.lengths[index]), float(estimate.times[index])
            if math.isfinite(length):
                lines.append(self.tr("Segment {k}: {length}, {time}").format(
                    k=index + 1, length=fmt_len(length), time=fmt_time(time)))
        lines.append(self.tr("Start: end of the last segment (robot pose unknown)") if assumed
                     else self.tr("Start: the robot's current pose"))
        self.preview.set_info("<br>".join(lines))

    # --- running
    def _plan_for_run(self) -> Plan | None:
        plan = self.current_plan()
        if plan is None or not len(plan):
            self.show_message(self.tr("The plan has no segments"), "error")
            return None
        if self._sync is not None and self._sync.busy:
            self.show_message(self.tr("Wait until the point upload or move ends"), "warn")
            return None
        return plan

    def run(self, start: int = 0, single: bool = False, *, resume: bool = False) -> bool:
        """Check, offer an upload, confirm, then run from ``start`` (``single``: one segment).
        Returns True when the run (or the upload before it) started."""
        plan = self._plan_for_run()
        if plan is None:
            return False
        if not self._runner.connected:
            self.show_message(self.tr("Not connected to a controller"), "error")
            return False
        pose = self._pose()
        issues = check_plan(plan, self._points.ledger, self.limits, pose, start_index=start,
                            loops=1 if single else plan.loops)
        self._issues = issues
        self.segments.set_issues(issues)
        self._set_summary(issues, plan)
        errors = [i for i in issues if i.kind is IssueKind.ERROR]
        if errors:
            first = errors[0]
            if first.segment is not None:
                self.select_segments([first.segment])
            self.show_message(self.tr("Cannot run: {summary}. First: {message}").format(
                summary=self._summary_text.split("\n")[0], message=first.message), "error")
            return False
        needs = ids_needing_upload(issues)
        if needs:
            if self._sync is None:
                self.show_message(self.tr("Cannot run: %n point(s) need upload", "", len(needs)), "error")
                return False
            question = self.tr("%n point(s) of the plan are not on the controller: ", "", len(needs))
            question += ", ".join(f"P{pid}" for pid in needs[:20]) + "\n\n" + self.tr("Upload now, then run?")
            if not self._confirm(self.tr("Upload points"), question):
                return False
            if self._sync.upload(needs):
                self._pending_run = (start, single, resume)
                return True
            return False
        return self._confirm_and_start(plan, start, single, resume)

    def _confirm_and_start(self, plan: Plan, start: int, single: bool, resume: bool) -> bool:
        warnings = [i for i in self._issues if i.kind is IssueKind.WARNING]
        if resume:
            k = (self._runner.resume_from or 0) + 1
            what = self.tr("Resume plan '{name}' from segment {k}?").format(name=plan.name, k=k)
        elif single:
            what = self.tr("Run segment {k} of plan '{name}' (one step)?").format(k=start + 1, name=plan.name)
        elif start:
            what = self.tr("Run plan '{name}' from segment {k}?").format(name=plan.name, k=start + 1)
        else:
            what = self.tr("Run plan '{name}'?").format(name=plan.name)
        text = what + "\n\n" + self.tr("The robot will move.")
        if warnings:
            text += "\n\n" + self.tr("Warnings:") + "\n" + "\n".join(f"• {w.message}" for w in warnings[:8])
        if not self._confirm(self.tr("Run plan"), text):
            return False
        try:
            if resume and plan is self._run_plan and plan.revision == self._run_revision:
                self._runner.resume_run()
            elif resume:
                # the plan was edited since: a new run of the current segments from the same place
                loop = self._runner.resume_loop or 1
                self._run_revision = plan.revision
                self._runner.start(plan, start=start, start_loop=loop)
            else:
                loop = 1
                if single and self._next_step is not None and self._next_step[0] == start:
                    loop = self._next_step[1]
                self._run_plan = plan
                self._run_revision = plan.revision
                self._runner.start(plan, start=start, start_loop=loop, single=single)
        except (TeachPadError, RuntimeError) as exc:
            self.show_message(str(exc), "error")
            return False
        return True

    @Slot()
    def run_from_selected(self) -> None:
        rows = self.selected_segments()
        self.run(rows[0] if rows else 0)

    @Slot()
    def step(self) -> None:
        rows = self.selected_segments()
        start = rows[0] if rows else (self._next_step[0] if self._next_step else 0)
        self.run(start, single=True)

    @Slot()
    def stop(self) -> None:
        self._pending_run = None
        self._runner.stop()
        if self._sync is not None and self._sync.operation == "upload":
            self._sync.cancel_upload()

    @Slot()
    def resume_from(self) -> None:
        """"Resume from k": re-check from segment k, then continue the stopped run."""
        k = self._runner.resume_from
        if k is None:
            return
        if self._run_plan is not None and self._run_plan is not self.current_plan():
            row = self._plans.row_of(self._run_plan)
            if row is not None:
                self.select_plan(row)
        self.run(k, resume=True)

    @Slot()
    def upload_needed(self) -> None:
        plan = self.current_plan()
        if plan is None or self._sync is None:
            return
        ids = ids_needing_upload(self._issues)
        if ids:
            self._sync.upload(ids)

    # --- reactions
    @Slot(object)
    def _on_upload_finished(self, report: UploadReport) -> None:
        pending, self._pending_run = self._pending_run, None
        self.recheck()
        if pending is None:
            return
        if not report.all_ok:
            self.show_message(self.tr("The upload did not complete: the plan was not started"), "error")
            return
        plan = self.current_plan()
        if plan is not None:
            start, single, resume = pending
            self._confirm_and_start(plan, start, single, resume)

    @Slot(bool)
    def _on_running(self, running: bool) -> None:
        self.segments.set_locked(running)
        self.plan_view.setEnabled(not running)
        if running:
            self.recheck()  # from the pose the run starts at
            self.preview.start_live()
            self.segments.set_run_marker(None, None)
        else:
            self.preview.stop_live()
        self._update_actions()

    @Slot(object)
    def _on_progress(self, progress: RunProgress) -> None:
        if progress.event is RunEvent.SEGMENT_STARTED:
            self.segments.set_run_marker(progress.index, None)
        loops = self.tr("endless") if progress.loops == 0 else str(progress.loops)
        self.run_label.setText(self.tr("Segment {k} of {n}, loop {i} of {m}").format(
            k=progress.index + 1, n=progress.count, i=progress.loop, m=loops))
        if progress.loops:
            total = progress.count * progress.loops
            done = (progress.loop - 1) * progress.count + progress.index
            if progress.event is RunEvent.SEGMENT_DONE:
                done += 1
            self.run_progress.setRange(0, total)
            self.run_progress.setValue(min(done, total))
        else:
            self.run_progress.setRange(0, 0)

    @Slot(object)
    def _on_run_finished(self, outcome: RunOutcome) -> None:
        if outcome.state is RunState.FINISHED:
            self.segments.set_run_marker(None, None)
            self.run_progress.setRange(0, 1)
            self.run_progress.setValue(1)
            self.run_label.setText(self.tr("Finished: {n} segments run").format(n=outcome.segments_done))
            self.show_message(self.tr("Plan finished"), "info")
            self._next_step = outcome.next_position
            if outcome.next_position is not None and self.current_plan() is self._run_plan:
                self.select_segments([outcome.next_position[0]])
        else:
            k = outcome.resume_from
            self.segments.set_run_marker(None, k if outcome.state is RunState.FAILED else None)
            if k is not None and self.current_plan() is self._run_plan:
                self.select_segments([k])
            level = "error" if outcome.state is RunState.FAILED else "warn"
            label = self.tr("Failed") if outcome.state is RunState.FAILED else self.tr("Stopped")
            self.run_label.setText(f"{label}: {outcome.message}")
            self.show_message(f"{label}: {outcome.message}", level)
        self._update_resume_text()
        self._update_actions()

    def _update_resume_text(self) -> None:
        k = self._runner.resume_from if self._runner.can_resume else None
        self.action_resume_from.setText(self.tr("Resume from segment {k}").format(k=k + 1) if k is not None
                                        else self.tr("Resume from segment"))

    @Slot()
    def _on_plans_reset(self) -> None:
        self.segments.set_ledger(self._points.ledger)
        self.select_plan(0 if self._plans.rowCount() else -1)

    @Slot(QModelIndex, int, int)
    def _on_plans_inserted(self, parent: QModelIndex, first: int, last: int) -> None:
        self.select_plan(first)

    @Slot(QModelIndex, int, int)
    def _on_plans_removed(self, parent: QModelIndex, first: int, last: int) -> None:
        plan = self.current_plan()
        if plan is not None and self._plans.row_of(plan) is None:
            self.select_plan(min(first, self._plans.rowCount() - 1))

    @Slot(object)
    def _on_plan_changed(self, plan: object) -> None:
        if plan is self.current_plan():
            self.recheck()

    @Slot(object)
    def _on_plan_shown(self, plan: object) -> None:
        row = self._plans.row_of(plan) if isinstance(plan, Plan) else None
        if row is not None:
            self.plan_view.blockSignals(True)
            self.plan_view.selectRow(row)
            self.plan_view.blockSignals(False)

    @Slot(object)
    def _on_segments_edited(self, plan: object) -> None:
        self._plans.refresh_plan(plan)
        self.recheck()

    @Slot()
    def _on_points_changed(self, *_args: Any) -> None:
        self.segments.refresh()
        self.recheck()

    @Slot(QModelIndex, QModelIndex)
    def _on_plan_row(self, current: QModelIndex, previous: QModelIndex) -> None:
        row = current.row()
        plan = self._plans.plan_at(row) if 0 <= row < self._plans.rowCount() else None
        self.segments.set_plan(plan)
        r = self._runner
        if not r.running:
            self.preview.clear_live()  # the last run's TCP trail belongs to its plan
            if plan is not None and plan is self._run_plan and r.can_resume and r.outcome is not None:
                failed = r.resume_from if r.outcome.state is RunState.FAILED else None
                self.segments.set_run_marker(None, failed)
        self._update_actions()

    @Slot(object)
    def _on_pose(self, pose: Pose) -> None:
        if not self._pose_known:
            # the first pose: segment 1 now starts at the robot, not at an assumed point
            self._pose_known = True
            if not self._runner.running:
                self.recheck()

    @Slot()
    def _on_segment_selection(self, *_args: Any) -> None:
        index = self._selected_index()
        self.preview.set_selected(index)
        plan = self.current_plan()
        if plan is not None and len(plan):
            start, assumed = self._start_of(plan)
            self._set_info(plan, estimate_plan(plan, self._points.ledger, start), assumed)
        self._update_actions()

    @Slot()
    def _update_actions(self, *_args: Any) -> None:
        r = self._runner
        running = r.running
        plan = self.current_plan()
        has_plan = plan is not None
        has_segments = has_plan and len(plan or ()) > 0
        rows = self.selected_segments()
        sync_busy = self._sync is not None and self._sync.busy
        can_start = r.connected and not running and has_segments and not sync_busy
        editable = has_plan and not running
        self.action_add_plan.setEnabled(not running)
        self.action_duplicate_plan.setEnabled(has_plan and not running)
        self.action_rename_plan.setEnabled(has_plan and not running)
        self.action_delete_plan.setEnabled(has_plan and not running)
        self.action_add_line.setEnabled(not running)
        self.action_add_arc.setEnabled(not running)
        self.action_delete_segment.setEnabled(editable and bool(rows))
        self.action_segment_up.setEnabled(editable and self.segments.can_move(rows, -1))
        self.action_segment_down.setEnabled(editable and self.segments.can_move(rows, 1))
        self.action_run.setEnabled(can_start)
        self.action_run_from.setEnabled(can_start and bool(rows))
        self.action_step.setEnabled(can_start)
        self.action_pause.setEnabled(running and not r.paused)
        self.action_resume.setEnabled(running and r.paused)
        self.action_stop.setEnabled(running or (self._sync is not None and self._sync.operation == "upload"))
        self.action_resume_from.setEnabled(r.connected and not running and r.can_resume and not sync_busy)
        self.action_upload_now.setEnabled(self._sync is not None and r.connected and not running
                                          and not sync_busy)
        self.upload_button.setEnabled(self.action_upload_now.isEnabled())
        self.resume_from_button.setVisible(r.can_resume)
