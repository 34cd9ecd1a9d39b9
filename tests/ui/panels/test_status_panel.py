"""StatusPanel: words and colours for mode, program, alarms, command results, clock and link."""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, QTranslator

from app.link.types import ConnectionState, LinkState
from app.models import CommandResult, ControllerStatus
from app.protocol.datetime_regs import ControllerClock, decode_clock, encode_clock
from app.protocol.enums import (
    Alarm,
    CommandKind,
    CommandStatus,
    ControllerMode,
    ProgramState,
    RunCommand,
)
from ui.palette import COLOR_ERROR, COLOR_OK, COLOR_WARN
from ui.panels.status_panel import StatusPanel
from ui.widgets_common import LEVEL_ERROR, LEVEL_OFF, LEVEL_OK, LEVEL_WARN


def status(
    mode: ControllerMode | int = ControllerMode.AUTO,
    program: ProgramState | int = ProgramState.STOPPED,
    alarms: int = 0,
    clock: ControllerClock | None = None,
) -> ControllerStatus:
    return ControllerStatus(mode, program, Alarm(alarms), 0xFF, clock)


@pytest.fixture
def panel(qtbot: Any) -> Iterator[StatusPanel]:
    widget = StatusPanel()
    qtbot.addWidget(widget)
    yield widget


@pytest.mark.parametrize(
    ("mode", "text", "level"),
    [
        (ControllerMode.MANUAL, "manual", LEVEL_OFF),
        (ControllerMode.AUTO, "auto", "info"),
        (ControllerMode.MODBUS_TEACH, "Modbus teach", LEVEL_WARN),
        (7, "unknown status 7", LEVEL_ERROR),
    ],
)
def test_mode_in_words(panel: StatusPanel, mode: int, text: str, level: str) -> None:
    panel.on_status(status(mode=mode))
    assert panel.mode_label.text() == text
    assert panel.mode_label.level() == level


@pytest.mark.parametrize(
    ("state", "text", "level"),
    [
        (ProgramState.STOPPED, "stopped", LEVEL_OFF),
        (ProgramState.RUNNING, "running", LEVEL_OK),
        (ProgramState.PAUSED, "paused", LEVEL_WARN),
        (9, "unknown status 9", LEVEL_ERROR),
    ],
)
def test_program_state_in_words(panel: StatusPanel, state: int, text: str, level: str) -> None:
    panel.on_status(status(program=state))
    assert panel.program_label.text() == text
    assert panel.program_label.level() == level


def test_one_lamp_per_alarm_bit_red_when_set(panel: StatusPanel) -> None:
    texts = {bit: lamp.text() for bit, lamp in panel.alarm_lamps.items()}
    assert texts == {
        Alarm.ESTOP: "emergency stop",
        Alarm.SERVO: "servo alarm",
        Alarm.BRAKE: "brake alarm",
        Alarm.ALGORITHM: "algorithm alarm",
        Alarm.ENCODER: "encoder angle alarm",
    }
    panel.on_status(status(alarms=Alarm.ESTOP | Alarm.ENCODER))
    for bit, lamp in panel.alarm_lamps.items():
        on = bit in (Alarm.ESTOP, Alarm.ENCODER)
        assert lamp.is_active() is on
        assert lamp.property("active") is on
        assert lamp.property("level") == (LEVEL_ERROR if on else LEVEL_OFF)
        assert (COLOR_ERROR in lamp.styleSheet()) is on
    assert not panel.other_alarm_lamp.is_active()
    panel.on_status(status(alarms=0))
    assert not any(lamp.is_active() for lamp in panel.alarm_lamps.values())


def test_unknown_alarm_bits_light_their_own_lamp(panel: StatusPanel) -> None:
    panel.on_status(status(alarms=Alarm.SERVO | (1 << 6) | (1 << 9)))
    assert panel.alarm_lamp_for(Alarm.SERVO).is_active()
    assert panel.other_alarm_lamp.is_active()
    assert panel.other_alarm_lamp.text() == "other bits: 6, 9"
    panel.on_alarms(0)
    assert not panel.other_alarm_lamp.is_active()
    assert panel.other_alarm_lamp.text() == "other bits"


def test_command_ok_is_green_and_decoded_by_kind(panel: StatusPanel) -> None:
    panel.on_command_result(
        CommandResult(
            RunCommand.TEACH_ENABLE, CommandKind.TEACH, CommandStatus(CommandKind.TEACH, 0xFF), True
        )
    )
    assert panel.command_label.text() == "teach enable: success."
    assert panel.command_label.property("ok") is True
    assert COLOR_OK in panel.command_label.styleSheet()


@pytest.mark.parametrize(
    ("command", "kind", "code", "text"),
    [
        (
            RunCommand.STEP_JOINT,
            CommandKind.MOVE,
            1,
            "incremental move (joint) refused by the controller: work mode error.",
        ),
        (
            RunCommand.CREATE_POINT,
            CommandKind.CREATE_POINT,
            1,
            "create temp point refused by the controller: bad point id.",
        ),
        (
            RunCommand.TEACH_DISABLE,
            CommandKind.TEACH,
            7,
            "teach disable refused by the controller: teach speed ratio not zero: enable/disable refused.",
        ),
        (
            RunCommand.MOVE_TO_POINT,
            CommandKind.MOVE,
            99,
            "move to temp point refused by the controller: unknown status 99.",
        ),
    ],
)
def test_command_error_is_red_and_decoded_by_kind(
    panel: StatusPanel, command: RunCommand, kind: CommandKind, code: int, text: str
) -> None:
    panel.on_command_result(CommandResult(command, kind, CommandStatus(kind, code), False))
    assert panel.command_label.text() == text
    assert panel.command_label.property("ok") is False
    assert COLOR_ERROR in panel.command_label.styleSheet()
    assert str(code) in panel.command_label.toolTip()


def test_command_without_status_uses_ok_and_message(panel: StatusPanel) -> None:
    panel.on_command_result(CommandResult(RunCommand.RUN_PROGRAM, None, None, False, "link lost"))
    assert panel.command_label.text() == "Failed: link lost"


def test_an_operators_stop_is_not_shown_as_a_failure(panel: StatusPanel) -> None:
    from app.errors import Reason

    panel.on_command_result(
        CommandResult(
            RunCommand.MOVE_TO_POINT,
            CommandKind.MOVE,
            CommandStatus(CommandKind.MOVE, 0),
            False,
            "move to temp point stopped by the operator",
            reason=Reason("stopped_by_operator", {"command": int(RunCommand.MOVE_TO_POINT)}),
        )
    )
    assert "stopped by the operator" in panel.command_label.text()
    assert COLOR_ERROR not in panel.command_label.styleSheet()


def test_clock_and_drift(panel: StatusPanel) -> None:
    controller = dt.datetime(2025, 3, 4, 5, 6, 7)
    clock = decode_clock(encode_clock(controller))
    panel.on_clock(clock, now=controller - dt.timedelta(seconds=3.2))
    assert panel.clock_label.text() == "2025-03-04 05:06:07"
    assert panel.drift_label.text() == "+3 s"
    assert panel.drift_label.property("drift") == pytest.approx(3.2)
    assert COLOR_OK in panel.drift_label.styleSheet()
    assert "07E9 0304 0005 0607" in panel.clock_label.toolTip()
    assert "576..579" in panel.clock_label.toolTip()

    panel.on_clock(clock, now=controller + dt.timedelta(seconds=42))
    assert panel.drift_label.text() == "-42 s"
    assert COLOR_WARN in panel.drift_label.styleSheet()
    panel.on_clock(clock, now=controller + dt.timedelta(hours=1))
    assert COLOR_ERROR in panel.drift_label.styleSheet()
    panel.on_clock(clock, now=controller + dt.timedelta(seconds=0.4))
    assert panel.drift_label.text() == "+0 s"  # not "-0 s"


def test_clock_arrives_with_the_status(panel: StatusPanel) -> None:
    controller = dt.datetime.now().replace(microsecond=0)
    panel.on_status(status(clock=decode_clock(encode_clock(controller))))
    assert panel.clock_label.text() == controller.strftime("%Y-%m-%d %H:%M:%S")
    assert abs(panel.drift_label.property("drift")) < 5


def test_invalid_clock_shows_raw_words(panel: StatusPanel) -> None:
    clock = decode_clock([2025, 0x0D20, 25, 0])  # month 13
    assert clock.value is None
    panel.on_clock(clock)
    assert panel.clock_label.text() == "invalid date/time"
    assert COLOR_ERROR in panel.clock_label.styleSheet()
    assert "07E9 0D20 0019 0000" in panel.clock_label.toolTip()
    assert panel.drift_label.text() == "—"


@pytest.mark.parametrize(
    ("state", "text", "level"),
    [
        (LinkState.CONNECTED, "connected", LEVEL_OK),
        (LinkState.CONNECTING, "connecting", LEVEL_WARN),
        (LinkState.NOT_ANSWERING, "not answering", LEVEL_WARN),
        (LinkState.DOWN, "link down", LEVEL_ERROR),
        (LinkState.DISCONNECTED, "disconnected", LEVEL_OFF),
    ],
)
def test_link_state(panel: StatusPanel, state: LinkState, text: str, level: str) -> None:
    panel.on_connection(ConnectionState(state, "no answer", "10.0.0.5:502"))
    assert panel.link_lamp.text() == text
    assert panel.link_lamp.level() == level
    assert panel.link_message.text() == "10.0.0.5:502 — no answer"


def test_monitor_only_is_shown(panel: StatusPanel) -> None:
    panel.on_connection(ConnectionState(LinkState.CONNECTED, "", "127.0.0.1:502", monitor_only=True))
    assert panel.link_message.text() == "127.0.0.1:502 — monitor only: writes blocked"


def test_rtt(panel: StatusPanel) -> None:
    panel.on_rtt(1.26)
    assert panel.rtt_label.text() == "1.3 ms"
    panel.on_rtt(float("nan"))
    assert panel.rtt_label.text() == "—"


class _Upper(QTranslator):
    """Translates the protocol texts to upper case, to prove they go through translate()."""

    def translate(self, context: str, source: str, disambiguation: str | None = None, n: int = -1) -> str:
        return source.upper() if context == "Protocol" else ""

    def isEmpty(self) -> bool:
        return False


def test_language_change_redraws_everything(qtbot: Any, panel: StatusPanel) -> None:
    panel.on_status(
        status(mode=ControllerMode.MODBUS_TEACH, program=ProgramState.RUNNING, alarms=Alarm.BRAKE)
    )
    assert panel.mode_label.text() == "Modbus teach"
    translator = _Upper()
    app = QCoreApplication.instance()
    assert app is not None
    app.installTranslator(translator)  # Qt sends LanguageChange to every widget
    try:
        qtbot.waitUntil(lambda: panel.mode_label.text() == "MODBUS TEACH", timeout=2000)
        assert panel.program_label.text() == "RUNNING"
        assert panel.alarm_lamp_for(Alarm.BRAKE).text() == "BRAKE ALARM"
        assert panel.alarm_lamp_for(Alarm.BRAKE).is_active()
    finally:
        app.removeTranslator(translator)
    qtbot.waitUntil(lambda: panel.mode_label.text() == "Modbus teach", timeout=2000)
