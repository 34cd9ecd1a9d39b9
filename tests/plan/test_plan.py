"""Plans: segment validation, pre-run checks, arc geometry, lengths and times."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from app.errors import InvalidInput
from app.models import Pose
from app.plan.checks import IssueCode, PlanLimits, check_plan, has_errors, ids_needing_upload
from app.plan.estimates import (
    SEGMENT_OVERHEAD_S,
    estimate_plan,
    estimate_time,
    move_timeout,
    segment_timeouts,
)
from app.plan.geometry import arc_geometry, plan_path, segment_length, segment_path
from app.plan.issue_kind import IssueKind
from app.plan.segments import Plan, Segment, SegmentKind
from app.points.fields import FieldError
from app.points.ledger import PointLedger
from app.points.point import SyncState, make_point

ON = SyncState.ON_CONTROLLER
HOME = (400.0, 0.0, 450.0)


def ledger() -> PointLedger:
    """A horizontal circle of radius 100 around (400, 0, 300), plus odd points."""
    return PointLedger(
        [
            make_point(1, "home", (*HOME, 180, 0, 0), sync=ON),
            make_point(5, "W", (300, 0, 300, 180, 0, 0), sync=ON),
            make_point(6, "N", (400, 100, 300, 180, 0, 0), sync=ON),
            make_point(7, "E", (500, 0, 300, 180, 0, 0), sync=ON),
            make_point(8, "S", (400, -100, 300, 180, 0, 0), sync=ON),
            make_point(9, "mid W-E", (400, 0, 300, 180, 0, 0), sync=ON),
            make_point(10, "W again", (300, 0, 300.05, 180, 0, 0), sync=ON),
            make_point(11, "new", (350, 50, 300, 180, 0, 0), sync=SyncState.CHANGED),
            make_point(
                12, "failed", (350, -50, 300, 180, 0, 0), sync=SyncState.FAILED, sync_error="bad point id"
            ),
            make_point(13, "tool 1", (450, 50, 300, 180, 0, 0), tool=0, sync=ON),
        ]
    )


def circle_plan(loops: int = 1) -> Plan:
    return Plan("circle", [Segment.line(5, 100), Segment.arc(6, 7, 50), Segment.arc(8, 5, 50)], loops)


# --- segments and plans ---------------------------------------------------------------------


def test_segment_validation_and_editing() -> None:
    assert Segment(SegmentKind.LINE, 3, via_id=4).via_id is None
    assert Segment("arc", 3, 4).kind is SegmentKind.ARC  # type: ignore[arg-type]
    for bad in ({"speed": math.nan}, {"speed": math.inf}, {"tool": 201}, {"end_id": -1}, {"end_id": 1.5}):
        args: dict[str, object] = {"kind": SegmentKind.LINE, "end_id": 1}
        args.update(bad)
        with pytest.raises(FieldError):
            Segment(**args)  # type: ignore[arg-type]
    seg = Segment.line(3)
    arc = seg.with_field("kind", "arc")
    assert arc.is_arc and arc.via_id is None
    arc = arc.with_field("via", "4").with_field("orientation", "kept").with_field("ignore_middle", "yes")
    assert (arc.via_id, arc.orientation_changes, arc.ignore_middle) == (4, False, True)
    assert arc.with_field("kind", "line").via_id is None
    assert arc.with_field("via", "").via_id is None
    assert arc.get("orientation") == "kept" and arc.text == "arc via P4 to P3, 50 mm/s"
    with pytest.raises(FieldError, match="speed"):
        seg.with_field("speed", "fast")
    with pytest.raises(FieldError):
        seg.with_field("colour", 1)


def test_plan_mutations_return_what_undo_needs() -> None:
    plan = circle_plan()
    rev = plan.revision
    old = plan.remove(1)
    assert len(plan) == 2
    plan.insert(1, old)
    plan.move(0, 2)
    assert [s.end_id for s in plan.segments] == [7, 5, 5]
    plan.move(2, 0)
    edit = plan.set_field(0, "speed", "75")
    assert edit.old.speed == 100 and plan[0].speed == 75
    plan.replace(0, edit.old)
    assert plan.segments == circle_plan().segments and plan.revision > rev
    assert plan.set_loops(0) == 1 and plan.loops == 0
    with pytest.raises(FieldError):
        plan.set_loops(-1)
    with pytest.raises(FieldError):
        Plan(" ")
    assert plan.rename(" new ") == "circle" and plan.name == "new"
    assert plan.replace_point_id(5, 55) == [0, 2] and plan.point_ids() == {55, 6, 7, 8}


# --- checks -------------------------------------------------------------------------------------


def test_good_plan_has_no_issues() -> None:
    assert check_plan(circle_plan(), ledger(), current_pose=HOME) == []


def test_missing_point_is_an_error_naming_the_segment() -> None:
    plan = Plan("p", [Segment.line(5), Segment.arc(99, 7), Segment.line(42)])
    issues = check_plan(plan, ledger(), current_pose=HOME)
    assert [(i.segment, i.kind, i.code, i.point_id) for i in issues] == [
        (1, IssueKind.ERROR, IssueCode.MISSING_POINT, 99),
        (2, IssueKind.ERROR, IssueCode.MISSING_POINT, 42),
    ]
    assert issues[0].message == "segment 2: middle point P99 does not exist"
    assert has_errors(issues)


def test_needs_upload_is_distinct_from_errors_and_reported_once_per_point() -> None:
    plan = Plan("p", [Segment.line(11), Segment.line(12), Segment.line(11), Segment.line(5)])
    issues = check_plan(plan, ledger(), current_pose=HOME)
    assert not has_errors(issues)
    assert [(i.segment, i.kind, i.point_id) for i in issues] == [
        (0, IssueKind.NEEDS_UPLOAD, 11),
        (1, IssueKind.NEEDS_UPLOAD, 12),
    ]
    assert "changed on host" in issues[0].message
    assert "bad point id" in issues[1].message
    assert ids_needing_upload(issues) == [11, 12]
    lg = ledger()
    lg.mark_all_unknown()
    assert ids_needing_upload(check_plan(circle_plan(), lg, current_pose=HOME)) == [5, 6, 7, 8]


def test_collinear_and_coincident_arcs_are_errors() -> None:
    lg = ledger()
    collinear = Plan("p", [Segment.line(5), Segment.arc(9, 7)])  # W -> centre -> E: one line
    (issue,) = check_plan(collinear, lg, current_pose=HOME)
    assert (issue.segment, issue.kind, issue.code) == (1, IssueKind.ERROR, IssueCode.ARC_COLLINEAR)
    assert issue.message.startswith("segment 2: the arc's three points are (nearly) on one line")

    beyond = Plan("p", [Segment.line(5), Segment.arc(7, 9)])  # middle point beyond the end
    assert [i.code for i in check_plan(beyond, lg, current_pose=HOME)] == [IssueCode.ARC_COLLINEAR]

    same = Plan("p", [Segment.line(5), Segment.arc(10, 7)])  # middle 0.05 mm from the start
    (issue,) = check_plan(same, lg, current_pose=HOME)
    assert issue.code is IssueCode.ARC_POINTS_COINCIDE and "start and middle" in issue.message
    relaxed = PlanLimits(min_point_distance=0.01, collinear_tolerance=0.01)
    assert check_plan(same, lg, relaxed, current_pose=HOME) == []

    closed = Plan("p", [Segment.line(5), Segment.arc(7, 5)])  # back to the start: no circle
    (issue,) = check_plan(closed, lg, current_pose=HOME)
    assert issue.code is IssueCode.ARC_POINTS_COINCIDE and "start and end" in issue.message


def test_speed_range() -> None:
    speeds = [0, -1, 1000, 1000.5]
    plan = Plan("p", [Segment.line(end, v) for end, v in zip((5, 6, 7, 8), speeds, strict=True)])
    issues = check_plan(plan, ledger(), current_pose=HOME)
    assert [(i.segment, i.code) for i in issues] == [
        (0, IssueCode.BAD_SPEED),
        (1, IssueCode.BAD_SPEED),
        (3, IssueCode.BAD_SPEED),
    ]
    assert "speed 1000.5 mm/s is not in (0, 1000] mm/s" in issues[2].message
    assert check_plan(plan, ledger(), PlanLimits(max_speed=2000), HOME)[-1].segment == 1


def test_first_arc_checked_from_the_current_pose() -> None:
    lg = ledger()
    plan = Plan("p", [Segment.arc(9, 7)])
    issues = check_plan(plan, lg)
    assert [(i.kind, i.code) for i in issues] == [(IssueKind.WARNING, IssueCode.ARC_START_UNKNOWN)]
    assert check_plan(plan, lg, current_pose=Pose(300, 0, 300, 180, 0, 0))[0].code is IssueCode.ARC_COLLINEAR
    assert check_plan(plan, lg, current_pose=lg.point(6)) == []
    assert check_plan(plan, lg, current_pose=np.array([400.0, 100.0, 300.0, 0, 0, 0])) == []


def test_start_index_and_later_loops() -> None:
    lg = ledger()
    # segment 2 starts from W (end of segment 1); from the current pose at N it is collinear-free too
    plan = Plan("p", [Segment.line(5), Segment.arc(9, 7)], loops=1)
    assert check_plan(plan, lg, current_pose=lg.point(6), start_index=1) == []
    # with more loops, segment 2 also runs from W on loop 2: collinear there
    issues = check_plan(plan, lg, current_pose=lg.point(6), start_index=1, loops=2)
    assert [(i.segment, i.code) for i in issues] == [(1, IssueCode.ARC_COLLINEAR)]
    assert "on loops after the first, starting at the end of segment 1" in issues[0].message
    # segment 1 on later loops starts at the end of the last segment
    wrap = Plan("p", [Segment.arc(9, 7), Segment.line(5)], loops=3)
    issues = check_plan(wrap, lg, current_pose=lg.point(6))
    assert [(i.segment, i.code) for i in issues] == [(0, IssueCode.ARC_COLLINEAR)]
    assert "on loops after the first" in issues[0].message
    assert check_plan(wrap, lg, current_pose=lg.point(6), start_index=2)[0].code is IssueCode.BAD_START


def test_empty_plan_zero_length_and_tool_mismatch() -> None:
    lg = ledger()
    assert check_plan(Plan("e"), lg)[0].code is IssueCode.EMPTY_PLAN
    issues = check_plan(Plan("p", [Segment.line(1), Segment.line(13)]), lg, current_pose=HOME)
    assert [(i.segment, i.kind, i.code) for i in issues] == [
        (0, IssueKind.WARNING, IssueCode.ZERO_LENGTH),
        (1, IssueKind.WARNING, IssueCode.TOOL_MISMATCH),
    ]
    assert "taught with tool 0" in issues[1].message and not has_errors(issues)


# --- geometry ------------------------------------------------------------------------------------


def test_arc_is_a_true_circle_through_the_middle_point() -> None:
    lg = ledger()
    seg = Segment.arc(6, 7)
    pts = segment_path(lg.point(5), seg, lg, samples=41)
    centre = np.array([400.0, 0.0, 300.0])
    assert pts.shape == (41, 3)
    assert np.allclose(np.linalg.norm(pts - centre, axis=1), 100.0, atol=1e-6, rtol=0)
    assert np.min(np.linalg.norm(pts - [400, 100, 300], axis=1)) < 1e-6  # passes through M
    assert np.allclose(pts[0], [300, 0, 300]) and np.allclose(pts[-1], [500, 0, 300])
    assert np.allclose(pts[:, 2], 300.0)  # in the plane of the three points
    assert np.all(pts[:, 1] >= -1e-9)  # via N: the northern half, not the southern
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert steps.max() < 2 * steps.min() + 1e-9  # evenly spread
    assert segment_length(lg.point(5), seg, lg) == pytest.approx(math.pi * 100, abs=1e-9)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_arcs_in_space(seed: int) -> None:
    rng = np.random.default_rng(seed)
    s, m, e = rng.uniform(-500, 500, size=(3, 200, 3))
    geo = arc_geometry(s, m, e)
    for p in (s, m, e):
        assert np.allclose(np.linalg.norm(p - geo.centre, axis=1), geo.radius, atol=1e-6, rtol=0)
        assert np.allclose(np.einsum("ij,ij->i", p - geo.centre, geo.normal), 0.0, atol=1e-6)
    assert np.all((geo.via_angle > 0) & (geo.via_angle < geo.sweep) & (geo.sweep < 2 * math.pi))
    lg = PointLedger([make_point(1, pose=(*m[0], 0, 0, 0)), make_point(2, pose=(*e[0], 0, 0, 0))])
    pts = segment_path(s[0], Segment.arc(1, 2), lg, samples=64)
    d = np.linalg.norm(pts - geo.centre[0], axis=1)
    assert np.allclose(d, geo.radius[0], atol=1e-6, rtol=0)
    assert np.min(np.linalg.norm(pts - m[0], axis=1)) < 1e-6
    # the polyline of the samples approaches the arc length
    fine = segment_path(s[0], Segment.arc(1, 2), lg, samples=4000)
    poly = float(np.linalg.norm(np.diff(fine, axis=0), axis=1).sum())
    assert poly == pytest.approx(float(geo.length[0]), rel=1e-5)


def test_long_way_round_arc() -> None:
    lg = ledger()
    # W -> S -> N: three quarters of the circle (through the south and east)
    assert segment_length(lg.point(5), Segment.arc(8, 6), lg) == pytest.approx(1.5 * math.pi * 100)


def test_degenerate_arcs_and_missing_points() -> None:
    lg = ledger()
    with pytest.raises(InvalidInput, match="no circle"):
        segment_path(lg.point(5), Segment.arc(9, 7), lg)
    with pytest.raises(InvalidInput, match="no circle"):
        segment_length(lg.point(5), Segment.arc(9, 7), lg)
    with pytest.raises(InvalidInput, match="P99 does not exist"):
        segment_path(HOME, Segment.line(99), lg)
    with pytest.raises(InvalidInput, match="3 samples"):
        segment_path(HOME, Segment.line(5), lg, samples=2)


def test_line_path_and_lengths() -> None:
    lg = ledger()
    pts = segment_path(HOME, Segment.line(5), lg, samples=5)
    assert np.allclose(pts, np.linspace([400, 0, 450], [300, 0, 300], 5))
    assert segment_length(HOME, Segment.line(5), lg) == pytest.approx(math.hypot(100, 150))
    assert estimate_time(100.0, 50.0) == pytest.approx(2.0 + SEGMENT_OVERHEAD_S)
    with pytest.raises(InvalidInput):
        estimate_time(1.0, 0.0)


def test_plan_path_marks_unknown_segments_and_draws_bad_arcs_as_polylines() -> None:
    lg = ledger()
    plan = Plan("p", [Segment.line(5), Segment.arc(9, 7), Segment.line(99), Segment.line(6)])
    path = plan_path(plan, lg, HOME, samples=8)
    assert path.xyz.shape == (32, 3) and list(path.segment[::8]) == [0, 1, 2, 3]
    xyz = path.xyz.reshape(4, 8, 3)
    assert np.isfinite(xyz[:2]).all()
    assert np.allclose(xyz[1, :, 1], 0.0) and np.allclose(xyz[1, -1], [500, 0, 300])  # S-M-E polyline
    assert np.isnan(xyz[2:]).all()  # missing end, then an unknown start
    no_start = plan_path(plan, lg, None, samples=8)
    assert np.isnan(no_start.xyz[:8]).all() and np.isfinite(no_start.xyz[8:16]).all()


def test_estimates_with_loops() -> None:
    lg = ledger()
    plan = circle_plan(loops=3)
    est = estimate_plan(plan, lg, HOME)
    first_line = math.hypot(100, 150)
    circle = 2 * math.pi * 100
    assert est.lengths == pytest.approx([first_line, math.pi * 100, math.pi * 100])
    assert est.loop_length == pytest.approx(first_line + circle)
    assert est.wrap_length == pytest.approx(0.0, abs=1e-9)  # the circle ends where the line goes
    assert est.next_loop_length == pytest.approx(circle)
    assert est.total_length == pytest.approx(first_line + 3 * circle)
    per_loop_overhead = 3 * SEGMENT_OVERHEAD_S
    assert est.loop_time == pytest.approx(first_line / 100 + circle / 50 + per_loop_overhead)
    assert est.total_time == pytest.approx(est.loop_time + 2 * (circle / 50 + per_loop_overhead))
    assert est.unknown == ()
    endless = estimate_plan(plan, lg, HOME, loops=0)
    assert math.isinf(endless.total_time)
    unknown = estimate_plan(plan, lg, None, loops=1)
    assert unknown.unknown == (0,)
    assert unknown.loop_time == pytest.approx(circle / 50 + 2 * SEGMENT_OVERHEAD_S)


def test_timeouts() -> None:
    lg = ledger()
    assert move_timeout(1.0) == 10.0 and move_timeout(100.0) == 300.0 and move_timeout(math.nan) == 10.0
    slow = Plan("p", [Segment.line(5, 1.0), Segment.arc(6, 7, 1.0)], loops=2)
    outs = segment_timeouts(slow, lg, None)
    assert outs[0] == pytest.approx(3 * (200.0 + SEGMENT_OVERHEAD_S))  # W from E on later loops
    assert outs[1] == pytest.approx(3 * (math.pi * 100 + SEGMENT_OVERHEAD_S))
    assert segment_timeouts(Plan("p", [Segment.line(5, 1.0)]), lg, None) == [None]


def test_thousand_segments_are_fast() -> None:
    lg = ledger()
    segments = [
        Segment.arc(6, 7) if i % 4 == 1 else Segment.arc(8, 5) if i % 4 == 2 else Segment.line(5)
        for i in range(1000)
    ]
    plan = Plan("big", segments)
    t0 = time.perf_counter()
    path = plan_path(plan, lg, HOME, samples=32)
    est = estimate_plan(plan, lg, HOME)
    issues = check_plan(plan, lg, current_pose=HOME)
    elapsed = time.perf_counter() - t0
    assert path.xyz.shape == (32000, 3) and np.isfinite(path.xyz).all()
    assert est.unknown == () and not has_errors(issues)
    assert elapsed < 2.0  # typically ~0.05 s; generous for slow CI


# --- resuming an arc part-way ----------------------------------------------------------------
def _resume_issues(x: float, y: float, z: float = 300.0) -> list[tuple[IssueKind, IssueCode]]:
    issues = check_plan(circle_plan(), ledger(), current_pose=(x, y, z, 180, 0, 0), start_index=1)
    return [(it.kind, it.code) for it in issues if it.segment == 1]


def test_resuming_an_arc_from_its_planned_start_is_fine() -> None:
    assert _resume_issues(300.0, 0.0) == []


def test_resuming_an_arc_before_its_middle_point_is_fine() -> None:
    # on the circle W -> N -> E, a quarter of the way to N
    a = math.radians(135.0)
    assert _resume_issues(400 + 100 * math.cos(a), 100 * math.sin(a)) == []


def test_resuming_an_arc_past_its_middle_point_is_an_error() -> None:
    a = math.radians(45.0)  # between N (90 deg) and E (0 deg): past the middle point
    assert _resume_issues(400 + 100 * math.cos(a), 100 * math.sin(a)) == [
        (IssueKind.ERROR, IssueCode.ARC_RESUME_PAST_MIDDLE)
    ]


def test_an_arc_from_elsewhere_with_a_larger_sweep_is_a_warning() -> None:
    # off the circle, beyond E: the circle through here, N and E sweeps the long way round
    assert _resume_issues(520.0, -40.0) == [(IssueKind.WARNING, IssueCode.ARC_RESUME_PAST_MIDDLE)]
