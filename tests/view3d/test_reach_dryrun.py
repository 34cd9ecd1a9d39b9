"""Reachability of points and paths (and check_plan's report of it); the dry run timeline."""

from __future__ import annotations

import numpy as np
import pytest

from app.models import Pose
from app.plan.checks import IssueCode, check_plan
from app.plan.estimates import estimate_plan
from app.plan.issue_kind import IssueKind
from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.points.point import make_point
from app.view3d.kinematics import ArmModel, Reach
from app.view3d.path import DryRun
from app.view3d.profile import default_profile
from app.view3d.reach import ReachChecker

DOWN = (180.0, 0.0, 180.0)  # tool pointing down


def _ledger(far: bool = False) -> PointLedger:
    return PointLedger(
        [
            make_point(1, "A", (450, -100, 350, *DOWN)),
            make_point(2, "B", (500, 0, 420, *DOWN)),
            make_point(3, "C", (450, 100, 350, *DOWN)),
            make_point(9, "far", (1400 if far else 450, 0, 300, *DOWN)),
        ]
    )


@pytest.fixture(name="checker")
def checker_fixture() -> ReachChecker:
    return ReachChecker(ArmModel(default_profile()))


def test_points_in_and_out_of_reach(checker: ReachChecker) -> None:
    reach = checker.points(list(_ledger(far=True)))
    assert reach == {1: Reach.OK, 2: Reach.OK, 3: Reach.OK, 9: Reach.UNREACHABLE}


def test_check_plan_reports_an_unreachable_point_only_when_asked(checker: ReachChecker) -> None:
    ledger = _ledger(far=True)
    plan = Plan("p", [Segment.line(1), Segment.arc(2, 3), Segment.line(9)])
    pose = Pose(450, -100, 350, *DOWN)
    before = check_plan(plan, ledger, current_pose=pose)
    assert not any(i.code in (IssueCode.UNREACHABLE, IssueCode.JOINT_LIMIT) for i in before)
    issues = check_plan(plan, ledger, current_pose=pose, reach=checker.plan_issues)
    reach = [i for i in issues if i.code is IssueCode.UNREACHABLE]
    assert [(i.segment, i.point_id, i.kind) for i in reach] == [(2, 9, IssueKind.ERROR)]
    assert reach[0].message.startswith("segment 3: ") and "out of the robot model's reach" in reach[0].message
    assert [i for i in issues if i.code not in (IssueCode.UNREACHABLE,)] == before


def test_path_between_reachable_points_can_leave_the_reach(checker: ReachChecker) -> None:
    # two points on either side of the base, close to it: the straight line passes the J1 axis
    ledger = PointLedger(
        [make_point(1, "L", (-150, -300, 900, *DOWN)), make_point(2, "R", (-150, 300, 900, *DOWN))]
    )
    plan = Plan("through", [Segment.line(2)])
    start = Pose(-150, -300, 900, *DOWN)
    path = checker.path(plan, ledger, start)
    assert path.bad_mask.shape == (path.xyz.shape[0],)
    ok_path = checker.path(Plan("ok", [Segment.arc(2, 3)]), _ledger(), Pose(450, -100, 350, *DOWN))
    assert not ok_path.bad_mask.any() and ok_path.first_bad == (None,)


def test_dry_run_follows_the_estimates_and_the_true_arc() -> None:
    ledger = _ledger()
    plan = Plan("p", [Segment.arc(2, 3, speed=100.0), Segment.line(1, speed=50.0)])
    pose = Pose(450, -100, 350, *DOWN)
    run = DryRun(plan, ledger, pose)
    est = estimate_plan(plan, ledger, (450, -100, 350))
    assert run.duration == pytest.approx(float(est.times.sum()))
    assert run.at(0.0).pose[:3] == pytest.approx((450, -100, 350))  # type: ignore[index]
    assert run.at(run.duration).pose[:3] == pytest.approx((450, -100, 350))  # type: ignore[index]
    # half way through the arc's motion the tool is on the circle through A B C
    t = run.overhead + (float(est.times[0]) - run.overhead) / 2.0
    state = run.at(t)
    assert state.segment == 0 and state.fraction == pytest.approx(0.5)
    centre = np.array([450.0, 0.0, 350.0])  # not the centre; check the distance to the circle instead
    xyz = np.array(state.pose[:3])  # type: ignore[index]
    from app.plan.geometry import arc_geometry

    geo = arc_geometry(np.array([450, -100, 350.0]), np.array([500, 0, 420.0]), np.array([450, 100, 350.0]))
    assert np.linalg.norm(xyz - geo.centre[0]) == pytest.approx(geo.radius[0], rel=1e-3)
    assert np.dot(xyz - geo.centre[0], geo.normal[0]) == pytest.approx(0.0, abs=1e-6)
    assert not np.allclose(xyz, centre)
    assert run.at(float(est.times[0]) + 0.01).segment == 1


@pytest.mark.parametrize("loops", [3, 20])
def test_dry_run_plays_every_loop_of_the_plan(loops: int) -> None:
    """The timeline holds all N loops (the estimate's total time); every loop after the first
    starts where the plan ends (A), as the runner runs it, not at the robot's pose."""
    ledger = _ledger()
    plan = Plan(
        "p", [Segment.line(2, speed=100.0), Segment.line(3, speed=100.0), Segment.line(1, speed=80.0)]
    )
    plan.set_loops(loops)
    pose = Pose(600, 0, 500, *DOWN)  # away from the plan: the first loop's first segment is longer
    run = DryRun(plan, ledger, pose)
    est = estimate_plan(plan, ledger, (600, 0, 500))
    assert run.duration == pytest.approx(est.total_time)
    assert run.at(0.0).loop == 1 and run.at(0.0).pose[:3] == pytest.approx((600, 0, 500))  # type: ignore[index]
    second = est.loop_time + 1e-6
    state = run.at(second)
    assert (state.loop, state.loops, state.segment) == (2, loops, 0)
    assert state.pose[:3] == pytest.approx((450, -100, 350))  # type: ignore[index]  # the plan's end, A
    # half way through the last loop's first segment: half way from A to B
    t = est.loop_time + (loops - 2) * est.next_loop_time + est.wrap_time / 2 + run.overhead / 2
    state = run.at(t)
    assert (state.loop, state.segment) == (loops, 0)
    assert state.pose[:3] == pytest.approx((475, -50, 385))  # type: ignore[index]
    assert run.at(run.duration).loop == loops
    assert run.at(run.duration).pose[:3] == pytest.approx((450, -100, 350))  # type: ignore[index]


def test_dry_run_of_an_endless_plan_plays_a_later_loop_too() -> None:
    from app.view3d.path import ENDLESS_LOOPS_SHOWN

    ledger = _ledger()
    plan = Plan("p", [Segment.line(2), Segment.line(1)])
    plan.set_loops(0)
    run = DryRun(plan, ledger, Pose(600, 0, 500, *DOWN))
    est = estimate_plan(plan, ledger, (600, 0, 500), loops=ENDLESS_LOOPS_SHOWN)
    assert run.duration == pytest.approx(est.total_time)
    assert (run.at(run.duration).loop, run.at(run.duration).loops) == (ENDLESS_LOOPS_SHOWN, 0)
