"""The planner's presenter without Qt: check summaries, the start, estimate lines, what blocks
a run, progress and which actions are enabled."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from app.models import Pose
from app.plan.checks import check_plan
from app.plan.estimates import SEGMENT_OVERHEAD_S, estimate_plan
from app.plan.presenter import (
    Level,
    PanelState,
    RunBlock,
    RunBlocker,
    RunKind,
    action_states,
    format_duration,
    format_length,
    plan_info,
    plan_start,
    progress_bar,
    run_gate,
    run_kind,
    summarize_checks,
)
from app.plan.segments import Plan, Segment
from tests.plan.test_plan import HOME, circle_plan, ledger

IDLE = PanelState(
    connected=True,
    running=False,
    paused=False,
    can_resume=False,
    has_plan=True,
    segments=3,
    selected=True,
    can_move_up=True,
    can_move_down=False,
    has_sync=True,
    sync_busy=False,
    uploading=False,
)


def test_a_plan_that_passes_reads_ok_and_runs() -> None:
    issues = check_plan(circle_plan(), ledger(), current_pose=HOME)
    checks = summarize_checks(issues)
    assert checks.passed and checks.level is Level.OK and checks.details == ""
    gate = run_gate(issues)
    assert gate.block is RunBlock.NONE and gate.first_error is None and gate.uploads == ()


def test_errors_come_first_then_uploads_then_warnings() -> None:
    # P11 needs an upload, P12 failed its upload, P99 does not exist, P13 has another tool
    plan = Plan("mixed", [Segment.line(11), Segment.line(12), Segment.line(99), Segment.line(13)])
    issues = check_plan(plan, ledger(), current_pose=(300, 0, 300))
    checks = summarize_checks(issues)
    assert (checks.errors, checks.warnings, checks.uploads) == (1, 1, (11, 12))
    assert checks.level is Level.ERROR and not checks.passed
    assert checks.first_row_error == "segment 3: end point P99 does not exist"
    assert checks.details.count("\n") == len(issues) - 1
    gate = run_gate(issues)
    assert gate.block is RunBlock.ERRORS and gate.first_error is not None and gate.first_error.segment == 2
    without_error = run_gate([i for i in issues if not i.is_error])
    assert without_error.block is RunBlock.UPLOAD and without_error.uploads == (11, 12)
    assert summarize_checks([i for i in issues if not i.is_error]).level is Level.INFO
    only_warning = [i for i in issues if i.point_id == 13]
    assert summarize_checks(only_warning).level is Level.WARN
    assert run_gate(only_warning).warnings == (only_warning[0].message,)


def test_whole_plan_messages_are_kept_apart() -> None:
    checks = summarize_checks(check_plan(Plan("empty", []), ledger()))
    assert checks.whole_plan == ("plan 'empty' has no segments",) and checks.first_row_error == ""


def test_the_start_is_the_pose_else_the_last_end_else_unknown() -> None:
    plan, points = circle_plan(), ledger()
    assert plan_start(plan, points, Pose(1, 2, 3, 0, 0, 0)) == ((1.0, 2.0, 3.0), False)
    assert plan_start(plan, points, None) == ((300.0, 0.0, 300.0), True)  # the loop closes at W
    assert plan_start(Plan("empty", []), points, None) == (None, True)
    assert plan_start(Plan("lost", [Segment.line(99)]), points, None) == (None, True)


def test_lengths_and_times_are_formatted() -> None:
    assert format_length(1234.56) == "1,234.6 mm" and format_length(math.inf) == "∞"
    assert format_duration(12.46) == "12.5 s" and format_duration(125.0) == "2 min 05.0 s"
    assert format_duration(math.inf) == "∞"


def test_plan_info_names_the_selected_segment_and_the_unknown_ones() -> None:
    plan = Plan("circle", [*circle_plan().segments, Segment.line(99)], loops=2)
    estimate = estimate_plan(plan, ledger(), (300, 0, 300))
    info = plan_info(plan, estimate, 0, assumed_start=False)
    assert (info.name, info.segments, info.loops, info.unknown) == ("circle", 4, 2, (4,))
    assert info.selected is not None and info.selected.number == 1
    assert info.selected.length == "0.0 mm" and info.selected.time == f"{SEGMENT_OVERHEAD_S:.1f} s"
    assert plan_info(plan, estimate, 3, assumed_start=True).selected is None  # unknown length
    assert plan_info(plan, estimate, None, assumed_start=True).assumed_start
    endless = plan_info(replace_loops(plan, 0), estimate_plan(replace_loops(plan, 0), ledger()), None, True)
    assert endless.loops == 0 and endless.total_length == "∞" and endless.total_time == "∞"


def replace_loops(plan: Plan, loops: int) -> Plan:
    return Plan(plan.name, list(plan.segments), loops)


@pytest.mark.parametrize(
    ("start", "single", "resume", "kind"),
    [
        (0, False, False, RunKind.WHOLE),
        (2, False, False, RunKind.FROM),
        (2, True, False, RunKind.STEP),
        (0, True, False, RunKind.STEP),
        (2, True, True, RunKind.RESUME),
    ],
)
def test_run_kind(start: int, single: bool, resume: bool, kind: RunKind) -> None:
    assert run_kind(start, single, resume) is kind


def test_progress_counts_segments_over_all_loops() -> None:
    assert progress_bar(0, 4, 1, 2, segment_done=False) == (0, 8)
    assert progress_bar(1, 4, 2, 2, segment_done=True) == (6, 8)
    assert progress_bar(3, 4, 2, 2, segment_done=True) == (8, 8)
    assert progress_bar(1, 4, 7, 0, segment_done=True) is None  # endless: a busy bar


def test_actions_idle_connected() -> None:
    s = action_states(IDLE)
    assert s.run and s.run_from and s.add_plan and s.edit_plan and s.delete_segment and s.segment_up
    assert not (s.segment_down or s.pause or s.resume or s.stop or s.resume_from or s.resume_from_visible)
    assert s.upload_now


def test_actions_while_running_and_paused() -> None:
    running = action_states(replace(IDLE, running=True))
    assert running.pause and running.stop and not running.resume
    assert not (
        running.run
        or running.add_plan
        or running.edit_plan
        or running.delete_segment
        or running.upload_now
        or running.resume_from
    )
    paused = action_states(replace(IDLE, running=True, paused=True))
    assert paused.resume and not paused.pause and paused.stop


def test_actions_need_a_link_segments_and_no_upload() -> None:
    assert not action_states(replace(IDLE, connected=False)).run
    assert not action_states(replace(IDLE, segments=0)).run
    assert not action_states(replace(IDLE, selected=False)).run_from
    busy = action_states(replace(IDLE, sync_busy=True, uploading=True))
    assert not (busy.run or busy.upload_now) and busy.stop  # Stop cancels the upload
    assert not action_states(replace(IDLE, has_sync=False)).upload_now
    stopped = action_states(replace(IDLE, can_resume=True))
    assert stopped.resume_from and stopped.resume_from_visible
    assert not action_states(replace(IDLE, can_resume=True, connected=False)).resume_from


def test_run_is_disabled_while_the_checks_find_errors() -> None:
    """Errors disable Run, Run from here and Step, with the reason; warnings and points that
    need an upload do not (the run asks, or offers the upload, first)."""
    plan = Plan("broken", [Segment.line(11), Segment.line(99)])
    checks = summarize_checks(check_plan(plan, ledger(), current_pose=(300, 0, 300)))
    assert checks.errors == 1
    state = replace(IDLE, check_errors=checks.errors, first_error=checks.first_row_error)
    s = action_states(state)
    assert not (s.run or s.run_from) and s.run_blocker is RunBlocker.CHECKS
    assert s.first_error == "segment 2: end point P99 does not exist"
    assert s.add_segment and s.edit_plan and s.delete_segment  # the operator can still fix it
    fixed = action_states(replace(state, check_errors=0, first_error=""))
    assert fixed.run and fixed.run_blocker is RunBlocker.NONE and fixed.first_error == ""
    # the first reason wins: no link says so even when the checks fail too
    assert action_states(replace(state, connected=False)).run_blocker is RunBlocker.NO_LINK
    assert action_states(replace(state, running=True)).run_blocker is RunBlocker.RUNNING
    assert action_states(replace(state, segments=0)).run_blocker is RunBlocker.NO_SEGMENTS
    assert action_states(replace(state, sync_busy=True)).run_blocker is RunBlocker.SYNC_BUSY
