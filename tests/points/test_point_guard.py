"""The controller's points are never assumed: a second Modbus client overwrites a point on the
simulator, and the guarded run must not silently move the arm to the overwritten pose.

Everything is asserted at the simulator (its pose, its stored points, its write log)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from app.plan.runner import PlanRunner, RunState
from app.plan.segments import Plan, Segment
from app.points.guard import PointGuard, PointMismatch
from app.points.ledger import PointLedger
from app.points.point import make_point
from app.protocol import registers
from app.protocol.registers import CANARY_GV

MakeClient = Callable[..., Any]
SPEED = 120.0  # mm/s: 30 mm moves of 0.25 s (a much shorter move can end between two status polls)
TOLERANCE = 0.01  # mm: the simulator reaches a point exactly (float32 on the wire)


def _ledger(start: tuple[float, ...]) -> PointLedger:
    x, y, z, a, b, c = start
    return PointLedger(
        [
            make_point(1, "a", (x + 30, y, z, a, b, c)),
            make_point(2, "b", (x + 30, y + 30, z, a, b, c)),
            make_point(3, "c", (x, y + 30, z, a, b, c)),
        ]
    )


PLAN = Plan("square", [Segment.line(1, SPEED), Segment.line(2, SPEED), Segment.line(3, SPEED)])
ELSEWHERE_OFFSET = (-40.0, -40.0, 25.0)


def _elsewhere(point: tuple[float, ...]) -> tuple[float, ...]:
    return (
        point[0] + ELSEWHERE_OFFSET[0],
        point[1] + ELSEWHERE_OFFSET[1],
        point[2] + ELSEWHERE_OFFSET[2],
        *point[3:],
    )


def _near(pose: tuple[float, ...], target: tuple[float, ...]) -> bool:
    return math.dist(pose[:3], target[:3]) <= TOLERANCE


def test_an_overwrite_between_upload_and_run_is_undone_before_the_move(
    sim: Any, make_client: MakeClient
) -> None:
    ours, other = make_client(sim), make_client(sim)
    ledger = _ledger(ours.read_pose().xyzabc)
    guard = PointGuard({p.id: p for p in ledger})
    assert guard.ensure(ours, [1, 2, 3]) == [1, 2, 3]
    host_p2 = ledger.point(2).xyzabc
    assert _near(sim.state().points[2], host_p2)

    # Another tool overwrites P2 after our upload, before the run.
    wrong = _elsewhere(host_p2)
    assert other.create_point(2, pose=wrong, wait=True).ok
    assert _near(sim.state().points[2], wrong)

    outcome = PlanRunner(PLAN).run(ours, guard)
    assert outcome.state is RunState.FINISHED, outcome.message
    final = sim.state()
    assert _near(final.pose, ledger.point(3).xyzabc)
    assert _near(final.points[2], host_p2)  # re-created from the host's copy before segment 2
    # the arm passed the host's P2, never the overwritten pose
    assert guard.created == [1, 2, 3, 1, 2, 3]


class _OverwriteBeforeMove:
    """Our client, but a second client overwrites ``point_id`` right before our move to it:
    the residual window between our create-point and our move command."""

    def __init__(self, client: Any, other: Any, point_id: int, pose: tuple[float, ...]) -> None:
        self._client, self._other, self._id, self._pose = client, other, point_id, pose

    def __getattr__(self, name: str) -> Any:
        return getattr(self._client, name)

    def move_to_point(self, end_id: int, **kwargs: Any) -> Any:
        if end_id == self._id:
            assert self._other.create_point(self._id, pose=self._pose, wait=True).ok
        return self._client.move_to_point(end_id, **kwargs)


def test_an_overwrite_in_the_residual_window_stops_the_run_at_that_segment(
    sim: Any, make_client: MakeClient
) -> None:
    ours, other = make_client(sim), make_client(sim)
    ledger = _ledger(ours.read_pose().xyzabc)
    wrong = _elsewhere(ledger.point(2).xyzabc)
    guard = PointGuard({p.id: p for p in ledger})
    guard.ensure(ours, [1, 2, 3])
    client = _OverwriteBeforeMove(ours, other, 2, wrong)

    outcome = PlanRunner(PLAN).run(client, guard)
    assert outcome.state is RunState.FAILED
    assert isinstance(outcome.error, PointMismatch) and "P2" in outcome.message
    assert outcome.resume_from == 1  # segment 2, to be checked and run again
    final = sim.state()
    assert not final.moving
    assert _near(final.pose, wrong)  # it moved there once (the stated residual window) ...
    assert not _near(final.pose, ledger.point(3).xyzabc)  # ... and nothing was sent after that
    assert guard.created == [1, 2, 3, 1, 2]  # segment 3's point was never even re-created


def test_without_refresh_an_overwritten_point_stops_the_run(sim: Any, make_client: MakeClient) -> None:
    """``--no-upload``: the operator's responsibility, but the arrival check still stops the run."""
    ours, other = make_client(sim), make_client(sim)
    ledger = _ledger(ours.read_pose().xyzabc)
    for p in ledger:
        sim.add_point(p.id, p.xyzabc)
    wrong = _elsewhere(ledger.point(1).xyzabc)
    assert other.create_point(1, pose=wrong, wait=True).ok
    guard = PointGuard({p.id: p for p in ledger}, refresh=False)
    outcome = PlanRunner(PLAN).run(ours, guard)
    assert outcome.state is RunState.FAILED and isinstance(outcome.error, PointMismatch)
    assert outcome.resume_from == 0
    assert guard.created == [] and sim.writes_to(registers.gv_reg(CANARY_GV)) == []
    assert _near(sim.state().pose, wrong) and not _near(sim.state().pose, ledger.point(2).xyzabc)


def test_a_restart_during_the_run_is_noticed_and_the_points_restored(
    sim: Any, make_client: MakeClient
) -> None:
    ours = make_client(sim)
    ledger = _ledger(ours.read_pose().xyzabc)
    guard = PointGuard({p.id: p for p in ledger})
    guard.ensure(ours, [1, 2, 3])
    assert guard.uploaded == {1, 2, 3}

    class RestartAfterFirst:
        def __init__(self) -> None:
            self.moves = 0

        def __getattr__(self, name: str) -> Any:
            return getattr(ours, name)

        def move_to_point(self, end_id: int, **kwargs: Any) -> Any:
            result = ours.move_to_point(end_id, **kwargs)
            self.moves += 1
            if self.moves == 1:
                sim.restart_controller()  # temp points and GV0..GV99 wiped, link stays up
            return result

    client = RestartAfterFirst()
    outcome = PlanRunner(PLAN).run(client, guard)
    assert outcome.state is RunState.FINISHED, outcome.message
    assert guard.restarts == 1
    assert _near(sim.state().pose, ledger.point(3).xyzabc)
    assert set(sim.state().points) == {2, 3}  # what was re-created after the restart


def test_the_guard_keeps_only_the_last_create_points_it_sent(
    sim: Any, make_client: MakeClient, monkeypatch: Any
) -> None:
    """A run with endless loops re-creates its points before every segment: the guard's record of
    them keeps the last CREATED_KEPT, it does not grow for as long as the run goes (issue 18)."""
    from app.points import guard as guard_module

    monkeypatch.setattr(guard_module, "CREATED_KEPT", 4)
    ours = make_client(sim)
    ledger = _ledger(ours.read_pose().xyzabc)
    guard = PointGuard({p.id: p for p in ledger})
    for _ in range(3):
        guard.before_segment(ours, [1, 2, 3])
    assert guard.created == [3, 1, 2, 3]  # the last four of the nine sent
