"""3D view panel: the arm, the taught points and the selected plan, from any angle.

The arm is drawn from a robot model profile (:mod:`app.view3d.profile`, the simulator's arm by
default; the window's :class:`~ui.panels.view3d_robot.RobotModelSource`, whose reach checker the
planner's checks share): from the controller's joint angles when it reports them, else from the pose through
the profile's IK — then an "estimate" badge says so; "stale" when the robot's state is not
fresh. Points are markers coloured by sync state; the selection follows the points table both
ways. The selected plan is a ghost path (lines and true arcs of :mod:`app.plan.geometry`,
middle points as squares, the start as a green dot, one arrow per segment); during a run the
segment being run is highlighted and the TCP leaves a trace. Points and path samples the
profile cannot reach (or only past a joint limit) are red. The dry run bar plays the plan on
the drawn arm without sending anything, every loop of it ("loop 2 of 20"). *Fit all* frames
the arm, the points and the plan, *Fit plan* the selected plan's path and its points; until the
operator moves the camera it follows the scene (:mod:`ui.panels.view3d_canvas` says when). What
the scene shows of the points and the plan (colours, sampling, red samples) is worked out
without widgets in :mod:`ui.panels.view3d_scene`.

The header names the robot model in use (its file and whether it agrees with the controller in
the tooltip); a model whose forward kinematics disagree with the controller's pose is said in
words under it and as a badge (:mod:`app.view3d.agreement`). *Robot model…* is an engineer's:
disabled with the role it needs for the others (the window's safety gate), and refused in words
if reached another way (:class:`~ui.panels.view3d_robot.ModelGuard`).

Live values arrive at the poll rate; the arm is redrawn at most :data:`LIVE_FPS` times a second
from the latest one. The panel is connected to the window's parts with :meth:`bind`,
:meth:`attach_points`, :meth:`attach_planner` and :meth:`attach_runner`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any, Final

import numpy as np
from PySide6.QtCore import QEvent, QItemSelection, QTimer, Signal, Slot
from PySide6.QtGui import QHideEvent, QShowEvent
from PySide6.QtWidgets import (
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QSizePolicy,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.link.state import RobotState
from app.models import Pose
from app.plan.geometry import plan_path
from app.plan.segments import Plan
from app.points.ledger import PointLedger
from app.view3d.agreement import MODEL_TOLERANCE_DEG, MODEL_TOLERANCE_MM, ModelAgreement
from app.view3d.camera import Preset
from app.view3d.kinematics import ArmTracker, Reach
from app.view3d.path import DryRun, DryRunState, start_of
from app.view3d.profile import RobotProfile
from app.view3d.reach import PathReach, ReachChecker
from ui.joins import join_names, join_sentences
from ui.messages_plan import issue_text
from ui.models.points_model import PointsModel
from ui.palette import COLOR_CURVE_PURPLE, COLOR_ERROR, COLOR_INFO, COLOR_NEUTRAL, COLOR_WARN
from ui.panels.view3d_canvas import View3DCanvas
from ui.panels.view3d_dryrun import DryRunBar
from ui.panels.view3d_robot import RobotModelSource
from ui.panels.view3d_scene import SYNC_COLORS, arc_middles, bad_path_samples, path_samples, reach_checked
from ui.widgets.lines_label import LinesLabel

LIVE_FPS: Final = 30
TRACE_LENGTH: Final = 2000  # live TCP positions kept for the trace


class View3DPanel(QWidget):
    """See the module docstring. Signal ``besideToggled(bool)``: the user wants the view beside
    the planner (True) or in its own tab (False)."""

    besideToggled = Signal(bool)

    def __init__(
        self, points: PointsModel, parent: QWidget | None = None, *, robot: RobotModelSource | None = None
    ) -> None:
        super().__init__(parent)
        self.setObjectName("View3DPanel")
        self._points = points
        self.robot = robot or RobotModelSource(parent=self)  # the window's, shared with the planner
        self.model = self.robot.model
        self.tracker = ArmTracker(self.model)
        self.plan: Plan | None = None
        self.path_reach: PathReach | None = None
        self.point_reach: dict[int, Reach] = {}
        self._pose: Pose | None = None
        self._joints: tuple[float, ...] | None = None
        self._fresh = True
        self._state: RobotState | None = None
        self._points_panel: Any = None
        self._planner: Any = None
        self._trace = np.full((TRACE_LENGTH, 3), np.nan)
        self._trace_n = 0
        self._running = False
        self._dry: DryRunState | None = None
        self._refit_arm = False  # the first pose after connecting: frame the arm where it is
        self._dry_joints: np.ndarray | None = None
        self._scene_dirty = True

        self.canvas = View3DCanvas(self)
        self.canvas.pointClicked.connect(self._on_point_clicked)
        self.dry_bar = DryRunBar(self)
        self.dry_bar.stateChanged.connect(self._on_dry_state)
        self.preset_buttons: dict[Preset, QToolButton] = {}
        bar = QHBoxLayout()
        bar.setContentsMargins(0, 0, 0, 0)
        for preset in Preset:
            button = QToolButton(self)
            button.clicked.connect(lambda _c=False, p=preset: self.set_preset(p))
            self.preset_buttons[preset] = button
            bar.addWidget(button)
        self.fit_button = QToolButton(self)
        self.fit_button.clicked.connect(self.canvas.fit_all)
        self.fit_plan_button = QToolButton(self)
        self.fit_plan_button.setObjectName("View3DFitPlanButton")
        self.fit_plan_button.clicked.connect(self.fit_plan)
        self.ortho_button = QToolButton(self)
        self.ortho_button.setCheckable(True)
        self.ortho_button.toggled.connect(self._on_ortho)
        self.beside_button = QToolButton(self)
        self.beside_button.setCheckable(True)
        self.beside_button.toggled.connect(self.besideToggled)
        for w in (self.fit_button, self.fit_plan_button, self.ortho_button):
            bar.addWidget(w)
        bar.addStretch(1)
        self.profile_button = QToolButton(self)
        self.profile_button.setObjectName("RobotModelButton")
        self.profile_button.clicked.connect(self.choose_profile)
        self.message_label = QLabel(self)
        self.message_label.setWordWrap(True)
        self.message_label.setStyleSheet(f"color: {COLOR_ERROR};")
        self.message_label.setVisible(bool(self.robot.problem))
        self.message_label.setText(self.robot.problem)
        self.robot.profileChanged.connect(self._on_profile)
        self.robot.problemRaised.connect(self._show_problem)
        self.robot.agreementChanged.connect(self._show_agreement)
        # the model in use, on its own line under the buttons (elided, whole in the tooltip)
        self.model_label = LinesLabel(1, self)
        self.model_label.setObjectName("View3DModelLabel")
        self.model_label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        self.model_label.setStyleSheet(f"color: {COLOR_NEUTRAL};")
        self.agreement_label = QLabel(self)  # the model disagrees with the controller: in words
        self.agreement_label.setObjectName("View3DAgreementLabel")
        self.agreement_label.setWordWrap(True)
        self.agreement_label.setStyleSheet(f"color: {COLOR_ERROR}; font-weight: bold;")
        self.agreement_label.hide()
        self.reach_label = QLabel(self)
        self.reach_label.setWordWrap(True)
        self.reach_label.setStyleSheet(f"color: {COLOR_ERROR};")
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addLayout(bar)
        model_row = QHBoxLayout()  # the model in use, its button, and where the view lives
        model_row.setContentsMargins(0, 0, 0, 0)
        model_row.addWidget(self.model_label, 1)
        model_row.addWidget(self.profile_button)
        model_row.addWidget(self.beside_button)
        layout.addLayout(model_row)
        layout.addWidget(self.agreement_label)
        layout.addWidget(self.canvas, 1)
        layout.addWidget(self.message_label)
        layout.addWidget(self.reach_label)
        layout.addWidget(self.dry_bar)

        self._live_timer = QTimer(self)
        self._live_timer.setSingleShot(True)
        self._live_timer.setInterval(1000 // LIVE_FPS)
        self._live_timer.timeout.connect(self._update_arm)
        self._scene_timer = QTimer(self)
        self._scene_timer.setSingleShot(True)
        self._scene_timer.setInterval(0)
        self._scene_timer.timeout.connect(self.refresh_scene)
        for signal in (
            points.dataChanged,
            points.rowsInserted,
            points.rowsRemoved,
            points.rowsMoved,
            points.modelReset,
        ):
            signal.connect(self._schedule_scene)
        self.retranslate()
        self.refresh_scene()
        self._update_arm()

    # --- wiring --------------------------------------------------------------------------
    def bind(self, state: RobotState) -> None:
        """Follow the robot's pose, joints and freshness."""
        self._state = state
        state.poseChanged.connect(self.on_pose)
        state.jointsChanged.connect(self.on_joints)
        state.freshnessChanged.connect(self.on_fresh)
        self._fresh = state.fresh
        if state.pose is not None:
            self.on_pose(state.pose)

    def attach_points(self, points_panel: Any) -> None:
        """Selection both ways with the points table (``PointsPanel``)."""
        self._points_panel = points_panel
        points_panel.table.selectionModel().selectionChanged.connect(self._on_table_selection)

    def attach_planner(self, planner: Any) -> None:
        """Show the planner's plan (``PlannerPanel.current_plan()``) and follow its edits."""
        self._planner = planner
        seg = planner.segments
        for signal in (
            seg.modelReset,
            seg.dataChanged,
            seg.rowsInserted,
            seg.rowsRemoved,
            seg.rowsMoved,
            seg.listEdited,
        ):
            signal.connect(self._schedule_scene)
        planner.plan_view.model().dataChanged.connect(self._schedule_scene)  # a plan's loops (the dry run)
        self._schedule_scene()

    def attach_runner(self, runner: Any) -> None:
        """Trace the TCP and highlight the running segment during a run (``PlanRunController``)."""
        runner.runningChanged.connect(self.on_running)
        runner.progressChanged.connect(self.on_progress)

    # --- texts ---------------------------------------------------------------------------
    def retranslate(self) -> None:
        names = {
            Preset.TOP: self.tr("Top"),
            Preset.FRONT: self.tr("Front"),
            Preset.SIDE: self.tr("Side"),
            Preset.ISO: self.tr("Iso"),
        }
        for preset, button in self.preset_buttons.items():
            button.setText(names[preset])
            button.setToolTip(self.tr("Look at the scene from a preset direction"))
        self.fit_button.setText(self.tr("Fit all"))
        self.fit_button.setToolTip(
            self.tr("Show the arm, the points and the plan (the view follows them again until you move it)")
        )
        self.fit_plan_button.setText(self.tr("Fit plan"))
        self.fit_plan_button.setToolTip(self.tr("Show the selected plan's path and its points"))
        self.ortho_button.setText(self.tr("Orthographic"))
        self.ortho_button.setToolTip(self.tr("Parallel projection (no perspective)"))
        self.profile_button.setText(self.tr("Robot model…"))
        self.profile_button.setToolTip(self.tr("Load another robot model profile (JSON; engineer)"))
        self._show_agreement(self.robot.agreement)
        self.beside_button.setText(self.tr("Beside the planner"))
        self.beside_button.setToolTip(self.tr("Show the 3D view next to the planner, not in its own tab"))
        self.canvas.setToolTip(
            self.tr("Drag: rotate · Shift or right drag: pan · Wheel: zoom · Click a point: select it")
        )
        self._show_reach()
        self._update_badges()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- camera --------------------------------------------------------------------------
    @property
    def reach(self) -> ReachChecker:
        """The active profile's reach checker (the planner's checks use the same one)."""
        return self.robot.reach

    def set_profile(self, profile: RobotProfile) -> None:
        """Draw and check with another robot model (the planner's checks follow)."""
        self.robot.set_profile(profile)

    @Slot(object)
    def _on_profile(self, _profile: RobotProfile) -> None:
        self.model = self.robot.model
        self.tracker = ArmTracker(self.model)
        self._dry_joints = None
        self.retranslate()
        self.refresh_scene()
        self._update_arm()

    def load_profile_file(self, path: str) -> bool:
        """Load a profile file (an engineer's); a bad one, or a role that may not, is refused in
        words (the model in use stays)."""
        error = self.robot.load_file(path)
        if error is not None:
            self._show_problem(self.tr("Robot model not loaded: %1").replace("%1", error))
            return False
        self.message_label.hide()
        return True

    def _show_model(self) -> None:
        """The model's name in the header; its file and its agreement with the controller in
        the tooltip."""
        name = self.robot.profile.name
        self.model_label.setText(self.tr("Robot model: %1").replace("%1", name))
        lines = [
            self.tr("Robot model: %1").replace("%1", name),
            self.tr("File: %1").replace("%1", self.robot.path)
            if self.robot.path
            else self.tr("Shipped with TeachPad"),
        ]
        agreement = self.robot.agreement
        if agreement is None:
            lines.append(self.tr("Not compared with the controller (no joint angles from it)"))
        elif agreement.agrees:
            lines.append(
                self.tr("Agrees with the controller's pose (within %1 mm, %2°)")
                .replace("%1", f"{MODEL_TOLERANCE_MM:g}")
                .replace("%2", f"{MODEL_TOLERANCE_DEG:g}")
            )
        else:
            lines.append(self.agreement_label.text())
        self.model_label.setToolTip("\n".join(lines))

    @Slot(object)
    def _show_agreement(self, agreement: ModelAgreement | None) -> None:
        off = agreement is not None and not agreement.agrees
        if agreement is not None and off:
            from app.view3d.agreement import model_issue

            self.agreement_label.setText(issue_text(model_issue(agreement)))
        self.agreement_label.setVisible(off)
        self._show_model()
        self._update_badges()

    @Slot(str)
    def _show_problem(self, text: str) -> None:
        self.message_label.setText(text)
        self.message_label.show()

    @Slot()
    def choose_profile(self) -> None:
        refused = self.robot.refusal()  # before the file dialog: an operator gets no dialog
        if refused is not None:
            self._show_problem(self.tr("Robot model not loaded: %1").replace("%1", refused))
            return
        from importlib import resources

        folder = os.path.dirname(self.robot.path) or str(resources.files("app.view3d").joinpath("profiles"))
        path, _filter = QFileDialog.getOpenFileName(
            self, self.tr("Load a robot model profile"), folder, self.tr("Robot model profiles (*.json)")
        )
        if path:
            self.load_profile_file(path)

    def set_preset(self, preset: Preset) -> None:
        """Look from a preset direction at the whole scene (the view follows it again)."""
        self.canvas.set_camera(self.canvas.camera.preset(preset))
        self.canvas.fit_all()

    @Slot()
    def fit_plan(self) -> None:
        """Frame the selected plan's path and the points it uses."""
        self.canvas.fit_to(self.plan_bounds())

    def plan_bounds(self) -> np.ndarray:
        """The selected plan's path samples and its points, (n, 3)."""
        ids = self.canvas.plan_ids
        points = [p.xyz for p in self.ledger if p.id in ids]
        return np.concatenate([self.canvas.path_xyz, np.array(points, dtype=np.float64).reshape(-1, 3)])

    @Slot(bool)
    def _on_ortho(self, ortho: bool) -> None:
        from dataclasses import replace

        self.canvas.set_camera(replace(self.canvas.camera, ortho=ortho))
        self.canvas.auto_fit()  # the same scene framed in the other projection (unless moved)

    # --- live robot ----------------------------------------------------------------------
    @Slot(object)
    def on_pose(self, pose: Pose) -> None:
        if self._pose is None:
            self._refit_arm = True
        self._pose = pose
        if pose.joints is not None and len(pose.joints) >= self.model.dof:
            self._joints = tuple(pose.joints)
        if self._running and all(np.isfinite((pose.x, pose.y, pose.z))):
            self._add_trace((pose.x, pose.y, pose.z))
        self._schedule_arm()

    @Slot(object)
    def on_joints(self, joints: Sequence[float] | None) -> None:
        self._joints = None if joints is None or len(joints) < self.model.dof else tuple(joints)
        self._schedule_arm()

    @Slot(bool)
    def on_fresh(self, fresh: bool) -> None:
        if fresh and not self._fresh:  # (re)connected, or answering again: frame the arm where it is
            self._refit_arm = True
        self._fresh = fresh
        self._update_badges()

    @Slot(bool)
    def on_running(self, running: bool) -> None:
        self._running = running
        if running:
            self._trace_n = 0
            self.canvas.set_trace(np.zeros((0, 3)))
        else:
            self.canvas.set_active_segment(None)

    @Slot(object)
    def on_progress(self, progress: Any) -> None:
        self.canvas.set_active_segment(int(progress.index) if self._running else None)

    def _add_trace(self, xyz: tuple[float, float, float]) -> None:
        if self._trace_n == TRACE_LENGTH:
            self._trace[:-1] = self._trace[1:]
            self._trace_n -= 1
        self._trace[self._trace_n] = xyz
        self._trace_n += 1

    def _schedule_arm(self) -> None:
        if self.isVisible() and not self._live_timer.isActive():
            self._live_timer.start()

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        if self._scene_dirty:
            self.refresh_scene()
        self._update_arm()

    def hideEvent(self, event: QHideEvent) -> None:
        """Hidden (another tab, the window closed): no timers, no work until shown again."""
        super().hideEvent(event)
        self._live_timer.stop()
        if self._scene_timer.isActive():
            self._scene_timer.stop()
            self._scene_dirty = True
        self.dry_bar.play_button.setChecked(False)

    @Slot()
    def _update_arm(self) -> None:
        """Draw the arm from the latest joints (or the pose through IK); nothing while hidden."""
        if not self.isVisible():
            return
        if self._running and self._trace_n > 1:
            self.canvas.set_trace(self._trace[: self._trace_n].copy())
        if self._joints is not None:
            q = self.tracker.from_joints(self._joints)
        elif self._pose is not None and all(np.isfinite(self._pose.xyzabc)):
            q = self.tracker.from_pose(self._pose.xyzabc)
        else:
            q = self.tracker.joints
        self.canvas.set_arm(self.model.link_points(q), self.model.joint_points(q), self.model.forward(q))
        if self._refit_arm:
            self._refit_arm = False
            self.canvas.auto_fit()
        self._update_badges()

    def _update_badges(self) -> None:
        badges: list[tuple[str, str]] = []
        if self._dry is not None:
            badges.append((self.tr("dry run: nothing is sent"), COLOR_CURVE_PURPLE))
        if self._pose is None and self._joints is None:
            badges.append((self.tr("no pose: home position shown"), COLOR_NEUTRAL))
        elif self.tracker.estimated:
            badges.append((self.tr("estimate (from the pose, no joint angles)"), COLOR_INFO))
        if self.tracker.reach is Reach.UNREACHABLE and self._pose is not None and self._joints is None:
            badges.append((self.tr("pose out of the model's reach"), COLOR_ERROR))
        elif self.tracker.reach is Reach.JOINT_LIMIT:
            badges.append((self.tr("past a joint limit"), COLOR_ERROR))
        if self._state is not None and not self._fresh:
            badges.append((self.tr("stale"), COLOR_WARN))
        agreement = self.robot.agreement
        if agreement is not None and not agreement.agrees:
            badges.append((self.tr("the robot model disagrees with the controller"), COLOR_ERROR))
        self.canvas.set_badges(badges)

    # --- scene ---------------------------------------------------------------------------
    @Slot()
    def _schedule_scene(self, *_args: object) -> None:
        if not self.isVisible():
            self._scene_dirty = True
        elif not self._scene_timer.isActive():
            self._scene_timer.start()

    @property
    def ledger(self) -> PointLedger:
        return self._points.ledger

    @Slot()
    def refresh_scene(self) -> None:
        """Points, reach and the plan's path again (after an edit or another plan)."""
        self._scene_dirty = False
        ledger = self.ledger
        points = list(ledger)
        plan = self._planner.current_plan() if self._planner is not None else None
        self.plan = plan
        self.point_reach = self.reach.points(reach_checked(points, plan))
        xyz = np.array([p.xyz for p in points], dtype=np.float64).reshape(-1, 3)
        bad = np.array([self.point_reach.get(p.id, Reach.OK) is not Reach.OK for p in points], dtype=bool)
        self.canvas.set_points(
            xyz, [p.id for p in points], [p.label for p in points], [SYNC_COLORS[p.sync] for p in points], bad
        )
        self._show_plan(plan, ledger)
        self._show_reach()
        self._on_table_selection()
        self.canvas.auto_fit()  # a new project, new points, another plan: framed (unless moved)

    def _show_plan(self, plan: Plan | None, ledger: PointLedger) -> None:
        self.canvas.set_plan_ids(plan.point_ids() if plan is not None else set())
        self.fit_plan_button.setEnabled(plan is not None and len(plan) > 0)
        if plan is None or not len(plan):
            self.path_reach = None
            self.canvas.set_path(
                np.zeros((0, 3)), np.zeros(0, dtype=np.intp), np.zeros(0, dtype=bool), np.zeros((0, 3)), None
            )
            self.dry_bar.set_run(None)
            return
        start, _rot = start_of(plan, ledger, self._pose)
        path = plan_path(plan, ledger, start, path_samples(plan))
        self.path_reach = self.reach.path(plan, ledger, self._pose)
        bad = bad_path_samples(path.xyz, path.segment, self.path_reach)
        self.canvas.set_path(path.xyz, path.segment, bad, arc_middles(plan, ledger), start)
        self.dry_bar.set_run(DryRun(plan, ledger, self._pose))

    def _show_reach(self) -> None:
        bad_points = sorted(pid for pid, r in self.point_reach.items() if r is not Reach.OK)
        parts = []
        if bad_points:
            names = join_names(f"P{pid}" for pid in bad_points[:8]) + (" …" if len(bad_points) > 8 else "")
            parts.append(
                self.tr("Out of the robot model's reach: %n point(s) (%1)", "", len(bad_points)).replace(
                    "%1", names
                )
            )
        if self.path_reach is not None:
            segs = [i + 1 for i, b in enumerate(self.path_reach.first_bad) if b is not None]
            if segs:
                parts.append(
                    self.tr("the path leaves the reach in %n segment(s) (%1)", "", len(segs)).replace(
                        "%1", join_names(str(s) for s in segs[:8])
                    )
                )
        self.reach_label.setText(join_sentences(parts))
        self.reach_label.setVisible(bool(parts))

    # --- selection -----------------------------------------------------------------------
    @Slot()
    def _on_table_selection(self, *_args: QItemSelection) -> None:
        if self._points_panel is None:
            return
        ids = {self._points.point_at(row).id for row in self._points_panel.selected_rows()}
        self.canvas.set_selected(ids)

    @Slot(int)
    def _on_point_clicked(self, point_id: int) -> None:
        if point_id < 0:
            ids: set[int] = set()
        else:
            ids = {point_id}
        self.canvas.set_selected(ids)
        if self._points_panel is not None:
            row = self._points.row_of(point_id) if point_id >= 0 else None
            self._points_panel.select_rows([] if row is None else [row])

    # --- dry run -------------------------------------------------------------------------
    @Slot(object)
    def _on_dry_state(self, state: DryRunState | None) -> None:
        self._dry = state
        if state is None or state.pose is None:
            self.canvas.set_ghost_arm(None, None)
            self.canvas.set_active_segment(None)
            self._update_badges()
            return
        result = self.model.inverse_pose(state.pose, self._dry_seed())
        q = result.joints if result.joints is not None else self._dry_seed()
        self._dry_joints = q
        self.canvas.set_ghost_arm(self.model.link_points(q), self.model.forward(q))
        self.canvas.set_active_segment(state.segment)
        self._update_badges()

    def _dry_seed(self) -> np.ndarray:
        return self._dry_joints if self._dry_joints is not None else self.tracker.joints
