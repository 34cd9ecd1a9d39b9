"""RobotClient against the real simulator over TCP (and RTU framing over TCP)."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.errors import (
    AlarmRaised,
    CommandRefused,
    CommandStopped,
    CommandTimeout,
    InvalidInput,
    LinkError,
    ModbusExceptionError,
    ResponseTimeout,
    WriteBlocked,
)
from app.link.client import RobotClient
from app.link.transport import TrafficRecord
from app.link.types import StepFrame
from app.protocol.codec import WordOrder, decode_floats
from app.protocol.enums import (
    Alarm,
    CommandKind,
    ControllerMode,
    CreatePointStatus,
    MoveStatus,
    ProgramMotionMode,
    ProgramState,
    TeachFrame,
    WorkMode,
)
from tests.link.hostile.server import crc16
from tests.waits import join

FC06, FC10 = 0x06, 0x10
# Create/teach commands publish 0 (received) for command_latency before the final code. The
# default 1 ms window is shorter than one scheduling hiccup on a loaded 2-core machine, so the
# tests that chain many create/teach commands give the simulated controller a 20 ms scan.
SCAN = 0.02

MakeClient = Callable[..., RobotClient]  # the make_client fixture (tests/conftest.py)


def wire(sim: Any, since: int = 0) -> list[tuple[int, int, int]]:
    """(function code, first register, register count) of each write the simulator received,
    but the completion rule's writes to GV291 (582; tests/link/test_completion_profiles.py)."""
    return [(w.function_code, w.address, len(w.values)) for w in sim.writes[since:] if w.address != 582]


def close(a: tuple[float, ...], b: tuple[float, ...], tol: float = 0.05) -> bool:
    return all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))


@pytest.fixture
def scan_sim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=SCAN)


# --- reads --------------------------------------------------------------------------------


def test_read_pose_and_status_match_the_controller(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    pose = c.read_pose()
    state = sim.state()
    assert close(pose.xyzabc, state.pose, 1e-3)
    assert pose.joints is not None and close(pose.joints, state.joints[:6], 1e-3)
    assert close(pose.ext, state.ext, 1e-3)
    status = c.read_status(with_clock=True)
    assert status.mode is ControllerMode.AUTO
    assert status.program_state is ProgramState.STOPPED
    assert status.alarms == Alarm.NONE
    assert status.command_status_code == 0
    assert status.clock is not None and status.clock.value is not None
    assert c.read_clock().value is not None
    assert c.last_status == status
    # one FC03 each: 412..511 and 560..583
    reads: list[bytes] = []
    c.add_observer(lambda r: reads.append(r.frame) if r.direction == "tx" else None)
    c.read_pose()
    c.read_status()
    assert [f[7:] for f in reads] == [bytes.fromhex("03 019C 0064"), bytes.fromhex("03 0230 0018")]


def test_raw_and_gv_access(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    c.write_gv(10, [1.5, -2.25, 3e6])
    assert c.read_gv(10, 3) == [1.5, -2.25, 3e6]
    c.write_registers(100, [1, 2, 3])
    assert c.read_registers(100, 3) == [1, 2, 3]
    c.write_register(110, 0xBEEF)
    assert c.read_registers(110, 1) == [0xBEEF]
    assert wire(sim) == [(FC10, 20, 6), (FC10, 100, 3), (FC06, 110, 1)]
    with pytest.raises(InvalidInput, match="control registers"):
        c.write_registers(438, [0, 0, 0, 0])
    with pytest.raises(InvalidInput, match="control registers"):
        c.write_gv(220, [1.0])
    with pytest.raises(InvalidInput):
        c.write_gv(0, [math.nan])
    assert len(sim.writes) == 3


def test_command_status_uses_the_last_command_kind(scan_sim: Any, make_client: MakeClient) -> None:
    c = make_client(scan_sim)
    c.create_point(3)
    status = c.command_status()
    assert status.kind is CommandKind.CREATE_POINT and status.member is CreatePointStatus.DONE


@pytest.mark.parametrize("encoding", ["float", "int"])
@pytest.mark.parametrize("order", [WordOrder.LOW_FIRST, WordOrder.HIGH_FIRST])
def test_status_encodings_and_word_orders(
    sim_factory: Any, make_client: MakeClient, encoding: str, order: WordOrder
) -> None:
    sim = sim_factory(status_encoding=encoding, word_order=order, command_latency=SCAN)
    c = make_client(sim)
    assert close(c.read_pose().xyzabc, sim.state().pose, 1e-3)
    result = c.create_point(7, pose=[1, 2, 3, 4, 5, 6])
    assert result.ok and c.read_status().command_status_code == 0xFF
    assert sim.state().points[7] == (1, 2, 3, 4, 5, 6)


# --- function 1 ---------------------------------------------------------------------------


def test_step_base_batches_its_writes(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    x0 = sim.state().pose[0]
    result = c.step(StepFrame.BASE, [10, 0, 0, 0, 0, 0], speed=200)
    assert result.ok and result.status is not None and result.status.member is MoveStatus.DONE
    state = sim.state()
    assert not state.moving and state.pose[0] == pytest.approx(x0 + 10, abs=0.01)
    # GV200-205, GV236-240 (first time: unknown), GV225, then 440 <- 0x41 with 0x06
    assert wire(sim) == [(FC10, 400, 12), (FC10, 472, 10), (FC10, 450, 2), (FC06, 440, 1)]
    assert sim.writes[-1].values == (0x41,)
    n = len(sim.writes)
    c.step(StepFrame.BASE, [-10, 0, 0, 0, 0, 0], speed=200)
    assert wire(sim, n) == [(FC10, 400, 12), (FC10, 450, 2), (FC06, 440, 1)]  # ext unchanged
    n = len(sim.writes)
    c.step(StepFrame.JOINT, [0] * 6, ext_offsets=[5, 0, 0, 0, 0], speed=10)
    assert wire(sim, n) == [(FC10, 400, 12), (FC10, 472, 10), (FC10, 450, 2), (FC06, 440, 1)]
    assert sim.state().joints[6] == pytest.approx(5, abs=0.01)


def test_step_joint_moves_the_joint(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    j1 = sim.state().joints[0]
    c.step(StepFrame.JOINT, [5, 0, 0, 0, 0, 0], speed=10)
    assert sim.state().joints[0] == pytest.approx(j1 + 5, abs=0.01)
    assert sim.writes[-1].values == (0x40,)
    assert c.read_pose().joints[0] == pytest.approx(j1 + 5, abs=0.01)  # type: ignore[index]


def test_step_writes_auto_mode_only_when_manual(sim_factory: Any, make_client: MakeClient) -> None:
    sim = sim_factory(work_mode=WorkMode.MANUAL)
    c = make_client(sim)
    c.step(StepFrame.BASE, [0, 0, 5, 0, 0, 0], speed=200)
    assert wire(sim)[0] == (FC06, 444, 1) and sim.writes[0].values == (1,)
    n = len(sim.writes)
    c.step(StepFrame.BASE, [0, 0, -5, 0, 0, 0], speed=200)
    assert (FC06, 444, 1) not in wire(sim, n)


def test_refused_step_raises_command_refused(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    with pytest.raises(CommandRefused) as info:
        c.step(StepFrame.JOINT, [1000, 0, 0, 0, 0, 0], speed=10)  # beyond the joint limit
    assert info.value.status.member is MoveStatus.CALCULATION_ERROR
    assert "calculation error" in str(info.value)


# --- function 2 ---------------------------------------------------------------------------


def test_create_point_from_pose_and_from_gvs(scan_sim: Any, make_client: MakeClient) -> None:
    sim = scan_sim
    c = make_client(sim)
    result = c.create_point(5)
    assert result.ok and result.kind is CommandKind.CREATE_POINT
    assert close(sim.state().points[5], sim.state().pose, 1e-3)
    assert wire(sim) == [(FC10, 400, 4), (FC10, 490, 2), (FC06, 440, 1)]
    n = len(sim.writes)
    c.create_point(6, pose=[400, 10, 300, 180, 0, 90], gv_start=10)
    assert sim.state().points[6] == (400, 10, 300, 180, 0, 90)
    # GV10-15, GV200-202 (id, 1, 10); GV245 cached; 440 <- 0xE0
    assert wire(sim, n) == [(FC10, 20, 12), (FC10, 400, 6), (FC06, 440, 1)]
    assert sim.writes[-1].values == (0xE0,)
    n = len(sim.writes)
    c.create_point(7, pose=[400, 10, 300, 180, 0, 90], tool=3)
    assert wire(sim, n) == [(FC10, 0, 12), (FC10, 400, 6), (FC10, 490, 2), (FC06, 440, 1)]


def test_create_point_refused_by_the_controller(sim_factory: Any, make_client: MakeClient) -> None:
    sim = sim_factory(point_id_max=100, command_latency=SCAN)
    c = make_client(sim)
    with pytest.raises(CommandRefused) as info:
        c.create_point(500)
    assert info.value.status.member is CreatePointStatus.BAD_POINT_ID
    assert "bad point id" in str(info.value)


def test_upload_points_batched(sim_factory: Any, make_client: MakeClient) -> None:
    sim = sim_factory(point_id_max=100, command_latency=0.005)
    c = make_client(sim)
    points = [(i, [300.0 + i, 10.0, 400.0, 180.0, 0.0, float(i)]) for i in range(1, 31)]
    points.insert(10, (150, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]))  # the controller refuses id 150
    seen: list[tuple[int, int]] = []

    def progress(done: int, total: int) -> bool:
        seen.append((done, total))
        return True

    results = c.upload_points(points, progress=progress)
    assert len(results) == 31 and seen[-1] == (31, 31)
    assert [r.details["point_id"] for r in results] == [float(p[0]) for p in points]
    failed = [r for r in results if not r.ok]
    assert len(failed) == 1 and failed[0].details["point_id"] == 150.0
    assert failed[0].status is not None and failed[0].status.member is CreatePointStatus.BAD_POINT_ID
    stored = sim.state().points
    for pid, pose in points:
        if pid != 150:
            assert stored[pid] == tuple(pose)
    # one GV245 write, then per point: GV200-202, 440 and, while the controller works on it, the
    # next point's pose into the other block (GV0-5 / GV6-11; the first pose goes before)
    w = wire(sim)
    assert w[0] == (FC10, 490, 2)
    expected = [(FC10, 0, 12)]
    for i in range(31):
        expected += [(FC10, 400, 6), (FC06, 440, 1)]
        if i < 30:
            expected.append((FC10, 12 * ((i + 1) % 2), 12))
    assert w[1:] == expected
    # each command named its own block in GV202, and its block held its pose then
    params = [decode_floats(list(w.values), WordOrder.LOW_FIRST) for w in sim.writes if w.address == 400]
    assert [(int(v[0]), v[2]) for v in params] == [(p[0], 6.0 * (i % 2)) for i, p in enumerate(points)]


def test_upload_points_cancel_and_validation(scan_sim: Any, make_client: MakeClient) -> None:
    c = make_client(scan_sim)
    points = [(i, [300.0, 0.0, 400.0, 180.0, 0.0, 0.0]) for i in range(10)]
    results = c.upload_points(points, progress=lambda done, total: done < 3)
    assert len(results) == 3 and all(r.ok for r in results)
    n = len(scan_sim.writes)
    with pytest.raises(InvalidInput):
        c.upload_points([(1, [0.0] * 6), (2, [0.0, math.inf, 0.0, 0.0, 0.0, 0.0])])
    with pytest.raises(InvalidInput):
        c.upload_points([(20000, [0.0] * 6)])
    assert len(scan_sim.writes) == n  # nothing reached the wire
    assert c.upload_points([]) == []


def test_upload_points_stops_on_link_loss(sim_factory: Any, make_client: MakeClient) -> None:
    sim = sim_factory(command_latency=SCAN)
    c = make_client(sim)
    points = [(i, [300.0, 0.0, 400.0, 180.0, 0.0, 0.0]) for i in range(10)]

    def progress(done: int, total: int) -> bool:
        if done == 2:
            sim.stop()
        return True

    results = c.upload_points(points, progress=progress)
    assert [r.ok for r in results] == [True, True, False]
    assert "connect" in results[-1].message


# --- function 3 ---------------------------------------------------------------------------


def test_move_to_point_line_and_arc(scan_sim: Any, make_client: MakeClient) -> None:
    sim = scan_sim
    c = make_client(sim)
    home = sim.state().pose
    c.create_point(1)
    c.create_point(2, pose=[home[0], home[1] + 40, home[2], *home[3:]])
    c.create_point(3, pose=[home[0] + 20, home[1] + 20, home[2], *home[3:]])
    n = len(sim.writes)
    result = c.move_to_point(2, speed=400)
    assert result.ok
    assert close(sim.state().pose[:3], (home[0], home[1] + 40, home[2]), 0.05)
    # GV200-203 one 0x10, GV225, GV245 cached, 440 <- 0x42
    assert wire(sim, n) == [(FC10, 400, 8), (FC10, 450, 2), (FC06, 440, 1)]
    assert sim.writes[-1].values == (0x42,)
    result = c.move_to_point(1, via_id=3, speed=400, orientation_changes=False)
    assert result.ok and close(sim.state().pose[:3], home[:3], 0.05)
    with pytest.raises(CommandRefused) as info:
        c.move_to_point(99)
    assert info.value.status.member is MoveStatus.BAD_END_POINT


def test_alarm_while_moving(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    c.step(StepFrame.BASE, [0, 60, 0, 0, 0, 0], speed=50, wait=False)
    tracker = c.last_tracker
    assert tracker is not None
    assert sim.wait_for(lambda s: s.moving, 2.0)
    sim.set_alarm(Alarm.ESTOP, True)
    with pytest.raises(AlarmRaised) as info:
        c.wait(tracker)
    assert info.value.alarms == Alarm.ESTOP and "emergency stop" in str(info.value)


def test_host_stop_and_pause_resume(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    c.step(StepFrame.BASE, [0, 40, 0, 0, 0, 0], speed=100, wait=False)
    tracker = c.last_tracker
    assert tracker is not None
    while not tracker.motion_seen:
        assert c.poll(tracker) is None
    c.pause()
    assert sim.wait_for(lambda s: s.paused, 2.0)
    assert c.read_status().program_state is ProgramState.PAUSED
    c.resume()
    assert sim.wait_for(lambda s: not s.paused, 2.0)
    c.stop()
    assert tracker.finished
    with pytest.raises(CommandStopped, match="stopped by the operator") as stopped:
        c.wait(tracker)
    assert stopped.value.code == "stopped_by_operator"  # its own outcome, not a failure kind
    assert tracker.result is not None and tracker.result.stopped_by_operator
    assert sim.wait_for(lambda s: not s.moving, 2.0)


def test_stop_by_someone_else_ends_the_wait(
    sim: Any, make_client: MakeClient, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "STOP_SETTLE", 0.05)
    c = make_client(sim)
    other = make_client(sim)
    c.step(StepFrame.BASE, [0, -40, 0, 0, 0, 0], speed=100, wait=False)
    tracker = c.last_tracker
    assert tracker is not None
    while not tracker.motion_seen:
        c.poll(tracker)
    other.stop()
    with pytest.raises(CommandStopped, match="program state returned to stopped"):
        c.wait(tracker)


# --- the stale 0xFF ----------------------------------------------------------------------


def test_stale_done_is_not_taken_for_the_new_command(sim_factory: Any, make_client: MakeClient) -> None:
    delay = 0.25
    sim = sim_factory(status_delay=delay, command_latency=SCAN)
    c = make_client(sim)
    c.create_point(1)  # leaves 0xFF in GV291
    assert c.read_status().command_status_code == 0xFF
    result = c.create_point(2)
    assert result.ok and result.details["elapsed"] >= delay
    # A move that ends while the old 0xFF is still published is not "done" until GV291 says so.
    x0 = sim.state().pose[0]
    result = c.step(StepFrame.BASE, [40, 0, 0, 0, 0, 0], speed=100)
    assert result.ok and result.details["elapsed"] >= delay
    state = sim.state()
    assert not state.moving and state.pose[0] == pytest.approx(x0 + 40, abs=0.01)
    # A refusal under the stale 0xFF is reported as a refusal.
    with pytest.raises(CommandRefused):
        c.move_to_point(77)


def test_controller_that_never_acknowledges(
    sim_factory: Any, make_client: MakeClient, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "ACK_TIMEOUT", 0.2)
    sim = sim_factory(status_delay=5.0, command_latency=SCAN)
    c = make_client(sim)
    with pytest.raises(CommandTimeout, match=r"did not acknowledge create temp point within 0\.2 s"):
        c.create_point(1)


# --- function 4 ---------------------------------------------------------------------------


def test_teach_enable_jog_disable(scan_sim: Any, make_client: MakeClient) -> None:
    sim = scan_sim
    # no request goes out while the test waits for the jog to move: the simulator's 0.3 s
    # watchdog would stop it, before it has moved 1 mm when a loaded process starves its ticker
    sim.set_watchdog(None)
    c = make_client(sim)
    result = c.teach_enable(TeachFrame.BASE, 0, 1)
    assert result.ok and result.kind is CommandKind.TEACH
    assert wire(sim) == [(FC10, 400, 8), (FC06, 440, 1)] and sim.writes[-1].values == (0x80,)
    assert sim.state().teach_enabled and c.read_status().mode is ControllerMode.MODBUS_TEACH
    x0 = sim.state().pose[0]
    c.teach_set_ratio(50)
    assert sim.wait_for(lambda s: s.pose[0] > x0 + 1, 2.0)
    c.teach_set_axis(2, 0)  # ratio 0 first, then GV201-202
    n = len(sim.writes)
    assert not sim.state().jogging
    z0 = sim.state().pose[2]
    c.teach_set_ratio(30)
    assert sim.wait_for(lambda s: s.pose[2] < z0 - 1, 2.0)
    result = c.teach_disable()  # writes ratio 0 itself
    assert result.ok and not sim.state().teach_enabled
    assert wire(sim, n - 2)[:2] == [(FC10, 406, 2), (FC10, 402, 4)]
    n = len(sim.writes)
    c.teach_enable(TeachFrame.TOOL, 1, 1, tool_frame=2)
    assert wire(sim, n) == [(FC10, 400, 8), (FC10, 490, 2), (FC06, 440, 1)]
    c.teach_disable()
    n = len(sim.writes)
    c.teach_enable(TeachFrame.USER, 1, 1, user_frame=4)
    assert wire(sim, n) == [(FC10, 400, 8), (FC10, 482, 2), (FC06, 440, 1)]
    c.teach_disable()
    with pytest.raises(InvalidInput):
        c.teach_enable(TeachFrame.BASE, 6, 1)  # J7 is not a cartesian axis
    with pytest.raises(InvalidInput):
        c.teach_set_ratio(101)


# --- plain commands ------------------------------------------------------------------------


def test_plain_commands(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    c.set_work_mode(WorkMode.MANUAL)
    assert sim.state().work_mode is WorkMode.MANUAL
    c.set_work_mode(WorkMode.AUTO)
    c.run_program(2, ProgramMotionMode.SINGLE_RUN, cycles=1, speed_ratio=100)
    assert sim.wait_for(lambda s: s.moving, 2.0)
    assert (FC10, 446, 4) in wire(sim)
    c.stop()
    assert sim.wait_for(lambda s: not s.moving, 2.0)
    c.step(StepFrame.JOINT, [10, 0, 0, 0, 0, 0], speed=20)
    c.go_zero(0)
    assert sim.wait_for(lambda s: not s.moving and abs(s.joints[0]) < 1e-6, 5.0)
    assert sim.writes[-1].address == 445 and sim.writes[-1].values == (0,)
    c.go_zero(None)
    assert sim.writes[-1].values == (0x0B,)
    c.stop()
    for w in sim.writes:
        if 440 <= w.address <= 445:
            assert w.function_code == FC06 and len(w.values) == 1


def test_invalid_input_is_refused_before_the_wire(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim, point_id_max=100)
    before = sim.requests_count
    bad: list[Any] = [
        lambda: c.step(StepFrame.BASE, [math.nan, 0, 0, 0, 0, 0]),
        lambda: c.step(StepFrame.BASE, [1, 0, 0]),
        lambda: c.step(StepFrame.BASE, [0] * 6),
        lambda: c.step(StepFrame.BASE, [1, 0, 0, 0, 0, 0], speed=0),
        lambda: c.step("base", [1, 0, 0, 0, 0, 0]),  # type: ignore[arg-type]  # a wrong type on purpose
        lambda: c.create_point(101),
        lambda: c.create_point(-1),
        lambda: c.create_point(1, pose=[0, 0, 0, 0, 0, math.inf]),
        lambda: c.create_point(1, gv_start=95),
        lambda: c.create_point(1, tool=201),
        lambda: c.move_to_point(1, via_id=1),
        lambda: c.move_to_point(1, speed=-1),
        lambda: c.teach_enable(5, 0, 1),  # type: ignore[arg-type]
        lambda: c.teach_enable(TeachFrame.JOINT, 11, 1),
        lambda: c.teach_enable(TeachFrame.JOINT, 0, 2),
        lambda: c.teach_set_ratio(-1),
        lambda: c.run_program(1, speed_ratio=0),
        lambda: c.run_program(1, mode=7),  # type: ignore[arg-type]
        lambda: c.go_zero(11),
        lambda: c.set_work_mode(3),  # type: ignore[arg-type]
        lambda: c.write_register(440, 70000),
    ]
    for call in bad:
        with pytest.raises(InvalidInput):
            call()
    assert sim.requests_count == before and sim.writes == []


def test_monitor_only_makes_no_writes(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim, monitor_only=True)
    before = sim.requests_count
    ops: list[Any] = [
        lambda: c.step(StepFrame.BASE, [1, 0, 0, 0, 0, 0]),
        lambda: c.create_point(1),
        lambda: c.upload_points([(1, [0.0] * 6)]),
        lambda: c.move_to_point(1),
        lambda: c.teach_enable(TeachFrame.BASE, 0, 1),
        lambda: c.teach_set_ratio(10),
        lambda: c.teach_set_axis(1, 1),
        lambda: c.teach_disable(),
        lambda: c.set_work_mode(WorkMode.AUTO),
        lambda: c.ensure_auto(),
        c.stop,
        c.pause,
        c.resume,
        lambda: c.go_zero(None),
        lambda: c.run_program(1),
        lambda: c.write_gv(0, [1.0]),
        lambda: c.write_register(0, 1),
        lambda: c.write_registers(0, [1]),
    ]
    for op in ops:
        with pytest.raises(WriteBlocked, match="monitor-only"):
            op()
    assert sim.writes == [] and sim.requests_count == before
    assert c.read_pose() is not None  # reads still work


# --- link errors --------------------------------------------------------------------------


def test_modbus_exception_is_readable(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, range(440, 441))
    with pytest.raises(ModbusExceptionError) as info:
        c.teach_disable()
    assert str(info.value) == "controller refused write to register 440 (GV220_L): illegal data address"
    assert info.value.function_code == FC06 and info.value.exception_code == 2
    sim.set_exception(ExcCodes.DEVICE_BUSY, range(560, 584))
    with pytest.raises(
        ModbusExceptionError,
        match=r"read of registers 560\.\.583 \(GV280\.\.GV291\): "
        "server device busy",
    ):
        c.read_status()
    sim.set_exception(None)
    c.read_status()


def test_silent_controller_times_out(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim, timeout=0.2)
    sim.set_silent(True)
    with pytest.raises(ResponseTimeout) as info:
        c.read_status()
    assert str(info.value) == f"controller did not answer within 0.2 s (127.0.0.1:{sim.port})"
    sim.set_silent(False)
    # this read must be answered: a roomy timeout (a loaded test process can hold the answer 0.2 s)
    assert c.read_status(timeout=2.0).mode is ControllerMode.AUTO
    stats = c.stats
    assert (stats.requests, stats.answers, stats.timeouts, stats.resyncs, stats.reconnects) == (2, 1, 1, 1, 1)
    assert stats.last_error == str(info.value)


def test_dead_server_then_reconnect(sim_factory: Any, make_client: MakeClient) -> None:
    sim = sim_factory(command_latency=SCAN)
    port = sim.port
    c = make_client(sim, timeout=2.0)  # roomy: the dead server refuses at once, the live one must answer
    c.create_point(1)  # GV245 written and cached
    sim.stop()
    with pytest.raises(LinkError):
        c.read_status()
    with pytest.raises(
        LinkError,
        match=rf"^cannot reconnect to the controller at 127\.0\.0\.1:{port} "
        r"\(the link was lost\): connection refused$",
    ):
        c.read_status()
    assert not c.connected
    sim2 = sim_factory(port=port, command_latency=SCAN)
    assert c.read_status().mode is ControllerMode.AUTO  # reconnects by itself
    assert c.connected
    c.create_point(1)
    assert (FC10, 490, 2) in wire(sim2)  # the tool cache was dropped with the link


def test_dropped_connection(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    c.read_status()
    assert sim.drop_connections() == 1
    try:
        c.read_status()
    except LinkError:
        pass  # the first request may notice the closed socket
    assert c.read_status().mode is ControllerMode.AUTO


def test_connect_failure(make_client: MakeClient) -> None:
    class Dead:
        port = 1
        config = type("C", (), {"framer": "socket", "word_order": WordOrder.LOW_FIRST})

    c = make_client(Dead(), connect=False, timeout=0.3)
    with pytest.raises(
        LinkError,
        match=r"^cannot connect to the controller at 127\.0\.0\.1:1: "
        r"connection refused$",
    ):
        c.connect()


# --- observability ---------------------------------------------------------------------------


def test_observer_sees_the_seed_frames(sim: Any, make_client: MakeClient) -> None:
    c = make_client(sim)
    records: list[TrafficRecord] = []
    c.add_observer(records.append)
    c.write_gv(200, [30.0])
    tx, rx = records
    assert (tx.direction, rx.direction) == ("tx", "rx") and tx.transport == "tcp"
    assert tx.frame[2:6] == bytes.fromhex("0000 000B")  # protocol 0, length 11
    assert tx.frame[6:] == bytes.fromhex("01 10 01 90 00 02 04 00 00 41 F0")
    assert rx.frame[:2] == tx.frame[:2]  # same transaction id
    assert rx.frame[2:] == bytes.fromhex("0000 0006 01 10 01 90 00 02")
    records.clear()
    c.read_status()
    assert len(records) == 2 and len(records[1].frame) == 7 + 2 + 48
    c.remove_observer(records.append)
    records.clear()

    def boom(*args: object) -> None:
        raise AssertionError("a record was built with nobody observing")

    c._transport._emit = boom  # type: ignore[method-assign,assignment]  # a tripwire, not the real signature
    c.read_status()
    c.write_gv(200, [1.0])
    assert records == []


def test_broken_observer_does_not_break_the_link(
    sim: Any, make_client: MakeClient, caplog: pytest.LogCaptureFixture
) -> None:
    c = make_client(sim)

    def bad(record: TrafficRecord) -> None:
        raise RuntimeError("observer bug")

    c.add_observer(bad)
    assert c.read_status().mode is ControllerMode.AUTO
    assert "traffic observer" in caplog.text


def test_rtu_framing(sim_factory: Any, make_client: MakeClient) -> None:
    sim = sim_factory(framer="rtu", command_latency=SCAN)
    c = make_client(sim, framer="rtu")
    records: list[TrafficRecord] = []
    c.add_observer(records.append)
    assert close(c.read_pose().xyzabc, sim.state().pose, 1e-3)
    tx, rx = records
    assert tx.transport == "rtu"
    assert tx.frame == bytes.fromhex("01 03 019C 0064") + crc16(bytes.fromhex("01 03 019C 0064"))
    assert len(rx.frame) == 3 + 200 + 2 and rx.frame[-2:] == crc16(rx.frame[:-2])
    assert c.create_point(4).ok
    c.step(StepFrame.BASE, [0, 0, 5, 0, 0, 0], speed=200)


def test_client_in_a_thread_while_another_reads(scan_sim: Any, make_client: MakeClient) -> None:
    """Two clients (two links) at once: one moves, the other watches the pose change."""
    mover = make_client(scan_sim)
    watcher = make_client(scan_sim)
    y0 = watcher.read_pose().y
    done = threading.Event()
    errors: list[BaseException] = []

    def move() -> None:
        try:
            mover.step(StepFrame.BASE, [0, 30, 0, 0, 0, 0], speed=100)
        except BaseException as exc:  # reported below
            errors.append(exc)
        finally:
            done.set()

    thread = threading.Thread(target=move)
    thread.start()
    seen = set()
    deadline = time.monotonic() + 30.0  # the step has its own (move) timeout, well under this
    while not done.is_set():
        assert time.monotonic() < deadline, "the step did not end"
        seen.add(round(watcher.read_pose().y, 1))
    join(thread, "the stepping thread")
    assert not errors
    assert len(seen) > 3 and max(seen) == pytest.approx(y0 + 30, abs=0.1)


def test_clients_are_context_managers(sim: Any) -> None:
    from app.connection import ConnectionSettings

    with RobotClient(ConnectionSettings(port=sim.port)) as c:
        assert c.connected
    assert not c.connected


def test_late_answer_is_not_taken_for_the_next_request(sim: Any, make_client: MakeClient) -> None:
    # roomy for the requests that must be answered (a loaded test process can hold an answer
    # 0.1 s); only the pose read has the short timeout its late answer misses
    c = make_client(sim, timeout=2.0)
    c.write_gv(0, [42.0])
    sim.set_response_delay(0.3)
    with pytest.raises(ResponseTimeout):
        c.read_pose(timeout=0.1)  # 100 registers; its answer arrives late
    sim.set_response_delay(0.0)
    assert c.read_gv(0, 1) == [42.0]  # a fresh link, not the late pose frame
    assert c.read_status().mode is ControllerMode.AUTO


def test_settings_are_checked() -> None:
    from app.connection import ConnectionSettings

    for bad in (
        {"port": 0},
        {"unit": 300},
        {"timeout": 0},
        {"framer": "ascii"},
        {"parity": "X"},
        {"point_id_min": 5, "point_id_max": 1},
        {"word_order": "low-first"},
    ):
        with pytest.raises(InvalidInput):
            RobotClient(ConnectionSettings(**bad))
