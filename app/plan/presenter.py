"""What the planner shows about a plan, worked out without Qt: the checks' summary, where the
plan starts, the estimate lines, what a run needs first, the run's progress and which actions
are enabled. The planner widget (``ui/panels/planner_panel.py``) only translates and draws.

Texts that reach the operator are translated by the widget; this module gives it counts,
levels, numbers and the issues worded by the widget's own ``text`` function (an issue's code and
arguments in the operator's language, ``ui/messages.issue_text``); without one, the issues'
English messages (the CLI, tests).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from app.models import Pose
from app.plan.checks import PlanIssue, ids_needing_upload
from app.plan.estimates import PlanEstimate
from app.plan.issue_kind import IssueKind
from app.plan.segments import Plan
from app.points.ledger import PointLedger

XYZ = tuple[float, float, float]
IssueText = Callable[[PlanIssue], str]  # one issue as a sentence


def english(issue: PlanIssue) -> str:
    """An issue's own message (plain English)."""
    return issue.message


ENDLESS = "∞"


class Level(enum.Enum):
    """How a message reads: the colour of the summary line and of the status line."""

    OK = "ok"
    INFO = "info"
    WARN = "warn"
    ERROR = "error"


@dataclass(frozen=True)
class CheckSummary:
    """The checks of a plan in a few numbers, for the line under the segment table."""

    errors: int
    warnings: int
    uploads: tuple[int, ...]  # ids of the points to upload first
    first_row_error: str  # the first error on a segment's row ("" when none)
    whole_plan: tuple[str, ...]  # messages about the whole plan (no segment)
    details: str  # every issue, one a line (the tooltip)

    @property
    def passed(self) -> bool:
        """Nothing to report: ready to run."""
        return not (self.errors or self.warnings or self.uploads)

    @property
    def level(self) -> Level:
        if self.errors:
            return Level.ERROR
        if self.uploads:
            return Level.INFO
        return Level.WARN if self.warnings else Level.OK


def summarize_checks(
    issues: Sequence[PlanIssue], text: IssueText = english, line: IssueText = str
) -> CheckSummary:
    """Count the issues by kind; keep the first row error and the whole-plan messages (worded by
    ``text``); ``line`` words an issue with its kind for the details."""
    row_errors = [text(i) for i in issues if i.kind is IssueKind.ERROR and i.segment is not None]
    return CheckSummary(
        errors=sum(1 for i in issues if i.kind is IssueKind.ERROR),
        warnings=sum(1 for i in issues if i.kind is IssueKind.WARNING),
        uploads=tuple(ids_needing_upload(issues)),
        first_row_error=row_errors[0] if row_errors else "",
        whole_plan=tuple(text(i) for i in issues if i.segment is None),
        details="\n".join(line(i) for i in issues),
    )


def plan_start(plan: Plan, ledger: PointLedger, pose: Pose | None) -> tuple[XYZ | None, bool]:
    """Where segment 1 starts, and whether that is assumed: the robot's pose when known, else
    the end of the last segment (the plan as a loop), else unknown (None, True)."""
    if pose is not None:
        return (pose.x, pose.y, pose.z), False
    if len(plan):
        last = ledger.get(plan[len(plan) - 1].end_id)
        if last is not None:
            x, y, z = last.xyz
            return (float(x), float(y), float(z)), True
    return None, True


def format_length(mm: float) -> str:
    """``1,234.5 mm``; ``∞`` for an endless plan."""
    return ENDLESS if math.isinf(mm) else f"{mm:,.1f} mm"


def format_duration(seconds: float) -> str:
    """``2 min 05.0 s`` or ``12.5 s``; ``∞`` for an endless plan."""
    if math.isinf(seconds):
        return ENDLESS
    minutes, rest = divmod(seconds, 60.0)
    return f"{int(minutes)} min {rest:04.1f} s" if minutes else f"{rest:.1f} s"


@dataclass(frozen=True)
class SegmentEstimate:
    number: int  # 1-based
    length: str
    time: str


@dataclass(frozen=True)
class PlanInfo:
    """The estimate lines under the preview, formatted but not yet worded."""

    name: str
    segments: int
    loops: int  # 0: endless
    loop_length: str
    loop_time: str
    total_length: str
    total_time: str
    unknown: tuple[int, ...]  # 1-based numbers of the segments left out (at most 10)
    selected: SegmentEstimate | None  # the selected segment, when its length is known
    assumed_start: bool  # the start is the last segment's end, the robot's pose being unknown


def plan_info(plan: Plan, estimate: PlanEstimate, selected: int | None, assumed_start: bool) -> PlanInfo:
    chosen: SegmentEstimate | None = None
    if selected is not None and 0 <= selected < len(plan):
        length, time = float(estimate.lengths[selected]), float(estimate.times[selected])
        if math.isfinite(length):
            chosen = SegmentEstimate(selected + 1, format_length(length), format_duration(time))
    return PlanInfo(
        name=plan.name,
        segments=len(plan),
        loops=plan.loops,
        loop_length=format_length(estimate.loop_length),
        loop_time=format_duration(estimate.loop_time),
        total_length=format_length(estimate.total_length),
        total_time=format_duration(estimate.total_time),
        unknown=tuple(i + 1 for i in estimate.unknown[:10]),
        selected=chosen,
        assumed_start=assumed_start,
    )


class RunBlock(enum.Enum):
    """What stands between the checks and a run."""

    NONE = "none"  # run (after the operator confirms)
    ERRORS = "errors"  # refuse: the plan cannot run as it is
    UPLOAD = "upload"  # upload the points first (then run)


@dataclass(frozen=True)
class RunGate:
    block: RunBlock
    first_error: PlanIssue | None  # the first error (select its segment, quote it)
    uploads: tuple[int, ...]  # point ids to upload before the run
    warnings: tuple[str, ...]  # shown in the confirmation (at most 8)


MAX_WARNINGS_SHOWN = 8


def run_gate(issues: Sequence[PlanIssue], text: IssueText = english) -> RunGate:
    """Errors refuse the run; points that need an upload come next; warnings are quoted
    (worded by ``text``)."""
    errors = [i for i in issues if i.kind is IssueKind.ERROR]
    uploads = tuple(ids_needing_upload(issues))
    warnings = tuple(text(i) for i in issues if i.kind is IssueKind.WARNING)[:MAX_WARNINGS_SHOWN]
    if errors:
        block = RunBlock.ERRORS
    elif uploads:
        block = RunBlock.UPLOAD
    else:
        block = RunBlock.NONE
    return RunGate(block, errors[0] if errors else None, uploads, warnings)


class RunKind(enum.Enum):
    """How the confirmation asks: resume, one step, from a segment, or the whole plan."""

    RESUME = "resume"
    STEP = "step"
    FROM = "from"
    WHOLE = "whole"


def run_kind(start: int, single: bool, resume: bool) -> RunKind:
    if resume:
        return RunKind.RESUME
    if single:
        return RunKind.STEP
    return RunKind.FROM if start else RunKind.WHOLE


def progress_bar(index: int, count: int, loop: int, loops: int, segment_done: bool) -> tuple[int, int] | None:
    """``(done, total)`` segments of the whole run; None for an endless plan (a busy bar)."""
    if not loops:
        return None
    total = count * loops
    done = (loop - 1) * count + index + (1 if segment_done else 0)
    return min(done, total), total


@dataclass(frozen=True)
class PanelState:
    """What the planner's actions depend on."""

    connected: bool
    running: bool
    paused: bool
    can_resume: bool
    has_plan: bool
    segments: int
    selected: bool  # some segment rows are selected
    can_move_up: bool
    can_move_down: bool
    has_sync: bool  # a point uploader is attached
    sync_busy: bool
    uploading: bool
    check_errors: int = 0  # errors the plan's checks found (warnings do not count)
    first_error: str = ""  # the first of them, quoted in Run's tooltip


class RunBlocker(enum.Enum):
    """Why Run (and Run from here, Step) is disabled; the widget words it as Run's tooltip."""

    NONE = "none"
    NO_LINK = "no link"
    RUNNING = "running"
    NO_SEGMENTS = "no segments"
    SYNC_BUSY = "sync busy"
    CHECKS = "checks"  # the plan's checks found errors


@dataclass(frozen=True)
class ActionStates:
    """Enabled (and visible) states of the planner's actions."""

    add_plan: bool
    edit_plan: bool  # rename, duplicate, delete
    add_segment: bool
    delete_segment: bool
    segment_up: bool
    segment_down: bool
    run: bool  # run, step
    run_from: bool
    pause: bool
    resume: bool
    stop: bool
    resume_from: bool
    upload_now: bool
    resume_from_visible: bool
    run_blocker: RunBlocker = RunBlocker.NONE  # why ``run`` is False
    first_error: str = ""  # the checks' first error when ``run_blocker`` is CHECKS


def run_blocker(s: PanelState) -> RunBlocker:
    """The first reason a run cannot start: no connection, a run going, no segments, an upload
    in progress, then errors in the plan's checks (warnings do not block: the run asks first)."""
    if not s.connected:
        return RunBlocker.NO_LINK
    if s.running:
        return RunBlocker.RUNNING
    if s.segments <= 0:
        return RunBlocker.NO_SEGMENTS
    if s.sync_busy:
        return RunBlocker.SYNC_BUSY
    if s.check_errors:
        return RunBlocker.CHECKS
    return RunBlocker.NONE


def action_states(s: PanelState) -> ActionStates:
    """Run needs a connection, no run going, segments, no upload in progress and a plan whose
    checks found no error; edits need a plan and no run; Stop also cancels an upload."""
    blocker = run_blocker(s)
    can_start = blocker is RunBlocker.NONE
    editable = s.has_plan and not s.running
    return ActionStates(
        add_plan=not s.running,
        edit_plan=editable,
        add_segment=not s.running,
        delete_segment=editable and s.selected,
        segment_up=editable and s.can_move_up,
        segment_down=editable and s.can_move_down,
        run=can_start,
        run_from=can_start and s.selected,
        pause=s.running and not s.paused,
        resume=s.running and s.paused,
        stop=s.running or (s.has_sync and s.uploading),
        resume_from=s.connected and not s.running and s.can_resume and not s.sync_busy,
        upload_now=s.has_sync and s.connected and not s.running and not s.sync_busy,
        resume_from_visible=s.can_resume,
        run_blocker=blocker,
        first_error=s.first_error if blocker is RunBlocker.CHECKS else "",
    )


__all__ = [
    "ActionStates",
    "CheckSummary",
    "Level",
    "PanelState",
    "PlanInfo",
    "RunBlock",
    "RunBlocker",
    "RunGate",
    "RunKind",
    "SegmentEstimate",
    "action_states",
    "format_duration",
    "format_length",
    "plan_info",
    "plan_start",
    "progress_bar",
    "run_blocker",
    "run_gate",
    "run_kind",
    "summarize_checks",
]
