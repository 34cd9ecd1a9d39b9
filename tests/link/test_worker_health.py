"""The worker's freshness and health: signal order of a poll, *not answering*, shutdown that
never blocks the GUI on the network (RobotWorker / RobotLink against the real simulator)."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtCore import QObject, QThread, Signal

from app import timing
from app.link import robot_link as robot_link_module
from app.link.ops import JogPress, Step
from app.link.robot_link import RobotLink
from app.link.state import PollUpdate
from app.link.stats import LinkStats
from app.link.types import ConnectionState, JogRequest, LinkState, StepFrame
from app.link.worker import RobotWorker
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol.enums import TeachFrame
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    connection_settings,
    fast_reconnect_fixture,
    is_state,
    jogging,
    link_fixture,
    ratio_writes,
)

pytestmark = pytest.mark.timeout(60)


class Rig(QObject):
    """A bare RobotWorker in its own QThread, seen from the GUI thread: every signal it has is
    relayed here (queued, in order), and calls go to it queued, as RobotLink makes them."""

    polled = Signal(object)  # PollUpdate: the worker's one delivery per poll
    linkStatsChanged = Signal(object)  # noqa: N815
    commandFinished = Signal(object)  # noqa: N815
    connectionChanged = Signal(object)  # noqa: N815
    stopped = Signal()
    connectTo = Signal(object)  # noqa: N815
    shutdown = Signal()

    def __init__(self) -> None:
        super().__init__()
        self.worker_thread = QThread()  # not self.thread: that would shadow QObject.thread()
        self.worker = RobotWorker(timing.POLL_HZ_DEFAULT, canary_gv=None)
        self.worker.moveToThread(self.worker_thread)
        self.worker_thread.started.connect(self.worker.start)
        for name in (
            "polled",
            "linkStatsChanged",
            "commandFinished",
            "connectionChanged",
            "stopped",
        ):
            getattr(self.worker, name).connect(getattr(self, name))
        self.connectTo.connect(self.worker.connect_to)
        self.shutdown.connect(self.worker.shutdown)
        self.worker_thread.start()

    def connect_sim(self, qtbot: Any, sim: Any, **overrides: Any) -> None:
        with qtbot.waitSignal(
            self.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=SIGNAL_TIMEOUT_MS
        ):
            self.connectTo.emit(connection_settings(sim, **overrides))


_still_running: list[Rig] = []  # rigs whose thread did not end: kept, never destroyed while running


@pytest.fixture
def rig(qtbot: Any, fast_reconnect: None) -> Iterator[Rig]:
    """The shutdown is a queued call after which the worker quits its own thread."""
    made = Rig()
    try:
        yield made
    finally:
        try:
            with qtbot.waitSignal(made.stopped, timeout=SIGNAL_TIMEOUT_MS):
                made.shutdown.emit()
        finally:
            if not made.worker_thread.wait(SIGNAL_TIMEOUT_MS):
                _still_running.append(made)  # destroying a running QThread would abort the whole run
                pytest.fail(f"the worker's thread did not end within {SIGNAL_TIMEOUT_MS} ms", pytrace=False)


def test_command_finished_comes_after_the_pose_and_status_of_its_poll(qtbot: Any, sim: Any, rig: Rig) -> None:
    events: list[tuple[str, Any]] = []

    def on_polled(update: PollUpdate) -> None:  # one delivery: its parts in the order they happened
        if update.pose is not None:
            events.append(("pose", update.pose))
        if update.status is not None:
            events.append(("status", update.status))
        if update.good_at is not None:
            events.append(("poll", update.good_at))

    rig.polled.connect(on_polled)
    rig.commandFinished.connect(lambda r: events.append(("result", r)))
    rig.connect_sim(qtbot, sim)
    with qtbot.waitSignal(rig.commandFinished, timeout=SIGNAL_TIMEOUT_MS) as blocker:
        rig.worker.submit(Step(StepFrame.JOINT, [3.0, 0, 0, 0, 0, 0], (0.0,) * 5, 10.0))
    result: CommandResult = blocker.args[0]
    assert result.ok, result.message
    done = next(i for i, (kind, value) in enumerate(events) if kind == "result" and value is result)
    assert events[done - 1][0] == "poll"  # the poll that saw it end, its freshness, then the result
    last_pose: Pose = next(v for k, v in reversed(events[:done]) if k == "pose")
    assert last_pose.joints is not None
    assert last_pose.joints[0] == pytest.approx(sim.state().joints[0], abs=1e-3)  # the final pose
    statuses: list[ControllerStatus] = [v for k, v in events[:done] if k == "status"]
    assert statuses  # the status that said "done" was published before the result
    polls = [v for k, v in events if k == "poll"]
    assert polls == sorted(polls) and all(isinstance(t, float) for t in polls)
    assert polls[-1] <= time.monotonic()


def test_link_stats_are_reported(qtbot: Any, sim: Any, rig: Rig, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "RTT_REPORT_PERIOD", 0.05)
    stats: list[LinkStats] = []
    rig.linkStatsChanged.connect(stats.append)
    rig.connect_sim(qtbot, sim)
    qtbot.waitUntil(lambda: len(stats) >= 2, timeout=SIGNAL_TIMEOUT_MS)
    assert all(isinstance(s, LinkStats) for s in stats)
    assert stats[-1].answers > stats[0].answers and stats[-1] != stats[-2]


@pytest.mark.parametrize("poll_hz", [20.0, 50.0])
def test_a_silent_controller_is_not_answering_after_one_poll(
    qtbot: Any, sim: Any, link: RobotLink, poll_hz: float
) -> None:
    link.set_poll_rate(poll_hz)
    connect(qtbot, link, sim, poll_timeout=None)  # the product's poll timeout (0.15 s on TCP)
    states: list[ConnectionState] = []
    link.connectionChanged.connect(states.append)
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.NOT_ANSWERING), timeout=SIGNAL_TIMEOUT_MS
    ):
        silent_at = time.monotonic()
        sim.set_silent(True)
    elapsed = time.monotonic() - silent_at  # measured at the signal's arrival in the GUI thread
    print(f"not answering after {elapsed * 1000:.0f} ms at {poll_hz:g} Hz")
    assert states[-1].state is LinkState.NOT_ANSWERING  # not torn down on the first miss
    assert "did not answer" in states[-1].message
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=SIGNAL_TIMEOUT_MS
    ):
        sim.set_silent(False)
    assert LinkState.DOWN not in [s.state for s in states]


def test_not_answering_for_long_goes_down_and_reconnects(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "NOT_ANSWERING_DOWN_AFTER", 0.2)
    connect(qtbot, link, sim, poll_timeout=0.3)
    states: list[LinkState] = []
    link.connectionChanged.connect(lambda s: states.append(s.state))
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.DOWN), timeout=SIGNAL_TIMEOUT_MS
    ):
        sim.set_silent(True)
    with qtbot.waitSignal(link.controllerReconnected, timeout=SIGNAL_TIMEOUT_MS):
        sim.set_silent(False)
    assert states.index(LinkState.NOT_ANSWERING) < states.index(LinkState.DOWN)
    assert states[-1] is LinkState.CONNECTED


def test_jog_during_silence_gets_ratio_zero_first_when_it_answers(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    # a controller without a communication watchdog: the resync after the silent poll closes the
    # jog's connection, which would otherwise stop the jog at the simulator by itself
    sim.set_watchdog(None)
    connect(qtbot, link, sim, poll_timeout=0.3)
    link.submit(JogPress(JogRequest(TeachFrame.JOINT, 0, 1, 20.0)))
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.NOT_ANSWERING), timeout=SIGNAL_TIMEOUT_MS
    ):
        sim.set_silent(True)
    assert jogging(sim)  # the controller cannot hear us yet
    writes_before = len(sim.writes)
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=SIGNAL_TIMEOUT_MS
    ):
        sim.set_silent(False)
    first = sim.writes[writes_before]
    assert first.address == 406 and first.values == (0, 0)  # GV203 = 0: the first write back
    assert not sim.state().jogging and ratio_writes(sim)[-1] == 0.0


def test_shutdown_with_a_silent_controller_does_not_block_the_gui(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "SHUTDOWN_WAIT", 0.3)
    connect(qtbot, link, sim, timeout=2.0, poll_timeout=1.0)  # the safety writes wait 2 s for an answer
    link.submit(JogPress(JogRequest(TeachFrame.JOINT, 0, 1, 20.0)))
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    sim.set_silent(True)
    t0 = time.monotonic()
    link.shutdown()
    blocked = time.monotonic() - t0
    print(f"shutdown blocked the GUI {blocked * 1000:.0f} ms")
    assert blocked < 0.3 + 1.0  # the wait's bound, not the 2 s network timeout
    assert link.is_running  # still inside its safety write: kept alive, never destroyed running
    assert any(thread is link._thread for thread, _ in robot_link_module._detached)  # kept referenced
    qtbot.waitUntil(lambda: not link.is_running, timeout=10_000)  # it ends by itself ...
    qtbot.waitUntil(lambda: not robot_link_module._detached, timeout=10_000)  # ... and is let go


def test_shutdown_writes_ratio_zero_and_ends_the_thread(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim)
    link.submit(JogPress(JogRequest(TeachFrame.JOINT, 0, 1, 20.0)))
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    link.shutdown()
    assert not link.is_running
    assert ratio_writes(sim)[-1] == 0.0 and not sim.state().teach_enabled


def test_a_silent_controller_is_reported_with_a_reason_the_ui_can_translate(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    """The poll's error carries its cause as a code (no_answer) beside the English text, so the
    Chinese UI never shows "controller did not answer within ..."."""
    from app.link.types import WorkerError
    from ui.messages import error_text

    connect(qtbot, link, sim, poll_timeout=0.3)
    with qtbot.waitSignal(
        link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS, check_params_cb=lambda e: e.operation == "poll"
    ) as blocker:
        sim.set_silent(True)
    error: WorkerError = blocker.args[0]
    assert error.reason is not None and error.reason.code == "no_answer"
    assert "did not answer" in error.message  # the CLI's and the log's English stays
    assert error_text(error)  # and the UI has a sentence for it
    sim.set_silent(False)
