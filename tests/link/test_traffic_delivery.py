"""The captured traffic reaches the GUI thread in batches (issue 10: fewer queued calls per poll)
and nothing is left behind: every frame, in order, at capture off, at disconnect, and a command's
frames before its result. Against the real simulator; the frames are checked against what the
simulator served (its request count, its writes) and against the MBAP transaction ids (one per
request on the main link, consecutive)."""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, Qt

from app import timing
from app.link.ops import CreatePoint, JogPress
from app.link.robot_link import RobotLink
from app.link.transport import TrafficRecord
from app.link.types import JogRequest, LinkState
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import TeachFrame
from tests.ui.pendant_support import SIGNAL_TIMEOUT_MS, connect, is_state, jogging

pytestmark = pytest.mark.timeout(60)

NEVER = 60.0  # s: a delivery period no test outlives, so only the flushes deliver


@pytest.fixture(name="link")
def quiet_link_fixture(qtbot: Any, monkeypatch: pytest.MonkeyPatch) -> Iterator[RobotLink]:
    """A link whose only connection is the main one (no stop line, no canary), polling at 100 Hz."""
    monkeypatch.setattr(timing, "RECONNECT_BACKOFF", (0.05, 0.1, 0.2))
    robot_link = RobotLink(poll_hz=100, canary_gv=None, stop_line=False)
    try:
        yield robot_link
    finally:
        robot_link.shutdown()
        assert not robot_link.is_running


class Batches:
    """The trafficObserved batches the GUI thread received, in order."""

    def __init__(self, link: RobotLink) -> None:
        self.batches: list[tuple[TrafficRecord, ...]] = []
        link.trafficObserved.connect(self.batches.append)

    @property
    def frames(self) -> list[TrafficRecord]:
        return [r for batch in self.batches for r in batch]

    def tx(self) -> list[TrafficRecord]:
        return [r for r in self.frames if r.direction == "tx"]


def _tid(record: TrafficRecord) -> int:
    return int.from_bytes(record.frame[0:2], "big")


def _writes(got: Batches) -> int:
    return sum(1 for r in got.tx() if r.frame[7] in (0x06, 0x10))


def consecutive(tids: list[int]) -> bool:
    return all((b - a) % 0x10000 == 1 for a, b in itertools.pairwise(tids))


def assert_whole_and_in_order(frames: list[TrafficRecord]) -> None:
    """Each request followed by its answer, transaction ids consecutive: no frame lost or moved."""
    assert frames, "no traffic delivered"
    directions = [r.direction for r in frames]
    assert directions == ["tx", "rx"] * (len(frames) // 2)
    tids = [_tid(r) for r in frames]
    assert tids[0::2] == tids[1::2]  # each answer is its request's
    requests = tids[0::2]
    assert consecutive(requests), requests


def _capturing(qtbot: Any, sim: Any, link: RobotLink, polls: int) -> Batches:
    """Capture on, connected, and ``polls`` polls (status + pose) served: the batches delivered."""
    link.set_traffic_capture(True)
    got = Batches(link)
    connect(qtbot, link, sim)
    start = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count >= start + 2 * polls, timeout=SIGNAL_TIMEOUT_MS)
    return got


def test_frames_arrive_batched_every_one_in_order(qtbot: Any, sim: Any, link: RobotLink) -> None:
    link.set_traffic_capture(True)  # before the link exists: every request is captured
    got = Batches(link)
    connect(qtbot, link, sim)
    start = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count >= start + 200, timeout=10_000)  # ~1 s of 100 Hz polls
    batches_during = len(got.batches)
    link.disconnect()
    qtbot.waitUntil(lambda: sim.connections_count == 0, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(lambda: len(got.tx()) == sim.requests_count, timeout=SIGNAL_TIMEOUT_MS)
    assert_whole_and_in_order(got.frames)
    polls_seen = sim.requests_count // 2  # status + pose per poll
    # one batch per TRAFFIC_DELIVERY_PERIOD (plus the connection changes), not one per poll
    assert 2 <= batches_during < polls_seen / 3, (batches_during, polls_seen)


def test_capture_off_delivers_what_was_captured(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "TRAFFIC_DELIVERY_PERIOD", NEVER)
    got = _capturing(qtbot, sim, link, polls=10)
    served_before_off = sim.requests_count
    with qtbot.waitSignal(link.trafficObserved, timeout=SIGNAL_TIMEOUT_MS):
        link.set_traffic_capture(False)
    tx = got.tx()
    # every request the simulator served before capture went off, and not one poll's worth more
    assert served_before_off <= len(tx) <= sim.requests_count
    assert_whole_and_in_order(got.frames)
    delivered = len(got.frames)
    seen = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count >= seen + 10, timeout=SIGNAL_TIMEOUT_MS)  # polls go on
    QCoreApplication.processEvents()  # any batch already queued to this thread lands
    assert len(got.frames) == delivered  # off: nothing more


def test_disconnect_delivers_every_frame(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "TRAFFIC_DELIVERY_PERIOD", NEVER)
    got = _capturing(qtbot, sim, link, polls=10)
    link.submit(
        JogPress(JogRequest(TeachFrame.BASE, 0, 1, 20.0))
    )  # the disconnect then writes ratio 0, teach off
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    at_end: list[tuple[int, int]] = []
    link.connectionChanged.connect(lambda _s: at_end.append((len(got.tx()), _writes(got))))
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED), timeout=SIGNAL_TIMEOUT_MS
    ):
        link.disconnect()
    assert not sim.state().teach_enabled
    # delivered before the GUI heard of the disconnect: every request the simulator served,
    # the close's own writes (after the last poll) included
    assert at_end[-1] == (sim.requests_count, len(sim.writes))
    assert_whole_and_in_order(got.frames)


def test_lost_link_delivers_its_frames_before_down(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "TRAFFIC_DELIVERY_PERIOD", NEVER)
    monkeypatch.setattr(timing, "NOT_ANSWERING_DOWN_AFTER", 0.3)
    got = _capturing(qtbot, sim, link, polls=10)
    at_down: list[int] = []
    link.connectionChanged.connect(
        lambda s: at_down.append(len(got.tx())) if s.state is LinkState.DOWN else None
    )
    answered_before = sim.requests_count
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.DOWN), timeout=SIGNAL_TIMEOUT_MS
    ):
        sim.set_silent(True)
    # in the GUI before it heard "down": every request answered before the silence, and the
    # unanswered ones after it
    assert at_down and at_down[0] > answered_before
    tx = got.tx()[: at_down[0]]
    tids = [_tid(r) for r in tx]
    assert consecutive(tids), tids
    sim.set_silent(False)


def test_a_commands_frames_come_before_its_result(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "TRAFFIC_DELIVERY_PERIOD", NEVER)
    got = _capturing(qtbot, sim, link, polls=0)
    writes_at_result: list[int] = []

    def on_result(_result: CommandResult) -> None:  # what the GUI has when the result is shown
        writes_at_result.append(_writes(got))

    link.commandFinished.connect(on_result)
    with qtbot.waitSignal(link.commandFinished, timeout=SIGNAL_TIMEOUT_MS) as done:
        link.submit(CreatePoint(7, [100.0, 0.0, 300.0, 0.0, 0.0, 0.0], 0))
    assert done.args[0].ok, done.args[0].message
    assert len(sim.writes) >= 2  # the pose, the command
    assert writes_at_result == [len(sim.writes)]  # all of its writes were already in the table
    writes = [r for r in got.tx() if r.frame[7] in (0x06, 0x10)]
    assert int.from_bytes(writes[-1].frame[8:10], "big") == registers.REG_RUN_COMMAND  # the command last


def test_a_batch_crosses_threads_as_one_immutable_object(qtbot: Any, sim: Any, link: RobotLink) -> None:
    """Issue 18: a batch was a list (``Signal(list)``: copied into a QVariantList in the worker,
    one QVariant per record, and back into a new list in the GUI thread). It is one tuple of
    frozen records now, handed over as it is: the GUI thread gets the object the worker made."""
    made: list[object] = []  # what the worker emitted (recorded in the worker thread)
    link.set_traffic_capture(True)
    _ = link._worker  # made now, so its own signal can be watched from the start
    assert link._made is not None
    link._made.trafficObserved.connect(made.append, Qt.ConnectionType.DirectConnection)
    got = _capturing(qtbot, sim, link, polls=10)
    qtbot.waitUntil(lambda: len(got.batches) >= 2, timeout=SIGNAL_TIMEOUT_MS)
    batch = got.batches[0]
    assert isinstance(batch, tuple) and batch
    assert all(isinstance(record, TrafficRecord) for record in batch)
    with pytest.raises(dataclasses.FrozenInstanceError):
        batch[0].frame = b""  # type: ignore[misc]
    assert batch is made[0]  # not a copy made on the way
