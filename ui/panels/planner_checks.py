"""The planner's checks list: what :func:`app.plan.checks.check_plan` says of the plan on display
(with the plan limits, the safety envelope and reduced speed, and the robot model's reach), shown
on the segment rows and in the summary line, with the estimates and the preview beside them.

The same :meth:`PlannerChecks.check` makes the checks before a run (``planner_run``), so what the
list shows is what blocks Run. ``reach`` is the active robot model's
(:meth:`ui.panels.view3d_robot.RobotModelSource.plan_issues`, shared with the 3D view), None
until the window gives one.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from app.models import Pose
from app.plan.checks import PlanIssue, PlanLimits, ReachCheck, check_plan
from app.plan.estimates import estimate_plan
from app.plan.presenter import plan_info, plan_start, summarize_checks
from app.plan.segments import Plan
from app.points.ledger import PointLedger
from app.safety.envelope import Envelope
from ui.messages_plan import issue_line, issue_text
from ui.models.segment_model import SegmentTableModel
from ui.panels.plan_preview import PlanPreview
from ui.panels.planner_widgets import PlanChecksBar

RECHECK_COALESCE_MS = 300  # a moving arm re-checks the plan at most this often
POSE_MOVED_MM = 0.01  # X Y Z (mm) or A B C (degrees) this far from the checked pose: check again


def pose_moved(pose: Pose, checked: Pose) -> bool:
    """``pose`` is not where the shown checks assumed the robot (segment 1 starts there)."""
    return any(abs(a - b) > POSE_MOVED_MM for a, b in zip(pose.xyzabc, checked.xyzabc, strict=True))


class PlannerChecks:
    """Checks, estimates and preview of the planner's plan (the panel says when)."""

    def __init__(
        self,
        segments: SegmentTableModel,
        preview: PlanPreview,
        checks_bar: PlanChecksBar,
        ledger: Callable[[], PointLedger],
        pose: Callable[[], Pose | None],
        has_sync: bool,
        limits: PlanLimits | None = None,
    ) -> None:
        self._segments = segments
        self._preview = preview
        self._bar = checks_bar
        self._ledger = ledger
        self._pose = pose
        self._has_sync = has_sync
        self.limits = limits or PlanLimits()
        self.envelope: Envelope | None = None  # the safety envelope
        self.reduced_speed = False
        self.reach: ReachCheck | None = None  # the robot model's reach
        self.issues: list[PlanIssue] = []
        self.summary_text = ""
        self.held = False  # an emergency stop or servo alarm is set: nothing is "ready to run"

    def check(
        self, plan: Plan, pose: Pose | None, *, start_index: int = 0, loops: int | None = None
    ) -> list[PlanIssue]:
        return check_plan(
            plan,
            self._ledger(),
            self.limits,
            pose,
            start_index=start_index,
            loops=plan.loops if loops is None else loops,
            envelope=self.envelope,
            reduced_speed=self.reduced_speed,
            reach=self.reach,
        )

    def recheck(self, plan: Plan | None, selected: int | None) -> None:
        """Check ``plan`` from the robot's pose and show it all (``selected``: the segment row)."""
        if plan is None:
            self.issues = []
            self._preview.clear()
            self.show([], None)
            self._preview.set_info("")
            return
        ledger, pose = self._ledger(), self._pose()
        start, assumed = plan_start(plan, ledger, pose)
        self.issues = self.check(plan, pose)
        estimate = estimate_plan(plan, ledger, start)
        self._segments.set_estimate(estimate.lengths, estimate.times)
        self._preview.show_plan(plan, ledger, start, selected)
        self.show(self.issues, plan)
        self._preview.show_info(plan_info(plan, estimate, selected, assumed))

    def show(self, issues: Sequence[PlanIssue], plan: Plan | None) -> str:
        """Show ``issues`` on the rows and the summary line; returns the summary."""
        self.issues = list(issues)
        self._segments.set_issues(self.issues)
        checks = summarize_checks(issues, issue_text, issue_line) if plan is not None else None
        self.summary_text = self._bar.show_checks(checks, self._has_sync, self.held)
        return self.summary_text

    def show_info(self, plan: Plan | None, selected: int | None) -> None:
        """Lengths and times under the preview (the selection changed)."""
        if plan is None or not len(plan):
            return
        ledger = self._ledger()
        start, assumed = plan_start(plan, ledger, self._pose())
        self._preview.show_info(plan_info(plan, estimate_plan(plan, ledger, start), selected, assumed))
