"""A Stop asked after the point guard's create was answered, before its move was requested.

The guarded moves (the points table's *Move to point*, each segment of a plan run) are a chain:
the worker creates the points, its answer crosses to the GUI thread, and only then is the move
requested. The worker's Stop cancels the motions queued *before* it; the move of a chain is
requested after it. The window's STOP pressed in between must end the chain: no move reaches the
controller (asserted at the simulator: no 0x42 in its write log of register 440, the arm still).

The gap is made deterministic: the test waits (on the GUI thread, without processing its events)
until the worker has emitted the create's answer, then presses STOP, then lets the answer in.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.robot_link import RobotLink
from app.models import CommandResult
from app.plan.segments import Plan, Segment
from app.protocol.enums import RunCommand
from app.protocol.registers import REG_RUN_COMMAND
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    project_dialogs_fixture,
    register_writes,
    step_by_link,
    teach_here,
    translator_fixture,
    window_fixture,
)
from ui.main_window import TAB_POINTS, MainWindow

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

MOVE, CREATE = int(RunCommand.MOVE_TO_POINT), int(RunCommand.CREATE_POINT)
ANSWER_WAIT_S = 20.0  # the worker's answer to the create (a condition, not a pause)


@pytest.fixture(name="sim")
def writable_sim_fixture(sim_factory: Any) -> Any:
    return sim_factory(gv291="writable")


@pytest.fixture(name="link")
def link_fixture(qapp: Any) -> Iterator[RobotLink]:
    robot_link = RobotLink()
    yield robot_link
    robot_link.shutdown()


def _teach_away(qtbot: Any, window: MainWindow, sim: Any) -> tuple[float, ...]:
    """P1 taught 40 mm along X from here, then the arm stepped back: P1 is 40 mm away."""
    connect(qtbot, window.link, sim)
    window.work_tabs.setCurrentIndex(TAB_POINTS)
    step_by_link(qtbot, window.link, 40.0)
    teach_here(qtbot, window.point_sync)
    step_by_link(qtbot, window.link, -40.0)
    return tuple(sim.state().pose)


def _on_next_answer(link: RobotLink) -> threading.Event:
    """Set (on the worker thread) when the worker emits its next command result."""
    answered = threading.Event()
    worker = link._made  # the worker's own signal, heard on the thread that emits it
    assert worker is not None

    def heard(_result: CommandResult) -> None:
        answered.set()

    worker.commandFinished.connect(heard, Qt.ConnectionType.DirectConnection)
    return answered


def _moves_after(sim: Any, index: int) -> list[int]:
    return [value for at, value in register_writes(sim, REG_RUN_COMMAND) if at > index and value == MOVE]


def test_stop_after_the_create_answer_sends_no_move_to_point(
    qtbot: Any, window: MainWindow, sim: Any
) -> None:
    before = _teach_away(qtbot, window, sim)
    mark = len(sim.writes)
    answered = _on_next_answer(window.link)
    assert window.point_sync.move_to(1, 50.0)
    assert answered.wait(ANSWER_WAIT_S)  # the create's answer is on its way to the GUI thread
    assert [v for at, v in register_writes(sim, REG_RUN_COMMAND) if at >= mark] == [CREATE]
    with qtbot.waitSignal(window.point_sync.moveFinished, timeout=SIGNAL_TIMEOUT_MS) as finished:
        window.control_bar.stop_button.click()  # the window's STOP, not the points panel's
    assert finished.args == [False, "stopped"]
    qtbot.waitUntil(lambda: any(w.address == 441 for w in list(sim.writes)[mark:]), timeout=SIGNAL_TIMEOUT_MS)
    stop_at = max(i for i, w in enumerate(list(sim.writes)) if w.address == 441)
    assert _moves_after(sim, mark) == [], "the move went out after the operator's Stop"
    assert stop_at > mark
    assert math.dist(sim.state().pose[:3], before[:3]) < 0.01  # the arm never moved


def test_stop_after_a_segment_create_answer_ends_the_plan_run_unmoved(
    qtbot: Any, window: MainWindow, sim: Any
) -> None:
    """The same gap in a plan run: the window's STOP (not the planner's) ends the run stopped."""
    before = _teach_away(qtbot, window, sim)
    plan = Plan("to P1", [Segment.line(1, 50.0)])
    mark = len(sim.writes)
    answered = _on_next_answer(window.link)
    run = window.run_controller
    run.start(plan)
    assert answered.wait(ANSWER_WAIT_S)
    with qtbot.waitSignal(run.runningChanged, check_params_cb=lambda on: not on, timeout=SIGNAL_TIMEOUT_MS):
        window.control_bar.stop_button.click()
    assert "stopped" in run.end_reason.lower() or "停止" in run.end_reason
    assert run.sent_segments == []
    assert _moves_after(sim, mark) == []
    assert math.dist(sim.state().pose[:3], before[:3]) < 0.01
