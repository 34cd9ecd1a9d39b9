"""PlanRunner sequencing and resume logic, against a scripted fake client (no I/O, no sleeps)."""

from __future__ import annotations

import pytest

from app.errors import AlarmRaised, CommandRefused, CommandStopped, CommandTimeout, InvalidInput, LinkError
from app.models import CommandResult
from app.plan.runner import PlanRunner, RunEvent, RunProgress, RunState
from app.plan.segments import Plan, Segment
from app.points.guard import PointGuard, PointMismatch, PointNotCreated
from app.points.point import TempPoint, make_point
from app.protocol.enums import CommandKind, CommandStatus
from tests.fakes import DONE, FakeClient, failed


def plan(loops: int = 1) -> Plan:
    return Plan(
        "p",
        [
            Segment.line(1, 100),
            Segment.arc(2, 3, 50, orientation_changes=False, ignore_middle=True, tool=4),
            Segment.line(4, 25),
            Segment.line(5, 10),
        ],
        loops,
    )


def ends(client: FakeClient) -> list[int]:
    return [m["end"] for m in client.moves]


class Recorder:
    def __init__(self) -> None:
        self.events: list[RunProgress] = []

    def __call__(self, p: RunProgress) -> None:
        self.events.append(p)

    def short(self) -> list[tuple[str, int, int]]:
        names = {
            RunEvent.SEGMENT_STARTED: "start",
            RunEvent.SEGMENT_DONE: "done",
            RunEvent.FINISHED: "finished",
            RunEvent.STOPPED: "stopped",
            RunEvent.FAILED: "failed",
        }
        return [(names[e.event], e.index, e.loop) for e in self.events]


def test_runs_all_segments_in_order_with_their_parameters() -> None:
    client, rec = FakeClient(), Recorder()
    runner = PlanRunner(plan(), timeouts=[10.0, 20.0, None, 5.0], progress=rec)
    outcome = runner.run(client)
    assert outcome.ok and outcome.state is RunState.FINISHED and outcome.segments_done == 4
    assert outcome.resume_from is None and outcome.next_position is None
    assert ends(client) == [1, 3, 4, 5]
    assert client.moves[1] == {
        "end": 3,
        "via": 2,
        "orientation_changes": False,
        "ignore_middle": True,
        "speed": 50.0,
        "tool": 4,
        "wait": True,
        "timeout": 20.0,
    }
    assert client.moves[0]["via"] is None and client.moves[2]["timeout"] is None
    assert rec.short() == [
        ("start", 0, 1),
        ("done", 0, 1),
        ("start", 1, 1),
        ("done", 1, 1),
        ("start", 2, 1),
        ("done", 2, 1),
        ("start", 3, 1),
        ("done", 3, 1),
        ("finished", 3, 1),
    ]
    assert rec.events[2].text == "loop 1/1, segment 2/4" and rec.events[2].count == 4
    assert rec.events[2].message == "arc via P2 to P3, 50 mm/s"
    assert client.stops == 0


def test_loops_and_progress_order() -> None:
    client, rec = FakeClient(), Recorder()
    outcome = PlanRunner(plan(loops=3), progress=rec).run(client)
    assert outcome.ok and outcome.segments_done == 12
    assert ends(client) == [1, 3, 4, 5] * 3
    starts = [(i, loop) for kind, i, loop in rec.short() if kind == "start"]
    assert starts == [(i, loop) for loop in (1, 2, 3) for i in range(4)]
    assert rec.short()[-1] == ("finished", 3, 3)
    assert PlanRunner(plan(loops=3), loops=1).run(FakeClient()).segments_done == 4


@pytest.mark.parametrize(
    ("error", "text"),
    [
        (CommandRefused(CommandStatus(CommandKind.MOVE, 13)), "bad end point id"),
        (AlarmRaised(1, "emergency stop"), "emergency stop"),
        (LinkError("connection lost"), "connection lost"),
    ],
)
def test_error_at_segment_k_stops_with_resume_from_k_and_resume_finishes(error: Exception, text: str) -> None:
    client, rec = FakeClient(move_script={2: error}), Recorder()
    runner = PlanRunner(plan(), progress=rec)
    outcome = runner.run(client)
    assert outcome.state is RunState.FAILED and not outcome.ok
    assert (outcome.resume_from, outcome.resume_loop) == (2, 1)
    assert outcome.error is error and outcome.segments_done == 2
    assert outcome.message.startswith("segment 3/4 (loop 1/1): ") and text in outcome.message
    assert ends(client) == [1, 3, 4]
    assert rec.short()[-2:] == [("start", 2, 1), ("failed", 2, 1)]
    assert runner.next_command() is None  # over until resumed

    runner.resume()
    outcome = runner.run(client)
    assert outcome.ok and outcome.segments_done == 4
    assert ends(client) == [1, 3, 4, 4, 5]  # segment 3 again, then 4
    assert client.stops == 0


def test_failed_result_without_exception() -> None:
    client = FakeClient(move_script={1: failed(12, "motion timeout")})
    outcome = PlanRunner(plan()).run(client)
    assert outcome.state is RunState.FAILED and outcome.resume_from == 1
    assert outcome.message.endswith("motion timeout")
    outcome = PlanRunner(plan()).run(FakeClient(move_script={0: failed(3)}))
    assert outcome.message.endswith("servo alarm")


def test_error_in_a_later_loop_records_the_loop_and_resume_continues_there() -> None:
    client = FakeClient(move_script={5: LinkError("gone")})  # call 5 = segment index 1 of loop 2
    runner = PlanRunner(plan(loops=2))
    outcome = runner.run(client)
    assert (outcome.resume_from, outcome.resume_loop) == (1, 2)
    assert "segment 2/4 (loop 2/2)" in outcome.message
    # the CLI resumes with a new runner (run-from-here)
    again = FakeClient()
    outcome = PlanRunner(plan(loops=2), start=1, start_loop=2).run(again)
    assert outcome.ok and ends(again) == [3, 4, 5]


def test_timeout_halts_the_robot() -> None:
    client = FakeClient(move_script={1: CommandTimeout("no completion after 10 s")})
    outcome = PlanRunner(plan()).run(client)
    assert client.stops == 1 and outcome.state is RunState.FAILED and outcome.resume_from == 1


def test_timeout_when_the_stop_fails_too() -> None:
    class DeadLink(FakeClient):
        def stop(self) -> None:
            raise LinkError("not connected")

    outcome = PlanRunner(plan()).run(DeadLink(move_script={0: CommandTimeout("no completion")}))
    assert "no completion; the stop command failed too: not connected" in outcome.message


def test_stop_request_between_segments() -> None:
    client = FakeClient()
    runner = PlanRunner(plan())
    client.move_script = {1: lambda: runner.request_stop()}  # requested while segment 2 runs
    outcome = runner.run(client)
    assert outcome.state is RunState.STOPPED and ends(client) == [1, 3]
    assert (outcome.resume_from, outcome.resume_loop) == (2, 1)  # segment 2 finished normally
    assert outcome.message == "stopped on request before segment 3"
    runner.resume()
    assert runner.run(client).ok and ends(client) == [1, 3, 4, 5]


def test_stop_from_the_progress_callback() -> None:
    client = FakeClient()
    runner: PlanRunner

    def progress(p: RunProgress) -> None:
        if p.event is RunEvent.SEGMENT_DONE and p.index == 0:
            runner.request_stop()

    runner = PlanRunner(plan(), progress=progress)
    assert runner.run(client).resume_from == 1 and ends(client) == [1]


def test_motion_stopped_mid_segment_resumes_that_segment() -> None:
    client = FakeClient(move_script={2: CommandStopped("stopped by the controller")})
    runner = PlanRunner(plan())
    outcome = runner.run(client)
    assert outcome.state is RunState.STOPPED and outcome.resume_from == 2


def test_ctrl_c_stops_the_controller() -> None:
    client = FakeClient(move_script={1: KeyboardInterrupt()})
    outcome = PlanRunner(plan()).run(client)
    assert client.stops == 1
    assert outcome.state is RunState.STOPPED and outcome.resume_from == 1
    assert "interrupted (Ctrl-C)" in outcome.message


def test_unexpected_exception_halts_and_propagates() -> None:
    client = FakeClient(move_script={0: ZeroDivisionError("bug")})
    runner = PlanRunner(plan())
    with pytest.raises(ZeroDivisionError):
        runner.run(client)
    assert client.stops == 1 and runner.state is RunState.FAILED and runner.resume_from == 0


def test_run_from_here_and_single_step() -> None:
    client = FakeClient()
    assert PlanRunner(plan(), start=2).run(client).ok and ends(client) == [4, 5]

    client, rec = FakeClient(), Recorder()
    runner = PlanRunner(plan(loops=2), start=3, single=True, progress=rec)
    outcome = runner.run(client)
    assert outcome.ok and ends(client) == [5]
    assert outcome.next_position == (0, 2)  # the next step would be segment 1 of loop 2
    assert rec.short() == [("start", 3, 1), ("done", 3, 1), ("finished", 3, 1)]
    last = PlanRunner(plan(), start=3, single=True)
    assert last.run(FakeClient()).next_position is None


def state_of(runner: PlanRunner) -> RunState:
    """The runner's state read through a call: mypy keeps no narrowing across the runner's methods."""
    return runner.state


def test_step_by_step_driving_without_blocking() -> None:
    rec = Recorder()
    runner = PlanRunner(plan(loops=2), progress=rec)
    cmd = runner.next_command()
    assert cmd is not None and (cmd.index, cmd.loop, cmd.count, cmd.loops) == (0, 1, 4, 2)
    assert state_of(runner) is RunState.RUNNING and runner.current == cmd
    assert cmd.move_kwargs() == {
        "via_id": None,
        "orientation_changes": True,
        "ignore_middle": False,
        "speed": 100.0,
        "tool": 200,
        "timeout": None,
    }
    with pytest.raises(RuntimeError, match="still running"):
        runner.next_command()
    runner.on_result(DONE)
    assert state_of(runner) is RunState.READY and runner.position == (1, 1)
    with pytest.raises(RuntimeError, match="no segment is running"):
        runner.on_result(DONE)
    cmd = runner.next_command()
    assert cmd is not None and cmd.segment.via_id == 2
    runner.on_stopped()  # the worker sent client.stop() itself
    assert state_of(runner) is RunState.STOPPED and (runner.resume_from, runner.resume_loop) == (1, 1)
    assert runner.next_command() is None
    runner.resume()
    done = 0
    while (cmd := runner.next_command()) is not None:
        runner.on_result(DONE)
        done += 1
    assert done == 7 and state_of(runner) is RunState.FINISHED and runner.segments_done == 8
    with pytest.raises(RuntimeError, match="cannot resume"):
        runner.resume()


def test_on_error_and_not_ok_result_after_stop_request_count_as_stopped() -> None:
    runner = PlanRunner(plan())
    runner.next_command()
    runner.request_stop()
    runner.on_result(failed(0, "stopped"))
    assert state_of(runner) is RunState.STOPPED and runner.resume_from == 0
    runner = PlanRunner(plan())
    runner.next_command()
    runner.on_error(LinkError("gone"))
    assert state_of(runner) is RunState.FAILED and runner.error is not None
    runner = PlanRunner(plan())
    runner.on_stopped("operator")  # before anything ran
    assert state_of(runner) is RunState.STOPPED and runner.resume_from == 0


def test_endless_loops_until_stopped() -> None:
    client = FakeClient()
    runner = PlanRunner(plan(loops=0))
    client.move_script = {9: lambda: runner.request_stop()}
    outcome = runner.run(client)
    assert outcome.state is RunState.STOPPED and len(client.moves) == 10
    assert (outcome.resume_from, outcome.resume_loop) == (2, 3)


def test_invalid_runs_are_refused() -> None:
    with pytest.raises(InvalidInput, match="no segments"):
        PlanRunner(Plan("e"))
    with pytest.raises(InvalidInput, match="segment 5"):
        PlanRunner(plan(), start=4)
    with pytest.raises(InvalidInput, match="loop 3 of 2"):
        PlanRunner(plan(loops=2), start_loop=3)
    with pytest.raises(InvalidInput, match="timeouts"):
        PlanRunner(plan(), timeouts=[1.0])
    with pytest.raises(InvalidInput):
        PlanRunner(plan(), loops=-1)


def test_runner_takes_a_snapshot_of_the_plan() -> None:
    p = plan()
    runner = PlanRunner(p)
    p.remove(0)
    client = FakeClient()
    assert runner.run(client).ok and ends(client) == [1, 3, 4, 5]


# --- the point guard around each segment ----------------------------------------------------------


def _guard_points() -> dict[int, TempPoint]:
    return {i: make_point(i, f"p{i}", (100.0 * i, 0, 300, 180, 0, 0)) for i in range(1, 6)}


def test_guard_recreates_each_segments_points_right_before_its_move() -> None:
    client = FakeClient()
    guard = PointGuard(_guard_points())
    calls: list[tuple[str, int]] = []
    real_create, real_move = client.create_point, client.move_to_point

    def create(point_id: int, **kwargs: object) -> CommandResult:
        calls.append(("create", point_id))
        return real_create(point_id, **kwargs)  # type: ignore[arg-type]

    def move(end_id: int, **kwargs: object) -> CommandResult:
        calls.append(("move", end_id))
        return real_move(end_id, **kwargs)  # type: ignore[arg-type]

    client.create_point = create  # type: ignore[method-assign]
    client.move_to_point = move  # type: ignore[method-assign]
    outcome = PlanRunner(plan()).run(client, guard)
    assert outcome.ok
    assert calls == [
        ("create", 1),
        ("move", 1),
        ("create", 2),
        ("create", 3),
        ("move", 3),
        ("create", 4),
        ("move", 4),
        ("create", 5),
        ("move", 5),
    ]


def test_guard_mismatch_fails_at_that_segment_and_sends_nothing_more() -> None:
    points = _guard_points()
    client = FakeClient(stored={i: p.xyzabc for i, p in points.items()})
    guard = PointGuard(points, refresh=False)
    client.stored[4] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)  # the controller's P4 is not ours
    outcome = PlanRunner(plan()).run(client, guard)
    assert outcome.state is RunState.FAILED and isinstance(outcome.error, PointMismatch)
    assert outcome.resume_from == 2 and ends(client) == [1, 3, 4]
    assert "away from P4 'p4'" in outcome.message and client.creates == []


def test_guard_refused_point_fails_before_the_move() -> None:
    client = FakeClient(create_script={1: failed(1, "no")})
    outcome = PlanRunner(plan()).run(client, PointGuard(_guard_points()))
    assert outcome.state is RunState.FAILED and isinstance(outcome.error, PointNotCreated)
    assert ends(client) == [1] and outcome.resume_from == 1 and "refused to create P2" in outcome.message


def test_guard_restart_check_forgets_the_uploads() -> None:
    client = FakeClient()
    guard = PointGuard(_guard_points())
    assert guard.ensure(client, [1, 2, 1]) == [1, 2]
    assert guard.ensure(client, [1, 2, 3]) == [3]  # this process created 1 and 2 since the check
    client.gvs.clear()  # the controller restarted: GV99 reads 0
    assert guard.ensure(client, [1, 2, 3]) == [1, 2, 3] and guard.restarts == 1
    assert client.gvs[99] != 0  # armed again
