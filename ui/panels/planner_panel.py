"""Trajectory planner panel: plans of the project, their segments, checks, preview and runs.

Layout (:mod:`ui.panels.planner_layout`): the plan list (name, loops, segments; add / duplicate /
delete, rename and loops edited in place) is a side pane, hidden on a narrow planner (*Plans*
shows it; the segments' title names the plan); the segment table (editable, undoable) with the
checks on its rows sits beside the preview (one projection at a time, its tabs) or, on a wide
planner, above the three projections; under both, the checks' summary (Upload now, Check) and the
run strip (Run, Run from here, Step, Pause, Resume, Stop, Resume from k; progress "segment k of n,
loop i of m").

Checks (:func:`app.plan.checks.check_plan`, with the robot model's reach once
:meth:`PlannerPanel.set_reach` gave it), estimates and the preview are recomputed whenever the
plan, the points or the selection change, when the arm moves (segment 1 starts at the robot:
coalesced, a hidden planner catches up when shown) and when the connection changes (the link down:
segment 1 from an assumed start, the plan's end). Before a run the checks are made again from the
robot's current pose: errors refuse the run, points that need an upload are offered for upload
("1 point needs upload — Upload now?") and the run starts when the upload succeeded.

The robot is driven by a :class:`~ui.controllers.plan_run_controller.PlanRunController`; uploads go through
a :class:`~ui.panels.points_panel.PointSyncController`. Questions to the operator go through the
injectable ``confirm(title, text) -> bool`` callable.

What is shown is worked out without Qt by :mod:`app.plan.presenter`. The panel composes its
parts: ``planner_actions`` (the QActions), ``planner_widgets`` (plan list, segment editor, run
box, checks bar), ``planner_layout`` (how they share the room), ``planner_checks`` (the checks
list, estimates, preview), ``planner_edit`` (plan and segment edits), ``planner_run`` (the run
flow), ``planner_follow`` (the plan on display kept in step with the list, the undo stack and the
points).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

from PySide6.QtCore import QEvent, QModelIndex, QPersistentModelIndex, QTimer, Signal, Slot
from PySide6.QtGui import QAction, QShowEvent
from PySide6.QtWidgets import QGroupBox, QLabel, QSizePolicy, QTableView, QVBoxLayout, QWidget

from app.models import Pose
from app.plan.checks import PlanIssue, PlanLimits, ReachCheck
from app.plan.presenter import Level, PanelState, action_states
from app.plan.runner import RunEvent, RunOutcome, RunProgress, RunState
from app.plan.segments import Plan, SegmentKind
from app.points.upload import UploadReport
from app.safety.envelope import Envelope
from ui.controllers.plan_run_controller import PauseState, PlanRunController
from ui.controllers.plan_run_reasons import foreign_pause_text
from ui.controllers.point_sync import PointSyncController
from ui.controllers.safety import lock_editing
from ui.dialogs.confirm import ConfirmFn, ask_confirmation
from ui.messages_plan import issue_text
from ui.models.plan_columns import PLAN_COL_NAME
from ui.models.plan_model import PlanListModel
from ui.models.points_model import PointsModel
from ui.models.segment_model import SegmentTableModel
from ui.panels.plan_preview import PlanPreview
from ui.panels.planner_actions import PlannerActions
from ui.panels.planner_checks import RECHECK_COALESCE_MS, PlannerChecks, pose_moved
from ui.panels.planner_edit import PlanEdits, install_point_pickers
from ui.panels.planner_follow import PlanFollower
from ui.panels.planner_layout import PlannerLayout
from ui.panels.planner_run import PlanRunFlow
from ui.panels.planner_widgets import (
    STATUS_COLOURS,
    PlanChecksBar,
    PlanListBox,
    PlanRunBox,
    SegmentEditorBox,
)

ModelIndex = QModelIndex | QPersistentModelIndex


class PlannerPanel(QWidget):
    """Plans, segments, checks, preview and run controls (see the module docstring).

    Public: ``action_*`` QActions (add / duplicate / delete plan, add line / arc, delete /
    move segment, run, run from here, step, pause, resume, stop, resume from k, upload now,
    check); :meth:`select_plan`, :meth:`current_plan`, :meth:`selected_segments`,
    :meth:`recheck`, :meth:`run`; ``segments`` (the :class:`SegmentTableModel`),
    ``preview``; signal ``statusMessage(str)``.
    """

    statusMessage = Signal(str)

    def __init__(
        self,
        plans: PlanListModel,
        points: PointsModel,
        run_controller: PlanRunController | None = None,
        point_sync: PointSyncController | None = None,
        parent: QWidget | None = None,
        *,
        confirm: ConfirmFn | None = None,
        limits: PlanLimits | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("PlannerPanel")
        self._plans = plans
        self._points = points
        self._runner = run_controller or PlanRunController(parent=self, points=points)
        self._sync = point_sync
        self._confirm = confirm or ask_confirmation(self)
        self._checked_pose: Pose | None = None  # the robot's pose the shown checks were made from
        self._alarm_hold = False
        # A moving arm re-checks at most every RECHECK_COALESCE_MS (poses come at the poll rate).
        self._recheck_timer = QTimer(self)
        self._recheck_timer.setSingleShot(True)
        self._recheck_timer.setInterval(RECHECK_COALESCE_MS)
        self._recheck_timer.timeout.connect(self._recheck_if_idle)

        self.segments = SegmentTableModel(plans.undo_stack, points.ledger, self)
        self.run_flow = PlanRunFlow(self, self._runner, point_sync, points, self)
        self.edits = PlanEdits(self, plans, self.segments, self)
        e = self.edits
        self.add_plan, self.rename_plan, self.duplicate_plan = e.add_plan, e.rename_plan, e.duplicate_plan
        self.delete_plan, self.add_segment = e.delete_plan, e.add_segment
        self.delete_segments, self.move_segments = e.delete_segments, e.move_segments
        self._make_actions()
        self._build()
        self.checks = PlannerChecks(
            self.segments,
            self.preview,
            self.checks_bar,
            lambda: self._points.ledger,
            self._pose,
            point_sync is not None,
            limits,
        )
        self.retranslate()

        plans.editRejected.connect(lambda text: self.show_message(text, "error"))
        self.segments.editRejected.connect(lambda text: self.show_message(text, "error"))
        for view in (self.plan_view, self.segment_view):
            view.doubleClicked.connect(self._say_why_not_editable)
        self.follower = PlanFollower(self, plans, points, self.segments, self._update_actions, self)

        r = self._runner
        r.runningChanged.connect(self._on_running)
        r.pausedChanged.connect(self._update_actions)
        r.connectedChanged.connect(self._on_connected)
        r.progressChanged.connect(self._on_progress)
        r.runFinished.connect(self._on_run_finished)
        r.pausedByForeign.connect(self._on_paused_by_foreign)
        r.resumeRefused.connect(self._on_resume_refused)
        r.pauseStateChanged.connect(self._on_pause_state)
        if r.link is not None:  # the pose's one signal, the link's picture of the robot
            r.link.state.poseChanged.connect(self.preview.on_pose)
            r.link.state.poseChanged.connect(self._on_pose)
        if point_sync is not None:
            r.pointsMissing.connect(point_sync.points_missing)
            point_sync.busyChanged.connect(self._update_actions)
            point_sync.uploadFinished.connect(self._on_upload_finished)

        if plans.rowCount():
            self.select_plan(0)
        self._update_actions()

    # --- construction
    def _make_actions(self) -> None:
        slots: dict[str, Callable[[], Any]] = {
            "add_plan": self.add_plan,
            "rename_plan": self.rename_plan,
            "duplicate_plan": self.duplicate_plan,
            "delete_plan": self.delete_plan,
            "add_line": lambda: self.add_segment(SegmentKind.LINE),
            "add_arc": lambda: self.add_segment(SegmentKind.ARC),
            "delete_segment": self.delete_segments,
            "segment_up": lambda: self.move_segments(-1),
            "segment_down": lambda: self.move_segments(1),
            "check": self.recheck,
            "upload_now": self.upload_needed,
            "run": lambda: self.run(0),
            "run_from": self.run_from_selected,
            "step": self.step,
            "pause": self._runner.pause,
            "resume": self._runner.resume,
            "stop": self.stop,
            "resume_from": self.resume_from,
        }
        self.planner_actions = PlannerActions(self, slots)
        a = self.planner_actions
        self.action_add_plan, self.action_rename_plan = a["add_plan"], a["rename_plan"]
        self.action_duplicate_plan, self.action_delete_plan = a["duplicate_plan"], a["delete_plan"]
        self.action_add_line, self.action_add_arc = a["add_line"], a["add_arc"]
        self.action_delete_segment = a["delete_segment"]
        self.action_segment_up, self.action_segment_down = a["segment_up"], a["segment_down"]
        self.action_check, self.action_upload_now = a["check"], a["upload_now"]
        self.action_run, self.action_run_from, self.action_step = a["run"], a["run_from"], a["step"]
        self.action_pause, self.action_resume, self.action_stop = a["pause"], a["resume"], a["stop"]
        self.action_resume_from = a["resume_from"]

    def _build(self) -> None:
        """The boxes; how they share the room is :class:`~ui.panels.planner_layout.PlannerLayout`."""
        self.plans_box = PlanListBox(
            self._plans,
            [
                self.action_add_plan,
                self.action_rename_plan,
                self.action_duplicate_plan,
                self.action_delete_plan,
            ],
            self,
        )
        self.plan_view: QTableView = self.plans_box.plan_view
        self.run_box = PlanRunBox(
            self.action_run,
            self.action_run_from,
            self.action_step,
            self.action_pause,
            self.action_resume,
            self.action_stop,
            self.action_resume_from,
            self,
        )
        self.resume_from_button = self.run_box.resume_from_button
        self.run_label = self.run_box.run_label
        self.run_progress = self.run_box.run_progress

        self.checks_bar: PlanChecksBar = PlanChecksBar(self.upload_needed, self.recheck, self)
        self.summary = self.checks_bar.summary
        self.upload_button = self.checks_bar.upload_button
        self.check_button = self.checks_bar.check_button
        self.action_show_plans = QAction(self)  # the plans list shown (PlannerLayout toggles it)
        self.action_show_plans.setCheckable(True)
        segment_actions = [
            self.action_show_plans,
            self.action_add_line,
            self.action_add_arc,
            self.action_delete_segment,
            self.action_segment_up,
            self.action_segment_down,
        ]
        self.segments_box = SegmentEditorBox(self.segments, self._points, segment_actions, self)
        self.segment_view: QTableView = self.segments_box.segment_view
        self.point_pickers = install_point_pickers(self.segment_view, lambda: self._points.ledger)

        self.preview: PlanPreview = PlanPreview(self)
        self.preview_box = QGroupBox(self)
        self.preview_box.setObjectName("PlanPreviewBox")
        preview_layout = QVBoxLayout(self.preview_box)
        preview_layout.setContentsMargins(6, 4, 6, 6)
        preview_layout.addWidget(self.preview)

        self.arrangement = PlannerLayout(
            self.plans_box,
            self.segments_box,
            self.preview_box,
            self.checks_bar,
            self.run_box,
            self.action_show_plans,
            self,
        )
        self.status = QLabel(self)
        self.status.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        # as high for Chinese as for Latin text (a CJK fallback font is taller): the boxes above
        # do not move when a message appears (the run strip moved 1 px after a stop in zh_CN)
        probe = QLabel("Ag \u505c\u6b62")
        probe.setFont(self.status.font())
        self.status.setFixedHeight(probe.sizeHint().height())
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.setSpacing(4)
        layout.addWidget(self.arrangement, 1)
        layout.addWidget(self.status)

    def retranslate(self) -> None:
        self.planner_actions.retranslate()
        self.plans_box.retranslate()
        self.run_box.retranslate()
        self.segments_box.retranslate()
        self.arrangement.retranslate()
        self.checks_bar.retranslate()
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
        return list(self.checks.issues)

    @property
    def summary_text(self) -> str:
        return self.checks.summary_text

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
            selection.select(
                self.segments.index(row, 0), selection.SelectionFlag.Select | selection.SelectionFlag.Rows
            )
        if rows:
            selection.setCurrentIndex(self.segments.index(rows[0], 0), selection.SelectionFlag.NoUpdate)
            self.segment_view.scrollTo(self.segments.index(rows[0], 0))

    def set_confirm(self, confirm: ConfirmFn) -> None:
        """Replace the operator's yes/no question (tests answer without a dialog)."""
        self._confirm = confirm

    @Slot(str, str)
    def show_message(self, text: str, level: str = "info") -> None:
        known = {lv.value: lv for lv in Level}
        colour = STATUS_COLOURS[known[level]] if level in known else ""
        self.status.setStyleSheet(f"color: {colour};" if colour else "")
        self.status.setText(text)
        self.status.setToolTip(text)
        self.statusMessage.emit(text)

    def _clear_message(self) -> None:
        self.status.setStyleSheet("")
        self.status.clear()
        self.status.setToolTip("")

    # --- checks, estimates, preview
    def _pose(self) -> Pose | None:
        """The robot's pose while connected; None while the link is down (the arm may be moved
        meanwhile: segment 1 is shown from an assumed start, as before the first connection)."""
        return self._runner.last_pose if self._runner.connected else None

    @Slot()
    def set_edit_permission(self, reason: str | None) -> None:
        """Role gating: plan and segment edits only while ``reason`` is None (else disabled, not
        hidden, with ``reason`` as the tooltip); runs stay the operator's."""
        self.planner_actions.edit_reason = reason
        for view in (self.plan_view, self.segment_view):
            lock_editing(view, reason is not None)
        self._update_actions()

    @Slot()
    def _say_why_not_editable(self) -> None:
        """A double click on a cell the role may not edit says why (it opened nothing)."""
        reason = self.planner_actions.edit_reason
        if reason is not None:
            self.show_message(self.tr("This cell cannot be edited: {why}").format(why=reason), "warn")

    def set_envelope(self, envelope: Envelope | None, reduced_speed: bool = False) -> None:
        """The safety envelope the checks (and Run) use; its boxes are drawn in the preview."""
        self.checks.envelope, self.checks.reduced_speed = envelope, reduced_speed
        self.preview.set_envelope(envelope)
        self.recheck()

    def set_reach(self, reach: ReachCheck | None, model: str = "") -> None:
        """The robot model's reach check (the 3D view's): its errors block Run like the others;
        ``model`` names the robot model (beside the preview's Fit)."""
        self.checks.reach = reach
        self.preview.set_reach_model(model if reach is not None else "")
        self.recheck()

    def set_reach_model(self, model: str) -> None:
        """Another robot model checks the reach now: name it."""
        self.preview.set_reach_model(model)

    def recheck(self) -> None:
        """Checks, estimates and preview of the plan on display."""
        plan = self.current_plan()
        self.segments_box.set_plan_name(plan.name if plan is not None else "")
        self._checked_pose = self._pose()
        self.checks.recheck(plan, self._selected_index())
        self._update_actions()

    def _selected_index(self) -> int | None:
        rows = self.selected_segments()
        return rows[0] if rows else None

    # --- running (the flow: planner_run.py)
    def confirm(self, title: str, text: str) -> bool:
        return self._confirm(title, text)

    def show_issues(self, issues: list[PlanIssue], plan: Plan) -> str:
        """Show checks made for a run on the rows and the summary; returns the summary."""
        summary = self.checks.show(issues, plan)
        self._update_actions()
        return summary

    def run(self, start: int = 0, single: bool = False, *, resume: bool = False) -> bool:
        """Check, offer an upload, confirm, then run from ``start`` (``single``: one segment).
        Returns True when the run (or the upload before it) started."""
        return self.run_flow.run(start, single, resume=resume)

    @Slot()
    def run_from_selected(self) -> None:
        rows = self.selected_segments()
        self.run(rows[0] if rows else 0)

    @Slot()
    def step(self) -> None:
        self.run(self.run_flow.step_start(self.selected_segments()), single=True)

    @Slot()
    def stop(self) -> None:
        self.run_flow.stop()

    @Slot()
    def resume_from(self) -> None:
        """ "Resume from k": re-check from segment k, then continue the stopped run."""
        k = self._runner.resume_from
        if k is None:
            return
        run_plan = self.run_flow.run_plan
        if run_plan is not None and run_plan is not self.current_plan():
            row = self._plans.row_of(run_plan)
            if row is not None:
                self.select_plan(row)
        self.run(k, resume=True)

    @Slot()
    def upload_needed(self) -> None:
        self.run_flow.upload_needed()

    # --- reactions
    @Slot(object)
    def _on_upload_finished(self, report: UploadReport) -> None:
        self.recheck()
        self.run_flow.upload_finished(report)

    @Slot(bool)
    def _on_running(self, running: bool) -> None:
        self.segments.set_locked(running)
        self.plan_view.setEnabled(not running)
        if running:
            self._clear_message()  # the last run's "Plan finished" / how it ended is history now
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
        self.run_box.show_progress(progress)

    @Slot(object)
    def _on_run_finished(self, outcome: RunOutcome) -> None:
        self.run_flow.run_finished(outcome)
        run_plan = self.run_flow.run_plan
        if outcome.state is RunState.FINISHED:
            self.segments.set_run_marker(None, None)
            self.run_box.show_finished(outcome.segments_done)
            self.show_message(self.tr("Plan finished"), "info")
            if outcome.next_position is not None and self.current_plan() is run_plan:
                self.select_segments([outcome.next_position[0]])
        else:
            k = outcome.resume_from
            self.segments.set_run_marker(None, k if outcome.state is RunState.FAILED else None)
            if k is not None and self.current_plan() is run_plan:
                self.select_segments([k])
            level = "error" if outcome.state is RunState.FAILED else "warn"
            text = self._runner.outcome_text(outcome)
            self.run_box.show_ended(text)
            self.show_message(text, level)
        self._update_resume_text()
        self._update_actions()

    @Slot(str, float)
    def _on_paused_by_foreign(self, what: str, value: float) -> None:
        """The run paused itself at a sign of another master: the run box says why."""
        text = foreign_pause_text(what, value)
        self.run_box.show_paused(text)
        self.show_message(text, "warn")

    @Slot(object)
    def _on_pause_state(self, state: PauseState) -> None:
        """The run's Pause: pausing until the controller confirms it, paused after, or refused
        (issue 19): the run box says it, never "paused" before the controller did."""
        text = self.run_flow.pause_text(state)
        if text:
            self.run_box.show_paused(text)
        if state in (PauseState.UNCONFIRMED, PauseState.STOPPING, PauseState.REFUSED):
            self.show_message(text, "error" if state is PauseState.REFUSED else "warn")
        self._update_actions()

    @Slot(str)
    def _on_resume_refused(self, text: str) -> None:
        self.run_box.show_paused(text)
        self.show_message(text, "warn")

    def _update_resume_text(self) -> None:
        runs = self._runner
        k = runs.resume_from if runs.can_resume else None
        runner = runs.runner
        many = runner is not None and runner.loops != 1  # the loop is named: "…, loop 2"
        self.planner_actions.set_resume_from(
            k + 1 if k is not None else None, runs.resume_loop if many else None
        )

    @Slot(object)
    def _on_pose(self, pose: Pose) -> None:
        """The arm moved (a jog, a step, the hand pendant): segment 1 starts somewhere else, so
        its checks ("the line goes nowhere ... from the current pose") and the estimates are made
        again (coalesced; not during a run: the run's checks were made from where it started;
        a hidden planner catches up when shown)."""
        if self._runner.running or self._recheck_timer.isActive() or not self.isVisible():
            return
        if self._checked_pose is None or pose_moved(pose, self._checked_pose):
            self._recheck_timer.start()

    @Slot(bool)
    def _on_connected(self, connected: bool) -> None:
        """Connected: the checks start from the robot's pose (its first poll re-checks); the link
        down: from an assumed start. Either way the estimates are made again."""
        self._recheck_timer.stop()
        self._recheck_if_idle()
        self._update_actions()

    @Slot()
    def _recheck_if_idle(self) -> None:
        """Re-check unless a run goes on; a long plan spaces the next pose's re-check out to ten
        times what this one took (a 1,000-segment plan takes ~60 ms: at most ~10 % of the GUI
        thread while the arm moves)."""
        if self._runner.running:
            return
        started = time.perf_counter()
        self.recheck()
        took_ms = (time.perf_counter() - started) * 1000.0
        self._recheck_timer.setInterval(max(RECHECK_COALESCE_MS, int(10 * took_ms)))

    def _pose_changed_since_check(self) -> bool:
        pose, checked = self._pose(), self._checked_pose
        if pose is None or checked is None:
            return (pose is None) != (checked is None)
        return pose_moved(pose, checked)

    def showEvent(self, event: QShowEvent) -> None:
        """Shown again: checks made while the arm moved out of sight are made now."""
        super().showEvent(event)
        if not self._runner.running and self._pose_changed_since_check():
            self.recheck()

    def set_alarm_hold(self, hold: bool) -> None:
        """An emergency stop or servo alarm is set (MotionController.alarmHoldChanged)."""
        changed = bool(hold) != self._alarm_hold
        self._alarm_hold = bool(hold)
        if changed:
            self.checks.held = self._alarm_hold
            self.checks.show(self.checks.issues, self.current_plan())  # not "ready to run" under one
        self._update_actions()

    @Slot()
    def _update_actions(self, *_args: Any) -> None:
        r = self._runner
        plan = self.current_plan()
        rows = self.selected_segments()
        sync = self._sync
        errors = [issue_text(i) for i in self.checks.issues if i.is_error]
        states = action_states(
            PanelState(
                connected=r.connected,
                running=r.running,
                paused=r.paused,
                can_resume=r.can_resume,
                has_plan=plan is not None,
                segments=len(plan) if plan is not None else 0,
                selected=bool(rows),
                can_move_up=self.segments.can_move(rows, -1),
                can_move_down=self.segments.can_move(rows, 1),
                has_sync=sync is not None,
                sync_busy=sync is not None and sync.busy,
                uploading=sync is not None and sync.operation == "upload",
                check_errors=len(errors),
                first_error=errors[0] if errors else "",
            )
        )
        self.planner_actions.apply(states)
        if r.can_pause:  # the run's last Pause failed: it can be pressed again (Resume stays)
            self.planner_actions.all["pause"].setEnabled(True)
        if self._alarm_hold:  # an e-stop / servo alarm: nothing that starts motion (Stop, Pause stay)
            for name in ("run", "run_from", "step", "resume", "resume_from"):
                self.planner_actions.all[name].setEnabled(False)
        self.upload_button.setEnabled(self.action_upload_now.isEnabled())
        self.resume_from_button.setVisible(states.resume_from_visible)
