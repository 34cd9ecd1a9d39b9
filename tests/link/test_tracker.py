"""CommandTracker fed with synthetic status sequences (no wire)."""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from app import timing
from app.errors import AlarmRaised, CommandRefused, CommandStopped, CommandTimeout
from app.link.tracker import CommandTracker
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import (
    STATUS_SENTINEL,
    Alarm,
    CommandKind,
    ControllerMode,
    CreatePointStatus,
    MoveStatus,
    ProgramState,
    RunCommand,
    TeachStatus,
)

DONE = 0xFF
STOPPED, RUNNING, PAUSED = ProgramState.STOPPED, ProgramState.RUNNING, ProgramState.PAUSED
HOME = Pose(100.0, 0.0, 500.0, 180.0, 0.0, 0.0)


def st(code: int, state: ProgramState = STOPPED, alarms: Alarm = Alarm.NONE) -> ControllerStatus:
    return ControllerStatus(ControllerMode.AUTO, state, alarms, code)


def moved(dx: float) -> Pose:
    return Pose(100.0 + dx, 0.0, 500.0, 180.0, 0.0, 0.0)


Step = tuple[float, ControllerStatus, Pose | None]


def feed(tracker: CommandTracker, steps: Sequence[Step]) -> tuple[int, CommandResult]:
    """Feed (t, status, pose) samples; return (index, result) of the first result (fail if none)."""
    for i, (t, status, pose) in enumerate(steps):
        result = tracker.update(status, pose, t)
        if result is not None:
            return i, result
    pytest.fail(f"no result after {len(steps)} samples")


def feed_silent(tracker: CommandTracker, steps: Sequence[Step]) -> None:
    """Feed (t, status, pose) samples that must all pass without a result."""
    for t, status, pose in steps:
        assert tracker.update(status, pose, t) is None


def test_stale_done_is_not_taken_for_the_new_create_point() -> None:
    tr = CommandTracker(RunCommand.CREATE_POINT, st(DONE), None, 0.0, unconfirmed_after=1.0)
    # The old 0xFF lingers (status delay), then 0 (received), then the new 0xFF.
    i, result = feed(
        tr, [(0.01, st(DONE), None), (0.1, st(DONE), None), (0.2, st(0), None), (0.3, st(DONE), None)]
    )
    assert i == 3
    assert result.ok and result.kind is CommandKind.CREATE_POINT
    assert result.status is not None and result.status.member is CreatePointStatus.DONE
    assert result.details["ack_after"] == pytest.approx(0.2)
    assert tr.error is None


def test_unacknowledged_command_times_out_with_a_clear_message(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)
    # GV291 at 0 (initial, e.g. after power-on): a taken command would have changed it
    tr = CommandTracker(RunCommand.TEACH_ENABLE, st(0), None, 0.0)
    assert tr.update(st(0), None, 0.4) is None
    result = tr.update(st(0), None, 0.5)
    assert result is not None and not result.ok and not result.unconfirmed
    assert isinstance(tr.error, CommandTimeout)
    assert "did not acknowledge teach enable" in str(tr.error)
    assert "'initial'" in str(tr.error)


def test_error_code_after_ack_is_a_refusal_with_the_decoded_status() -> None:
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0)
    i, result = feed(tr, [(0.01, st(DONE), HOME), (0.02, st(0), HOME), (0.03, st(13), HOME)])
    assert i == 2 and not result.ok
    assert isinstance(tr.error, CommandRefused)
    assert tr.error.status.member is MoveStatus.BAD_END_POINT
    assert "bad end point id" in result.message


def test_stale_error_code_is_ignored_until_the_code_changes() -> None:
    # The previous command failed with 13; the new one is a fine move.
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(13), HOME, 0.0)
    i, result = feed(
        tr,
        [
            (0.01, st(13, RUNNING), moved(1)),
            (0.02, st(13, RUNNING), moved(2)),
            (0.03, st(6, RUNNING), moved(3)),
            (0.04, st(DONE), moved(4)),
        ],
    )
    assert i == 3 and result.ok


def test_first_error_when_pre_code_was_initial() -> None:
    tr = CommandTracker(RunCommand.TEACH_ENABLE, st(0), None, 0.0)
    _, result = feed(tr, [(0.01, st(0), None), (0.02, st(TeachStatus.RATIO_NOT_ZERO), None)])
    assert not result.ok and isinstance(tr.error, CommandRefused)
    assert tr.error.status.member is TeachStatus.RATIO_NOT_ZERO


def test_move_acknowledged_by_motion_still_waits_for_a_fresh_done() -> None:
    """Program state running and pose moving ack the move, but the stale 0xFF is not 'done'."""
    tr = CommandTracker(RunCommand.STEP_BASE, st(DONE), HOME, 0.0)
    steps = [
        (0.01, st(DONE, RUNNING), moved(1)),
        (0.05, st(DONE, RUNNING), moved(5)),
        (0.10, st(DONE, STOPPED), moved(10)),
        (0.2, st(DONE, STOPPED), moved(10)),
    ]
    feed_silent(tr, steps)
    assert tr.acknowledged and tr.motion_seen
    i, result = feed(tr, [(0.25, st(0), moved(10)), (0.26, st(DONE), moved(10))])
    assert i == 1 and result.ok


def test_pose_change_alone_acknowledges_a_fast_move() -> None:
    # A move so short the host saw neither 0, 6 nor RUNNING; then the new 0xFF from pre-code 0.
    tr = CommandTracker(RunCommand.STEP_JOINT, st(0), HOME, 0.0)
    assert tr.update(st(0), moved(0.5), 0.01) is None
    assert tr.acknowledged
    result = tr.update(st(DONE), moved(1), 0.02)
    assert result is not None and result.ok


def test_alarm_while_waiting_raises_alarm() -> None:
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0)
    i, result = feed(
        tr, [(0.01, st(6, RUNNING), moved(1)), (0.02, st(0, STOPPED, Alarm.ESTOP | Alarm.SERVO), moved(1))]
    )
    assert i == 1 and not result.ok
    assert isinstance(tr.error, AlarmRaised)
    assert tr.error.alarms == int(Alarm.ESTOP | Alarm.SERVO)
    assert "emergency stop" in str(tr.error) and "servo alarm" in str(tr.error)


def test_program_state_back_to_stopped_with_initial_code_is_a_stop(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "STOP_SETTLE", 0.1)
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0)
    steps = [
        (0.01, st(0, RUNNING), moved(1)),
        (0.02, st(6, RUNNING), moved(2)),
        (0.03, st(0, STOPPED), moved(3)),
        (0.08, st(0, STOPPED), moved(3)),
        (0.14, st(0, STOPPED), moved(3)),
    ]
    i, result = feed(tr, steps)
    assert i == 4 and not result.ok
    assert isinstance(tr.error, CommandStopped)


def test_transient_initial_before_done_is_not_a_stop(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "STOP_SETTLE", 0.1)
    tr = CommandTracker(RunCommand.STEP_BASE, st(DONE), HOME, 0.0)
    steps = [
        (0.01, st(DONE, RUNNING), moved(1)),
        (0.05, st(DONE, STOPPED), moved(2)),
        (0.06, st(0, STOPPED), moved(2)),
        (0.08, st(DONE, STOPPED), moved(2)),
    ]
    i, result = feed(tr, steps)
    assert i == 3 and result.ok


def test_host_sent_stop_ends_the_wait() -> None:
    tr = CommandTracker(RunCommand.STEP_BASE, st(DONE), HOME, 0.0)
    assert tr.update(st(6, RUNNING), moved(1), 0.01) is None
    result = tr.stopped(0.02)
    assert not result.ok and isinstance(tr.error, CommandStopped)
    assert "stopped by the operator" in result.message
    # Later reads do not change the outcome.
    assert tr.update(st(DONE), moved(1), 0.03) is result


def test_paused_move_keeps_waiting_and_resumes() -> None:
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0)
    steps = [
        (0.01, st(6, RUNNING), moved(1)),
        (0.02, st(6, PAUSED), moved(1)),
        (5.0, st(6, PAUSED), moved(1)),
        (9.0, st(6, PAUSED), moved(1)),
        (15.0, st(6, RUNNING), moved(2)),
        (15.1, st(DONE), moved(3)),
    ]
    i, result = feed(tr, steps)
    assert i == 5 and result.ok


def test_move_without_progress_times_out(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "MOVE_TIMEOUT_MIN", 1.0)
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0)
    assert tr.update(st(6, RUNNING), moved(1), 0.5) is None
    assert tr.update(st(6, RUNNING), moved(2), 1.2) is None  # progress extends the deadline
    assert tr.update(st(6, RUNNING), moved(2), 2.1) is None
    result = tr.update(st(6, RUNNING), moved(2), 2.3)
    assert result is not None and isinstance(tr.error, CommandTimeout)
    assert "did not complete within 1.0 s" in result.message
    assert "moving" in result.message


def test_explicit_timeout_is_a_hard_deadline() -> None:
    tr = CommandTracker(RunCommand.STEP_BASE, st(DONE), HOME, 0.0, timeout=0.5)
    assert tr.update(st(6, RUNNING), moved(1), 0.3) is None
    result = tr.update(st(6, RUNNING), moved(2), 0.6)
    assert result is not None and isinstance(tr.error, CommandTimeout)


def test_create_point_overall_timeout(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "CREATE_POINT_TIMEOUT", 0.5)
    tr = CommandTracker(RunCommand.CREATE_POINT, st(DONE), None, 0.0)
    assert tr.update(st(0), None, 0.1) is None
    result = tr.update(st(0), None, 0.6)
    assert result is not None and isinstance(tr.error, CommandTimeout)
    assert "create temp point did not complete" in result.message


def test_teach_code_6_is_an_alarm_not_moving() -> None:
    tr = CommandTracker(RunCommand.TEACH_ENABLE, st(DONE), None, 0.0)
    _, result = feed(tr, [(0.01, st(TeachStatus.ALGORITHM_ALARM), None)])
    assert not result.ok and isinstance(tr.error, CommandRefused)
    assert "algorithm alarm" in result.message


def test_move_that_ends_without_a_status_update_is_unknown(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 1.0)
    monkeypatch.setattr(timing, "STOP_SETTLE", 0.1)
    tr = CommandTracker(RunCommand.STEP_BASE, st(DONE), HOME, 0.0)
    steps = [
        (0.01, st(DONE, RUNNING), moved(1)),
        (0.05, st(DONE, STOPPED), moved(2)),
        (0.5, st(DONE, STOPPED), moved(2)),
        (0.99, st(DONE, STOPPED), moved(2)),
    ]
    feed_silent(tr, steps)
    result = tr.update(st(DONE, STOPPED), moved(2), 1.0)
    assert result is not None and isinstance(tr.error, CommandTimeout)
    assert "the arm moved and stopped" in result.message and "result is unknown" in result.message


def test_poll_interval_backs_off_to_the_cap(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "ACK_BACKOFF_FIRST", 0.001)
    monkeypatch.setattr(timing, "ACK_BACKOFF_CAP", 0.01)
    monkeypatch.setattr(timing, "MOVE_POLL_INTERVAL", 0.02)
    tr = CommandTracker(RunCommand.STEP_BASE, st(DONE), HOME, 0.0)
    intervals = []
    for k in range(7):
        tr.update(st(DONE, RUNNING), moved(k), 0.001 * k)
        intervals.append(tr.poll_interval(0.001 * k))
    assert intervals == [0.001, 0.002, 0.004, 0.008, 0.016, 0.02, 0.02]  # moves: capped by their poll
    short = CommandTracker(RunCommand.CREATE_POINT, st(DONE), None, 0.0, rule="sentinel", pre_code=SENT)
    for _ in range(6):
        short.update(st(SENT), None, 0.0)
    assert short.poll_interval(0.0) == 0.01  # never a spin, never slower than the cap


def test_poll_interval_does_not_sleep_past_the_unconfirmed_deadline() -> None:
    tr = CommandTracker(RunCommand.CREATE_POINT, st(DONE), None, 0.0, unconfirmed_after=0.05)
    for _ in range(8):
        tr.update(st(DONE), None, 0.046)
    assert tr.poll_interval(0.046) == pytest.approx(0.004)


# --- the completion rules on the timing profiles (tracker level; the wire: test_completion_profiles)

SENT = STATUS_SENTINEL


def sentinel(command: RunCommand) -> CommandTracker:
    return CommandTracker(command, st(DONE), None, 0.0, rule="sentinel", pre_code=SENT)


def test_sentinel_fast_result_straight_to_done_is_confirmed() -> None:
    tr = sentinel(RunCommand.CREATE_POINT)
    result = tr.update(st(DONE), None, 0.001)  # no 0 ever visible, the old code was 0xFF too
    assert result is not None and result.ok and not result.unconfirmed
    assert result.status is not None and result.status.member is CreatePointStatus.DONE


def test_sentinel_fast_error_is_reported() -> None:
    tr = sentinel(RunCommand.CREATE_POINT)
    result = tr.update(st(1), None, 0.001)
    assert result is not None and not result.ok and isinstance(tr.error, CommandRefused)
    assert "bad point id" in result.message


def test_sentinel_slow_waits_through_the_sentinel_and_the_zero() -> None:
    tr = sentinel(RunCommand.TEACH_DISABLE)
    i, result = feed(
        tr,
        [(t / 1000, st(SENT), None) for t in range(1, 40, 5)]
        + [(0.045, st(0), None), (0.06, st(DONE), None)],
    )
    assert i == 9 and result.ok and not result.unconfirmed
    assert result.details["ack_after"] == pytest.approx(0.045)


def test_sentinel_that_stays_is_not_acknowledged(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)
    tr = sentinel(RunCommand.CREATE_POINT)
    assert tr.update(st(SENT), None, 0.4) is None
    result = tr.update(st(SENT), None, 0.5)
    assert result is not None and not result.ok and isinstance(tr.error, CommandTimeout)
    assert "sent, waiting for the controller" in result.message


def test_observe_fast_unchanged_done_is_done_unconfirmed_after_the_window() -> None:
    tr = CommandTracker(RunCommand.CREATE_POINT, st(DONE), None, 0.0, unconfirmed_after=0.05)
    assert tr.update(st(DONE), None, 0.001) is None
    assert tr.update(st(DONE), None, 0.049) is None
    result = tr.update(st(DONE), None, 0.05)
    assert result is not None and result.ok and result.unconfirmed
    assert result.status is not None and result.status.member is CreatePointStatus.DONE
    assert tr.error is None
    assert "done, unconfirmed" in result.message


def test_observe_fast_error_is_a_change_and_never_unconfirmed() -> None:
    tr = CommandTracker(RunCommand.CREATE_POINT, st(DONE), None, 0.0, unconfirmed_after=0.05)
    result = tr.update(st(1), None, 0.001)
    assert result is not None and not result.ok and not result.unconfirmed
    assert isinstance(tr.error, CommandRefused)


def test_observe_stale_error_is_refused_never_a_success() -> None:
    tr = CommandTracker(RunCommand.CREATE_POINT, st(1), None, 0.0, unconfirmed_after=0.05)
    assert tr.update(st(1), None, 0.01) is None
    result = tr.update(st(1), None, 0.06)
    assert result is not None and not result.ok and result.unconfirmed
    assert isinstance(tr.error, CommandRefused) and "from the previous command" in result.message


def test_observe_slow_change_inside_the_window_is_confirmed() -> None:
    tr = CommandTracker(RunCommand.CREATE_POINT, st(DONE), None, 0.0, unconfirmed_after=0.05)
    i, result = feed(
        tr, [(0.001, st(DONE), None), (0.02, st(DONE), None), (0.03, st(0), None), (0.04, st(DONE), None)]
    )
    assert i == 3 and result.ok and not result.unconfirmed


def test_observe_moves_are_never_unconfirmed(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0, unconfirmed_after=0.05)
    assert tr.update(st(DONE), HOME, 0.1) is None
    result = tr.update(st(DONE), HOME, 0.5)
    assert result is not None and not result.ok and not result.unconfirmed
    assert isinstance(tr.error, CommandTimeout)


@pytest.mark.parametrize(
    ("command", "before", "after"),
    [
        (RunCommand.TEACH_ENABLE, ControllerMode.AUTO, ControllerMode.MODBUS_TEACH),
        (RunCommand.TEACH_DISABLE, ControllerMode.MODBUS_TEACH, ControllerMode.AUTO),
    ],
)
def test_observe_teach_is_confirmed_by_the_controller_mode(
    command: RunCommand, before: ControllerMode, after: ControllerMode
) -> None:
    pre = ControllerStatus(before, STOPPED, Alarm.NONE, DONE)
    tr = CommandTracker(command, pre, None, 0.0, unconfirmed_after=0.05)
    assert tr.update(pre, None, 0.001) is None
    result = tr.update(ControllerStatus(after, STOPPED, Alarm.NONE, DONE), None, 0.002)
    assert result is not None and result.ok and not result.unconfirmed
    assert result.status is not None and result.status.member is TeachStatus.DONE


def test_a_move_whose_status_never_changed_is_done_when_it_stands_at_its_target() -> None:
    """A short move on a fast controller with a read-only GV291: 0xFF before and after, the
    arm went and stopped. At the X Y Z the host sent for the end point, it ended there."""
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0)
    tr.target = (150.0, 0.0, 500.0)
    steps = [
        (0.01, st(DONE), moved(20.0)),
        (0.05, st(DONE), moved(50.0)),
        (0.1, st(DONE), moved(50.0)),
        (0.3, st(DONE), moved(50.0)),
        (0.41, st(DONE), moved(50.0)),
    ]
    i, result = feed(tr, steps)
    assert i == 4 and result.ok and not result.unconfirmed  # after stop_settle, long before ack_timeout
    assert "arrived at the point" in result.message


def test_a_move_whose_status_never_changed_stopping_elsewhere_stays_unknown(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)
    tr = CommandTracker(RunCommand.MOVE_TO_POINT, st(DONE), HOME, 0.0)
    tr.target = (150.0, 0.0, 500.0)  # the arm stops 10 mm short: not confirmed
    steps = [
        (0.01, st(DONE), moved(20.0)),
        (0.05, st(DONE), moved(40.0)),
        (0.4, st(DONE), moved(40.0)),
        (0.8, st(DONE), moved(40.0)),
    ]
    i, result = feed(tr, steps)
    assert i == 3 and not result.ok and "result is unknown" in result.message


def test_a_joint_step_whose_status_never_changed_is_done_at_its_target_joints() -> None:
    before = Pose(100.0, 0.0, 500.0, 180.0, 0.0, 0.0, joints=(0.0,) * 6)
    tr = CommandTracker(RunCommand.STEP_JOINT, st(DONE), before, 0.0)
    tr.target_joints = (5.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    there = Pose(101.0, 9.0, 500.0, 180.0, 0.0, 5.0, joints=(5.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    i, result = feed(tr, [(0.01, st(DONE), there), (0.1, st(DONE), there), (0.41, st(DONE), there)])
    assert i == 2 and result.ok


def test_a_step_that_moves_external_axes_is_done_only_when_they_arrived_too(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A joint step of J1 and E1 whose whole move a stalled host missed (0xFF before and after):
    done when J1..J6 and E1..E5 stand where the host sent them; E1 short of it stays unknown."""
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)
    before = Pose(100.0, 0.0, 500.0, 180.0, 0.0, 0.0, joints=(0.0,) * 6)
    ext_target = (3.0, 0.0, 0.0, 0.0, 0.0)
    joints_there = (5.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    there = Pose(101.0, 9.0, 500.0, 180.0, 0.0, 5.0, ext=ext_target, joints=joints_there)
    short = Pose(101.0, 9.0, 500.0, 180.0, 0.0, 5.0, ext=(1.0, 0.0, 0.0, 0.0, 0.0), joints=joints_there)
    tr = CommandTracker(RunCommand.STEP_JOINT, st(DONE), before, 0.0)
    tr.target_joints, tr.target_ext = joints_there, ext_target
    i, result = feed(tr, [(0.01, st(DONE), there), (0.1, st(DONE), there), (0.41, st(DONE), there)])
    assert i == 2 and result.ok and "arrived at the point" in result.message
    tr = CommandTracker(RunCommand.STEP_JOINT, st(DONE), before, 0.0)
    tr.target_joints, tr.target_ext = joints_there, ext_target
    i, result = feed(
        tr, [(0.01, st(DONE), short), (0.1, st(DONE), short), (0.41, st(DONE), short), (0.8, st(DONE), short)]
    )
    assert i == 3 and not result.ok and "result is unknown" in result.message


# --- a long wait (issue 18: "a long move crashes the client") ----------------------------------


def _long_move_tracker() -> CommandTracker:
    return CommandTracker(
        RunCommand.STEP_BASE, st(DONE), HOME, 0.0, rule="sentinel", pre_code=STATUS_SENTINEL
    )


def test_a_ten_minute_move_is_read_at_the_cap_to_the_end_without_overflow_or_growth() -> None:
    """Ten minutes of a move's wait, as CommandClient.wait paces it (the clock injected: each read
    at the time the tracker planned). It used to raise OverflowError at the 1025th read (about
    11 s into a move at the 10 ms cap); the tracker's memory must not grow with the reads either:
    what the tenth minute's 6,000 reads leave allocated is measured (the old list of read times
    kept ~200 kB of it)."""
    import tracemalloc

    tr = _long_move_tracker()
    moving = st(int(MoveStatus.MOVING), RUNNING)
    poses = (moved(0.0), moved(0.002))  # the arm moves between every two reads (made once)
    now, reads, longest = 0.0, 0, 0.0
    kept_before = kept_after = 0
    try:
        while now < 600.0:
            if now >= 540.0 and not tracemalloc.is_tracing():  # the tenth minute, measured
                tracemalloc.start()
                kept_before = tracemalloc.get_traced_memory()[0]
            assert tr.update(moving, poses[reads & 1], now) is None
            reads += 1
            interval = tr.poll_interval(now)
            longest = max(longest, interval)
            now += interval
        kept_after = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    result = tr.update(st(DONE), poses[reads & 1], now)
    assert result is not None and result.ok
    assert tr.reads > 60_000  # a read every MOVE_POLL_INTERVAL all along
    assert longest == pytest.approx(timing.MOVE_POLL_INTERVAL)
    assert kept_after - kept_before < 4096  # a few small objects, not one per read


def test_backoff_of_any_read_count_is_the_cap() -> None:
    from app.link.tracker import backoff

    assert backoff(0.001, 0.01, 0) == 0.001
    assert backoff(0.001, 0.01, -3) == 0.001
    assert backoff(0.001, 0.01, 3) == 0.008
    for doublings in (1023, 1024, 1025, 10**6, 10**12):
        assert backoff(0.001, 0.01, doublings) == 0.01
