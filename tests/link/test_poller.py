"""The poller against the simulator: read order, publish order, silence, freshness."""

from __future__ import annotations

from typing import Any

import pytest

from app import timing
from app.link.client import RobotClient
from app.link.types import LinkState, Operation, StepFrame
from app.models import Pose
from tests.link.harness import PartsHost


def test_status_is_read_before_the_pose(host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    host.connect(sim)
    reads: list[str] = []
    client = host.client
    assert client is not None
    for name in ("read_status", "read_pose"):
        original = getattr(client, name)

        def spy(*args: Any, _name: str = name, _original: Any = original, **kwargs: Any) -> Any:
            reads.append(_name)
            return _original(*args, **kwargs)

        monkeypatch.setattr(client, name, spy)
    host.poll()
    assert reads == ["read_status", "read_pose"]


def test_a_poll_publishes_pose_status_then_freshness_then_the_result(host: PartsHost, sim: Any) -> None:
    host.connect(sim)
    client = host.client
    assert client is not None
    client.step(StepFrame.JOINT, [1.0, 0, 0, 0, 0, 0], (0.0,) * 5, 10.0, wait=False)
    tracker = client.last_tracker
    assert tracker is not None
    host.motion.track(Operation.STEP, tracker, motion=True, request_id=5)
    host.out.clear()
    while host.motion.active is not None:
        host.poll()
    names = [
        n for n in host.names() if n in ("poseChanged", "statusChanged", "pollSucceeded", "commandFinished")
    ]
    done = names.index("commandFinished")
    assert names[done - 1] == "pollSucceeded"  # the result comes after that poll's data
    last_pose: Pose = host.of("poseChanged")[-1]
    assert last_pose.joints is not None
    assert last_pose.joints[0] == pytest.approx(sim.state().joints[0], abs=1e-3)
    result = host.of("commandFinished")[-1]
    assert result.ok and result.request_id == 5


def test_one_silent_poll_is_not_answering_and_an_answer_is_connected_again(host: PartsHost, sim: Any) -> None:
    host.connect(sim, poll_timeout=0.3)
    host.out.clear()
    sim.set_silent(True)
    host.poll()
    assert host.states() == [LinkState.NOT_ANSWERING]
    assert host.link_up  # not torn down on the first miss
    assert host.of("errorOccurred")[0].operation == Operation.POLL
    host.poll()
    assert host.states() == [LinkState.NOT_ANSWERING]  # shown once
    sim.set_silent(False)
    host.poll_until_answered()
    assert host.states() == [LinkState.NOT_ANSWERING, LinkState.CONNECTED]
    assert "pollSucceeded" in host.names()


def test_silence_that_lasts_takes_the_link_down(
    host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "NOT_ANSWERING_DOWN_AFTER", 0.1)
    host.connect(sim, poll_timeout=0.06)
    sim.set_silent(True)
    for _ in range(4):
        host.poll()
    assert LinkState.DOWN in host.states() and not host.link_up and not host.polling
    assert host.reconnect_delays  # retrying by itself


def test_poll_uses_the_poll_timeout_not_the_command_timeout(host: PartsHost, sim: Any) -> None:
    host.connect(sim, timeout=2.0, poll_timeout=0.05)
    sim.set_silent(True)
    import time

    t0 = time.monotonic()
    host.poll()
    assert time.monotonic() - t0 < 1.5  # 0.05 s (plus load), not the 2 s command timeout
    sim.set_silent(False)


def test_link_stats_reported_at_most_once_a_period(
    host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "RTT_REPORT_PERIOD", 3600.0)
    host.connect(sim)
    for _ in range(5):
        host.poll()
    stats = host.of("linkStatsChanged")
    assert len(stats) == 1 and stats[0].answers > 0
    assert isinstance(host.client, RobotClient)
