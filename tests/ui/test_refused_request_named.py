"""A Pause, a Resume or a Manual/Auto switch the controller refuses (a Modbus exception: 6, busy)
names the command that was refused and says what to do, in both languages -- like the other
refusals ("Stop could not reach ...", "{command} not sent: ..."), not the anonymous "The controller
refused the request: Modbus exception 6". Pressed in the window at the simulator, which answers
that one register with exception 6: the simulator answered the request with the exception, did not
store it, and its state shows the command was not carried out (the program still running, still
paused, the mode unchanged). The words: the status dock's *Last command* and the event log."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from pymodbus.constants import ExcCodes
from PySide6.QtCore import Qt

from app.link.ops import Pause, RunProgram, Stop
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, ProgramState, WorkMode
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.main_window import MainWindow

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def _refused(
    window: MainWindow, sim: Any, qtbot: Any, address: int, press: Callable[[], None]
) -> CommandResult:
    """``press`` with the simulator answering ``address`` with exception 6: the failed result, once
    the simulator answered that request with the exception (its log of refused writes) and stored
    nothing at ``address``."""
    refused, writes = len(sim.refused_writes()), len(sim.writes_to(address))
    sim.set_exception(ExcCodes.DEVICE_BUSY, range(address, address + 1))
    try:
        with qtbot.waitSignal(
            window.link.commandFinished, check_params_cb=lambda r: not r.ok, timeout=SIGNAL_TIMEOUT_MS
        ) as finished:
            press()
    finally:
        sim.set_exception(None)
    # the simulator's log: that write answered with exception 6, and not stored
    assert [e.detail for e in sim.refused_writes()[refused:]] == [
        f"write fc=0x06 address={address}: exception 6"
    ]
    assert len(sim.writes_to(address)) == writes  # and did not carry it out
    result: CommandResult = finished.args[0]
    return result


def _said(window: MainWindow, qtbot: Any, start: str) -> str:
    """The refusal in *Last command* and the event log (as an error), starting with ``start``."""
    label = window.status_panel.command_label
    qtbot.waitUntil(lambda: label.text().startswith(start), timeout=SIGNAL_TIMEOUT_MS)
    logged = [e for e in window.event_log.model.events() if e.text == label.text()]
    assert [e.level for e in logged] == ["error"], label.text()
    return label.text()


def _in_chinese(window: MainWindow, start: str) -> str:
    window.set_language("zh_CN")
    label = window.status_panel.command_label
    assert label.text().startswith(start), label.text()
    assert_chinese(label.text())
    assert any(e.text == label.text() for e in window.event_log.model.events())
    return label.text()


def _run_program(qtbot: Any, window: MainWindow, sim: Any) -> None:
    connect(qtbot, window.link, sim)
    qtbot.waitUntil(lambda: window.control_bar.mode_text() != "", timeout=SIGNAL_TIMEOUT_MS)
    window.link.submit(RunProgram(1, ProgramMotionMode.CYCLE, 0, 20))
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)


def test_a_refused_pause_names_pause_says_to_press_stop_and_is_sent_again(
    qtbot: Any, sim: Any, window: MainWindow
) -> None:
    """A Pause the controller answers "busy" during a program: the window says "Pausing — the
    controller has not confirmed; press STOP" while the simulator's program runs on, sends it again
    (app/link/halt.py), and says the Pause was confirmed once the simulator paused."""
    _run_program(qtbot, window, sim)
    bar, hold = window.control_bar, window.jog_panel.hold_label
    refused = len(sim.refused_writes())
    sim.set_exception(ExcCodes.DEVICE_BUSY, range(registers.REG_PAUSE, registers.REG_PAUSE + 1), seconds=1.0)
    qtbot.mouseClick(bar.pause_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: hold.text().startswith("Pausing"), timeout=SIGNAL_TIMEOUT_MS)
    assert "press STOP" in hold.text(), hold.text()
    assert sim.refused_writes()[refused].detail == f"write fc=0x06 address={registers.REG_PAUSE}: exception 6"
    assert sim.state().program_state == ProgramState.RUNNING  # refused: not paused at the simulator
    window.set_language("zh_CN")
    assert_chinese(hold.text())
    qtbot.waitUntil(lambda: sim.state().paused, timeout=SIGNAL_TIMEOUT_MS)  # sent again: paused
    label = window.status_panel.command_label
    qtbot.waitUntil(lambda: "暂停" in label.text(), timeout=SIGNAL_TIMEOUT_MS)
    window.set_language("en")
    assert label.text().startswith("Pause confirmed by the controller"), label.text()
    assert not sim.writes_to(registers.REG_STOP)  # a busy second is not a Stop: resumable
    window.link.submit(Stop())
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)


def test_a_refused_resume_names_resume(qtbot: Any, sim: Any, window: MainWindow) -> None:
    _run_program(qtbot, window, sim)
    window.link.submit(Pause())
    qtbot.waitUntil(lambda: sim.state().paused, timeout=SIGNAL_TIMEOUT_MS)
    bar = window.control_bar
    _refused(
        window,
        sim,
        qtbot,
        registers.REG_RESUME,
        lambda: qtbot.mouseClick(bar.resume_button, Qt.MouseButton.LeftButton),
    )
    assert sim.state().paused  # still paused at the simulator
    text = _said(window, qtbot, "Resume refused by the controller (Modbus exception 6, server device busy)")
    assert "Press Resume again" in text, text
    _in_chinese(window, "控制器拒绝了继续（Modbus 异常 6，从站设备忙）")
    window.link.submit(Stop())
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)


@pytest.mark.parametrize(
    ("mode", "word", "chinese"), [(WorkMode.MANUAL, "manual", "手动"), (WorkMode.AUTO, "auto", "自动")]
)
def test_a_refused_mode_switch_names_the_mode(
    qtbot: Any, sim: Any, window: MainWindow, mode: WorkMode, word: str, chinese: str
) -> None:
    connect(qtbot, window.link, sim)
    bar = window.control_bar
    qtbot.waitUntil(lambda: bar.mode_text() != "", timeout=SIGNAL_TIMEOUT_MS)
    if mode is WorkMode.AUTO:  # from manual
        qtbot.mouseClick(bar.manual_button, Qt.MouseButton.LeftButton)
        qtbot.waitUntil(lambda: bar.mode_text() == "manual", timeout=SIGNAL_TIMEOUT_MS)
    before = sim.state().work_mode
    assert before is not mode
    button = bar.manual_button if mode is WorkMode.MANUAL else bar.auto_button
    _refused(
        window,
        sim,
        qtbot,
        registers.REG_WORK_MODE,
        lambda: qtbot.mouseClick(button, Qt.MouseButton.LeftButton),
    )
    assert sim.state().work_mode is before  # the mode did not change at the simulator
    text = _said(
        window,
        qtbot,
        f"Switch to {word} mode refused by the controller (Modbus exception 6, server device busy)",
    )
    assert "the work mode did not change" in text, text
    _in_chinese(window, f"控制器拒绝了切换到{chinese}模式（Modbus 异常 6，从站设备忙）")


def test_any_named_request_refused_says_which_and_the_bare_sentences_read(translator: Any) -> None:
    """Another request the controller refuses reads with its name; a reason without the
    exception's number falls back to the short sentence, still naming the command."""
    from app.errors import Reason
    from ui.messages import reason_text

    other = Reason("modbus_exception", {"function": 6, "exception": 6, "operation": "teach disable"})
    bare = Reason("modbus_exception", {"operation": "set mode"})
    assert (
        reason_text(other)
        == "teach disable refused by the controller: Modbus exception 6 (server device busy)."
    )
    assert reason_text(bare) == (
        "Work mode change refused by the controller: the work mode did not change. "
        "Switch it again in a moment."
    )
    assert translator.set_language("zh_CN")
    for reason in (other, bare):
        text = reason_text(reason)
        assert text is not None
        assert_chinese(text)
