"""The jog guard: pure decisions, and a jog toward a boundary against the simulator."""

from __future__ import annotations

import time
from typing import Any

import pytest

from app.models import Pose
from app.protocol import registers
from app.protocol.enums import TeachFrame
from app.safety.box import Box
from app.safety.envelope import Envelope, ViolationCode
from app.safety.jog_guard import (
    JOG_GUARD_EXTRA_MM,
    JOG_GUARD_WINDOW,
    ArmSpeeds,
    GuardTiming,
    JogGuard,
    JogMotion,
)

CELL = Box("work space", (-800.0, -100.0, 0.0), (800.0, 450.0, 900.0))
ENV = Envelope(
    joint_limits=((-170.0, 170.0), (-90.0, 135.0)),
    keep_in=CELL,
    keep_out=(Box("fixture A", (300.0, 200.0, 0.0), (400.0, 300.0, 600.0)),),
    max_jog_ratio=60,
    reduced_jog_ratio=10,
)


def at(x: float, y: float, z: float, joints: tuple[float, ...] | None = None) -> Pose:
    return Pose(x, y, z, 180.0, 0.0, 0.0, joints=joints)


def jog(axis: int, direction: int, ratio: float = 40, frame: TeachFrame = TeachFrame.BASE) -> JogMotion:
    return JogMotion(frame, axis, direction, ratio)


def test_margin_is_the_distance_covered_in_poll_period_plus_latency() -> None:
    guard = JogGuard(ENV, poll_period=0.02, latency=0.05, speeds=ArmSpeeds(linear=250.0))
    # 40 % of 250 mm/s = 100 mm/s over 0.07 s = 7 mm, plus the fixed extra
    assert guard.margin(jog(1, 0)) == pytest.approx(7.0 + JOG_GUARD_EXTRA_MM)
    assert guard.decide(at(0, -100 + 9, 400), jog(1, 0)).allow
    stop = guard.decide(at(0, -100 + 7, 400), jog(1, 0))
    assert not stop.allow and stop.violation is not None
    v = stop.violation
    assert (v.code, v.axis, v.value, v.limit) == (ViolationCode.KEEP_IN, "Y", -93.0, -100.0)
    assert v.approaching
    assert "within stopping distance" in stop.message
    # along the boundary, and back out, are allowed; a slower jog gets closer
    assert guard.decide(at(0, -99, 400), jog(0, 1)).allow
    back = guard.decide(at(0, -99, 400), jog(1, 1))
    assert back.allow
    assert guard.decide(at(0, -100 + 3, 400), jog(1, 0, ratio=5)).allow


def test_measured_horizon_covers_the_poses_age_the_next_poll_and_the_stop_write() -> None:
    guard = JogGuard(ENV, poll_period=0.02, latency=0.05)
    measured = GuardTiming()
    # nothing measured yet: the nominal poll period + latency
    assert measured.horizon(guard, 10.0, None) == pytest.approx(0.07)
    # a pose read that took 0.1 s (a slow answer), judged as it arrives: its age (0.1), the next
    # poll (period + a status and a pose read: 0.22) and the stop write's trip (0.1)
    measured.note_read(10.0, 10.1)
    assert measured.horizon(guard, 10.1, 10.0) == pytest.approx(0.1 + 0.22 + 0.1)
    # a standing arm: its last pose does not age
    assert measured.horizon(guard, 10.1, None) == pytest.approx(0.22 + 0.1)


def test_a_late_poll_during_a_jog_widens_the_horizon_for_a_while() -> None:
    guard = JogGuard(ENV, poll_period=0.02, latency=0.05)
    measured = GuardTiming()
    measured.note_decision(0.0, jogging=False)
    measured.note_decision(1.0, jogging=True)  # a gap from before the jog does not count
    assert measured.horizon(guard, 1.0, 1.0) == pytest.approx(0.07)
    measured.note_decision(1.02, jogging=True)
    measured.note_decision(1.32, jogging=True)  # the worker was descheduled: 0.3 s late
    assert measured.horizon(guard, 1.32, 1.32) == pytest.approx(0.3)
    # the margin follows: 40 % of 250 mm/s over 0.3 s, never less than the nominal one
    assert guard.margin(jog(1, 0), 0.3) == pytest.approx(30.0 + JOG_GUARD_EXTRA_MM)
    assert guard.margin(jog(1, 0), 0.0) == guard.margin(jog(1, 0))
    assert guard.decide(at(0, -100 + 9, 400), jog(1, 0)).allow  # nominally far enough ...
    late = guard.decide(at(0, -100 + 9, 400), jog(1, 0), 0.3)  # ... not after a late poll
    assert not late.allow and late.margin == pytest.approx(31.0)
    # joint limits too: 30 deg/s x 40 % over 0.3 s = 3.6 deg (nominally 0.84)
    near = at(0, 0, 400, (0.0, 132.0, 0, 0, 0, 0))
    assert guard.decide(near, jog(1, 1, frame=TeachFrame.JOINT)).allow
    assert not guard.decide(near, jog(1, 1, frame=TeachFrame.JOINT), 0.3).allow
    # a press right after: judged with at least the horizon the last decision used
    measured.note_horizon(1.32, 0.5)
    assert measured.horizon(guard, 1.4, None) == pytest.approx(0.5)
    assert measured.horizon(guard, 1.4, 1.4) == pytest.approx(0.3)
    # all forgotten after the window
    assert measured.horizon(guard, 1.33 + JOG_GUARD_WINDOW, None) == pytest.approx(0.07)


def test_past_the_boundary_only_back_out_is_allowed() -> None:
    guard = JogGuard(ENV, poll_period=0.02)
    outside = at(0, -120, 400)
    assert not guard.decide(outside, jog(1, 0)).allow
    assert not guard.decide(outside, jog(0, 1)).allow  # along the boundary stays outside: no
    decision = guard.decide(outside, jog(1, 1))
    assert decision.allow and decision.backing_out


def test_keep_out_zone_rotations_tool_frame_and_ratio_cap() -> None:
    guard = JogGuard(ENV, poll_period=0.02)
    near = at(350, 195, 400)
    stop = guard.decide(near, jog(1, 1))
    assert not stop.allow and stop.violation is not None and stop.violation.box == "fixture A"
    assert guard.decide(near, jog(3, 1)).allow  # rotation about the TCP does not move it
    # tool frame with A = 180: tool Y points along base -Y, so tool +Y moves away from the zone
    assert guard.decide(near, jog(1, 1, frame=TeachFrame.TOOL)).allow
    assert not guard.decide(near, jog(1, 0, frame=TeachFrame.TOOL)).allow
    too_fast = guard.decide(at(0, 0, 400), jog(0, 1, ratio=80))
    assert not too_fast.allow and too_fast.violation is not None
    assert too_fast.violation.code is ViolationCode.JOG_RATIO
    reduced = JogGuard(ENV, poll_period=0.02, reduced=True)
    assert not reduced.decide(at(0, 0, 400), jog(0, 1, ratio=20)).allow


def test_unknown_direction_user_and_joint_frames_need_a_full_margin() -> None:
    guard = JogGuard(ENV, poll_period=0.02)
    assert guard.decide(at(0, 0, 400), jog(1, 0, frame=TeachFrame.USER)).allow
    assert not guard.decide(at(0, -95, 400), jog(1, 1, frame=TeachFrame.USER)).allow  # margin 8 mm
    m = guard.margin(jog(0, 1, ratio=10, frame=TeachFrame.JOINT))
    assert guard.decide(at(0, -100 + m + 1, 400, (0.0,) * 6), jog(0, 1, 10, TeachFrame.JOINT)).allow
    assert not guard.decide(at(0, -100 + m - 1, 400, (0.0,) * 6), jog(0, 1, 10, TeachFrame.JOINT)).allow


def test_joint_limits_stop_before_and_allow_back_in() -> None:
    guard = JogGuard(ENV, poll_period=0.02)
    near_hi = at(0, 0, 400, (0.0, 134.0, 0, 0, 0, 0))
    stop = guard.decide(near_hi, jog(1, 1, frame=TeachFrame.JOINT))
    assert not stop.allow and stop.violation is not None
    assert (stop.violation.axis, stop.violation.limit) == ("J2", 135.0)
    assert guard.decide(near_hi, jog(1, 0, frame=TeachFrame.JOINT)).allow
    past = at(0, 0, 400, (0.0, 140.0, 0, 0, 0, 0))
    assert guard.decide(past, jog(1, 0, frame=TeachFrame.JOINT)).allow
    assert not guard.decide(past, jog(1, 1, frame=TeachFrame.JOINT)).allow


# --- against the simulator ------------------------------------------------------------------

POLL = 0.02  # s, the worker's 50 Hz
LATENCY = 0.1  # s, generous: the machine running the tests is shared


def _jog_until_guard_stops(
    client: Any, guard: JogGuard, measured: GuardTiming, motion: JogMotion, timeout: float
) -> tuple[bool, Pose, float]:
    """What the worker does while a jog button is held: poll the pose, ask the guard, write
    ratio 0 when it says stop. Returns (stopped by the guard, the pose it decided on, the
    look-ahead it used in mm)."""
    client.teach_set_ratio(motion.ratio)
    deadline = time.monotonic() + timeout
    next_poll = time.monotonic()
    while time.monotonic() < deadline:
        read_at = time.perf_counter()
        pose = client.read_pose()
        now = time.perf_counter()
        measured.note_read(read_at, now)
        measured.note_decision(now, jogging=True)
        horizon = measured.horizon(guard, now, read_at)  # as the worker: measured, for a late poll
        measured.note_horizon(now, horizon)
        decision = guard.decide(pose, motion, horizon)
        if not decision.allow:
            client.teach_set_ratio(0.0)
            return True, pose, decision.margin
        next_poll += POLL
        time.sleep(max(0.0, next_poll - time.monotonic()))  # the poll period, as the worker's timer
    client.teach_set_ratio(0.0)
    return False, client.read_pose(), 0.0


def test_a_jog_toward_a_boundary_stops_short_of_it_at_the_simulator(sim: Any, make_client: Any) -> None:
    # the last jog (back out) is awaited with no request going out: the simulator's 0.3 s watchdog
    # would stop it, short of 5 mm when a loaded process starves its ticker (not this test's subject)
    sim.set_watchdog(None)
    client = make_client(sim)
    y_start = sim.state().pose[1]
    limit = y_start - 60.0
    env = Envelope(keep_in=Box("cell", (-2000.0, limit, -2000.0), (2000.0, 2000.0, 2000.0)))
    guard = JogGuard(env, poll_period=POLL, latency=LATENCY, speeds=ArmSpeeds(linear=250.0))
    assert client.teach_enable(TeachFrame.BASE, 1, 0).ok  # Y, negative
    toward = JogMotion(TeachFrame.BASE, 1, 0, 20.0)  # 50 mm/s
    measured = GuardTiming()
    stopped, decided_at, margin = _jog_until_guard_stops(client, guard, measured, toward, timeout=10.0)
    assert stopped
    assert sim.wait_for(lambda s: not s.jogging, 2.0)
    final_y = sim.state().pose[1]
    # asserted at the server: the arm stopped before the boundary, and close to it
    assert limit < final_y < limit + margin + 20.0
    ratio_writes = sim.writes_to(registers.gv_reg(registers.GV_PARAM3) + 1)  # GV203's high word
    assert ratio_writes[-1].values == (0,) and len(ratio_writes) >= 2
    # at the boundary: further toward it is refused, back out is allowed and moves away
    standing = measured.horizon(guard, time.perf_counter(), None)  # a press: at least the stop's
    assert not guard.decide(client.read_pose(), toward, standing).allow
    client.teach_set_axis(1, 1)
    away = JogMotion(TeachFrame.BASE, 1, 1, 20.0)
    assert guard.decide(client.read_pose(), away).allow
    client.teach_set_ratio(away.ratio)
    assert sim.wait_for(lambda s: s.pose[1] > final_y + 5.0, 3.0)
    client.teach_disable()
    assert decided_at.y > limit


def test_the_workers_jog_request_is_accepted_as_it_is() -> None:
    from app.link.types import JogRequest

    guard = JogGuard(ENV, poll_period=0.02)
    assert not guard.decide(at(0, -95, 400), JogRequest(TeachFrame.BASE, 1, 0, 40.0)).allow
    assert guard.decide(at(0, -95, 400), JogRequest(TeachFrame.BASE, 1, 1, 40.0)).allow


def test_box_edges_for_drawing() -> None:
    edges = CELL.edges()
    assert edges.shape == (24, 3)
    lengths = sorted(float(abs(d).max()) for d in edges[1::2] - edges[::2])
    assert lengths == [550.0] * 4 + [900.0] * 4 + [1600.0] * 4
