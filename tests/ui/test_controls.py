"""Control bar, Esc, step and program panels, monitor-only, driven through the window."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.ops import RunProgram, Step, Stop
from app.link.types import StepFrame, WorkerError
from app.models import CommandResult
from app.protocol.enums import ControllerMode, ProgramMotionMode, ProgramState, WorkMode
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    register_writes,
    translator_fixture,
    window_fixture,
)

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _ok(predicate: Any = None) -> Any:
    return lambda r: isinstance(r, CommandResult) and r.ok and (predicate is None or predicate(r))


def _connected(qtbot: Any, window: Any, sim: Any, **overrides: Any) -> None:
    connect(qtbot, window.link, sim, **overrides)
    qtbot.waitUntil(lambda: window.control_bar.mode_text() != "", timeout=SIGNAL_TIMEOUT_MS)


def test_escape_and_stop_button_stop_a_running_program(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    assert window.menus.stop_action.shortcut().toString() == "Esc"
    assert window.control_bar.stop_button.isVisible() and window.control_bar.stop_button.isEnabled()
    window.program_panel.id_spin.setValue(2)
    qtbot.mouseClick(window.program_panel.run_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(window.link.commandFinished, check_params_cb=_stop_sent, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.keyClick(window, Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.STOPPED, timeout=SIGNAL_TIMEOUT_MS)
    # each stop: on the stop line when it is open, and on the main link (app/link/stop_line.py)
    first = len(register_writes(sim, 441))
    assert first in (1, 2)
    qtbot.mouseClick(window.program_panel.run_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(window.link.commandFinished, check_params_cb=_stop_sent, timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.STOPPED, timeout=SIGNAL_TIMEOUT_MS)
    assert len(register_writes(sim, 441)) - first in (1, 2)
    assert all(v == 1 for _, v in register_writes(sim, 441))


def _stop_sent(result: Any) -> bool:
    """The stop job is done: both of its writes (line and main link) are at the simulator."""
    return isinstance(result, CommandResult) and result.message == "stop: sent"


def test_pause_and_resume_buttons(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    window.link.submit(RunProgram(1, ProgramMotionMode.CYCLE, 0, 20))
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.mouseClick(window.control_bar.pause_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: sim.state().paused, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(lambda: window.status_panel.program_label.text() == "paused", timeout=SIGNAL_TIMEOUT_MS)
    qtbot.mouseClick(window.control_bar.resume_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: not sim.state().paused and sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    window.link.submit(Stop())
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)


def test_mode_switch_shows_the_controllers_real_mode(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    bar = window.control_bar
    assert bar.mode_text() == "auto" and bar.auto_button.isChecked() and not bar.manual_button.isChecked()
    qtbot.mouseClick(bar.manual_button, Qt.MouseButton.LeftButton)
    # The click alone does not change what is shown: the controller's next status does.
    qtbot.waitUntil(lambda: sim.state().work_mode is WorkMode.MANUAL, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(
        lambda: bar.mode_text() == "manual" and bar.manual_button.isChecked(), timeout=SIGNAL_TIMEOUT_MS
    )
    qtbot.mouseClick(bar.auto_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(
        lambda: bar.mode_text() == "auto" and bar.auto_button.isChecked(), timeout=SIGNAL_TIMEOUT_MS
    )
    assert sim.state().mode == ControllerMode.AUTO


def test_step_preset_and_exact_values(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    panel = window.step_panel
    window.tabs.setCurrentWidget(panel)
    assert panel.frame is StepFrame.JOINT and panel.speed_spin.suffix().strip() == "rpm"
    panel.set_preset(10.0)
    j1 = sim.state().joints[0]
    with qtbot.waitSignal(window.link.commandFinished, check_params_cb=_ok(), timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(panel.plus_buttons[0], Qt.MouseButton.LeftButton)
    assert sim.state().joints[0] == pytest.approx(j1 + 10.0, abs=1e-6)

    panel.set_frame(StepFrame.BASE)
    assert panel.speed_spin.suffix().strip() == "mm/s"
    assert panel.axis_labels[0].text() == "X" and panel.axis_labels[3].text() == "A"  # the unit: in the field
    assert panel.value_spins[0].suffix() == " mm" and panel.value_spins[3].suffix() == " °"
    z = sim.state().pose[2]
    panel.set_values([0.0, 0.0, -25.0])
    asked: list[str] = []

    def answer_no(_title: str, text: str) -> bool:
        asked.append(text)
        return False

    window.confirm = answer_no
    qtbot.mouseClick(panel.move_button, Qt.MouseButton.LeftButton)
    assert asked and "Z -25" in asked[0] and "mm/s" in asked[0]
    window.confirm = lambda _title, _text: True
    with qtbot.waitSignal(window.link.commandFinished, check_params_cb=_ok(), timeout=SIGNAL_TIMEOUT_MS):
        qtbot.mouseClick(panel.move_button, Qt.MouseButton.LeftButton)
    assert sim.state().pose[2] == pytest.approx(z - 25.0, abs=1e-3)
    speeds = [w for w in sim.writes if w.address == 450]
    assert len(speeds) == 2  # GV225 with each move: rpm for the joint step, mm/s for the base one


def test_program_and_go_zero_ask_first(qtbot: Any, sim: Any, window: Any) -> None:
    _connected(qtbot, window, sim)
    panel = window.program_panel
    questions: list[tuple[str, str]] = []

    def answer_no(title: str, text: str) -> bool:
        questions.append((title, text))
        return False

    window.confirm = answer_no
    qtbot.mouseClick(panel.run_button, Qt.MouseButton.LeftButton)
    panel.set_zero_axis(None)
    qtbot.mouseClick(panel.zero_button, Qt.MouseButton.LeftButton)
    assert [title for title, _ in questions] == ["Confirm program run", "Confirm go to zero"]
    assert "all axes" in questions[1][1]
    assert sim.writes == []  # nothing was sent without a yes

    window.confirm = lambda _title, _text: True
    panel.set_zero_axis(1)  # J2 (20 degrees at home) -> 0
    with qtbot.waitSignal(
        window.link.commandFinished,
        check_params_cb=_ok(lambda r: "zero" in r.message),
        timeout=SIGNAL_TIMEOUT_MS,
    ):
        qtbot.mouseClick(panel.zero_button, Qt.MouseButton.LeftButton)
    assert sim.state().joints[1] == pytest.approx(0.0, abs=1e-6)
    assert [v for _, v in register_writes(sim, 445)] == [1]


def test_monitor_only_disables_motion_and_writes_nothing(qtbot: Any, sim: Any, window: Any) -> None:
    errors: list[WorkerError] = []
    window.link.errorOccurred.connect(errors.append)
    _connected(qtbot, window, sim, monitor_only=True)
    assert not window.motion_enabled
    assert not window.jog_panel.axes_box.isEnabled()
    assert not window.step_panel.move_button.isEnabled()
    assert not window.program_panel.run_button.isEnabled()
    assert not window.control_bar.pause_button.isEnabled()
    assert window.control_bar.stop_button.isEnabled()  # Stop stays reachable
    assert window.motion_banner.isVisibleTo(window) and "Monitor only" in window.motion_banner.text()
    assert window.status_monitor_only.text() == "MONITOR ONLY"
    qtbot.mousePress(window.jog_panel.button(0, 1), Qt.MouseButton.LeftButton)  # disabled: nothing
    qtbot.mouseRelease(window.jog_panel.button(0, 1), Qt.MouseButton.LeftButton)
    window.link.submit(Step(StepFrame.JOINT, [1.0, 0, 0, 0, 0, 0]))  # behind the GUI's back
    qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)
    # the step's and the Stop's refusals (a poll that times out under load may add its own error)
    qtbot.waitUntil(lambda: {e.operation for e in errors} >= {"step", "stop"}, timeout=SIGNAL_TIMEOUT_MS)
    refused = [e for e in errors if e.operation in ("step", "stop")]
    assert all("monitor-only" in e.message for e in refused), [(e.operation, e.message) for e in errors]
    window.close()
    assert sim.writes == []


def test_motion_disabled_until_connected(qtbot: Any, sim: Any, window: Any) -> None:
    assert not window.motion_enabled and not window.jog_panel.axes_box.isEnabled()
    assert "Not connected" in window.motion_banner.text()
    _connected(qtbot, window, sim)
    assert window.motion_enabled and window.jog_panel.axes_box.isEnabled()
    assert not window.motion_banner.isVisibleTo(window)
