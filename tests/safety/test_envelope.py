"""The envelope's checks: targets, lines and arcs (sampled through app.plan.geometry), plans."""

from __future__ import annotations

import numpy as np
import pytest

from app.errors import InvalidInput
from app.models import Pose
from app.plan.checks import IssueCode, check_plan, has_errors
from app.plan.issue_kind import IssueKind
from app.plan.segments import Plan, Segment, SegmentKind
from app.points.ledger import PointLedger
from app.points.point import SyncState, make_point
from app.safety.box import Box
from app.safety.envelope import (
    Envelope,
    EnvelopeRefused,
    ViolationCode,
    check_path,
    check_segment,
    check_target,
    plan_violations,
    require_target,
)

CELL = Box("work space", (-800.0, -450.0, 0.0), (800.0, 450.0, 900.0))
FIXTURE = Box("fixture A", (300.0, -100.0, 0.0), (400.0, 100.0, 200.0))
ENV = Envelope(
    joint_limits=((-170, 170), (-90, 135)),
    keep_in=CELL,
    keep_out=(FIXTURE,),
    max_jog_ratio=50,
    max_speed=500,
    reduced_jog_ratio=10,
    reduced_speed=250,
)


def pose(x: float, y: float, z: float) -> Pose:
    return Pose(x, y, z, 180.0, 0.0, 0.0)


def test_target_outside_keep_in_names_axis_value_and_limit() -> None:
    v = check_target(ENV, pose(500, -593, 400))
    assert v is not None and v.code is ViolationCode.KEEP_IN
    assert (v.axis, v.value, v.limit) == ("Y", -593.0, -450.0)
    assert "Y = -593.0 mm is outside the allowed work space (below its limit -450.0 mm)" in v.message
    assert check_target(ENV, pose(500, 0, 400)) is None


def test_target_inside_keep_out_and_joint_and_speed() -> None:
    v = check_target(ENV, pose(350, 90, 100))
    assert v is not None
    assert (v.code, v.box, v.axis, v.limit) == (ViolationCode.KEEP_OUT, "fixture A", "Y", 100.0)
    v = check_target(ENV, pose(0, 0, 400), joints=(0, 140, 0))
    assert v is not None and (v.code, v.axis, v.limit) == (ViolationCode.JOINT_LIMIT, "J2", 135.0)
    v = check_target(ENV, pose(0, 0, 400), speed=600)
    assert (
        v is not None
        and v.code is ViolationCode.SPEED
        and v.limit == 500
        and "reduced-speed" not in v.message
    )
    assert check_target(ENV, pose(0, 0, 400), speed=300) is None  # reduced-speed mode caps it, not refuses
    with pytest.raises(EnvelopeRefused, match=r"^step refused: .*keep-out zone 'fixture A'") as info:
        require_target(ENV, pose(350, 0, 100), action="step")
    assert info.value.violation.code is ViolationCode.KEEP_OUT


def test_a_line_through_a_thin_zone_between_its_ends_is_caught() -> None:
    thin = Envelope(keep_out=(Box("light curtain", (-0.5, -1000, -1000), (0.5, 1000, 1000)),))
    v = check_path(thin, np.array([[-300.0, 0, 400], [300.0, 0, 400]]))
    assert v is not None and v.box == "light curtain" and v.value == pytest.approx(-0.5)
    assert check_path(thin, np.array([[10.0, 0, 400], [300.0, 0, 400]])) is None


def test_caps_and_reduced_mode() -> None:
    assert ENV.cap_jog_ratio(80) == 50 and ENV.cap_jog_ratio(80, reduced=True) == 10
    assert ENV.speed_cap(True) == 250 and ENV.speed_cap() == 500
    caps = ENV.motion_caps(reach=1000.0)  # what the client applies in reduced-speed mode
    assert (caps.jog_ratio(80), caps.jog_ratio(0), caps.program_ratio(100), caps.linear_speed(300)) == (
        10,
        0,
        10,
        250,
    )
    one_joint = 250 / 1000 * 60 / (2 * np.pi)  # rpm: a point 1000 mm from the axis at 250 mm/s
    assert caps.joint_speed(5.0, [10, 0, 0, 0, 0, 0]) == pytest.approx(one_joint)
    assert caps.joint_speed(5.0, [10, -10, 5, 0, 0, 0]) == pytest.approx(one_joint / 2.5)  # they add up
    assert caps.joint_speed(5.0, [0] * 6 + [100]) == pytest.approx(one_joint)  # external axes alone
    assert caps.joint_speed(0.5, [10, 0, 0, 0, 0, 0]) == 0.5
    with pytest.raises(InvalidInput, match="lower bound must be below"):
        Box("bad", (0, 0, 0), (0, 1, 1))
    with pytest.raises(InvalidInput, match="at most 100"):
        Envelope(max_jog_ratio=150)


def _ledger(*poses: tuple[float, float, float]) -> PointLedger:
    return PointLedger(
        [make_point(i + 1, pose=(*p, 180, 0, 0), sync=SyncState.ON_CONTROLLER) for i, p in enumerate(poses)]
    )


def test_arc_bulging_into_a_zone_is_caught_though_its_points_are_clear() -> None:
    # the circle through (250,-250), (250,250), (500,0) has centre (250,0), radius 250
    ledger = _ledger((250.0, 250.0, 100.0), (500.0, 0.0, 100.0))
    start = (250.0, -250.0, 100.0)
    inside_circle = Envelope(keep_out=(Box("post", (330.0, -20.0, 0.0), (360.0, 20.0, 200.0)),))
    assert check_segment(inside_circle, start, Segment(SegmentKind.ARC, end_id=2, via_id=1), ledger) is None
    on_arc = Envelope(keep_out=(Box("post", (480.0, -20.0, 0.0), (520.0, 20.0, 200.0)),))
    # S -> M (500, 0) -> E (250, 250): the arc passes through the post
    v = check_segment(on_arc, start, Segment(SegmentKind.ARC, end_id=1, via_id=2, speed=100), ledger)
    assert v is not None and v.code is ViolationCode.KEEP_OUT and v.box == "post"
    # a straight line S -> (250, 250) does not
    assert check_segment(on_arc, start, Segment(SegmentKind.LINE, end_id=1, speed=100), ledger) is None


def test_arc_leaving_keep_in_between_samples_of_its_points() -> None:
    ledger = _ledger((0.0, 400.0, 100.0), (400.0, 0.0, 100.0))
    # quarter+ circle of radius 400 about the origin from (0,-400): bulges to x = 400 at y = 0 -> E
    env = Envelope(keep_in=Box("cell", (-450, -450, 0), (390, 450, 900)))
    arc = Segment(SegmentKind.ARC, end_id=1, via_id=2, speed=100)
    v = check_segment(env, (0.0, -400.0, 100.0), arc, ledger)
    assert v is not None and v.code is ViolationCode.KEEP_IN and v.axis == "X" and v.limit == 390


def test_plan_through_a_keep_out_box_is_an_error_that_blocks_run() -> None:
    ledger = _ledger((200.0, 0.0, 100.0), (500.0, 0.0, 100.0), (500.0, 300.0, 100.0))
    plan = Plan(
        "weld",
        [
            Segment(SegmentKind.LINE, end_id=1, speed=100),
            Segment(SegmentKind.LINE, end_id=2, speed=100),  # crosses fixture A
            Segment(SegmentKind.LINE, end_id=3, speed=600),
        ],
    )  # too fast
    violations = plan_violations(plan, ledger, ENV, pose(0, 0, 100))
    assert [(v.segment, v.code) for v in violations] == [
        (1, ViolationCode.KEEP_OUT),
        (2, ViolationCode.SPEED),
    ]
    assert violations[0].message.startswith("segment 2: the path enters the keep-out zone 'fixture A'")
    issues = check_plan(plan, ledger, current_pose=pose(0, 0, 100), envelope=ENV)
    envelope_issues = [i for i in issues if i.code is IssueCode.OUTSIDE_ENVELOPE]
    assert [(i.segment, i.kind) for i in envelope_issues] == [(1, IssueKind.ERROR), (2, IssueKind.ERROR)]
    assert has_errors(issues)
    # without an envelope the plan checks are what they were
    assert not has_errors(check_plan(plan, ledger, current_pose=pose(0, 0, 100)))


def test_reduced_speed_caps_a_plans_segments_instead_of_refusing_them() -> None:
    ledger = _ledger((200.0, 0.0, 100.0), (200.0, 200.0, 100.0), (0.0, 200.0, 100.0))
    plan = Plan(
        "slow",
        [
            Segment(SegmentKind.LINE, end_id=1, speed=100),  # under the reduced cap (250)
            Segment(SegmentKind.LINE, end_id=2, speed=400),  # runs at 250
            Segment(SegmentKind.LINE, end_id=3, speed=600),  # above the envelope's maximum (500)
        ],
    )
    issues = check_plan(plan, ledger, current_pose=pose(0, 0, 100), envelope=ENV, reduced_speed=True)
    assert [(i.segment, i.kind, i.code) for i in issues] == [
        (1, IssueKind.WARNING, IssueCode.SPEED_CAPPED),
        (2, IssueKind.ERROR, IssueCode.OUTSIDE_ENVELOPE),  # refused in every mode
    ]
    assert issues[0].message == "segment 2: runs at 250 mm/s, the reduced-speed cap (planned 400 mm/s)"
    normal = check_plan(plan, ledger, current_pose=pose(0, 0, 100), envelope=ENV)
    assert [(i.segment, i.code) for i in normal] == [(2, IssueCode.OUTSIDE_ENVELOPE)]


def test_plan_without_a_start_pose_checks_the_first_end_point_only() -> None:
    ledger = _ledger((350.0, 0.0, 100.0), (0.0, 0.0, 100.0))
    plan = Plan("p", [Segment(SegmentKind.LINE, end_id=1, speed=100), Segment(SegmentKind.LINE, end_id=2)])
    vs = plan_violations(plan, ledger, ENV)
    assert [(v.segment, v.code) for v in vs] == [(0, ViolationCode.KEEP_OUT), (1, ViolationCode.KEEP_OUT)]


def test_scalar_and_vectorised_chord_tests_agree() -> None:
    rng = np.random.default_rng(7)
    box = Box("z", (-10.0, -20.0, -5.0), (10.0, 20.0, 5.0))
    a = rng.uniform(-40, 40, size=(400, 3))
    b = rng.uniform(-40, 40, size=(400, 3))
    b[::7, 1] = a[::7, 1]  # chords parallel to a face
    scalar = [box.chord_hits(a[k], b[k]) for k in range(len(a))]
    assert any(scalar) and not all(scalar)
    for k in range(len(a)):
        hit = box.segments_hit(np.repeat(a[k : k + 1], 5, axis=0), np.repeat(b[k : k + 1], 5, axis=0))
        assert (hit == 0) == scalar[k]
