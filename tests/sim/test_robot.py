"""The controller's state machine and motion, driven by explicit ticks (no sockets)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from app.protocol.enums import (
    Alarm,
    ControllerMode,
    MoveStatus,
    ProgramMotionMode,
    ProgramState,
    TeachFrame,
    TeachStatus,
    WorkMode,
)
from app.sim import kinematics as kin
from app.sim.motion import JOG_MAX_JOINT
from app.sim.robot import PROGRAMS, SimRobot

DT = 0.01


def run_until(robot: SimRobot, cond: Callable[[SimRobot], bool], max_s: float = 10.0) -> float:
    """Tick until ``cond`` holds; returns the simulated time it took."""
    t0 = robot.time
    while not cond(robot):
        assert robot.time - t0 < max_s, "condition not reached in simulated time"
        robot.tick(DT)
    return robot.time - t0


def idle(robot: SimRobot) -> bool:
    return not robot.busy


def test_starts_at_home_in_auto() -> None:
    robot = SimRobot()
    assert tuple(robot.joints[:6]) == pytest.approx(kin.HOME_JOINTS)
    assert robot.controller_mode is ControllerMode.AUTO
    assert robot.program_state is ProgramState.STOPPED


def test_joint_step_is_synchronous_and_timed() -> None:
    robot = SimRobot()
    offsets = [30.0, 0, 0, 0, 0, -15.0, 50.0, 0, 0, 0, 0]
    assert robot.step_joint(offsets, 10.0) == MoveStatus.MOVING  # 60 deg/s
    robot.tick(0.25)
    # J7 sets the pace (50 deg at 60 deg/s): after 0.25 s every axis is 30 % of the way
    assert robot.joints[6] == pytest.approx(15.0)
    assert robot.joints[0] == pytest.approx(9.0)
    assert robot.joints[5] == pytest.approx(-4.5)
    took = run_until(robot, idle)
    assert took == pytest.approx(50 / 60 - 0.25, abs=2 * DT)
    assert robot.command_status == 0xFF
    assert robot.joints[0] == pytest.approx(30.0)
    assert robot.joints[6] == pytest.approx(50.0)


def test_joint_step_outside_limits_is_a_calculation_error() -> None:
    robot = SimRobot()
    assert robot.step_joint([200.0], 10.0) == MoveStatus.CALCULATION_ERROR
    assert not robot.busy


def test_base_step_is_a_straight_line_at_speed() -> None:
    robot = SimRobot()
    start = np.array(robot.pose[:3])
    assert robot.step_base([50.0, -20.0, 30.0, 0, 0, 10.0], 200.0) == MoveStatus.MOVING
    took = run_until(robot, idle)
    end = np.array(robot.pose[:3])
    assert end - start == pytest.approx([50.0, -20.0, 30.0], abs=1e-2)
    assert took == pytest.approx(math.dist((0, 0, 0), (50, -20, 30)) / 200.0, abs=2 * DT)
    # every sample on the segment
    d = (end - start) / np.linalg.norm(end - start)
    for sample in robot.trajectory():
        rel = np.array(sample.pose[:3]) - start
        assert np.linalg.norm(rel - np.dot(rel, d) * d) < 0.05


def test_points_and_arc_through_the_middle() -> None:
    robot = SimRobot()
    x, y, z, a, b, c = robot.pose
    assert robot.create_point(1, (x + 100, y + 100, z, a, b, c), 200) == 0xFF
    assert robot.create_point(2, (x + 200, y, z, a, b, c), 200) == 0xFF
    assert robot.move_to_point(1, 2, 0, 0, 500.0) == MoveStatus.MOVING
    run_until(robot, idle)
    assert robot.command_status == 0xFF
    assert robot.pose[:3] == pytest.approx((x + 200, y, z), abs=1e-2)
    # circle through start, (x+100, y+100) and end: centre (x+100, y), radius 100
    dists = [math.dist(s.pose[:2], (x + 100, y)) for s in robot.trajectory()]
    assert max(dists) == pytest.approx(100.0, abs=0.1) and min(dists) == pytest.approx(100.0, abs=0.1)
    assert min(math.dist(s.pose[:2], (x + 100, y + 100)) for s in robot.trajectory()) < 3.0


def test_collinear_arc_and_missing_points() -> None:
    robot = SimRobot()
    x, y, z, a, b, c = robot.pose
    robot.create_point(1, (x + 50, y, z, a, b, c), 200)
    robot.create_point(2, (x + 100, y, z, a, b, c), 200)
    assert robot.move_to_point(1, 2, 0, 0, 100.0) == MoveStatus.CALCULATION_ERROR
    assert robot.move_to_point(-1, 99, 0, 0, 100.0) == MoveStatus.BAD_END_POINT
    assert robot.move_to_point(98, 2, 0, 0, 100.0) == MoveStatus.BAD_END_POINT
    # "ignore the middle point" still needs the point: only its orientation is ignored
    assert robot.move_to_point(98, 2, 0, 1, 100.0) == MoveStatus.BAD_END_POINT


def test_unreachable_point_is_refused_at_the_start() -> None:
    robot = SimRobot()
    robot.create_point(5, (1500.0, 0.0, 500.0, 180.0, 0.0, 0.0), 200)
    assert robot.move_to_point(-1, 5, 1, 0, 100.0) == MoveStatus.CALCULATION_ERROR


def test_create_point_id_range() -> None:
    robot = SimRobot(point_id_max=10)
    assert robot.create_point(10, None, 200) == 0xFF
    assert robot.create_point(11, None, 200) == 1
    assert robot.create_point(-1, None, 200) == 1
    assert robot.create_point(2.5, None, 200) == 1
    assert set(robot.points) == {10}


def test_manual_mode_refuses_and_alarms_refuse_moves() -> None:
    robot = SimRobot()
    robot.set_work_mode(WorkMode.MANUAL)
    assert robot.step_joint([1.0], 10) == MoveStatus.WORK_MODE_ERROR
    assert robot.teach_enable(TeachFrame.BASE, 0) == TeachStatus.WORK_MODE_ERROR
    robot.set_work_mode(WorkMode.AUTO)
    for bit, code in ((Alarm.ESTOP, 2), (Alarm.SERVO, 3), (Alarm.BRAKE, 4)):
        robot.set_alarm(bit, True)
        assert robot.step_joint([1.0], 10) == code
        assert robot.teach_enable(TeachFrame.BASE, 0) == code
        robot.set_alarm(bit, False)
    assert robot.step_joint([1.0], 10) == MoveStatus.MOVING


def test_estop_stops_a_move() -> None:
    robot = SimRobot()
    robot.step_joint([30.0], 10)
    robot.tick(0.1)
    robot.set_alarm(Alarm.ESTOP, True)
    j = robot.joints[0]
    robot.tick(0.1)
    assert robot.joints[0] == j
    assert robot.command_status == MoveStatus.ESTOP
    assert robot.program_state is ProgramState.STOPPED


def test_pause_resume_stop() -> None:
    robot = SimRobot()
    robot.step_joint([30.0], 10)
    robot.tick(0.1)
    assert robot.pause()
    j = robot.joints[0]
    robot.tick(0.2)
    assert robot.joints[0] == j
    paused = robot.program_state  # a local, so mypy does not keep the attribute narrowed
    assert paused is ProgramState.PAUSED
    assert robot.command_status == MoveStatus.MOVING
    assert robot.resume()
    robot.tick(0.1)
    assert robot.joints[0] > j
    robot.stop()
    assert robot.program_state is ProgramState.STOPPED
    assert robot.command_status == 0


def test_teach_jog_joint_frame_stops_at_the_limit() -> None:
    robot = SimRobot()
    assert robot.teach_enable(TeachFrame.JOINT, 5) == TeachStatus.RATIO_NOT_ZERO
    assert robot.teach_enable(TeachFrame.JOINT, 0) == 0xFF
    teaching = robot.controller_mode  # a local, so mypy does not keep the attribute narrowed
    assert teaching is ControllerMode.MODBUS_TEACH
    robot.set_teach_ratio(100, 4, 1)  # J5 positive at 30 deg/s
    robot.tick(0.5)
    assert robot.joints[4] == pytest.approx(kin.HOME_JOINTS[4] + JOG_MAX_JOINT * 0.5)
    run_until(robot, lambda r: r.joints[4] >= kin.JOINT_LIMITS[4][1], 10)
    robot.tick(0.5)
    assert robot.joints[4] == kin.JOINT_LIMITS[4][1]
    assert robot.teach_disable(100) == TeachStatus.RATIO_NOT_ZERO
    robot.set_teach_ratio(0, 4, 1)
    assert robot.teach_disable(0) == 0xFF
    assert robot.controller_mode is ControllerMode.AUTO


@pytest.mark.parametrize("frame", [TeachFrame.BASE, TeachFrame.USER, TeachFrame.TOOL])
def test_teach_jog_cartesian(frame: TeachFrame) -> None:
    robot = SimRobot()
    robot.teach_enable(frame, 0)
    z0 = robot.pose[2]
    robot.set_teach_ratio(40, 2, 0)  # Z negative at 100 mm/s
    for _ in range(20):
        robot.tick(DT)
    dz = robot.pose[2] - z0
    # base/user: -Z of the base; tool (pointing down at home): -Z of the tool is base +Z
    expected = 20.0 if frame is TeachFrame.TOOL else -20.0
    assert dz == pytest.approx(expected, abs=0.05)


def test_programs_run_and_finish() -> None:
    robot = SimRobot()
    start = robot.pose
    assert not robot.run_program(99, 1, 1, 100)
    assert robot.run_program(1, ProgramMotionMode.SINGLE_RUN, 1, 100)
    assert robot.program_state is ProgramState.RUNNING
    run_until(robot, idle, 10)
    assert robot.pose[:3] == pytest.approx(start[:3], abs=0.05)
    xs = [s.pose[0] for s in robot.trajectory()]
    assert max(xs) - min(xs) == pytest.approx(100.0, abs=0.1)
    # single step: one segment per run
    assert robot.run_program(2, ProgramMotionMode.SINGLE_STEP, 1, 100)
    run_until(robot, idle)
    assert robot.joints[0] == pytest.approx(15.0)
    # cycle: 2 cycles of the J7 shuttle
    assert robot.run_program(3, ProgramMotionMode.CYCLE, 2, 100)
    took = run_until(robot, idle, 20)
    assert took == pytest.approx(2 * 2 * 100 / 60.0, abs=0.1)
    assert set(PROGRAMS) >= {1, 2}


def test_go_zero_and_restart() -> None:
    robot = SimRobot()
    robot.teach_enable(TeachFrame.JOINT, 0)
    assert robot.go_zero(1)  # J2 only; disables teach
    assert not robot.teach_enabled
    run_until(robot, idle)
    assert robot.joints[1] == 0.0 and robot.joints[2] == pytest.approx(kin.HOME_JOINTS[2])
    robot.create_point(1, None, 200)
    robot.restart()
    assert robot.points == {}
    assert robot.command_status == 0
