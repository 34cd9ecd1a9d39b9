"""The motion tracker and the program-state watch (commands without GV291)."""

from __future__ import annotations

import pytest

from app import timing
from app.errors import Reason
from app.link.active import MotionTracker
from app.link.outcome import Outcome, outcome_of
from app.link.types import Operation
from app.link.watch import MotionWatch
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import Alarm, ControllerMode, ProgramState, RunCommand

IDLE = ControllerStatus(ControllerMode.AUTO, ProgramState.STOPPED, Alarm(0), 0)
RUNNING = ControllerStatus(ControllerMode.AUTO, ProgramState.RUNNING, Alarm(0), 0)


def _pose(x: float) -> Pose:
    return Pose(x, 0.0, 0.0, 0.0, 0.0, 0.0)


def test_watch_needs_motion_then_standing_still() -> None:
    watch = MotionWatch(RunCommand.RUN_PROGRAM, "run program 1", _pose(0), 0.0)
    assert watch.update(IDLE, _pose(0), 0.1) is None  # not started yet
    assert watch.update(RUNNING, _pose(5), 0.2) is None
    assert watch.update(IDLE, _pose(10), 0.3) is None  # still moving
    result = watch.update(IDLE, _pose(10), 0.4)
    assert result is not None and result.ok and result.message == "run program 1: done"


def test_watch_without_motion_is_refused_after_the_ack_timeout(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)
    watch = MotionWatch(None, "go to zero (all axes)", _pose(0), 0.0, operation=Operation.GO_ZERO)
    assert watch.update(IDLE, _pose(0), 0.4) is None
    result = watch.update(IDLE, _pose(0), 0.6)
    assert result is not None and not result.ok and "nothing moved within 0.5 s" in result.message
    assert outcome_of(result) is Outcome.REFUSED and result.reason == Reason(
        "no_motion", {"operation": "go to zero", "seconds": 0.5}
    )


def test_watch_ends_on_an_alarm() -> None:
    watch = MotionWatch(None, "go to zero (J1)", _pose(0), 0.0, operation=Operation.GO_ZERO)
    alarm = ControllerStatus(ControllerMode.AUTO, ProgramState.STOPPED, Alarm.ESTOP, 0)
    result = watch.update(alarm, _pose(0), 0.1)
    assert result is not None and not result.ok
    assert result.message == "go to zero (J1) refused by the controller: emergency stop"
    assert outcome_of(result) is Outcome.REFUSED and result.reason is not None
    assert result.reason.code == "refused_alarm" and result.reason.args["alarms"] == int(Alarm.ESTOP)
    # an alarm after the motion was seen ended it
    watch = MotionWatch(None, "go to zero (J1)", _pose(0), 0.0, operation=Operation.GO_ZERO)
    assert watch.update(RUNNING, _pose(3), 0.1) is None
    result = watch.update(alarm, _pose(4), 0.2)
    assert result is not None and result.message == "go to zero (J1): ended by an alarm: emergency stop"
    assert outcome_of(result) is Outcome.REFUSED


def test_go_to_zero_is_done_only_at_zero_when_joints_are_reported(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.5)

    def joints(j2: float) -> Pose:
        return Pose(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, joints=(0.0, j2, 0.0, 0.0, 0.0, 0.0))

    watch = MotionWatch(None, "go to zero (J2)", joints(30.0), 0.0, operation="go to zero", zero_axes=(1,))
    assert watch.update(RUNNING, joints(20.0), 0.1) is None
    result = watch.update(IDLE, joints(20.0), 0.2)  # stood still short of zero (stopped by someone)
    assert result is not None and outcome_of(result) is Outcome.STOPPED
    assert result.message == "go to zero (J2): the arm stopped before zero (J2 at 20.000)"
    watch = MotionWatch(None, "go to zero (J2)", joints(0.0), 0.0, operation="go to zero", zero_axes=(1,))
    result = watch.update(IDLE, joints(0.0), 0.6)  # nothing moved: it was already there
    assert result is not None and result.ok and result.message == "go to zero (J2): done (already at zero)"


def test_go_to_zero_already_there_while_the_controller_reports_running_for_a_moment() -> None:
    """The neighbouring case of "already at zero": a controller (the simulator among them) may report
    its program running for a poll or two on a go to zero with nothing to do; the pose never moved,
    so it still reads "already at zero" (it read plain "done" whenever a poll caught that moment)."""

    def joints(j2: float) -> Pose:
        return Pose(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, joints=(0.0, j2, 0.0, 0.0, 0.0, 0.0))

    watch = MotionWatch(None, "go to zero (J2)", joints(0.0), 0.0, operation="go to zero", zero_axes=(1,))
    assert watch.update(RUNNING, joints(0.0), 0.05) is None  # taken: running, nothing moved
    result = watch.update(IDLE, joints(0.0), 0.1)
    assert result is not None and result.ok and result.message == "go to zero (J2): done (already at zero)"
    assert result.reason is not None and result.reason.code == "zero_already"
    # one that moved (from off zero, or away and back) is plain done
    watch = MotionWatch(None, "go to zero (J2)", joints(0.0), 0.0, operation="go to zero", zero_axes=(1,))
    assert watch.update(RUNNING, joints(3.0), 0.05) is None
    assert watch.update(IDLE, joints(0.0), 0.1) is None  # still moving
    result = watch.update(IDLE, joints(0.0), 0.15)
    assert result is not None and result.ok and result.message == "go to zero (J2): done"
    # crept: each read within a read's step of the last (0.0009° a read), 0.09° from where it was sent;
    # another joint than the one asked moved: not "already at zero" either way
    watch = MotionWatch(None, "go to zero (J1)", joints(0.0), 0.0, operation="go to zero", zero_axes=(0,))
    for step in range(1, 101):
        assert watch.update(RUNNING, joints(0.0009 * step), 0.01 * step) is None
    result = watch.update(IDLE, joints(0.09), 1.1)
    assert result is not None and result.ok and result.message == "go to zero (J1): done"


def test_watch_outcome_unknown_and_stopped_reach_its_hook() -> None:
    seen: list[CommandResult] = []
    watch = MotionWatch(RunCommand.RUN_PROGRAM, "run program 1", _pose(0), 0.0, program=1)
    watch.note = seen.append
    result = watch.unknown(1.0, "status unreadable")
    assert outcome_of(result) is Outcome.UNKNOWN and seen == [result]
    assert result.message == (
        "run program 1: sent; the outcome is unknown \u2014 check the robot before sending it again "
        "(status unreadable)"
    )
    assert watch.stopped(2.0) is result and seen == [result]  # ended once
    watch = MotionWatch(RunCommand.RUN_PROGRAM, "run program 1", _pose(0), 0.0, program=1)
    watch.note = seen.append
    assert outcome_of(watch.stopped(1.0)) is Outcome.STOPPED and len(seen) == 2


class _Done:
    deadline = 0.0

    def update(self, status: ControllerStatus, pose: Pose | None, now: float) -> CommandResult | None:
        return CommandResult(RunCommand.CREATE_POINT, None, None, True, "created")

    def stopped(self, now: float) -> CommandResult:
        return CommandResult(None, None, None, False, "stopped")

    def unknown(
        self, now: float, cause: object = None, *, message: str | None = None, reason: Reason | None = None
    ) -> CommandResult:
        return CommandResult(None, None, None, False, message or "unknown", reason=reason)


def test_tracker_hands_out_the_result_once_with_its_request_id() -> None:
    tracker = MotionTracker()
    assert tracker.update(IDLE, _pose(0), 0.0) is None
    tracker.track(Operation.CREATE_POINT, _Done(), motion=False, request_id=7)
    assert tracker.motion_under_way is None  # a short command does not block motions
    done = tracker.update(IDLE, _pose(12.5), 0.0)
    assert done is not None
    result, rid = done
    assert rid == 7 and result.details["x"] == 12.5  # create point reports the pose it saw
    assert tracker.active is None and tracker.update(IDLE, _pose(0), 0.0) is None


def test_take_forgets_the_active_motion() -> None:
    tracker = MotionTracker()
    tracker.track(Operation.STEP, _Done(), motion=True, request_id=3)
    assert tracker.motion_under_way == Operation.STEP
    active = tracker.take()
    assert active is not None and active.request_id == 3 and tracker.take() is None


def test_motion_commands_start_without_waiting_and_refuse_a_second_motion(sim: object) -> None:
    from app.errors import InvalidInput as Refused
    from app.link.motion import MotionCommands
    from app.link.ops import CreatePoint, GoZero, Step
    from app.link.types import StepFrame
    from tests.link.harness import PartsHost

    host = PartsHost()
    try:
        host.connect(sim)
        commands = MotionCommands(
            host, host.motion, host.jog, host.poller, uploading=lambda: host.uploader.run is not None
        )
        host.request_id = 4
        commands.step(Step(StepFrame.JOINT, [2.0, 0, 0, 0, 0, 0], (0.0,) * 5, 1.0))  # about 0.33 s
        assert host.motion.active is not None and host.motion.active.request_id == 4
        with pytest.raises(Refused, match="still under way"):
            commands.go_zero(GoZero(None))
        with pytest.raises(Refused):  # nor a create point while it moves
            commands.create_point(CreatePoint(5, None, 200))
        assert host.motion.motion_under_way == "step"
    finally:
        host.close()
