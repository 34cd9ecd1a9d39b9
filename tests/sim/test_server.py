"""The simulator over real Modbus TCP, as a host sees it."""

from __future__ import annotations

import math
import socket
import time
from collections.abc import Callable
from typing import Any

import pytest
from pymodbus.constants import ExcCodes
from pymodbus.exceptions import ModbusIOException

from app.protocol.codec import WordOrder, decode_floats
from app.protocol.enums import Alarm, ControllerMode, ProgramState
from app.protocol.registers import (
    GV_EXPECTED_SPEED,
    GV_EXT_OFFSET0,
    GV_PARAM0,
    GV_PARAM3,
    GV_TOOL_FRAME,
    REG_GO_ZERO,
    REG_PAUSE,
    REG_PROGRAM_ID,
    REG_RESUME,
    REG_RUN_COMMAND,
    REG_STOP,
    REG_WORK_MODE,
)
from app.sim import kinematics
from app.sim.config import SimConfig
from app.sim.server import SimController
from tests.sim.conftest import Bus, poll

RUN = REG_RUN_COMMAND


def step_joint(bus: Bus, offsets: list[float], rpm: float, ext: list[float] | None = None) -> None:
    bus.set_gv(GV_PARAM0, (offsets + [0.0] * 6)[:6])
    bus.set_gv(GV_EXT_OFFSET0, (ext or []) + [0.0] * (5 - len(ext or [])))
    bus.set_gv(GV_EXPECTED_SPEED, [rpm])
    bus.write(RUN, 0x40)


def step_base(bus: Bus, offsets: list[float], speed: float) -> None:
    bus.set_gv(GV_PARAM0, (offsets + [0.0] * 6)[:6])
    bus.set_gv(GV_EXPECTED_SPEED, [speed])
    bus.write(RUN, 0x41)


def create_point(bus: Bus, point_id: float, pose: list[float] | None = None, first_gv: float = 0) -> int:
    if pose is not None:
        bus.set_gv(int(first_gv), pose)
        bus.set_gv(GV_PARAM0, [point_id, 1.0, first_gv])
    else:
        bus.set_gv(GV_PARAM0, [point_id, 0.0, 0.0])
    bus.set_gv(GV_TOOL_FRAME, [200.0])
    bus.write(RUN, 0xE0)
    return int(poll(bus.status, lambda s: s != 0, 2.0))


def move_to_point(
    bus: Bus, end: float, via: float = -1, orient: int = 1, ignore: int = 0, speed: float = 400.0
) -> None:
    bus.set_gv(GV_PARAM0, [via, end, float(orient), float(ignore)])
    bus.set_gv(GV_EXPECTED_SPEED, [speed])
    bus.write(RUN, 0x42)


def wait_move_result(bus: Bus, timeout: float = 5.0) -> int:
    return int(poll(bus.status, lambda s: s not in (0, 6), timeout))


def teach_enable(bus: Bus, frame: int, axis: int, direction: int, ratio: float = 0.0) -> int:
    bus.set_gv(GV_PARAM0, [float(frame), float(axis), float(direction), ratio])
    bus.write(RUN, 0x80)
    return int(poll(bus.status, lambda s: s != 0, 2.0))


# --- lifecycle --------------------------------------------------------------------------
def test_start_binds_and_stop_is_fast_and_idempotent() -> None:
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    assert sim.port > 0
    with socket.create_connection(("127.0.0.1", sim.port), timeout=1):
        pass
    t0 = time.monotonic()
    sim.stop()
    assert time.monotonic() - t0 < 0.5  # < 1 ms when idle; slack for a loaded machine
    sim.stop()
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", sim.port), timeout=0.5).close()


def test_port_in_use_raises(sim: SimController) -> None:
    other = SimController(SimConfig(host="127.0.0.1", port=sim.port))
    with pytest.raises(OSError):
        other.start()
    other.stop()


# --- function 1 -------------------------------------------------------------------------
def test_seed_case_1_joint_step(sim: SimController, bus: Bus) -> None:
    bus.write(REG_WORK_MODE, 1)
    pose0 = bus.pose()
    step_joint(bus, [30.0], 20.0)  # 120 deg/s: 0.25 s
    seen_status: list[int] = []
    j1_values: list[float] = []
    deadline = time.monotonic() + 5
    while True:
        status = bus.status()
        seen_status.append(status)
        j1_values.append(bus.joints()[0])
        if status == 0xFF:
            break
        assert time.monotonic() < deadline
    assert 6 in seen_status
    assert len({round(v, 3) for v in j1_values}) >= 3  # the pose changes over time
    assert j1_values == sorted(j1_values)
    assert bus.joints()[0] == pytest.approx(30.0, abs=1e-4)
    expected = kinematics.forward_pose([30.0, *kinematics.HOME_JOINTS[1:]])
    assert bus.pose() == pytest.approx(expected, abs=1e-2)
    assert bus.pose() != pytest.approx(pose0, abs=1)
    # the 0x06 write was taken once
    assert [w.values for w in sim.writes_to(RUN)] == [(0x40,)]
    assert bus.program_state() == ProgramState.STOPPED


def test_external_axes_and_base_step(sim: SimController, bus: Bus) -> None:
    step_joint(bus, [0.0], 100.0, ext=[10.0, 0.0, 0.0, 0.0, -5.0])
    assert wait_move_result(bus) == 0xFF
    assert bus.gv(212, 5) == pytest.approx([10.0, 0.0, 0.0, 0.0, -5.0])
    x, y, z = bus.pose()[:3]
    step_base(bus, [20.0, 0.0, -10.0], 500.0)
    assert wait_move_result(bus) == 0xFF
    assert bus.pose()[:3] == pytest.approx([x + 20.0, y, z - 10.0], abs=1e-2)


def test_manual_mode_refuses_motion(sim: SimController, bus: Bus) -> None:
    bus.write(REG_WORK_MODE, 0)
    assert bus.mode() == ControllerMode.MANUAL
    step_joint(bus, [5.0], 10.0)
    assert wait_move_result(bus) == 1
    assert teach_enable(bus, 0, 0, 1) == 1


# --- function 2 -------------------------------------------------------------------------
def test_create_points_overwrite_and_restart(sim: SimController, bus: Bus) -> None:
    assert create_point(bus, 1) == 0xFF
    assert sim.state().points[1] == pytest.approx(tuple(bus.pose()), abs=1e-3)
    pose = [400.0, 100.0, 300.0, 180.0, 0.0, 45.0]
    assert create_point(bus, 2, pose, first_gv=10) == 0xFF
    assert sim.state().points[2] == pytest.approx(pose, abs=1e-4)
    pose2 = [410.0, 90.0, 310.0, 170.0, 5.0, 40.0]
    assert create_point(bus, 2, pose2, first_gv=0) == 0xFF  # overwrite
    assert sim.state().points[2] == pytest.approx(pose2, abs=1e-4)
    assert create_point(bus, 10001) == 1  # out of range
    assert create_point(bus, 3, pose, first_gv=95) == 1  # six GVs would pass GV99
    assert set(sim.state().points) == {1, 2}
    sim.restart_controller()
    assert sim.state().points == {}
    assert bus.status() == 0
    move_to_point(bus, 2)
    assert wait_move_result(bus) == 13


def test_restart_clears_the_general_purpose_gvs(sim: SimController, bus: Bus) -> None:
    bus.set_gv(0, [1.5, 2.5])
    bus.set_gv(99, [12345.0])
    bus.set_gv(100, [7.0])  # outside GV0..GV99: kept
    assert bus.gv(99) == [12345.0]
    sim.restart_controller()
    assert bus.gv(0, 2) == [0.0, 0.0]
    assert bus.gv(99) == [0.0]
    assert bus.gv(100) == [7.0]
    bus.set_gv(99, [3.0])  # written after the restart: stays
    assert bus.gv(99) == [3.0]


def test_point_id_range_is_configurable(
    sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]
) -> None:
    sim = sim_factory(point_id_min=1, point_id_max=5)
    bus = make_bus(sim.port)
    assert create_point(bus, 0) == 1
    assert create_point(bus, 5) == 0xFF


# --- function 3 -------------------------------------------------------------------------
def test_move_to_point_line_ends_at_the_point(sim: SimController, bus: Bus) -> None:
    x, y, z, a, b, c = bus.pose()
    target = [x + 60.0, y - 40.0, z + 30.0, a, b, c + 20.0]
    assert create_point(bus, 7, target) == 0xFF
    move_to_point(bus, 7, orient=1, speed=500.0)
    assert wait_move_result(bus) == 0xFF
    got = bus.pose()
    assert got[:3] == pytest.approx(target[:3], abs=1e-2)
    assert got[5] == pytest.approx(target[5], abs=1e-2)


def test_orientation_kept_constant(sim: SimController, bus: Bus) -> None:
    x, y, z, a, b, c = bus.pose()
    assert create_point(bus, 7, [x + 50.0, y, z, a, b, c + 30.0]) == 0xFF
    move_to_point(bus, 7, orient=0, speed=500.0)
    assert wait_move_result(bus) == 0xFF
    assert bus.pose()[5] == pytest.approx(c, abs=1e-2)


def test_arc_passes_near_the_middle_point(sim: SimController, bus: Bus) -> None:
    x, y, z, a, b, c = bus.pose()
    assert create_point(bus, 1, [x + 80.0, y + 80.0, z, a, b, c]) == 0xFF
    assert create_point(bus, 2, [x + 160.0, y, z, a, b, c]) == 0xFF
    move_to_point(bus, 2, via=1, speed=600.0)
    assert wait_move_result(bus) == 0xFF
    assert bus.pose()[:3] == pytest.approx([x + 160.0, y, z], abs=1e-2)
    samples = [s.pose for s in sim.trajectory()]
    assert len(samples) > 10
    assert min(math.dist(p[:3], (x + 80.0, y + 80.0, z)) for p in samples) < 8.0
    for p in samples:  # on the circle: centre (x+80, y), radius 80
        assert math.dist(p[:2], (x + 80.0, y)) == pytest.approx(80.0, abs=0.1)


def test_ignore_middle_keeps_the_arc_but_not_the_middle_orientation(sim: SimController, bus: Bus) -> None:
    """Project decision on GV203: the path still goes through M; only M's orientation is ignored."""
    x, y, z, a, b, c = bus.pose()
    assert create_point(bus, 1, [x + 80.0, y + 80.0, z, a, b, c + 40.0]) == 0xFF  # M turned 40 deg
    assert create_point(bus, 2, [x + 160.0, y, z, a, b, c]) == 0xFF

    def run(ignore: int) -> list[tuple[float, ...]]:
        # 200 mm/s: 2 mm a tick at 100 Hz, so even ticks four times late under CPU load sample M
        move_to_point(bus, 2, via=1, ignore=ignore, speed=200.0)
        assert wait_move_result(bus) == 0xFF
        return [tuple(s.pose) for s in sim.trajectory()]

    def yaw_near_middle(samples: list[tuple[float, ...]]) -> float:
        nearest = min(samples, key=lambda p: math.dist(p[:3], (x + 80.0, y + 80.0, z)))
        assert math.dist(nearest[:3], (x + 80.0, y + 80.0, z)) < 8.0  # through M both times
        return (nearest[5] - c + 180.0) % 360.0 - 180.0

    assert yaw_near_middle(run(ignore=0)) == pytest.approx(40.0, abs=3.0)  # M's orientation reached
    step_base(bus, [-160.0, 0, 0, 0, 0, 0], 600.0)  # back to the start
    assert wait_move_result(bus) == 0xFF
    assert abs(yaw_near_middle(run(ignore=1))) < 1.0  # start and end share C: no turn at all


def test_bad_points_and_collinear_arc(sim: SimController, bus: Bus) -> None:
    x, y, z, a, b, c = bus.pose()
    move_to_point(bus, 42)
    assert wait_move_result(bus) == 13
    assert create_point(bus, 1, [x + 50.0, y, z, a, b, c]) == 0xFF
    assert create_point(bus, 2, [x + 100.0, y, z, a, b, c]) == 0xFF
    move_to_point(bus, 2, via=43)
    assert wait_move_result(bus) == 13
    move_to_point(bus, 2, via=1)  # collinear
    assert wait_move_result(bus) == 10
    assert create_point(bus, 3, [1800.0, 0.0, 400.0, a, b, c]) == 0xFF
    move_to_point(bus, 3)  # out of reach
    assert wait_move_result(bus) == 10


# --- pause / resume / stop, zero, programs ------------------------------------------------
def test_pause_resume_stop(sim: SimController, bus: Bus) -> None:
    step_joint(bus, [40.0], 2.0)  # 12 deg/s: long enough to pause
    poll(bus.program_state, lambda s: s == ProgramState.RUNNING)
    bus.write(REG_PAUSE, 1)
    assert bus.program_state() == ProgramState.PAUSED
    j = bus.joints()[0]
    assert sim.wait_for(lambda s: s.t > 0, 1)
    t0 = sim.state().t
    assert sim.wait_for(lambda s: s.t > t0 + 0.05, 2)  # ticks go on, the arm does not
    assert bus.joints()[0] == j
    assert bus.status() == 6
    bus.write(REG_RESUME, 1)
    assert bus.program_state() == ProgramState.RUNNING
    poll(lambda: bus.joints()[0], lambda v: v > j + 0.1)
    bus.write(REG_STOP, 1)
    assert bus.program_state() == ProgramState.STOPPED
    assert bus.status() == 0
    j = bus.joints()[0]
    t0 = sim.state().t
    assert sim.wait_for(lambda s: s.t > t0 + 0.05, 2)
    assert bus.joints()[0] == j


def test_go_to_zero(sim: SimController, bus: Bus) -> None:
    bus.write(REG_GO_ZERO, 1)  # J2: 20 deg at 90 deg/s
    assert bus.program_state() == ProgramState.RUNNING
    poll(bus.program_state, lambda s: s == ProgramState.STOPPED)
    joints = bus.joints()
    assert joints[1] == 0.0
    assert joints[2] == pytest.approx(kinematics.HOME_JOINTS[2])


def test_run_program_states(sim: SimController, bus: Bus) -> None:
    bus.write_regs(REG_PROGRAM_ID, [99, 1, 1, 100])
    bus.write(RUN, 0x01)
    assert bus.program_state() == ProgramState.STOPPED  # unknown program: not started
    bus.write_regs(REG_PROGRAM_ID, [2, 2, 0, 100])  # joint wiggle, endless cycle
    bus.write(RUN, 0x01)
    assert bus.program_state() == ProgramState.RUNNING
    bus.write(REG_PAUSE, 1)
    assert bus.program_state() == ProgramState.PAUSED
    bus.write(REG_RESUME, 1)
    assert bus.program_state() == ProgramState.RUNNING
    bus.write(REG_STOP, 1)
    assert bus.program_state() == ProgramState.STOPPED
    bus.write_regs(REG_PROGRAM_ID, [3, 1, 1, 100])  # J7 shuttle, once: 2 x 100 deg at 60 deg/s
    bus.write(RUN, 0x01)
    assert bus.program_state() == ProgramState.RUNNING
    poll(lambda: bus.gv(212)[0], lambda v: v > 50.0)
    poll(bus.program_state, lambda s: s == ProgramState.STOPPED, 6)
    assert bus.gv(212)[0] == pytest.approx(0.0, abs=1e-4)


# --- function 4 -------------------------------------------------------------------------
def test_teach_enable_jog_and_disable(sim: SimController, bus: Bus) -> None:
    assert teach_enable(bus, 3, 0, 1, ratio=10.0) == 7  # ratio must be 0
    assert bus.mode() == ControllerMode.AUTO
    assert teach_enable(bus, 3, 0, 1) == 0xFF
    assert bus.mode() == ControllerMode.MODBUS_TEACH
    j1 = bus.joints()[0]
    bus.set_gv(GV_PARAM3, [100.0])  # J1 positive at 30 deg/s
    poll(lambda: bus.joints()[0], lambda v: v > j1 + 1.0)
    bus.set_gv(GV_PARAM3, [0.0])
    assert sim.state().jogging is False
    j1 = bus.joints()[0]
    t0 = sim.state().t
    assert sim.wait_for(lambda s: s.t > t0 + 0.05, 2)
    assert bus.joints()[0] == j1
    assert bus.mode() == ControllerMode.MODBUS_TEACH  # still enabled
    # axis / direction change: ratio 0, GV201/202, ratio again
    bus.set_gv(GV_PARAM0 + 1, [5.0, 0.0])  # J6 negative
    j6 = bus.joints()[5]
    bus.set_gv(GV_PARAM3, [100.0])
    poll(lambda: bus.joints()[5], lambda v: v < j6 - 1.0)
    bus.write(RUN, 0x81)  # refused while the ratio is not 0
    assert poll(bus.status, lambda s: s != 0) == 7
    bus.set_gv(GV_PARAM3, [0.0])
    bus.write(RUN, 0x81)
    assert poll(bus.status, lambda s: s != 0) == 0xFF
    assert bus.mode() == ControllerMode.AUTO


def test_teach_frame_change_needs_re_enable(sim: SimController, bus: Bus) -> None:
    assert teach_enable(bus, 0, 2, 1) == 0xFF  # base frame, Z positive
    bus.set_gv(GV_PARAM0, [3.0])  # joint frame, not yet in force
    x, _y, z = bus.pose()[:3]
    j1 = bus.joints()[0]
    bus.set_gv(GV_PARAM3, [40.0])  # 100 mm/s
    poll(lambda: bus.pose()[2], lambda v: v > z + 2.0)
    bus.set_gv(GV_PARAM3, [0.0])
    assert bus.pose()[0] == pytest.approx(x, abs=1e-2)
    assert bus.joints()[0] == pytest.approx(j1, abs=1e-6)
    assert sim.state().teach_frame == 0
    bus.write(RUN, 0x81)
    poll(bus.status, lambda s: s == 0xFF)
    assert teach_enable(bus, 3, 0, 1) == 0xFF
    assert sim.state().teach_frame == 3
    bus.set_gv(GV_PARAM3, [100.0])
    poll(lambda: bus.joints()[0], lambda v: v > j1 + 1.0)


def test_manual_mode_and_go_zero_disable_teach(sim: SimController, bus: Bus) -> None:
    assert teach_enable(bus, 3, 0, 1) == 0xFF
    bus.write(REG_WORK_MODE, 0)
    assert bus.mode() == ControllerMode.MANUAL
    bus.write(REG_WORK_MODE, 1)
    assert teach_enable(bus, 3, 0, 1) == 0xFF
    bus.write(REG_GO_ZERO, 0)
    assert not sim.state().teach_enabled


# --- alarms -------------------------------------------------------------------------------
def test_estop_stops_motion_and_disables_teach(sim: SimController, bus: Bus) -> None:
    step_joint(bus, [40.0], 2.0)
    poll(lambda: bus.joints()[0], lambda v: v > 0.5)
    sim.set_alarm(Alarm.ESTOP, True)
    assert bus.alarms() == int(Alarm.ESTOP)
    assert bus.status() == 2
    assert bus.program_state() == ProgramState.STOPPED
    j = bus.joints()[0]
    t0 = sim.state().t
    assert sim.wait_for(lambda s: s.t > t0 + 0.05, 2)
    assert bus.joints()[0] == j
    step_joint(bus, [1.0], 10.0)
    assert wait_move_result(bus) == 2
    sim.set_alarm(Alarm.ESTOP, False)
    assert teach_enable(bus, 3, 0, 1) == 0xFF
    sim.set_alarm(Alarm.ESTOP, True)
    assert bus.mode() == ControllerMode.AUTO
    sim.set_alarm(Alarm.ESTOP, False)
    sim.set_alarm(Alarm.SERVO, True)
    step_joint(bus, [1.0], 10.0)
    assert wait_move_result(bus) == 3
    sim.set_alarm(Alarm.SERVO, False)
    sim.set_alarm(Alarm.BRAKE, True)
    assert teach_enable(bus, 3, 0, 1) == 4
    assert bus.alarms() == int(Alarm.BRAKE)


# --- GV291 encodings and timing -----------------------------------------------------------
def test_status_encodings(sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]) -> None:
    sim_f = sim_factory()
    bus_f = make_bus(sim_f.port)
    assert create_point(bus_f, 1) == 0xFF
    assert bus_f.read(582, 2) == [0x0000, 0x437F]  # 255.0, low word first
    sim_i = sim_factory(status_encoding="int")
    bus_i = make_bus(sim_i.port)
    assert create_point(bus_i, 1) == 0xFF
    assert bus_i.read(582, 2) == [0x00FF, 0x0000]


def test_word_order_high_first(
    sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]
) -> None:
    sim = sim_factory(word_order=WordOrder.HIGH_FIRST)
    bus = make_bus(sim.port, order=WordOrder.HIGH_FIRST)
    assert bus.pose() == pytest.approx(sim.state().pose, abs=1e-3)
    step_joint(bus, [5.0], 50.0)
    assert wait_move_result(bus) == 0xFF
    assert bus.read(582, 2) == [0x437F, 0x0000]
    assert bus.joints()[0] == pytest.approx(5.0, abs=1e-4)
    # a low-first reader sees nonsense
    assert decode_floats(bus.read(500, 2), WordOrder.LOW_FIRST)[0] != pytest.approx(5.0, abs=1)


def test_status_delay_keeps_the_old_value(sim: SimController, bus: Bus) -> None:
    assert create_point(bus, 1) == 0xFF
    sim.set_status_delay(0.3)
    t0 = time.monotonic()
    bus.set_gv(GV_PARAM0, [20000.0, 0.0])  # bad id: the new result will be 1
    bus.write(RUN, 0xE0)
    assert bus.status() == 0xFF  # stale
    poll(bus.status, lambda s: s == 1, 2.0)
    assert time.monotonic() - t0 >= 0.28


def test_command_latency_shows_initial(
    sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]
) -> None:
    sim = sim_factory(command_latency=0.2)
    bus = make_bus(sim.port)
    bus.set_gv(GV_PARAM0, [1.0, 0.0])
    bus.write(RUN, 0xE0)
    assert bus.status() == 0
    assert poll(bus.status, lambda s: s != 0, 2.0) == 0xFF


def test_instant_command_shows_initial_until_a_host_reads_it(sim: SimController, bus: Bus) -> None:
    """A slow host still sees the 0 between the old and the new 0xFF of a create point."""
    assert create_point(bus, 1) == 0xFF
    bus.set_gv(GV_PARAM0, [2.0, 0.0, 0.0])
    bus.write(RUN, 0xE0)
    t0 = sim.state().t
    # let the simulator run well past its command latency before the host looks
    assert sim.wait_for(lambda s: s.t > t0 + 0.05, 2)
    assert 2 in sim.state().points  # the point exists already ...
    assert bus.status() == 0  # ... but the host's first look still shows "received"
    assert bus.status() == 0xFF


# --- fault injection ----------------------------------------------------------------------
def test_response_delay(sim: SimController, bus: Bus) -> None:
    sim.set_response_delay(0.3)
    t0 = time.monotonic()
    bus.read(560)
    assert time.monotonic() - t0 >= 0.29
    sim.set_response_delay(0)
    t0 = time.monotonic()
    bus.read(560)
    assert time.monotonic() - t0 < 0.25


def test_drop_connections(sim: SimController) -> None:
    with socket.create_connection(("127.0.0.1", sim.port), timeout=2) as s:
        assert sim.wait_for(lambda _: sim.connections_count == 1, 2)
        assert sim.drop_connections() == 1
        assert s.recv(10) == b""  # closed by the server
    with socket.create_connection(("127.0.0.1", sim.port), timeout=2):
        pass  # still listening


def test_exception_injection(sim: SimController, bus: Bus) -> None:
    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, range(412, 424))
    rr = bus.client.read_holding_registers(412, count=12, device_id=1)
    assert rr.isError() and rr.exception_code == 2
    assert bus.read(560) is not None  # other addresses answer
    sim.set_exception(ExcCodes.DEVICE_BUSY)
    rr = bus.client.write_register(444, 1, device_id=1)
    assert rr.isError() and rr.exception_code == int(ExcCodes.DEVICE_BUSY)
    sim.set_exception(None)
    assert len(bus.pose()) == 6


def test_silent(sim: SimController, make_bus: Callable[..., Bus]) -> None:
    bus = make_bus(sim.port, timeout=0.2)
    sim.set_silent(True)
    before = sim.requests_count
    with pytest.raises(ModbusIOException):
        bus.client.write_register(444, 0, device_id=1)
    assert sim.requests_count == before + 1  # received ...
    assert sim.state().work_mode == 1  # ... not executed
    sim.set_silent(False)
    bus.close()
    bus2 = make_bus(sim.port)
    assert bus2.mode() == ControllerMode.AUTO


def test_unknown_run_command_is_an_illegal_value(sim: SimController, bus: Bus) -> None:
    before = bus.read(RUN)
    rr = bus.client.write_register(RUN, 0x33, device_id=1)
    assert rr.isError() and rr.exception_code == int(ExcCodes.ILLEGAL_VALUE)
    assert bus.read(RUN) == before  # not stored
    rr = bus.client.write_register(REG_WORK_MODE, 7, device_id=1)
    assert rr.isError() and rr.exception_code == int(ExcCodes.ILLEGAL_VALUE)
    assert bus.read(REG_WORK_MODE) == [1]
    assert bus.mode() == ControllerMode.AUTO


# --- framing, inspection, clock -----------------------------------------------------------
def test_rtu_framing_over_tcp(
    sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]
) -> None:
    sim = sim_factory(framer="rtu")
    bus = make_bus(sim.port, rtu=True)
    assert bus.pose() == pytest.approx(sim.state().pose, abs=1e-3)
    step_joint(bus, [2.0], 50.0)
    assert wait_move_result(bus) == 0xFF


def test_inspection_api(sim: SimController, bus: Bus) -> None:
    n0 = sim.requests_count
    bus.read(560, 24)
    bus.write(REG_WORK_MODE, 1)
    bus.set_gv(GV_PARAM0, [1.0, 2.0])
    assert sim.requests_count == n0 + 3
    assert [(w.function_code, w.values) for w in sim.writes_to(REG_WORK_MODE)] == [(6, (1,))]
    recs = sim.writes_to(401)
    assert len(recs) == 1 and recs[0].function_code == 16 and recs[0].address == 401
    assert sim.writes[-1].values == (0, 0x3F80, 0, 0x4000)
    snap: Any = sim.state()
    assert snap.mode == ControllerMode.AUTO and len(snap.joints) == 11 and len(snap.pose) == 6


def test_clock_registers(sim: SimController, bus: Bus) -> None:
    import datetime as dt

    from app.protocol.datetime_regs import decode_clock

    clock = decode_clock(bus.read(576, 4))
    assert clock.value is not None
    assert abs((clock.value - dt.datetime.now()).total_seconds()) < 5


def test_monitor_block_reads(sim: SimController, bus: Bus) -> None:
    assert len(bus.read(412, 100)) == 100
    regs = bus.read(560, 24)
    assert regs[0] == ControllerMode.AUTO and regs[1] == ProgramState.STOPPED


def test_the_write_log_keeps_the_last_writes_only(sim: Any, make_client: Any, monkeypatch: Any) -> None:
    """A simulator the GUI runs for days must not grow with every write (issue 18): past
    WRITE_LOG_LIMIT the oldest tenth is dropped, and counted."""
    from app.sim import server

    monkeypatch.setattr(server, "WRITE_LOG_LIMIT", 10)
    client = make_client(sim)
    for value in range(15):
        client.write_register(100, value)
    assert len(sim.writes) <= 10 and sim.writes_dropped == 15 - len(sim.writes)
    assert [w.values for w in sim.writes][-3:] == [(12,), (13,), (14,)]
