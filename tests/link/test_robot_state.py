"""RobotState (one signal per field, freshness) and request-id routing (Pending), alone and on
a real RobotLink talking to the simulator."""

from __future__ import annotations

import gc
import time
import weakref
from collections.abc import Iterator
from typing import Any

import pytest

from app.link.link_port import Pending, RequestRouter
from app.link.ops import CreatePoint, MoveToPoint, Pause, Step
from app.link.robot_link import RobotLink
from app.link.state import RobotState
from app.link.stats import LinkStats
from app.link.types import ConnectionState, LinkState, StepFrame, WorkerError
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import Alarm, ControllerMode, ProgramState
from tests.ui.fake_link import FakeLink
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
)

SIGNALS = (
    "connectionChanged",
    "freshnessChanged",
    "poseChanged",
    "jointsChanged",
    "statusChanged",
    "alarmsChanged",
    "lastResultChanged",
    "rttChanged",
    "statsChanged",
)
CONNECTED = ConnectionState(LinkState.CONNECTED, "", "10.0.0.5:502")


class Recorder:
    """Every signal of a RobotState, in order: (signal name, payload)."""

    def __init__(self, state: RobotState) -> None:
        self.seen: list[tuple[str, Any]] = []
        for name in SIGNALS:
            getattr(state, name).connect(lambda value, n=name: self.seen.append((n, value)))

    def names(self) -> list[str]:
        return [name for name, _ in self.seen]

    def take(self) -> list[str]:
        names, self.seen = self.names(), []
        return names


def _status(alarms: int = 0, mode: ControllerMode = ControllerMode.AUTO) -> ControllerStatus:
    return ControllerStatus(mode, ProgramState.STOPPED, Alarm(alarms), 0xFF)


@pytest.fixture
def state(qapp: Any) -> Iterator[RobotState]:
    robot_state = RobotState(freshness_limit=0.05)
    yield robot_state
    robot_state.set_connection(ConnectionState(LinkState.DISCONNECTED))  # stale: its timer stops
    assert not robot_state.fresh


def test_one_signal_per_changed_field(state: RobotState) -> None:
    rec = Recorder(state)
    assert state.connection.state is LinkState.DISCONNECTED and not state.fresh and state.age() is None
    state.set_connection(CONNECTED)
    state.set_connection(CONNECTED)  # unchanged: nothing
    assert rec.take() == ["connectionChanged"]
    assert state.connected and state.writable

    pose = Pose(1, 2, 3, 4, 5, 6, joints=(10.0, 20.0, 30.0, 0.0, 0.0, 0.0))
    state.set_pose(pose)
    state.set_pose(pose)
    assert rec.take() == ["poseChanged", "jointsChanged"]
    state.set_pose(Pose(1.5, 2, 3, 4, 5, 6, joints=pose.joints))  # the joints did not change
    assert rec.take() == ["poseChanged"]
    assert state.joints == (10.0, 20.0, 30.0, 0.0, 0.0, 0.0)

    state.set_status(_status(alarms=int(Alarm.BRAKE)))
    state.set_alarms(int(Alarm.BRAKE))  # the worker's own alarmsChanged: already known
    assert rec.take() == ["statusChanged", "alarmsChanged"]
    assert state.alarms == int(Alarm.BRAKE) and state.status == _status(alarms=int(Alarm.BRAKE))

    result = CommandResult(None, None, None, True, "stop: sent", request_id=3)
    state.set_last_result(result)
    state.set_last_result(result)  # the same outcome twice is two results
    assert rec.take() == ["lastResultChanged", "lastResultChanged"] and state.last_result == result

    state.set_rtt(1.25)
    state.set_rtt(1.25)
    state.set_stats(LinkStats(requests=4, answers=4))
    state.set_stats(LinkStats(requests=4, answers=4))
    assert rec.take() == ["rttChanged", "statsChanged"]
    assert state.rtt == 1.25 and state.stats.answers == 4


def test_monitor_only_is_connected_but_not_writable(state: RobotState) -> None:
    state.set_connection(ConnectionState(LinkState.CONNECTED, monitor_only=True))
    assert state.connected and not state.writable


def test_freshness_turns_stale_without_a_good_poll(qtbot: Any, state: RobotState) -> None:
    state.set_connection(CONNECTED)
    state.note_good_poll(time.monotonic() - 1.0)  # already older than the limit
    assert not state.fresh
    with qtbot.waitSignal(state.freshnessChanged, check_params_cb=lambda fresh: fresh, timeout=1000):
        state.note_good_poll(time.monotonic())
    assert state.fresh and state.age() is not None and state.age() < 0.05
    with qtbot.waitSignal(state.freshnessChanged, check_params_cb=lambda fresh: not fresh, timeout=1000):
        pass  # no poll: the timer turns it stale
    age = state.age()
    assert age is not None and age >= state.freshness_limit


def test_polls_keep_it_fresh_with_one_timer(qtbot: Any, state: RobotState) -> None:
    state.set_freshness_limit(0.4)
    state.set_connection(CONNECTED)
    changes: list[bool] = []
    state.freshnessChanged.connect(changes.append)
    deadline = time.monotonic() + 1.0  # the timer fires and re-arms twice meanwhile
    while time.monotonic() < deadline:
        state.note_good_poll(time.monotonic())
        qtbot.wait(5)  # let the freshness timer run between the polls
    assert changes == [True] and state.fresh


@pytest.mark.parametrize(
    "link_state", [LinkState.NOT_ANSWERING, LinkState.DOWN, LinkState.DISCONNECTED, LinkState.CONNECTING]
)
def test_anything_but_connected_is_stale_at_once(state: RobotState, link_state: LinkState) -> None:
    state.set_freshness_limit(60.0)
    state.set_connection(CONNECTED)
    state.note_good_poll(time.monotonic())
    assert state.fresh
    order: list[str] = []
    state.freshnessChanged.connect(lambda fresh: order.append(f"fresh={fresh}"))
    state.connectionChanged.connect(lambda c: order.append(c.state.name))
    state.set_connection(ConnectionState(link_state, "the controller does not answer"))
    assert not state.fresh
    assert order == ["fresh=False", link_state.name]  # a view of the connection already sees stale
    state.note_good_poll(time.monotonic())  # a late poll does not make a silent link live
    assert not state.fresh
    state.set_connection(CONNECTED)
    state.note_good_poll(time.monotonic())
    assert state.fresh


def test_the_limit_is_a_setting(state: RobotState) -> None:
    with pytest.raises(ValueError, match="freshness limit"):
        state.set_freshness_limit(0)
    state.set_connection(CONNECTED)
    state.note_good_poll(time.monotonic() - 0.2)
    state.set_freshness_limit(10.0)
    assert state.fresh and state.freshness_limit == 10.0
    state.set_freshness_limit(0.1)
    assert not state.fresh


# --- request ids matched in one place ----------------------------------------------------------


def test_router_hands_each_pending_its_own_outcome(qapp: Any) -> None:
    router = RequestRouter()
    first, second, third = router.track(7), router.track(8), router.track(9)
    assert router.track(7) is first
    got: dict[str, list[Any]] = {"first": [], "second": [], "third": []}
    for name, pending in (("first", first), ("second", second), ("third", third)):
        pending.finished.connect(got[name].append)
        pending.failed.connect(got[name].append)
    router.on_result(CommandResult(None, None, None, True, "eight", request_id=8))
    router.on_result(CommandResult(None, None, None, True, "nobody's", request_id=None))
    router.on_error(WorkerError("move to point", "seven", 7))
    router.on_result(CommandResult(None, None, None, True, "seven again", request_id=7))  # already done
    assert [r.message for r in got["second"]] == ["eight"]
    assert [e.message for e in got["first"]] == ["seven"]
    assert got["third"] == [] and len(router) == 1
    assert first.done and first.error is not None and second.result is not None and not third.done


def test_a_request_that_was_never_queued_fails(qtbot: Any) -> None:
    pending = RequestRouter().track(0)
    with qtbot.waitSignal(pending.failed, timeout=1000) as failed:
        pass
    assert "shut down" in failed.args[0].message


def test_the_fake_link_routes_like_the_link(qapp: Any) -> None:
    link = FakeLink()
    a = link.track(link.submit(MoveToPoint(1)))
    b = link.track(link.submit(MoveToPoint(2)))
    seen: list[tuple[Pending, str]] = []
    a.finished.connect(lambda r: seen.append((a, r.message)))
    b.finished.connect(lambda r: seen.append((b, r.message)))
    link.commandFinished.emit(CommandResult(None, None, None, True, "b done", request_id=b.request_id))
    link.commandFinished.emit(CommandResult(None, None, None, True, "a done", request_id=a.request_id))
    assert seen == [(b, "b done"), (a, "a done")]
    assert link.state.last_result is not None and link.state.last_result.message == "a done"


# --- on the real link ----------------------------------------------------------------------


def _outcomes(qtbot: Any, *pendings: Pending, timeout: int = SIGNAL_TIMEOUT_MS) -> dict[int, list[object]]:
    outcomes: dict[int, list[object]] = {p.request_id: [] for p in pendings}
    for pending in pendings:
        pending.finished.connect(outcomes[pending.request_id].append)
        pending.failed.connect(outcomes[pending.request_id].append)
    qtbot.waitUntil(lambda: all(outcomes.values()), timeout=timeout)
    return outcomes


def test_concurrent_requests_each_get_their_own_result(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    target = (400.0, 10.0, 300.0, 180.0, 0.0, 0.0)
    create = link.track(link.submit(CreatePoint(22, target)))
    pause = link.track(link.submit(Pause()))  # urgent: may overtake the create
    refused = link.track(
        link.submit(Step(StepFrame.JOINT, [0, 0, 0, 0, 0, 0]))
    )  # invalid: fails in the worker
    outcomes = _outcomes(qtbot, create, pause, refused)
    assert all(len(v) == 1 for v in outcomes.values())  # one outcome each, never another's
    for request_id, (outcome,) in outcomes.items():
        assert getattr(outcome, "request_id", None) == request_id
    assert create.result is not None and create.result.ok and "create temp point" in create.result.message
    assert pause.result is not None and pause.result.message == "pause: sent"
    assert refused.error is not None and "zero" in refused.error.message
    assert sim.state().points[22] == pytest.approx(target)


def test_two_creates_in_a_row_each_get_their_own_result(qtbot: Any, sim: Any, link: RobotLink) -> None:
    """The second create waits in the worker until the first one's outcome is known (GV291 tells
    one command at a time), then goes out: each request ends once, with its own result."""
    connect(qtbot, link, sim)
    target = (400.0, 10.0, 300.0, 180.0, 0.0, 0.0)
    first = link.track(link.submit(CreatePoint(21)))
    second = link.track(link.submit(CreatePoint(22, target)))
    third = link.track(link.submit(CreatePoint(23, target)))
    outcomes = _outcomes(qtbot, first, second, third)
    assert all(len(v) == 1 for v in outcomes.values())
    for pending in (first, second, third):
        assert pending.result is not None and pending.result.ok, pending.result
        assert pending.result.request_id == pending.request_id
    assert sim.state().points[22] == pytest.approx(target) and 21 in sim.state().points
    assert sim.state().points[23] == pytest.approx(target)


def _watch(link: RobotLink, request_id: int, outcomes: list[object]) -> weakref.ref[Pending]:
    """Track a request as the controllers do: lambdas that capture their Pending (a cycle through
    Qt's connection, which the garbage collector cannot see)."""
    pending = link.track(request_id)
    pending.finished.connect(lambda result: outcomes.append((pending.request_id, result)))
    pending.failed.connect(lambda error: outcomes.append((pending.request_id, error)))
    return weakref.ref(pending)


def test_a_pending_is_freed_once_its_request_ended(qtbot: Any, sim: Any, link: RobotLink) -> None:
    """Issue 18: every Pending whose lambdas captured it was kept for the life of the process
    (a leak per request). Once its one outcome was delivered, nothing keeps it."""
    connect(qtbot, link, sim)
    outcomes: list[object] = []
    target = (400.0, 10.0, 300.0, 180.0, 0.0, 0.0)
    refs = [_watch(link, link.submit(CreatePoint(30 + i, target)), outcomes) for i in range(8)]
    refs += [_watch(link, link.submit(Pause()), outcomes) for _ in range(4)]
    refs.append(
        _watch(link, link.submit(Step(StepFrame.JOINT, [0, 0, 0, 0, 0, 0])), outcomes)
    )  # fails in the worker
    refs.append(_watch(link, 0, outcomes))  # never queued: fails on the next turn of the loop
    qtbot.waitUntil(lambda: len(outcomes) == len(refs), timeout=SIGNAL_TIMEOUT_MS)
    assert len(link._router) == 0
    gc.collect()
    alive = [ref() for ref in refs if ref() is not None]
    assert alive == [], f"{len(alive)} of {len(refs)} Pendings still alive after their outcome"
    assert len(outcomes) == len(refs)  # and each delivered its outcome once


def test_the_state_follows_the_link(qtbot: Any, sim: Any, qapp: Any, fast_reconnect: None) -> None:
    link = RobotLink(canary_gv=None, freshness_limit=0.15)
    try:
        state = link.state
        with qtbot.waitSignal(
            state.freshnessChanged, check_params_cb=lambda fresh: fresh, timeout=SIGNAL_TIMEOUT_MS
        ):
            connect(qtbot, link, sim)
        assert state.connection is link.connection and state.connected
        assert state.pose is not None and state.status is not None and state.age() is not None
        qtbot.waitUntil(lambda: state.stats.answers > 0, timeout=SIGNAL_TIMEOUT_MS)
        with qtbot.waitSignal(
            state.freshnessChanged, check_params_cb=lambda fresh: not fresh, timeout=SIGNAL_TIMEOUT_MS
        ):
            sim.set_silent(True)
        qtbot.waitUntil(lambda: not state.connected, timeout=SIGNAL_TIMEOUT_MS)
        assert not state.fresh
        with qtbot.waitSignal(
            link.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=SIGNAL_TIMEOUT_MS
        ):
            sim.set_silent(False)
        qtbot.waitUntil(lambda: state.fresh, timeout=SIGNAL_TIMEOUT_MS)
    finally:
        link.shutdown()
