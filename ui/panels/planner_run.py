"""Starting a plan from the planner: check from the robot's pose, refuse on errors, offer the
upload of missing points (and run when it succeeded), ask the operator, then start, step or
resume the run on the :class:`~ui.controllers.plan_run_controller.PlanRunController`.

The decisions (what blocks a run, how to ask) come from :mod:`app.plan.presenter`; the planner
panel is the view this flow selects segments on and reports to.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from PySide6.QtCore import QObject

from app.errors import InvalidInput, TeachPadError
from app.plan.checks import PlanIssue, ids_needing_upload
from app.plan.issue_kind import IssueKind
from app.plan.presenter import RunBlock, RunKind, run_gate, run_kind
from app.plan.runner import RunOutcome, RunState
from app.plan.segments import Plan
from app.points.upload import UploadReport
from ui.controllers.plan_run_controller import PauseState, PlanRunController
from ui.controllers.point_sync import PointSyncController
from ui.joins import join_names
from ui.messages import error_text, refusal_text
from ui.messages_plan import issue_text
from ui.models.points_model import PointsModel
from ui.panels.planner_checks import PlannerChecks

MAX_POINTS_LISTED = 20  # point ids quoted in the upload question


class PlannerView(Protocol):
    """What the flow needs of the planner panel."""

    checks: PlannerChecks  # the checks list's check_plan (limits, envelope, reach)

    @property
    def issues(self) -> list[PlanIssue]: ...

    def current_plan(self) -> Plan | None: ...

    def select_segments(self, rows: Sequence[int]) -> None: ...

    def show_message(self, text: str, level: str = "info") -> None: ...

    def show_issues(self, issues: list[PlanIssue], plan: Plan) -> str:
        """Show checks made for a run; returns the summary line shown."""
        ...

    def confirm(self, title: str, text: str) -> bool: ...


class PlanRunFlow(QObject):
    """Run, step, resume and stop, with the upload in between; remembers the run's plan."""

    def __init__(
        self,
        view: PlannerView,
        runner: PlanRunController,
        sync: PointSyncController | None,
        points: PointsModel,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._view = view
        self._runner = runner
        self._sync = sync
        self._points = points
        self._pending: tuple[int, bool, bool] | None = None  # (start, single, resume) after an upload
        self.next_step: tuple[int, int] | None = None  # (segment, loop) the next Step runs
        self.run_plan: Plan | None = None  # the plan of the last run
        self._run_revision = -1  # the run plan's revision when the run started

    def _plan_for_run(self) -> Plan | None:
        plan = self._view.current_plan()
        if plan is None or not len(plan):
            self._view.show_message(self.tr("The plan has no segments"), "error")
            return None
        if self._sync is not None and self._sync.busy:
            self._view.show_message(self.tr("Wait until the point upload or move ends"), "warn")
            return None
        return plan

    def run(self, start: int = 0, single: bool = False, *, resume: bool = False) -> bool:
        """Check, offer an upload, confirm, then run from ``start`` (``single``: one segment).
        Returns True when the run (or the upload before it) started."""
        view = self._view
        plan = self._plan_for_run()
        if plan is None:
            return False
        refusal = self._runner.link_refusal()  # not connected, or the controller not answering
        if refusal is not None:
            view.show_message(error_text(refusal), "error")
            return False
        issues = view.checks.check(
            plan, self._runner.last_pose, start_index=start, loops=1 if single else plan.loops
        )
        view.show_issues(issues, plan)
        gate = run_gate(issues, issue_text)
        if gate.block is RunBlock.ERRORS and (first := gate.first_error) is not None:
            if first.segment is not None:
                view.select_segments([first.segment])
            errors = sum(1 for issue in issues if issue.kind is IssueKind.ERROR)
            view.show_message(  # one sentence: how many errors and the first one
                self.tr("Cannot run: the plan has %n error(s); the first: {message}", "", errors).format(
                    message=issue_text(first)
                ),
                "error",
            )
            return False
        if gate.block is RunBlock.UPLOAD:
            needs = list(gate.uploads)
            if self._sync is None:
                view.show_message(self.tr("Cannot run: %n point(s) need upload", "", len(needs)), "error")
                return False
            question = self.tr("%n point(s) of the plan are not on the controller: ", "", len(needs))
            question += join_names(f"P{pid}" for pid in needs[:MAX_POINTS_LISTED])
            question += "\n\n" + self.tr("Upload now, then run?")
            if not view.confirm(self.tr("Upload points"), question):
                return False
            if self._sync.upload(needs):
                self._pending = (start, single, resume)
                return True
            return False
        return self._confirm_and_start(plan, start, single, resume)

    def _question(self, plan: Plan, start: int, single: bool, resume: bool) -> str:
        kind = run_kind(start, single, resume)
        if kind is RunKind.RESUME:
            k = (self._runner.resume_from or 0) + 1
            what = self.tr("Resume plan '{name}' from segment {k}?").format(name=plan.name, k=k)
        elif kind is RunKind.STEP:
            what = self.tr("Run segment {k} of plan '{name}' (one step)?").format(k=start + 1, name=plan.name)
        elif kind is RunKind.FROM:
            what = self.tr("Run plan '{name}' from segment {k}?").format(name=plan.name, k=start + 1)
        else:
            what = self.tr("Run plan '{name}'?").format(name=plan.name)
        text = what + "\n\n" + self.tr("The robot will move.")
        warnings = run_gate(self._view.issues, issue_text).warnings
        if warnings:
            text += "\n\n" + self.tr("Warnings:") + "\n" + "\n".join(f"• {w}" for w in warnings)
        return text

    def _confirm_and_start(self, plan: Plan, start: int, single: bool, resume: bool) -> bool:
        if not self._view.confirm(self.tr("Run plan"), self._question(plan, start, single, resume)):
            return False
        try:
            if resume and plan is self.run_plan and plan.revision == self._run_revision:
                self._runner.resume_run()
            elif resume:
                # the plan was edited since: a new run of the current segments from the same place
                loop = self._runner.resume_loop or 1
                self._run_revision = plan.revision
                self._runner.start(plan, start=start, start_loop=loop)
            else:
                loop = 1
                if single and self.next_step is not None and self.next_step[0] == start:
                    loop = self.next_step[1]
                self.run_plan = plan
                self._run_revision = plan.revision
                self._runner.start(plan, start=start, start_loop=loop, single=single)
        except InvalidInput as exc:  # a bad start segment
            self._view.show_message(refusal_text(exc), "error")
            return False
        except TeachPadError as exc:  # no link, monitor-only...: in the operator's language
            self._view.show_message(error_text(exc), "error")
            return False
        except RuntimeError as exc:
            self._view.show_message(str(exc), "error")
            return False
        return True

    def pause_text(self, state: PauseState) -> str:
        """The run box's words for the run's Pause (empty: nothing to say)."""
        if state is PauseState.PAUSING:
            return self.tr("Pausing… (waiting for the controller to confirm the Pause)")
        if state is PauseState.UNCONFIRMED:
            return self.tr(
                "Pausing — the controller has not confirmed: the arm may still be moving. Pause is "
                "sent again at every poll. Press STOP if it must stop now."
            )
        if state is PauseState.STOPPING:
            return self.tr(
                "Pause not confirmed by the controller in time: Stop is sent instead, at every poll, "
                "until the controller takes it."
            )
        if state is PauseState.PAUSED:
            return self.tr("Paused (confirmed by the controller). Press Resume to go on.")
        if state is PauseState.REFUSED:
            text = self.tr(
                "Pause refused by the controller: the arm was not paused. Press STOP if it must stop "
                "now, or press Pause again."
            )
            why = self._runner.pause_refusal
            return f"{text} ({why})" if why else text
        return ""

    def step_start(self, selected: Sequence[int]) -> int:
        """Where Step starts: the selected segment, else where the last step left off."""
        if selected:
            return selected[0]
        return self.next_step[0] if self.next_step else 0

    def stop(self) -> None:
        """Stop the robot and the run; cancel an upload that would start one."""
        self._pending = None
        self._runner.stop()
        if self._sync is not None and self._sync.operation == "upload":
            self._sync.cancel_upload()

    def upload_needed(self) -> None:
        """Upload the points the last checks found missing on the controller."""
        if self._view.current_plan() is None or self._sync is None:
            return
        ids = ids_needing_upload(self._view.issues)
        if ids:
            self._sync.upload(ids)

    def upload_finished(self, report: UploadReport) -> None:
        """After an upload the run asked for: start it (asking first) when every point went."""
        pending, self._pending = self._pending, None
        if pending is None:
            return
        if not report.all_ok:
            self._view.show_message(self.tr("The upload did not complete: the plan was not started"), "error")
            return
        plan = self._view.current_plan()
        if plan is not None:
            start, single, resume = pending
            self._confirm_and_start(plan, start, single, resume)

    def run_finished(self, outcome: RunOutcome) -> None:
        if outcome.state is RunState.FINISHED:
            self.next_step = outcome.next_position
