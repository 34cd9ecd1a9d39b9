"""The whole teach -> ledger -> restore -> run workflow against the real simulator over TCP.

Each test drives the product's own pieces (RobotClient, PointLedger, staged_upload /
apply_upload, check_plan, PlanRunner) the way the GUI worker or the CLI does, and checks the
result on the simulated controller itself (``sim.state()``, ``sim.trajectory()``,
``sim.writes``). Speeds are high and distances short so the file runs in a few seconds.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from app.errors import CommandRefused, CommandStopped, CommandTimeout
from app.link.client import RobotClient
from app.link.types import StepFrame
from app.plan.checks import check_plan, has_errors, ids_needing_upload
from app.plan.geometry import arc_geometry, plan_path
from app.plan.runner import PlanRunner, RunEvent, RunProgress, RunState
from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger
from app.points.point import SyncState, point_from_pose
from app.protocol import registers
from app.protocol.enums import ProgramState
from tests.integration.support import (
    ARC_CENTRE,
    ARC_END_DEG,
    ARC_NORMAL,
    ARC_RADIUS,
    ARC_SPEED,
    ARC_U,
    ARC_V,
    ARC_VIA_DEG,
    LINE_POINTS,
    P1,
    P2,
    P3,
    WAIT,
    Background,
    MakeClient,
    along,
    arc_point,
    assert_controller_holds,
    assert_pose_at,
    control_writes,
    held_points,
    ledger_of,
    move_commands,
    restore,
    wait_sim_time,
)

# --------------------------------------------------------------------------------------------
# teach -> ledger -> restart -> unknown -> restore -> run
# --------------------------------------------------------------------------------------------

# (id, name, base-frame step from the previous taught place: X Y Z mm)
TEACH_STEPS = (
    (1, "ring S", (0.0, -60.0, -54.4)),
    (2, "ring E", (60.0, 60.0, 0.0)),
    (3, "ring N", (-60.0, 60.0, 0.0)),
    (4, "ring W", (-60.0, -60.0, 0.0)),
    (5, "centre low", (60.0, 0.0, -30.0)),
)


def test_teach_restart_restore_and_run_lines_and_arcs(sim: Any, make_client: MakeClient) -> None:
    client = make_client(sim)
    ledger = PointLedger()
    # Teach: step the arm to each place (function 1), create the temp point from the current
    # pose (function 2) and keep the host's copy of what was taught.
    for point_id, name, xyz in TEACH_STEPS:
        assert client.step(StepFrame.BASE, (*xyz, 0.0, 0.0, 0.0), speed=500.0).ok
        assert client.create_point(point_id).ok
        ledger.append(point_from_pose(point_id, client.read_pose(), name))
        ledger.set_sync(point_id, SyncState.ON_CONTROLLER)
    assert_controller_holds(sim, ledger)
    assert_pose_at(sim.state().pose, ledger.point(5).xyzabc, "the arm after teaching")

    # The controller's system logs in again: every temp point is gone.
    sim.restart_controller()
    assert held_points(sim) == {}
    assert ledger.mark_all_unknown() == list(range(len(ledger)))
    assert {p.sync for p in ledger} == {SyncState.UNKNOWN}

    plan = Plan(
        "ring",
        [
            Segment.line(1, speed=500.0),
            Segment.arc(2, 3, speed=300.0),
            Segment.arc(4, 1, speed=300.0),
            Segment.line(5, speed=500.0),
        ],
    )
    issues = check_plan(plan, ledger, current_pose=client.read_pose())
    assert not has_errors(issues), issues
    assert ids_needing_upload(issues) == [1, 2, 3, 4, 5]

    restore(client, ledger)
    assert_controller_holds(sim, ledger)
    assert check_plan(plan, ledger, current_pose=client.read_pose()) == []

    events: list[RunProgress] = []
    outcome = PlanRunner(plan, progress=events.append).run(client)
    assert outcome.ok, outcome.message
    assert outcome.segments_done == 4 and outcome.resume_from is None
    assert move_commands(sim) == 4
    assert [(e.event, e.index) for e in events] == [
        *((ev, i) for i in range(4) for ev in (RunEvent.SEGMENT_STARTED, RunEvent.SEGMENT_DONE)),
        (RunEvent.FINISHED, 3),
    ]
    final = sim.state()
    assert not final.moving and final.program_state is ProgramState.STOPPED
    assert_pose_at(final.pose, ledger.point(5).xyzabc, "the simulator's final pose")
    assert_pose_at(client.read_pose().xyzabc, ledger.point(5).xyzabc, "the pose the host reads")


# --------------------------------------------------------------------------------------------
# the arc: through the middle point, on the circle
# --------------------------------------------------------------------------------------------


def test_arc_passes_through_the_middle_point_on_the_circle(sim: Any, make_client: MakeClient) -> None:
    client = make_client(sim)
    start, via, end = arc_point(0.0), arc_point(ARC_VIA_DEG), arc_point(ARC_END_DEG)
    ledger = ledger_of({11: start, 12: via, 13: end})
    restore(client, ledger)
    plan = Plan("arc", [Segment.line(11, speed=500.0), Segment.arc(12, 13, speed=ARC_SPEED)])
    home = client.read_pose()

    # Step-wise API (the GUI worker's): take each command, send it, report its result.
    runner = PlanRunner(plan)
    traces: dict[int, list[Any]] = {}
    while (cmd := runner.next_command()) is not None:
        result = cmd.send(client)
        traces[cmd.index] = sim.trajectory()  # the samples of this segment's motion
        runner.on_result(result)
    assert runner.state is RunState.FINISHED

    xyz = np.array([s.pose[:3] for s in traces[1]])
    assert len(xyz) > 100, "too few trajectory samples to judge the arc"
    assert_pose_at(traces[1][0].pose, start, "the arc's first sample")
    assert_pose_at(traces[1][-1].pose, end, "the arc's last sample")
    assert_pose_at(sim.state().pose, end, "the final pose")

    # through the middle point
    to_via = np.linalg.norm(xyz - np.array(via[:3]), axis=1)
    assert to_via.min() < 1.0, f"the arc passes {to_via.min():.3f} mm from the middle point"
    # on the circle through the three points, in its plane, every sample
    rel = xyz - ARC_CENTRE
    radial = np.abs(np.linalg.norm(rel, axis=1) - ARC_RADIUS)
    off_plane = np.abs(rel @ ARC_NORMAL)
    assert radial.max() < 0.1, f"a sample is {radial.max():.3f} mm off the circle"
    assert off_plane.max() < 0.1, f"a sample is {off_plane.max():.3f} mm off the circle's plane"
    # travelled start -> middle -> end: the angle about the centre only grows, 0 .. 140 degrees
    angles = np.degrees(np.unwrap(np.arctan2(rel @ ARC_V, rel @ ARC_U)))
    assert np.all(np.diff(angles) > -1e-6), "the arc went backwards"
    assert abs(angles[0]) < 0.2 and abs(angles[-1] - ARC_END_DEG) < 0.2
    nearest = int(np.argmin(to_via))
    assert 0 < nearest < len(xyz) - 1 and abs(angles[nearest] - ARC_VIA_DEG) < 2.0

    # The host's preview draws the same circle the controller moved along.
    geo = arc_geometry(np.array([start[:3]]), np.array([via[:3]]), np.array([end[:3]]))
    assert np.allclose(geo.centre[0], ARC_CENTRE, atol=1e-6) and abs(geo.radius[0] - ARC_RADIUS) < 1e-6
    path = plan_path(plan, ledger, start=home)
    preview = path.xyz[path.segment == 1]
    assert np.abs(np.linalg.norm(preview - ARC_CENTRE, axis=1) - ARC_RADIUS).max() < 1e-6
    assert np.linalg.norm(preview - np.array(via[:3]), axis=1).min() < 1e-9


# --------------------------------------------------------------------------------------------
# pause / resume / stop
# --------------------------------------------------------------------------------------------

LINE_PLAN = Plan(
    "lines", [Segment.line(1, speed=300.0), Segment.line(2, speed=150.0), Segment.line(3, speed=150.0)]
)


def test_pause_resume_and_stop_a_blocking_run(sim: Any, make_client: MakeClient) -> None:
    """The blocking runner in its own thread; pause / resume / stop come from a second link
    (as ``teachpad-cli pause`` would while ``teachpad-cli run`` is running)."""
    worker, control = make_client(sim), make_client(sim)
    ledger = ledger_of(LINE_POINTS)
    restore(worker, ledger)
    runner = PlanRunner(LINE_PLAN)
    run = Background(lambda: runner.run(worker))

    def on_segment(index: int, a: tuple[float, ...], b: tuple[float, ...]) -> Any:
        def mid_way(s: Any) -> bool:
            cmd = runner.current
            return cmd is not None and cmd.index == index and s.moving and 0.15 < along(s.pose, a, b) < 0.6

        return mid_way

    # pause mid-segment 2: the arm freezes, the run waits
    assert sim.wait_for(on_segment(1, P1, P2), WAIT), "segment 2 never got under way"
    control.pause()
    assert sim.wait_for(lambda s: s.paused and s.program_state is ProgramState.PAUSED, WAIT)
    frozen = sim.state().pose
    wait_sim_time(sim, 0.3)
    paused = sim.state()
    assert paused.pose == frozen and paused.paused, "the arm moved while paused"
    assert run.alive and runner.state is RunState.RUNNING and runner.segments_done == 1

    # resume: the same move carries on
    control.resume()
    assert sim.wait_for(lambda s: not s.paused and s.moving and math.dist(s.pose[:3], frozen[:3]) > 1.0, WAIT)

    # stop mid-segment 3: the arm stops short of P3 and the run ends STOPPED there
    assert sim.wait_for(on_segment(2, P2, P3), WAIT), "segment 3 never got under way"
    runner.request_stop()
    control.stop()
    assert sim.wait_for(lambda s: not s.moving and s.program_state is ProgramState.STOPPED, WAIT)
    outcome = run.result()
    assert outcome.state is RunState.STOPPED, outcome.message
    assert outcome.resume_from == 2 and outcome.segments_done == 2
    assert isinstance(outcome.error, CommandStopped)
    stopped_at = sim.state().pose
    assert 0.15 < along(stopped_at, P2, P3) < 0.95
    wait_sim_time(sim, 0.2)
    assert sim.state().pose == stopped_at, "the arm moved after the stop"

    # the controller received exactly one pause, one resume, one stop (0x06 writes), in order
    pauses, resumes, stops = (
        control_writes(sim, r) for r in (registers.REG_PAUSE, registers.REG_RESUME, registers.REG_STOP)
    )
    assert (len(pauses), len(resumes), len(stops)) == (1, 1, 1)
    assert pauses[0].t < resumes[0].t < stops[0].t
    assert move_commands(sim) == 3

    # resume the run: segment 3 again, from where the arm stopped, to P3
    runner.resume()
    outcome = runner.run(worker)
    assert outcome.ok, outcome.message
    assert move_commands(sim) == 4
    assert_pose_at(sim.state().pose, P3, "the final pose")


def test_pause_resume_stop_with_the_step_wise_api(sim: Any, make_client: MakeClient) -> None:
    """One client, one thread, never blocking: the GUI worker's way (begin, poll, report)."""
    client = make_client(sim)
    ledger = ledger_of(LINE_POINTS)
    restore(client, ledger)
    runner = PlanRunner(LINE_PLAN)

    cmd = runner.next_command()
    assert cmd is not None and cmd.index == 0
    runner.on_result(cmd.send(client))  # segment 1 to the end

    cmd = runner.next_command()
    assert cmd is not None and cmd.index == 1
    cmd.send(client, wait=False)
    tracker = client.last_tracker
    assert tracker is not None

    def poll_until(condition: Any) -> None:
        """Keep polling the command (as the worker's timer does) until the simulator shows
        ``condition``; the command must stay under way the whole time."""

        def check(s: Any) -> bool:
            result = client.poll(tracker)
            assert result is None, f"the move ended early: {result}"
            return bool(condition(s))

        assert sim.wait_for(check, WAIT)

    poll_until(lambda s: s.moving and 0.15 < along(s.pose, P1, P2) < 0.5)
    client.pause()
    poll_until(lambda s: s.paused)
    frozen = sim.state().pose
    start_t = sim.state().t
    poll_until(lambda s: s.t >= start_t + 0.3)  # a paused move is neither done nor stopped
    assert sim.state().pose == frozen
    client.resume()
    poll_until(lambda s: math.dist(s.pose[:3], frozen[:3]) > 1.0)
    client.stop()  # the host's own stop ends its wait at once
    assert tracker.finished and isinstance(tracker.error, CommandStopped)
    runner.on_stopped()
    assert sim.wait_for(lambda s: not s.moving, WAIT)
    stopped_at = sim.state().pose
    assert 0.15 < along(stopped_at, P1, P2) < 0.95
    outcome = runner.outcome()
    assert outcome.state is RunState.STOPPED and outcome.resume_from == 1 and outcome.segments_done == 1
    for register in (registers.REG_PAUSE, registers.REG_RESUME, registers.REG_STOP):
        assert len(control_writes(sim, register)) == 1

    runner.resume()
    while (cmd := runner.next_command()) is not None:
        runner.on_result(cmd.send(client))
    assert runner.state is RunState.FINISHED and runner.segments_done == 3
    assert move_commands(sim) == 4  # segment 2 was sent again
    assert_pose_at(sim.state().pose, P3, "the final pose")


# --------------------------------------------------------------------------------------------
# a killed controller, and a refused segment
# --------------------------------------------------------------------------------------------


def test_killed_simulator_stops_the_run_and_resume_finishes(
    sim_factory: Any, make_client: MakeClient
) -> None:
    first = sim_factory()
    port = first.port
    client = make_client(first)
    ledger = ledger_of(LINE_POINTS)
    restore(client, ledger)
    runner = PlanRunner(LINE_PLAN)
    run = Background(lambda: runner.run(client))

    def mid_segment_2(s: Any) -> bool:
        cmd = runner.current
        return cmd is not None and cmd.index == 1 and s.moving and 0.15 < along(s.pose, P1, P2) < 0.6

    assert first.wait_for(mid_segment_2, WAIT), "segment 2 never got under way"
    first.stop()  # the controller dies mid-move
    outcome = run.result()
    assert outcome.state is RunState.FAILED
    assert outcome.resume_from == 1 and outcome.resume_loop == 1 and outcome.segments_done == 1
    # taken, then the link went: what the move did is unknown (the cause says why; the runner
    # adds that its stop failed too)
    assert isinstance(outcome.error, CommandTimeout), repr(outcome.error)
    assert "the outcome is unknown" in outcome.message and "connection refused" in outcome.message
    assert outcome.message.startswith("segment 2/3")
    assert f"127.0.0.1:{port}" in outcome.message  # names the controller that went away

    # A new controller on the same port knows no points: the host restores them and resumes.
    second = sim_factory(port=port)
    assert second.port == port and held_points(second) == {}
    ledger.mark_all_unknown()
    restore(client, ledger)  # the client reconnects by itself
    assert_controller_holds(second, ledger)
    runner.resume()
    outcome = runner.run(client)
    assert outcome.ok, outcome.message
    assert outcome.segments_done == 3
    assert move_commands(second) == 2  # segments 2 and 3 only
    assert_pose_at(second.state().pose, P3, "the final pose")


def test_point_lost_on_the_controller_fails_that_segment_with_the_reason(
    sim: Any, make_client: MakeClient
) -> None:
    client = make_client(sim)
    ledger = ledger_of(LINE_POINTS)
    restore(client, ledger)
    events: list[RunProgress] = []
    restarted: list[bool] = []

    def progress(p: RunProgress) -> None:
        events.append(p)
        if p.event is RunEvent.SEGMENT_STARTED and p.index == 1 and not restarted:
            restarted.append(True)
            sim.restart_controller()  # the controller forgets P2 just before segment 2 is sent

    runner = PlanRunner(LINE_PLAN, progress=progress)
    outcome = runner.run(client)
    assert outcome.state is RunState.FAILED
    assert outcome.resume_from == 1 and outcome.segments_done == 1
    assert isinstance(outcome.error, CommandRefused)
    assert outcome.error.status.code == 13
    assert outcome.message.startswith("segment 2/3") and "bad end point id" in outcome.message
    assert events[-1].event is RunEvent.FAILED and events[-1].index == 1
    assert move_commands(sim) == 2  # segment 2 was sent and refused; segment 3 never was
    state = sim.state()
    assert not state.moving
    assert_pose_at(state.pose, P1, "the arm after the refused segment")  # still where segment 1 ended

    ledger.mark_all_unknown()
    restore(client, ledger)
    runner.resume()
    outcome = runner.run(client)
    assert outcome.ok, outcome.message
    assert_pose_at(sim.state().pose, P3, "the final pose")


def test_client_reads_the_same_final_pose_as_the_simulator(sim: Any, make_client: MakeClient) -> None:
    """The run's end as the host sees it (GV206..211, float32) equals the simulator's truth."""
    client: RobotClient = make_client(sim)
    ledger = ledger_of(LINE_POINTS)
    restore(client, ledger)
    outcome = PlanRunner(Plan("one", [Segment.line(3, speed=500.0)])).run(client)
    assert outcome.ok, outcome.message
    host = client.read_pose()
    truth = sim.state()
    assert_pose_at(host.xyzabc, truth.pose, "the host's pose")
    assert host.joints is not None
    assert all(abs(a - b) < 1e-3 for a, b in zip(host.joints, truth.joints[:6], strict=True))
