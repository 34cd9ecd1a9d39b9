"""Stop always stops (issue 18): a Stop while the link is not up -- disconnected by the operator,
lost and being reconnected -- or while the main link cannot carry it (not answering, the stop
line closed) goes to the last controller over a fresh connection, and says so; a controller it
cannot reach is said too. RobotLink + worker against the real simulator, asserted at the
simulator: its 441 write, its program state."""

from __future__ import annotations

import time
from typing import Any

import pytest

from app import timing
from app.link.ops import RunProgram, Step, Stop
from app.link.robot_link import RobotLink
from app.link.types import LinkState, WorkerError
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, ProgramState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
    register_writes,
)
from ui.messages import LEVEL_WARNING, error_text, result_level, result_text

pytestmark = pytest.mark.timeout(60)


def _run_endless_program(qtbot: Any, link: RobotLink, sim: Any) -> None:
    """Program 1 (the 100 mm square), cycling until stopped, at 20 %."""
    link.submit(RunProgram(1, ProgramMotionMode.CYCLE, 0, 20))
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)


def _fresh_stop(result: object) -> bool:
    return (
        isinstance(result, CommandResult)
        and result.reason is not None
        and result.reason.code == "stop_sent_fresh"
    )


def _a_stop(result: object) -> bool:
    """The Stop's own result (any: the test judges it), not the stopped command's."""
    return isinstance(result, CommandResult) and result.command is None and result.message.startswith("stop")


def _still_running(qtbot: Any, sim: Any) -> None:
    """The program goes on at the simulator (its arm keeps moving): nothing stopped it."""
    pose = sim.state().pose
    qtbot.waitUntil(lambda: sim.state().pose != pose, timeout=SIGNAL_TIMEOUT_MS)
    assert sim.state().program_state == ProgramState.RUNNING


def test_a_stop_after_a_disconnect_reaches_the_controller_over_a_fresh_connection(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    settings = connect(qtbot, link, sim)
    _run_endless_program(qtbot, link, sim)
    with qtbot.waitSignal(link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED)):
        link.disconnect()
    _still_running(qtbot, sim)  # a Disconnect does not stop the robot
    stops_before = len(register_writes(sim, registers.REG_STOP))
    with qtbot.waitSignal(
        link.commandFinished, check_params_cb=_fresh_stop, timeout=SIGNAL_TIMEOUT_MS
    ) as done:
        link.submit(Stop())
    result = done.args[0]
    assert result.ok and result.reason.args == {"endpoint": settings.endpoint}
    assert sim.wait_for(lambda s: s.program_state == ProgramState.STOPPED and not s.moving, 2.0)
    assert [v for _, v in register_writes(sim, registers.REG_STOP)[stops_before:]] == [1]
    text = result_text(result)
    assert (
        text
        == f"Stop sent to {settings.endpoint} over a fresh connection (TeachPad was not connected to it)."
    )
    assert result_level(result) == LEVEL_WARNING
    assert link.connection.state is LinkState.DISCONNECTED  # the stop connection is not the link
    # ... and it was closed (the simulator sees the close a moment after the client made it)
    qtbot.waitUntil(lambda: sim.connections_count == 0, timeout=SIGNAL_TIMEOUT_MS)


def test_a_stop_after_the_link_was_lost_reaches_the_controller_answering_again(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Silenced, the link goes DOWN and waits to reconnect; the controller answers again, but the
    link has not reconnected yet: the Stop goes over a fresh connection all the same."""
    monkeypatch.setattr(timing, "NOT_ANSWERING_DOWN_AFTER", 0.3)
    settings = connect(qtbot, link, sim)
    monkeypatch.setattr(timing, "RECONNECT_BACKOFF", (60.0,))  # no reconnect during the test
    _run_endless_program(qtbot, link, sim)
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.DOWN), timeout=3 * SIGNAL_TIMEOUT_MS
    ):
        sim.set_silent(True)
    sim.set_silent(False)
    _still_running(qtbot, sim)
    with qtbot.waitSignal(
        link.commandFinished, check_params_cb=_fresh_stop, timeout=SIGNAL_TIMEOUT_MS
    ) as done:
        link.submit(Stop())
    assert done.args[0].ok and done.args[0].reason.args["endpoint"] == settings.endpoint
    assert sim.wait_for(lambda s: s.program_state == ProgramState.STOPPED and not s.moving, 2.0)
    assert link.connection.state is LinkState.DOWN  # still waiting for its own reconnect


def test_a_stop_with_the_stop_line_closed_and_the_main_link_wedged_goes_over_a_fresh_connection(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    """The stop line is closed (and stays so) and the main link's answers are held 30 s: the main
    link's stop gets no answer, a fresh connection carries it; the program stops long before the
    held stop could land."""
    settings = connect(qtbot, link, sim)
    worker = link._worker
    qtbot.waitUntil(lambda: worker.stop_line.up, timeout=SIGNAL_TIMEOUT_MS)
    worker.stop_line.enabled = False  # no reopening
    worker.stop_line.close()
    qtbot.waitUntil(lambda: len(sim.connection_ids()) == 1, timeout=SIGNAL_TIMEOUT_MS)
    _run_endless_program(qtbot, link, sim)
    [main] = sim.connection_ids()
    sim.set_response_delay(30.0, connection=main)
    sent = time.monotonic()
    with qtbot.waitSignal(
        link.commandFinished, check_params_cb=_a_stop, timeout=3 * SIGNAL_TIMEOUT_MS
    ) as done:
        link.submit(Stop())
    result = done.args[0]
    assert result.ok and time.monotonic() - sent < 10.0  # long before the held answer (30 s)
    assert sim.wait_for(lambda s: s.program_state == ProgramState.STOPPED, 1.0)
    if result.reason is None:
        # a poll already out when Stop was pressed timed out first: the link went over a new
        # connection of its own (not held) and its stop was answered there -- also the arm stopped
        assert result.message == "stop: sent"
        return
    assert result.reason.code == "stop_sent_fresh" and result.reason.args["endpoint"] == settings.endpoint
    if "cause" in result.reason.args:  # the main link's stop timed out (it was still up)
        assert result.reason.args["cause"] == "no_answer"
        assert "the main connection did not take it" in result_text(result)
        assert "the main connection did not take it" in result_text(result)


def test_a_stop_that_cannot_reach_the_controller_says_so(qtbot: Any, sim: Any, link: RobotLink) -> None:
    settings = connect(qtbot, link, sim)
    _run_endless_program(qtbot, link, sim)
    with qtbot.waitSignal(link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED)):
        link.disconnect()
    sim.set_silent(True)  # it takes the connection, never answers
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as failed:
        link.submit(Stop())
    error = failed.args[0]
    assert isinstance(error, WorkerError) and error.operation == "stop"
    assert error.reason is not None and error.reason.code == "stop_unreachable"
    assert error_text(error) == (
        f"Stop could not reach the controller at {settings.endpoint}: The controller did not answer. "
        "Check the robot."
    )


def test_a_stop_without_any_controller_known_sends_nothing(qtbot: Any, link: RobotLink) -> None:
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as failed:
        link.submit(Stop())
    assert error_text(failed.args[0]) == "Not connected to a controller: nothing was sent."


def test_a_monitor_only_stop_after_a_disconnect_sends_nothing(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim, monitor_only=True)
    with qtbot.waitSignal(link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED)):
        link.disconnect()
    # the simulator sees the close a moment after the client made it
    qtbot.waitUntil(lambda: sim.connections_count == 0, timeout=SIGNAL_TIMEOUT_MS)
    requests = sim.requests_count
    with qtbot.waitSignal(link.errorOccurred, timeout=SIGNAL_TIMEOUT_MS) as failed:
        link.submit(Stop())
    assert error_text(failed.args[0]) == "Monitor-only mode: nothing was sent to the controller."
    assert sim.requests_count == requests and sim.connections_count == 0


def test_motions_in_flight_until_their_outcome(qtbot: Any, sim: Any, link: RobotLink) -> None:
    from app.link.types import StepFrame

    connect(qtbot, link, sim)
    assert not link.motions_in_flight
    with qtbot.waitSignal(link.commandFinished, timeout=SIGNAL_TIMEOUT_MS):
        request_id = link.submit(Step(StepFrame.BASE, (0.0, 0.0, -5.0, 0.0, 0.0, 0.0), speed=50.0))
        assert request_id and link.motions_in_flight == ("step",)
    assert not link.motions_in_flight
