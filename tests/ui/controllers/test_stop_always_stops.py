"""Stop always stops, in the window (issue 18): Disconnect during a running program, then STOP
(it reaches the controller); Disconnect and the close ask "stop first?" only when something is
under way (Cancel keeps the connection); Reconnect is any role's, another controller the
administrator's. Against the real simulator, asserted at the simulator."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.ops import RunProgram, Step, Stop
from app.link.types import LinkState, StepFrame
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, ProgramState
from app.safety.audit_read import query
from app.safety.roles import REQUIRED_ROLE, Action, Role
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    connection_settings,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
    project_dialogs_fixture,
    register_writes,
    translator_fixture,
    window_fixture,
)
from ui.controllers.link_guard import MOVING_WINDOW
from ui.dialogs.stop_first import StopFirst, StopFirstQuestion, stop_first_box

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


class Answers:
    """Answers "stop first?" with ``answer`` and keeps every question asked."""

    def __init__(self, answer: StopFirst) -> None:
        self.answer = answer
        self.asked: list[StopFirstQuestion] = []

    def __call__(self, question: StopFirstQuestion) -> StopFirst:
        self.asked.append(question)
        return self.answer


def _connected(qtbot: Any, window: Any, sim: Any) -> Any:
    settings = connect(qtbot, window.link, sim)
    qtbot.waitUntil(lambda: window.link.state.status is not None, timeout=SIGNAL_TIMEOUT_MS)
    return settings


def _program_running(qtbot: Any, window: Any, sim: Any) -> None:
    """Program 1 cycling until stopped, at 20 %, seen running by the window too."""
    window.link.submit(RunProgram(1, ProgramMotionMode.CYCLE, 0, 20))
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    status = window.link.state
    qtbot.waitUntil(
        lambda: status.status is not None and status.status.program_state == ProgramState.RUNNING,
        timeout=SIGNAL_TIMEOUT_MS,
    )


def _idle(qtbot: Any, window: Any) -> None:
    """Nothing under way as the window sees it: the last motion is older than the moving window."""
    qtbot.waitUntil(lambda: window.link_guard.under_way.items() == [], timeout=SIGNAL_TIMEOUT_MS)


def _disconnect(qtbot: Any, window: Any) -> None:
    with qtbot.waitSignal(
        window.link.connectionChanged,
        check_params_cb=is_state(LinkState.DISCONNECTED),
        timeout=SIGNAL_TIMEOUT_MS,
    ):
        window.menus.disconnect_action.trigger()


def _a_new_poll(qtbot: Any, window: Any) -> None:
    """The worker went on polling (what was queued before has run)."""
    with qtbot.waitSignal(window.link.state.poseChanged, timeout=SIGNAL_TIMEOUT_MS):
        pass


def test_disconnect_during_a_program_then_stop_reaches_the_controller(
    qtbot: Any, sim: Any, window: Any
) -> None:
    settings = _connected(qtbot, window, sim)
    _program_running(qtbot, window, sim)
    answers = window.link_guard.ask = Answers(StopFirst.LEAVE)
    _disconnect(qtbot, window)
    [question] = answers.asked  # it asked, naming what runs and where
    assert question.title == "Disconnect" and settings.endpoint in question.text
    assert "a program is running" in question.text and question.stop_label == "Stop, then disconnect"
    pose = sim.state().pose
    qtbot.waitUntil(lambda: sim.state().pose != pose, timeout=SIGNAL_TIMEOUT_MS)  # it runs on
    assert sim.state().program_state == ProgramState.RUNNING
    stops = len(register_writes(sim, registers.REG_STOP))
    assert window.control_bar.stop_button.isEnabled()

    def fresh(result: object) -> bool:
        return isinstance(result, CommandResult) and result.ok and result.reason is not None

    with qtbot.waitSignal(window.link.commandFinished, check_params_cb=fresh, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)
    assert sim.wait_for(lambda s: s.program_state == ProgramState.STOPPED and not s.moving, 2.0)
    assert [v for _, v in register_writes(sim, registers.REG_STOP)[stops:]] == [1]
    said = f"Stop sent to {settings.endpoint} over a fresh connection"
    qtbot.waitUntil(
        lambda: any(said in e.text for e in window.event_log.model.events()), timeout=SIGNAL_TIMEOUT_MS
    )


def test_disconnect_asks_only_while_something_is_under_way_and_cancel_keeps_the_link(
    qtbot: Any, sim: Any, window: Any
) -> None:
    _connected(qtbot, window, sim)
    answers = window.link_guard.ask = Answers(StopFirst.CANCEL)
    _idle(qtbot, window)
    _disconnect(qtbot, window)  # nothing under way: no question
    assert answers.asked == []

    _connected(qtbot, window, sim)
    _program_running(qtbot, window, sim)
    window.menus.disconnect_action.trigger()
    assert len(answers.asked) == 1  # cancelled: the link stays, the program runs
    _a_new_poll(qtbot, window)
    assert window.link.state.connection.state is LinkState.CONNECTED
    assert sim.state().program_state == ProgramState.RUNNING

    answers.answer = StopFirst.STOP
    stops = len(register_writes(sim, registers.REG_STOP))
    _disconnect(qtbot, window)
    assert len(answers.asked) == 2
    assert sim.wait_for(lambda s: s.program_state == ProgramState.STOPPED, 2.0)
    assert len(register_writes(sim, registers.REG_STOP)) > stops  # the stop went before the link closed


def test_disconnect_names_a_move_in_flight(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    answers = window.link_guard.ask = Answers(StopFirst.CANCEL)
    window.link.submit(Step(StepFrame.BASE, (0.0, 0.0, -60.0, 0.0, 0.0, 0.0), speed=20.0))  # 3 s
    assert window.link.motions_in_flight == ("step",)
    window.menus.disconnect_action.trigger()
    [question] = answers.asked
    assert "incremental move: under way" in question.text
    qtbot.waitUntil(lambda: sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(lambda: window.link_guard.under_way.pose_moving(), timeout=SIGNAL_TIMEOUT_MS)
    window.link.submit(Stop())
    qtbot.waitUntil(lambda: window.link.motions_in_flight == (), timeout=SIGNAL_TIMEOUT_MS)
    assert sim.wait_for(lambda s: not s.moving, 2.0)
    _idle(qtbot, window)  # (the close at the teardown asks nothing: Cancel would keep the window)


def test_closing_the_window_during_a_program_asks_and_stops(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    _program_running(qtbot, window, sim)
    answers = window.link_guard.ask = Answers(StopFirst.CANCEL)
    assert not window.close()  # cancelled: the window, the link and the program stay
    [question] = answers.asked
    assert question.title == "Close TeachPad" and "a program is running" in question.text
    assert window.isVisible()
    _a_new_poll(qtbot, window)
    assert window.link.state.connection.state is LinkState.CONNECTED
    assert sim.state().program_state == ProgramState.RUNNING
    answers.answer = StopFirst.STOP
    stops = len(register_writes(sim, registers.REG_STOP))
    assert window.close()
    assert sim.wait_for(lambda s: s.program_state == ProgramState.STOPPED and not s.moving, 2.0)
    assert len(register_writes(sim, registers.REG_STOP)) > stops


def test_closing_the_window_leaving_the_program_running(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    _program_running(qtbot, window, sim)
    window.link_guard.ask = Answers(StopFirst.LEAVE)
    stops = len(register_writes(sim, registers.REG_STOP))
    assert window.close()
    pose = sim.state().pose
    qtbot.waitUntil(lambda: sim.state().pose != pose, timeout=SIGNAL_TIMEOUT_MS)
    assert sim.state().program_state == ProgramState.RUNNING
    assert len(register_writes(sim, registers.REG_STOP)) == stops


def test_closing_an_idle_window_asks_nothing(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    answers = window.link_guard.ask = Answers(StopFirst.CANCEL)
    _idle(qtbot, window)
    assert window.close() and answers.asked == []


def test_an_unattended_close_stops_a_running_program(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    _program_running(qtbot, window, sim)
    answers = window.link_guard.ask = Answers(StopFirst.LEAVE)
    assert window.close_unattended()
    assert answers.asked == []
    assert sim.wait_for(lambda s: s.program_state == ProgramState.STOPPED, 2.0)


def test_an_operator_reconnects_to_the_same_controller_not_to_another(
    qtbot: Any, sim_factory: Any, window: Any
) -> None:
    sim = sim_factory()
    other = sim_factory()
    safety = window.safety_menu.safety
    assert safety.role is Role.OPERATOR and REQUIRED_ROLE[Action.RECONNECT] is Role.OPERATOR
    menus = window.menus
    settings = _connected(qtbot, window, sim)
    assert not menus.reconnect_action.isEnabled()  # connected: nothing to reconnect
    _disconnect(qtbot, window)
    # the remembered connection names another controller (saved by an administrator, say): the
    # reconnect goes to this session's last one all the same
    window.settings.save_connection(connection_settings(other))
    assert menus.reconnect_action.isEnabled() and menus.reconnect_action in menus.file_menu.actions()
    with qtbot.waitSignal(
        window.link.connectionChanged,
        check_params_cb=is_state(LinkState.CONNECTED),
        timeout=SIGNAL_TIMEOUT_MS,
    ):
        menus.reconnect_action.trigger()
    assert window.link.settings == settings and sim.connections_count >= 1
    assert other.connections_count == 0
    # another controller: Connect... stays the administrator's (greyed, and refused if reached)
    assert not menus.connect_action.isEnabled() and "administrator" in menus.connect_action.toolTip()
    window.open_connection_dialog()
    refused = [r for r in query(safety.audit_dir) if r.result == "refused"]
    assert refused and refused[-1].command == "change connection"
    assert other.connections_count == 0 and window.link.settings == settings


def test_the_stop_first_box_defaults_to_stop_and_escapes_to_cancel(qtbot: Any) -> None:
    question = StopFirstQuestion(
        "Disconnect", "Under way", "Stop, then disconnect", "Disconnect without stopping"
    )
    box, answers = stop_first_box(None, question)
    qtbot.addWidget(box)
    assert answers[box.defaultButton()] is StopFirst.STOP
    assert answers[box.escapeButton()] is StopFirst.CANCEL
    assert sorted(b.text() for b in box.buttons() if answers[b] is not StopFirst.CANCEL) == [
        "Disconnect without stopping",
        "Stop, then disconnect",
    ]
    assert MOVING_WINDOW > 0
