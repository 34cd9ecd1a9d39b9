"""RobotWorker / RobotLink against the real simulator on a free port (no widgets)."""

from __future__ import annotations

import sys
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import worker as worker_module
from app.client import StepFrame
from app.models import CommandResult, Pose
from app.protocol.enums import Alarm, ControllerMode, ProgramState, TeachFrame, WorkMode
from app.worker import LinkState, RobotLink, WorkerError
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    connection_settings,
    fast_reconnect_fixture,
    gv_writes,
    is_state,
    jogging,
    link_fixture,
    ratio_writes,
    register_writes,
)

pytestmark = pytest.mark.timeout(60)


def _result(predicate: Any) -> Any:
    return lambda result: isinstance(result, CommandResult) and predicate(result)


def test_connect_poll_disconnect(qtbot: Any, sim: Any, link: RobotLink) -> None:
    states: list[LinkState] = []
    link.connectionChanged.connect(lambda s: states.append(s.state))
    with qtbot.waitSignals([link.poseChanged, link.statusChanged], timeout=SIGNAL_TIMEOUT_MS):
        connect(qtbot, link, sim)
    assert states[:2] == [LinkState.CONNECTING, LinkState.CONNECTED]
    assert link.state.endpoint == f"127.0.0.1:{sim.port}"
    with qtbot.waitSignal(link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED),
                          timeout=SIGNAL_TIMEOUT_MS):
        link.disconnect()
    qtbot.waitUntil(lambda: sim.connections_count == 0, timeout=SIGNAL_TIMEOUT_MS)
    assert sim.writes == []  # connecting, polling and disconnecting never write


def test_signals_only_on_change(qtbot: Any, sim: Any, link: RobotLink) -> None:
    with qtbot.waitSignal(link.poseChanged, timeout=SIGNAL_TIMEOUT_MS):
        connect(qtbot, link, sim)
    # The arm stands still: dozens of polls, no new pose.
    with qtbot.assertNotEmitted(link.poseChanged, wait=300):
        pass
    refs_before = sys.getrefcount(True)
    with qtbot.waitSignal(link.alarmsChanged, check_params_cb=lambda a: a == int(Alarm.SERVO),
                          timeout=SIGNAL_TIMEOUT_MS):
        sim.set_alarm(Alarm.SERVO, True)
    assert abs(sys.getrefcount(True) - refs_before) < 50  # the PySide6 6.12 bool refcount bug


def test_live_pose_while_the_simulator_moves(qtbot: Any, sim: Any, link: RobotLink) -> None:
    poses: list[Pose] = []
    link.poseChanged.connect(poses.append)
    connect(qtbot, link, sim)
    start = sim.state().joints[0]
    with qtbot.waitSignal(link.commandFinished, check_params_cb=_result(lambda r: r.ok),
                          timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.step(StepFrame.JOINT, [6.0, 0, 0, 0, 0, 0], speed=10.0)  # 60 deg/s: 0.1 s
    result = blocker.args[0]
    assert "done" in result.message
    assert sim.state().joints[0] == pytest.approx(start + 6.0, abs=1e-6)
    joints = [p.joints[0] for p in poses if p.joints]
    assert len(joints) >= 3  # intermediate poses were seen while moving
    assert joints[-1] == pytest.approx(start + 6.0, abs=1e-3)
    assert any(start + 0.1 < j < start + 5.9 for j in joints)


def test_jog_sequence_as_seen_by_the_simulator(qtbot: Any, sim: Any, link: RobotLink,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    connect(qtbot, link, sim)
    link.jog_press(TeachFrame.BASE, 0, 1, 40.0)
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    state = sim.state()
    assert state.mode == ControllerMode.MODBUS_TEACH and state.teach_ratio == 40.0
    # Frame/axis/direction with ratio 0 in one write, then 0x80, then the ratio.
    params = [i for i, w in enumerate(sim.writes) if w.address == 400 and len(w.values) == 8]
    enables = [i for i, v in register_writes(sim, 440) if v == 0x80]
    ratios = gv_writes(sim, 203)
    assert params and enables and params[0] < enables[0] < ratios[-1][0]
    assert ratios[-1][1] == 40.0

    link.set_jog_ratio(75.0)  # speed changes live while moving
    qtbot.waitUntil(lambda: sim.state().teach_ratio == 75.0, timeout=SIGNAL_TIMEOUT_MS)

    link.jog_release()
    qtbot.waitUntil(lambda: not sim.state().jogging, timeout=SIGNAL_TIMEOUT_MS)
    assert ratio_writes(sim)[-1] == 0.0
    assert sim.state().teach_enabled  # release keeps teach enabled

    # Another axis in the same frame: ratio 0, GV201-202, ratio -- no new enable.
    enables_before = len([v for _, v in register_writes(sim, 440) if v == 0x80])
    link.jog_press(TeachFrame.BASE, 2, 0, 30.0)
    qtbot.waitUntil(lambda: jogging(sim) and sim.state().teach_ratio == 30.0, timeout=SIGNAL_TIMEOUT_MS)
    assert len([v for _, v in register_writes(sim, 440) if v == 0x80]) == enables_before
    link.jog_release()
    qtbot.waitUntil(lambda: not sim.state().jogging, timeout=SIGNAL_TIMEOUT_MS)

    # Another frame: disable (0x81) then enable again.
    link.jog_press(TeachFrame.JOINT, 0, 1, 50.0)
    qtbot.waitUntil(lambda: jogging(sim) and sim.state().teach_frame == int(TeachFrame.JOINT),
                    timeout=SIGNAL_TIMEOUT_MS)
    commands = [v for _, v in register_writes(sim, 440)]
    assert commands[-2:] == [0x81, 0x80]
    link.jog_release()
    qtbot.waitUntil(lambda: not sim.state().jogging, timeout=SIGNAL_TIMEOUT_MS)

    # Idle: teach mode is switched off by itself.
    monkeypatch.setattr(worker_module, "TEACH_IDLE_DISABLE", 0.1)
    qtbot.waitUntil(lambda: not sim.state().teach_enabled, timeout=SIGNAL_TIMEOUT_MS)
    assert [v for _, v in register_writes(sim, 440)][-1] == 0x81


def test_release_cancels_a_press_still_queued(qtbot: Any, sim: Any, link: RobotLink) -> None:
    """Press and release while the worker is busy: the press must never start afterwards."""
    connect(qtbot, link, sim)
    sim.set_response_delay(0.15)
    seen = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count > seen, timeout=SIGNAL_TIMEOUT_MS)  # one in flight
    link.jog_press(TeachFrame.BASE, 0, 1, 50.0)
    link.jog_release()
    sim.set_response_delay(0.0)
    seen = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count > seen + 6, timeout=SIGNAL_TIMEOUT_MS)  # polls go on
    assert sim.writes == [] and not sim.state().teach_enabled


def test_stop_goes_out_before_queued_commands_and_polls(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    link.set_traffic_capture(True)
    frames: list[Any] = []
    link.trafficObserved.connect(frames.extend)
    qtbot.waitUntil(lambda: len(frames) > 4, timeout=SIGNAL_TIMEOUT_MS)
    # Hold the worker inside one slow transaction, queue work behind it, then stop.
    sim.set_response_delay(0.2)
    seen = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count > seen, timeout=SIGNAL_TIMEOUT_MS)
    writes_before = len(sim.writes)
    cancelled: list[CommandResult] = []
    link.commandFinished.connect(lambda r: cancelled.append(r) if "cancelled" in r.message else None)
    link.go_zero(0)
    link.go_zero(1)
    link.run_program(1)
    link.step(StepFrame.JOINT, [1.0, 0, 0, 0, 0, 0])
    link.stop()
    qtbot.waitUntil(lambda: len(cancelled) == 4, timeout=SIGNAL_TIMEOUT_MS)
    sim.set_response_delay(0.0)
    writes = sim.writes[writes_before:]
    assert [w.address for w in writes] == [441]  # the stop, and nothing that was queued
    # On the wire: the first request sent after the one in flight is the stop.
    qtbot.waitUntil(lambda: any(f.frame[7] == 0x06 for f in frames if f.direction == "tx"),
                    timeout=SIGNAL_TIMEOUT_MS)
    tx = [f for f in frames if f.direction == "tx"]
    stop_index = next(i for i, f in enumerate(tx) if f.frame[7] == 0x06)
    assert int.from_bytes(tx[stop_index].frame[8:10], "big") == 441
    in_flight_and_after = tx[stop_index - 1:]
    assert all(f.frame[7] == 0x03 for f in in_flight_and_after[:1])


def test_pause_resume_reach_the_simulator(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    link.run_program(2)  # the joint wiggle
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    link.pause()
    qtbot.waitUntil(lambda: sim.state().paused, timeout=SIGNAL_TIMEOUT_MS)
    link.resume()
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(link.commandFinished, check_params_cb=_result(lambda r: "stopped" in r.message),
                          timeout=SIGNAL_TIMEOUT_MS):
        link.stop()
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.STOPPED, timeout=SIGNAL_TIMEOUT_MS)


def test_monitor_only_never_writes(qtbot: Any, sim: Any, link: RobotLink) -> None:
    errors: list[WorkerError] = []
    link.errorOccurred.connect(errors.append)
    connect(qtbot, link, sim, monitor_only=True)
    assert link.state.monitor_only
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS):
        link.jog_press(TeachFrame.BASE, 0, 1, 50.0)
    link.jog_release()  # (a release right after a press would drop the press unsent)
    link.step(StepFrame.BASE, [1.0, 0, 0, 0, 0, 0])
    link.go_zero(None)
    link.set_mode(WorkMode.MANUAL)
    link.stop()
    qtbot.waitUntil(lambda: len(errors) >= 5, timeout=SIGNAL_TIMEOUT_MS)
    assert all("monitor-only" in e.message for e in errors)
    link.shutdown()
    assert sim.writes == []


def test_link_loss_then_reconnect_stops_the_jog_first(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    link.jog_press(TeachFrame.JOINT, 0, 1, 20.0)
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(link.connectionChanged, check_params_cb=is_state(LinkState.DOWN),
                          timeout=SIGNAL_TIMEOUT_MS):
        sim.set_silent(True)
    assert jogging(sim)  # like a real controller, the simulator keeps going without its master
    writes_before = len(sim.writes)
    with qtbot.waitSignal(link.controllerReconnected, timeout=SIGNAL_TIMEOUT_MS):
        sim.set_silent(False)
    assert not sim.state().jogging and not sim.state().teach_enabled
    after = sim.writes[writes_before:]
    disable = next(i for i, w in enumerate(after) if w.address == 440)
    assert after[disable].values == (0x81,)  # teach disable ...
    assert disable >= 1  # ... after ratio 0, and nothing else before
    assert all(w.address == 406 and w.values == (0, 0) for w in after[:disable])
    assert link.state.state is LinkState.CONNECTED


def test_dropped_connections_recover(qtbot: Any, sim: Any, link: RobotLink) -> None:
    """One lost socket is one failed poll (reported once), not a link loss; the next poll reconnects."""
    connect(qtbot, link, sim)
    states: list[LinkState] = []
    link.connectionChanged.connect(lambda s: states.append(s.state))
    with qtbot.waitSignal(link.errorOccurred, check_params_cb=lambda e: e.operation == "poll",
                          timeout=SIGNAL_TIMEOUT_MS):
        assert sim.drop_connections() == 1
    qtbot.waitUntil(lambda: sim.connections_count == 1, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(link.commandFinished, check_params_cb=_result(lambda r: r.ok),
                          timeout=SIGNAL_TIMEOUT_MS):
        link.step(StepFrame.JOINT, [0, 0, 0, 2.0, 0, 0], speed=10.0)
    assert states == []


def test_refusals_and_exceptions_are_results(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    sim.set_alarm(Alarm.ESTOP, True)
    with qtbot.waitSignal(link.commandFinished, check_params_cb=_result(lambda r: not r.ok),
                          timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.jog_press(TeachFrame.BASE, 0, 1, 10.0)
    assert "emergency stop" in blocker.args[0].message
    sim.set_alarm(Alarm.ESTOP, False)
    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, range(445, 446))
    with qtbot.waitSignal(link.commandFinished, check_params_cb=_result(lambda r: not r.ok),
                          timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.go_zero(3)
    assert "illegal data address" in blocker.args[0].message
    sim.set_exception(None)
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.step(StepFrame.JOINT, [0, 0, 0, 0, 0, 0])
    error = blocker.args[0]
    assert error.operation == "step" and "zero" in error.message and "Traceback" not in error.message


def test_commands_while_disconnected_are_errors(qtbot: Any, link: RobotLink) -> None:
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.stop()
    assert blocker.args[0] == WorkerError("stop", "not connected to a controller")


def test_unreachable_controller_goes_down_and_shuts_down_cleanly(qtbot: Any, sim_factory: Any,
                                                                 link: RobotLink) -> None:
    sim = sim_factory()
    port = sim.port
    sim.stop()
    with qtbot.waitSignal(link.connectionChanged, check_params_cb=is_state(LinkState.DOWN),
                          timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.connect_to(connection_settings(sim, port=port))
    assert str(port) in blocker.args[0].message
    link.shutdown()  # while retrying: returns promptly, no thread left running
    assert not link.is_running


def test_points_create_upload_and_move(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    pose = sim.state().pose
    with qtbot.waitSignal(link.commandFinished, check_params_cb=_result(lambda r: r.ok),
                          timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.create_point(7)
    details = blocker.args[0].details
    assert details["x"] == pytest.approx(pose[0], abs=1e-3) and 7 in sim.state().points
    target = (pose[0], pose[1] + 40.0, pose[2], pose[3], pose[4], pose[5])
    progress: list[tuple[int, int]] = []
    link.uploadProgress.connect(lambda done, total: progress.append((done, total)))
    with qtbot.waitSignal(link.commandFinished, check_params_cb=_result(lambda r: "uploaded" in r.message),
                          timeout=SIGNAL_TIMEOUT_MS) as blocker:
        link.upload_points([(8, target), (9, pose)])
    assert blocker.args[0].ok and blocker.args[0].message == "uploaded 2 of 2 points"
    assert progress == [(1, 2), (2, 2)] and sim.state().points[8] == pytest.approx(target)
    with qtbot.waitSignal(link.commandFinished, check_params_cb=_result(lambda r: r.ok),
                          timeout=SIGNAL_TIMEOUT_MS):
        link.move_to_point(8, speed=400.0)
    assert sim.state().pose[1] == pytest.approx(target[1], abs=1e-3)
