"""Every enum of tables 1 and 2, the alarm bits and the three GV291 status tables.

English descriptions are marked with ``QT_TRANSLATE_NOOP`` (a local no-op, so this module
stays Qt-free): ``pyside6-lupdate`` collects them and the GUI shows them through
``QCoreApplication.translate(context, text)``. The CLI prints them as they are.
"""

from __future__ import annotations

import enum
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

from app.protocol.codec import WordOrder, registers_to_float


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    """Mark ``text`` for translation in ``context``; returns it unchanged."""
    return text


TR_CONTEXT = "Protocol"


class RunCommand(enum.IntEnum):
    """Values written to register 440 (GV220_L)."""

    RUN_PROGRAM = 0x01
    STEP_JOINT = 0x40
    STEP_BASE = 0x41
    MOVE_TO_POINT = 0x42
    TEACH_ENABLE = 0x80
    TEACH_DISABLE = 0x81
    CREATE_POINT = 0xE0


RUN_COMMAND_TEXT: dict[RunCommand, str] = {
    RunCommand.RUN_PROGRAM: QT_TRANSLATE_NOOP("Protocol", "run program"),
    RunCommand.STEP_JOINT: QT_TRANSLATE_NOOP("Protocol", "incremental move (joint)"),
    RunCommand.STEP_BASE: QT_TRANSLATE_NOOP("Protocol", "incremental move (base)"),
    RunCommand.MOVE_TO_POINT: QT_TRANSLATE_NOOP("Protocol", "move to temp point"),
    RunCommand.TEACH_ENABLE: QT_TRANSLATE_NOOP("Protocol", "teach enable"),
    RunCommand.TEACH_DISABLE: QT_TRANSLATE_NOOP("Protocol", "teach disable"),
    RunCommand.CREATE_POINT: QT_TRANSLATE_NOOP("Protocol", "create temp point"),
}


class WorkMode(enum.IntEnum):
    """Register 444 (GV222_L)."""

    MANUAL = 0
    AUTO = 1


class ControllerMode(enum.IntEnum):
    """Register 560 (GV280_L)."""

    MANUAL = 0
    AUTO = 1
    MODBUS_TEACH = 2


CONTROLLER_MODE_TEXT: dict[ControllerMode, str] = {
    ControllerMode.MANUAL: QT_TRANSLATE_NOOP("Protocol", "manual"),
    ControllerMode.AUTO: QT_TRANSLATE_NOOP("Protocol", "auto"),
    ControllerMode.MODBUS_TEACH: QT_TRANSLATE_NOOP("Protocol", "Modbus teach"),
}


class ProgramState(enum.IntEnum):
    """Register 561 (GV280_H)."""

    STOPPED = 0
    RUNNING = 1
    PAUSED = 2


PROGRAM_STATE_TEXT: dict[ProgramState, str] = {
    ProgramState.STOPPED: QT_TRANSLATE_NOOP("Protocol", "stopped"),
    ProgramState.RUNNING: QT_TRANSLATE_NOOP("Protocol", "running"),
    ProgramState.PAUSED: QT_TRANSLATE_NOOP("Protocol", "paused"),
}


class ProgramMotionMode(enum.IntEnum):
    """Register 447 (GV223_H)."""

    SINGLE_STEP = 0
    SINGLE_RUN = 1
    CYCLE = 2


PROGRAM_MOTION_MODE_TEXT: dict[ProgramMotionMode, str] = {
    ProgramMotionMode.SINGLE_STEP: QT_TRANSLATE_NOOP("Protocol", "single step"),
    ProgramMotionMode.SINGLE_RUN: QT_TRANSLATE_NOOP("Protocol", "single run"),
    ProgramMotionMode.CYCLE: QT_TRANSLATE_NOOP("Protocol", "cycle"),
}


class TeachFrame(enum.IntEnum):
    """GV200 of function 4."""

    BASE = 0
    USER = 1
    TOOL = 2
    JOINT = 3


TEACH_FRAME_TEXT: dict[TeachFrame, str] = {
    TeachFrame.BASE: QT_TRANSLATE_NOOP("Protocol", "base"),
    TeachFrame.USER: QT_TRANSLATE_NOOP("Protocol", "user"),
    TeachFrame.TOOL: QT_TRANSLATE_NOOP("Protocol", "tool"),
    TeachFrame.JOINT: QT_TRANSLATE_NOOP("Protocol", "joint"),
}

CARTESIAN_AXIS_NAMES: tuple[str, ...] = ("X", "Y", "Z", "A", "B", "C")
JOINT_AXIS_NAMES: tuple[str, ...] = tuple(f"J{i}" for i in range(1, 12))


class Alarm(enum.IntFlag):
    """Register 562 (GV281_L) alarm bits."""

    NONE = 0
    ESTOP = 1 << 0
    SERVO = 1 << 1
    BRAKE = 1 << 2
    ALGORITHM = 1 << 3
    ENCODER = 1 << 4


ALARM_TEXT: dict[Alarm, str] = {
    Alarm.ESTOP: QT_TRANSLATE_NOOP("Protocol", "emergency stop"),
    Alarm.SERVO: QT_TRANSLATE_NOOP("Protocol", "servo alarm"),
    Alarm.BRAKE: QT_TRANSLATE_NOOP("Protocol", "brake alarm"),
    Alarm.ALGORITHM: QT_TRANSLATE_NOOP("Protocol", "algorithm alarm"),
    Alarm.ENCODER: QT_TRANSLATE_NOOP("Protocol", "encoder angle alarm"),
}
ALARM_BITS: tuple[Alarm, ...] = tuple(ALARM_TEXT)
ALARM_MASK = int(sum(ALARM_BITS))


def alarm_names(alarms: int) -> list[str]:
    """English names of the set alarm bits; unknown bits are named by number."""
    names = [ALARM_TEXT[a] for a in ALARM_BITS if alarms & a]
    names.extend(f"bit {b}" for b in range(16) if alarms & (1 << b) and not ALARM_MASK & (1 << b))
    return names


class CommandKind(enum.Enum):
    """Which status table decodes GV291: it depends on the last command sent."""

    MOVE = "move"  # incremental move (0x40/0x41) and move to temp point (0x42)
    CREATE_POINT = "create-point"  # 0xE0
    TEACH = "teach"  # 0x80 / 0x81

    @classmethod
    def of(cls, command: RunCommand) -> CommandKind | None:
        """The status table that answers ``command`` (None: GV291 is not used)."""
        if command in (RunCommand.STEP_JOINT, RunCommand.STEP_BASE, RunCommand.MOVE_TO_POINT):
            return cls.MOVE
        if command is RunCommand.CREATE_POINT:
            return cls.CREATE_POINT
        if command in (RunCommand.TEACH_ENABLE, RunCommand.TEACH_DISABLE):
            return cls.TEACH
        return None


STATUS_INITIAL = 0
STATUS_DONE = 0xFF
# What the host writes into GV291 just before a command when the controller keeps the host's
# value (completion rule "sentinel", app/link/tracker.py): in no status table, an integral
# float in 0..255 so both encodings decode it. Any other value read afterwards was written by
# the controller, for this command.
STATUS_SENTINEL = 0xA5


class MoveStatus(enum.IntEnum):
    """GV291 after an incremental move or a move to temp point."""

    INITIAL = 0
    DONE = 0xFF
    WORK_MODE_ERROR = 1
    ESTOP = 2
    SERVO_ALARM = 3
    BRAKE_ALARM = 4
    BUS_SERVO_INIT_ERROR = 5
    MOVING = 6
    DATA_LENGTH_ERROR = 7
    ENCODER_READ_ERROR = 8
    ENCODER_UPDATE_ERROR = 9
    CALCULATION_ERROR = 10
    ALGORITHM_ERROR = 11
    MOTION_TIMEOUT = 12
    BAD_END_POINT = 13


class CreatePointStatus(enum.IntEnum):
    """GV291 after creating a temp point."""

    INITIAL = 0
    DONE = 0xFF
    BAD_POINT_ID = 1


class TeachStatus(enum.IntEnum):
    """GV291 after teach enable / disable."""

    INITIAL = 0
    DONE = 0xFF
    WORK_MODE_ERROR = 1
    ESTOP = 2
    SERVO_ALARM = 3
    BRAKE_ALARM = 4
    BUS_SERVO_INIT_ERROR = 5
    ALGORITHM_ALARM = 6
    RATIO_NOT_ZERO = 7


MOVE_STATUS_TEXT: dict[int, str] = {
    0: QT_TRANSLATE_NOOP("Protocol", "initial"),
    0xFF: QT_TRANSLATE_NOOP("Protocol", "done"),
    1: QT_TRANSLATE_NOOP("Protocol", "work mode error"),
    2: QT_TRANSLATE_NOOP("Protocol", "emergency stop"),
    3: QT_TRANSLATE_NOOP("Protocol", "servo alarm"),
    4: QT_TRANSLATE_NOOP("Protocol", "brake alarm"),
    5: QT_TRANSLATE_NOOP("Protocol", "bus servo initialisation error"),
    6: QT_TRANSLATE_NOOP("Protocol", "moving"),
    7: QT_TRANSLATE_NOOP("Protocol", "data length error"),
    8: QT_TRANSLATE_NOOP("Protocol", "encoder angle read error"),
    9: QT_TRANSLATE_NOOP("Protocol", "encoder angle update error"),
    10: QT_TRANSLATE_NOOP("Protocol", "calculation error"),
    11: QT_TRANSLATE_NOOP("Protocol", "algorithm error while moving"),
    12: QT_TRANSLATE_NOOP("Protocol", "motion timeout"),
    13: QT_TRANSLATE_NOOP("Protocol", "bad end point id"),
}
CREATE_POINT_STATUS_TEXT: dict[int, str] = {
    0: QT_TRANSLATE_NOOP("Protocol", "initial"),
    0xFF: QT_TRANSLATE_NOOP("Protocol", "success"),
    1: QT_TRANSLATE_NOOP("Protocol", "bad point id"),
}
TEACH_STATUS_TEXT: dict[int, str] = {
    0: QT_TRANSLATE_NOOP("Protocol", "initial"),
    0xFF: QT_TRANSLATE_NOOP("Protocol", "success"),
    1: QT_TRANSLATE_NOOP("Protocol", "work mode error"),
    2: QT_TRANSLATE_NOOP("Protocol", "emergency stop"),
    3: QT_TRANSLATE_NOOP("Protocol", "servo alarm"),
    4: QT_TRANSLATE_NOOP("Protocol", "brake alarm"),
    5: QT_TRANSLATE_NOOP("Protocol", "bus servo initialisation error"),
    6: QT_TRANSLATE_NOOP("Protocol", "algorithm alarm"),
    7: QT_TRANSLATE_NOOP("Protocol", "teach speed ratio not zero: enable/disable refused"),
}

_STATUS_ENUM: dict[CommandKind, type[enum.IntEnum]] = {
    CommandKind.MOVE: MoveStatus,
    CommandKind.CREATE_POINT: CreatePointStatus,
    CommandKind.TEACH: TeachStatus,
}
_STATUS_TEXT: dict[CommandKind, dict[int, str]] = {
    CommandKind.MOVE: MOVE_STATUS_TEXT,
    CommandKind.CREATE_POINT: CREATE_POINT_STATUS_TEXT,
    CommandKind.TEACH: TEACH_STATUS_TEXT,
}
UNKNOWN_STATUS_TEXT = QT_TRANSLATE_NOOP("Protocol", "unknown status {code}")
SENTINEL_STATUS_TEXT = QT_TRANSLATE_NOOP("Protocol", "sent, waiting for the controller")


@dataclass(frozen=True)
class CommandStatus:
    """GV291 decoded with the table of the command that was sent last."""

    kind: CommandKind | None
    code: int

    @property
    def member(self) -> enum.IntEnum | None:
        """The enum member, or None for an unknown code or kind."""
        if self.kind is None:
            return None
        try:
            return _STATUS_ENUM[self.kind](self.code)
        except ValueError:
            return None

    @property
    def text(self) -> str:
        """English description (translate with context ``Protocol``)."""
        if self.code == STATUS_SENTINEL:
            return SENTINEL_STATUS_TEXT
        if self.kind is None:
            return MOVE_STATUS_TEXT.get(self.code, UNKNOWN_STATUS_TEXT.format(code=self.code))
        return _STATUS_TEXT[self.kind].get(self.code, UNKNOWN_STATUS_TEXT.format(code=self.code))

    @property
    def is_done(self) -> bool:
        return self.code == STATUS_DONE

    @property
    def is_initial(self) -> bool:
        return self.code == STATUS_INITIAL

    @property
    def is_pending(self) -> bool:
        """The host's own sentinel: the controller has not written its result yet."""
        return self.code == STATUS_SENTINEL

    @property
    def is_moving(self) -> bool:
        return self.kind is CommandKind.MOVE and self.code == MoveStatus.MOVING

    @property
    def is_error(self) -> bool:
        """A code that ends the command unsuccessfully (never true when the kind is unknown)."""
        if self.kind is None:
            return False
        return not (self.is_done or self.is_initial or self.is_moving or self.is_pending)


def decode_command_status(kind: CommandKind | None, code: int) -> CommandStatus:
    """Decode GV291's code for the command kind that was sent last."""
    return _decoded(kind, code)


@functools.lru_cache(maxsize=1024)  # immutable, and few (kind, code) pairs: every poll decodes one
def _decoded(kind: CommandKind | None, code: int) -> CommandStatus:
    return CommandStatus(kind, int(code))


def decode_status_registers(regs: Sequence[int], order: WordOrder = WordOrder.LOW_FIRST) -> int:
    """GV291 from its two registers (582, 583), either encoding (PROTOCOL.md section 7).

    A finite integral float32 in 0..255 wins; otherwise register 582 as uint16. (An integer
    0xFF in 582 with 0 in 583 is a float denormal, never integral, so the two can't clash.)

    A float32 status written in the *other* word order than ``order`` (the register profile's
    word order does not match the controller's, e.g. just after switching the profile) is read
    as that float too: its high word alone in 582 read as an integer was "unknown status 17279"
    (0x437F, the high word of 255.0), a refusal the controller never said. (An integer status
    0..255 in 582 read in the other order is a float below 1e-37, never integral either.)
    """
    if len(regs) != 2:
        raise ValueError("GV291 needs its two registers")
    for words in (regs, (regs[1], regs[0])):
        value = registers_to_float(words, order)
        if math.isfinite(value) and value.is_integer() and 0 <= value <= 255:
            return int(value)
    return int(regs[0]) & 0xFFFF


def program_state_text(value: int) -> str:
    try:
        return PROGRAM_STATE_TEXT[ProgramState(value)]
    except ValueError:
        return UNKNOWN_STATUS_TEXT.format(code=value)


def controller_mode_text(value: int) -> str:
    try:
        return CONTROLLER_MODE_TEXT[ControllerMode(value)]
    except ValueError:
        return UNKNOWN_STATUS_TEXT.format(code=value)
