"""Enums, alarm bits and the GV291 status tables (app/protocol/enums.py)."""

from __future__ import annotations

import enum

import pytest

from app.protocol.codec import WordOrder, float_to_registers
from app.protocol.enums import (
    ALARM_BITS,
    ALARM_MASK,
    CONTROLLER_MODE_TEXT,
    CREATE_POINT_STATUS_TEXT,
    MOVE_STATUS_TEXT,
    PROGRAM_MOTION_MODE_TEXT,
    PROGRAM_STATE_TEXT,
    QT_TRANSLATE_NOOP,
    RUN_COMMAND_TEXT,
    STATUS_DONE,
    STATUS_INITIAL,
    TEACH_FRAME_TEXT,
    TEACH_STATUS_TEXT,
    Alarm,
    CommandKind,
    CommandStatus,
    ControllerMode,
    CreatePointStatus,
    MoveStatus,
    ProgramMotionMode,
    ProgramState,
    RunCommand,
    TeachFrame,
    TeachStatus,
    WorkMode,
    alarm_names,
    controller_mode_text,
    decode_command_status,
    decode_status_registers,
    program_state_text,
)


def test_enum_values_follow_the_tables() -> None:
    assert [int(c) for c in RunCommand] == [0x01, 0x40, 0x41, 0x42, 0x80, 0x81, 0xE0]
    assert (WorkMode.MANUAL, WorkMode.AUTO) == (0, 1)
    assert [int(m) for m in ControllerMode] == [0, 1, 2]
    assert [int(s) for s in ProgramState] == [0, 1, 2]
    assert [int(m) for m in ProgramMotionMode] == [0, 1, 2]
    assert [int(f) for f in TeachFrame] == [0, 1, 2, 3]
    assert [int(a) for a in ALARM_BITS] == [1, 2, 4, 8, 16]
    assert ALARM_MASK == 0x1F
    assert (STATUS_INITIAL, STATUS_DONE) == (0, 0xFF)


@pytest.mark.parametrize(
    ("table", "enum_type"),
    [
        (RUN_COMMAND_TEXT, RunCommand),
        (CONTROLLER_MODE_TEXT, ControllerMode),
        (PROGRAM_STATE_TEXT, ProgramState),
        (PROGRAM_MOTION_MODE_TEXT, ProgramMotionMode),
        (TEACH_FRAME_TEXT, TeachFrame),
    ],
)
def test_every_member_has_a_text(table: dict[object, str], enum_type: type[enum.Enum]) -> None:
    assert set(table) == set(enum_type)
    assert all(text and text == text.strip() for text in table.values())


def test_translate_marker_is_a_no_op() -> None:
    assert QT_TRANSLATE_NOOP("Protocol", "moving") == "moving"


@pytest.mark.parametrize(
    ("command", "kind"),
    [
        (RunCommand.STEP_JOINT, CommandKind.MOVE),
        (RunCommand.STEP_BASE, CommandKind.MOVE),
        (RunCommand.MOVE_TO_POINT, CommandKind.MOVE),
        (RunCommand.CREATE_POINT, CommandKind.CREATE_POINT),
        (RunCommand.TEACH_ENABLE, CommandKind.TEACH),
        (RunCommand.TEACH_DISABLE, CommandKind.TEACH),
        (RunCommand.RUN_PROGRAM, None),
    ],
)
def test_command_kind_of(command: RunCommand, kind: CommandKind | None) -> None:
    assert CommandKind.of(command) is kind


# --- CommandStatus --------------------------------------------------------------------------

KIND_TABLES = [
    (CommandKind.MOVE, MOVE_STATUS_TEXT, MoveStatus),
    (CommandKind.CREATE_POINT, CREATE_POINT_STATUS_TEXT, CreatePointStatus),
    (CommandKind.TEACH, TEACH_STATUS_TEXT, TeachStatus),
]


@pytest.mark.parametrize(("kind", "table", "enum_type"), KIND_TABLES, ids=lambda v: getattr(v, "value", ""))
def test_each_table_names_every_code_of_its_enum(
    kind: CommandKind, table: dict[int, str], enum_type: type[enum.IntEnum]
) -> None:
    assert set(table) == {int(m) for m in enum_type}
    for code, text in table.items():
        status = decode_command_status(kind, code)
        assert status.text == text
        assert status.member == enum_type(code)


@pytest.mark.parametrize(
    ("kind", "code", "text"),
    [
        (CommandKind.MOVE, 0, "initial"),
        (CommandKind.MOVE, 0xFF, "done"),
        (CommandKind.MOVE, 6, "moving"),
        (CommandKind.MOVE, 7, "data length error"),
        (CommandKind.MOVE, 13, "bad end point id"),
        (CommandKind.CREATE_POINT, 0xFF, "success"),
        (CommandKind.CREATE_POINT, 1, "bad point id"),
        (CommandKind.TEACH, 0xFF, "success"),
        (CommandKind.TEACH, 6, "algorithm alarm"),
        (CommandKind.TEACH, 7, "teach speed ratio not zero: enable/disable refused"),
        (None, 13, "bad end point id"),  # no command known: the move table
    ],
)
def test_the_same_code_reads_per_kind(kind: CommandKind | None, code: int, text: str) -> None:
    assert CommandStatus(kind, code).text == text


@pytest.mark.parametrize(
    ("kind", "code"),
    [
        (CommandKind.MOVE, 14),
        (CommandKind.CREATE_POINT, 2),
        (CommandKind.TEACH, 8),
        (None, 99),
        (CommandKind.MOVE, 0xFE),
    ],
)
def test_unknown_codes(kind: CommandKind | None, code: int) -> None:
    status = CommandStatus(kind, code)
    assert status.text == f"unknown status {code}"
    assert status.member is None
    # with no command sent there is no table to call a code an error
    assert status.is_error is (kind is not None)


@pytest.mark.parametrize(
    ("kind", "code", "done", "initial", "moving", "error"),
    [
        (CommandKind.MOVE, 0xFF, True, False, False, False),
        (CommandKind.MOVE, 0, False, True, False, False),
        (CommandKind.MOVE, 6, False, False, True, False),
        (CommandKind.MOVE, 2, False, False, False, True),
        (CommandKind.TEACH, 6, False, False, False, True),  # algorithm alarm, not moving
        (CommandKind.TEACH, 0xFF, True, False, False, False),
        (CommandKind.CREATE_POINT, 1, False, False, False, True),
        (CommandKind.CREATE_POINT, 0, False, True, False, False),
    ],
)
def test_status_predicates(
    kind: CommandKind, code: int, done: bool, initial: bool, moving: bool, error: bool
) -> None:
    status = CommandStatus(kind, code)
    flags = (status.is_done, status.is_initial, status.is_moving, status.is_error)
    assert flags == (done, initial, moving, error)


def test_unknown_kind_has_no_member() -> None:
    assert CommandStatus(None, 0xFF).member is None
    assert CommandStatus(None, 0xFF).is_done
    assert decode_command_status(CommandKind.MOVE, 6.0).code == 6  # type: ignore[arg-type]


# --- GV291 from its two registers -----------------------------------------------------------


@pytest.mark.parametrize(
    ("regs", "order", "code"),
    [
        ([0x0000, 0x437F], WordOrder.LOW_FIRST, 0xFF),  # float 255.0
        ([0x00FF, 0x0000], WordOrder.LOW_FIRST, 0xFF),  # integer 0xFF in 582 (a denormal float)
        ([0x0000, 0x40C0], WordOrder.LOW_FIRST, 6),  # float 6.0
        ([0x000D, 0x0000], WordOrder.LOW_FIRST, 13),  # integer 13
        ([0x0000, 0x0000], WordOrder.LOW_FIRST, 0),
        ([0x0000, 0x3F80], WordOrder.LOW_FIRST, 1),
        ([0x437F, 0x0000], WordOrder.HIGH_FIRST, 0xFF),
        ([0x00FF, 0x0000], WordOrder.HIGH_FIRST, 0xFF),
        ([0x000D, 0x0000], WordOrder.HIGH_FIRST, 13),
        ([0x40C0, 0x0000], WordOrder.HIGH_FIRST, 6),
        ([0x1234, 0x5678], WordOrder.LOW_FIRST, 0x1234),  # garbage: register 582
        ([0x0000, 0x7FC0], WordOrder.LOW_FIRST, 0),  # NaN: register 582
        ([0x0000, 0x7F80], WordOrder.LOW_FIRST, 0),  # inf
        ([0x0000, 0xBF80], WordOrder.LOW_FIRST, 0),  # -1.0 is outside 0..255: register 582
        ([0x0000, 0x4380], WordOrder.LOW_FIRST, 0),  # 256.0 too
        ([0x0000, 0x3FC0], WordOrder.LOW_FIRST, 0),  # 1.5 is not integral
        ([0x0007, 0x0001], WordOrder.LOW_FIRST, 7),
    ],
)
def test_decode_status_registers(regs: list[int], order: WordOrder, code: int) -> None:
    assert decode_status_registers(regs, order) == code


@pytest.mark.parametrize("order", list(WordOrder))
@pytest.mark.parametrize("code", [0, 1, 6, 7, 13, 0xFF])
def test_both_encodings_agree(order: WordOrder, code: int) -> None:
    assert decode_status_registers(float_to_registers(float(code), order), order) == code
    assert decode_status_registers([code, 0], order) == code


@pytest.mark.parametrize("regs", [[], [0xFF], [0, 0, 0]])
def test_decode_status_registers_needs_two(regs: list[int]) -> None:
    with pytest.raises(ValueError):
        decode_status_registers(regs)


# --- Alarms and state texts -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("bits", "names"),
    [
        (0, []),
        (Alarm.ESTOP, ["emergency stop"]),
        (Alarm.SERVO, ["servo alarm"]),
        (Alarm.BRAKE, ["brake alarm"]),
        (Alarm.ALGORITHM, ["algorithm alarm"]),
        (Alarm.ENCODER, ["encoder angle alarm"]),
        (Alarm.ESTOP | Alarm.ENCODER, ["emergency stop", "encoder angle alarm"]),
        (0x1F, ["emergency stop", "servo alarm", "brake alarm", "algorithm alarm", "encoder angle alarm"]),
        (0x20, ["bit 5"]),
        (0x8001, ["emergency stop", "bit 15"]),
        (0x10000, []),  # beyond the 16-bit register
    ],
)
def test_alarm_names(bits: int, names: list[str]) -> None:
    assert alarm_names(bits) == names


@pytest.mark.parametrize(
    ("value", "text"), [(0, "manual"), (1, "auto"), (2, "Modbus teach"), (3, "unknown status 3")]
)
def test_controller_mode_text(value: int, text: str) -> None:
    assert controller_mode_text(value) == text


@pytest.mark.parametrize(
    ("value", "text"), [(0, "stopped"), (1, "running"), (2, "paused"), (9, "unknown status 9")]
)
def test_program_state_text(value: int, text: str) -> None:
    assert program_state_text(value) == text


def test_unknown_kind_is_never_an_error() -> None:
    status = CommandStatus(None, 6)
    assert not status.is_error
    assert status.text == "moving"
