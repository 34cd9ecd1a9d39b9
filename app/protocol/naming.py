"""Registers in words: the controller's map (PROTOCOL.md sections 2-4) applied to raw values.

``describe_registers`` names a run of register values (GVs as float32, table 1's and 2's
integers, the clock, GV291); ``summarize_registers``, ``single_write_text`` and ``range_label``
turn them into the short English texts of the traffic inspector and the logs.
"""

from __future__ import annotations

import bisect
import datetime as dt
import enum
import math
import struct
from array import array
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Final

from app.protocol import registers as regs
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout, decode_clock
from app.protocol.enums import (
    CARTESIAN_AXIS_NAMES,
    PROGRAM_MOTION_MODE_TEXT,
    RUN_COMMAND_TEXT,
    TEACH_FRAME_TEXT,
    CommandKind,
    ProgramMotionMode,
    RunCommand,
    WorkMode,
    alarm_names,
    controller_mode_text,
    decode_command_status,
    decode_status_registers,
    program_state_text,
)
from app.protocol.float_text import format_float32

SUMMARY_LIST_LIMIT: Final = 8  # values shown in a summary before "…"


# --- Naming registers ---------------------------------------------------------------------


class ItemKind(enum.Enum):
    """How a ``RegisterItem`` was decoded."""

    FLOAT = "float"  # one GV, two registers, float32 in the connection's word order
    INTEGER = "int"  # a named 16-bit register of table 1 or 2
    CLOCK = "clock"  # GV288-GV289, registers 576-579
    COMMAND_STATUS = "command-status"  # GV291, registers 582-583, either encoding
    RAW = "raw"  # a register with no meaning of its own here (shown in hex)


@dataclass(frozen=True)
class RegisterItem:
    """One named value found in a run of registers."""

    address: int  # first register
    raw: tuple[int, ...]  # the registers it was decoded from
    kind: ItemKind
    name: str  # by address: "GV202", "reg 440", "GV288–GV289", "GV291"
    role: str  # by meaning: "orientation", "X", "run command", "mode"; "" when none
    value: float | int | dt.datetime | None
    text: str  # the value for people: "1.0 (changes)", "auto", "done (0xFF)", "0x006B"

    @property
    def count(self) -> int:
        return len(self.raw)

    @property
    def last(self) -> int:
        """Last register of the item."""
        return self.address + len(self.raw) - 1

    @property
    def short(self) -> str:
        """``role=text`` (``name=text`` without a role), as used in summaries."""
        return f"{self.role or self.name}={self.text}"

    @property
    def label(self) -> str:
        """``GV202 orientation = 1.0 (changes)``."""
        who = f"{self.name} {self.role}" if self.role else self.name
        return f"{who} = {self.text}"


def _integral(value: float) -> int | None:
    if math.isfinite(value) and value.is_integer():
        return int(value)
    return None


Meaning = Callable[[float], str | None]


def _table(texts: Mapping[int, str]) -> Meaning:
    def meaning(value: float) -> str | None:
        key = _integral(value)
        return texts.get(key) if key is not None else None

    return meaning


def _tool_meaning(value: float) -> str | None:
    n = _integral(value)
    if n == regs.TOOL_NONE:
        return "no tool"
    return f"tool {n}" if n is not None and n >= 0 else None  # GV245's number, as the GUI and CSV show it


def _motion_meaning(value: float) -> str | None:
    n = _integral(value)
    if n == -1:
        return "line"
    return f"arc via point {n}" if n is not None and n >= 0 else None


def _teach_axis_meaning(value: float) -> str | None:
    # The frame (GV200) decides between X..C and J1..J11; it may be written in another frame.
    n = _integral(value)
    if n is None or not 0 <= n < regs.NUM_AXES_TOTAL:
        return None
    return f"{CARTESIAN_AXIS_NAMES[n]} or J{n + 1}" if n < len(CARTESIAN_AXIS_NAMES) else f"J{n + 1}"


_GvRole = tuple[str, Meaning | None]

_FIXED_GV_ROLES: dict[int, _GvRole] = {
    **{regs.GV_POSE + i: (axis, None) for i, axis in enumerate(CARTESIAN_AXIS_NAMES)},
    **{regs.GV_EXT_AXES + i: (f"J{i + 7}", None) for i in range(regs.NUM_EXTERNAL_AXES)},  # external axes
    **{regs.GV_JOINTS + i: (f"J{i + 1}", None) for i in range(regs.NUM_ROBOT_AXES)},
    **{regs.GV_EXT_OFFSET0 + i: (f"J{i + 7} offset", None) for i in range(regs.NUM_EXTERNAL_AXES)},
    regs.GV_EXPECTED_SPEED: ("speed", None),
    regs.GV_USER_FRAME: ("user frame", None),
    regs.GV_TOOL_FRAME: ("tool", _tool_meaning),
}

_TEACH_ROLES: dict[int, _GvRole] = {
    regs.GV_PARAM0: ("frame", _table({int(k): v for k, v in TEACH_FRAME_TEXT.items()})),
    regs.GV_PARAM1: ("axis", _teach_axis_meaning),
    regs.GV_PARAM2: ("direction", _table({0: "negative", 1: "positive"})),
    regs.GV_PARAM3: ("speed ratio", None),
}

# GV200..GV205 mean something different for each function (PROTOCOL.md section 3).
_PARAM_ROLES: dict[RunCommand, dict[int, _GvRole]] = {
    RunCommand.STEP_JOINT: {regs.GV_PARAM0 + i: (f"J{i + 1} offset", None) for i in range(6)},
    RunCommand.STEP_BASE: {
        regs.GV_PARAM0 + i: (f"{a} offset", None) for i, a in enumerate(CARTESIAN_AXIS_NAMES)
    },
    RunCommand.CREATE_POINT: {
        regs.GV_PARAM0: ("point id", None),
        regs.GV_PARAM1: ("source", _table({0: "current pose", 1: "from GVs"})),
        regs.GV_PARAM2: ("first GV", None),
    },
    RunCommand.MOVE_TO_POINT: {
        regs.GV_PARAM0: ("motion", _motion_meaning),
        regs.GV_PARAM1: ("end point", None),
        # The seed's step list says "whether orientation is kept"; its values win (erratum E8).
        regs.GV_PARAM2: ("orientation", _table({0: "kept", 1: "changes"})),
        regs.GV_PARAM3: ("ignore middle", _table({0: "no", 1: "yes"})),
    },
    RunCommand.TEACH_ENABLE: _TEACH_ROLES,
    RunCommand.TEACH_DISABLE: _TEACH_ROLES,
}


def _unknown(value: int) -> str:
    return f"unknown {value}"


def run_command_of(value: int) -> RunCommand | None:
    try:
        return RunCommand(value)
    except ValueError:
        return None


def _run_command_text(value: int) -> str:
    try:
        return RUN_COMMAND_TEXT[RunCommand(value)]
    except ValueError:
        return f"unknown command 0x{value:02X}"


def _work_mode_text(value: int) -> str:
    texts: dict[int, str] = {WorkMode.MANUAL: "manual", WorkMode.AUTO: "auto"}
    return texts.get(value, _unknown(value))


def _go_zero_text(value: int) -> str:
    if value == regs.GO_ZERO_ALL:
        return "all axes"
    return f"J{value + 1}" if 0 <= value < regs.NUM_AXES_TOTAL else f"unknown 0x{value:02X}"


def _program_mode_text(value: int) -> str:
    try:
        return PROGRAM_MOTION_MODE_TEXT[ProgramMotionMode(value)]
    except ValueError:
        return _unknown(value)


def _alarms_text(value: int) -> str:
    return " + ".join(alarm_names(value)) or "none"


@dataclass(frozen=True)
class _IntRegister:
    role: str
    text: Callable[[int], str]
    action: Callable[[int], str]  # FC06 phrase: "work mode auto", "stop", "teach enable"
    hex_value: bool = False


def _int_register(
    role: str,
    text: Callable[[int], str],
    *,
    bare: bool = False,
    hex_value: bool = False,
    action: Callable[[int], str] | None = None,
) -> _IntRegister:
    if action is None:
        action = (lambda _v: role) if bare else (lambda v: f"{role} {text(v)}")
    return _IntRegister(role, text, action, hex_value)


_INT_REGISTERS: dict[int, _IntRegister] = {
    regs.REG_RUN_COMMAND: _int_register(
        "run command", _run_command_text, action=_run_command_text, hex_value=True
    ),
    regs.REG_STOP: _int_register("stop", str, bare=True),
    regs.REG_PAUSE: _int_register("pause", str, bare=True),
    regs.REG_RESUME: _int_register("resume", str, bare=True),
    regs.REG_WORK_MODE: _int_register("work mode", _work_mode_text),
    regs.REG_GO_ZERO: _int_register("go to zero", _go_zero_text, hex_value=True),
    regs.REG_PROGRAM_ID: _int_register("program id", str),
    regs.REG_PROGRAM_MODE: _int_register("program mode", _program_mode_text),
    regs.REG_CYCLE_COUNT: _int_register("cycles", lambda v: "endless" if v == 0 else str(v)),
    regs.REG_PROGRAM_SPEED: _int_register("program speed", lambda v: f"{v}%"),
    regs.REG_RESOURCE_TYPE: _int_register("resource type", str),
    regs.REG_RESOURCE_PARAM: _int_register("resource params", lambda v: f"GV{v}"),
    regs.REG_CONTROLLER_MODE: _int_register("mode", controller_mode_text),
    regs.REG_PROGRAM_STATE: _int_register("program", program_state_text),
    regs.REG_ALARMS: _int_register("alarms", _alarms_text),
}

_CLOCK_START: Final = regs.gv_reg(regs.GV_DATE)  # 576
_CLOCK_COUNT: Final = 4
_COMMAND_STATUS_REG: Final = regs.gv_reg(regs.GV_COMMAND_STATUS)  # 582
# Registers that never hold a float: table 1's integers and the whole status block.
_NOT_FLOAT: Final = frozenset(
    [
        *range(regs.REG_RUN_COMMAND, regs.REG_PROGRAM_SPEED + 1),
        regs.REG_RESOURCE_TYPE,
        regs.REG_RESOURCE_PARAM,
        *range(regs.STATUS_BLOCK_START, regs.STATUS_BLOCK_START + regs.STATUS_BLOCK_COUNT),
    ]
)
# Unused registers inside the status block: listed as items, left out of summaries.
_STATUS_SPARE: Final = frozenset(
    r
    for r in range(regs.STATUS_BLOCK_START, regs.STATUS_BLOCK_START + regs.STATUS_BLOCK_COUNT)
    if r not in _INT_REGISTERS
    and not _CLOCK_START <= r < _CLOCK_START + _CLOCK_COUNT
    and r not in (_COMMAND_STATUS_REG, _COMMAND_STATUS_REG + 1)
)

_KNOWN_BLOCKS: dict[tuple[int, int], str] = {
    (regs.POSE_BLOCK_START, 12): "pose X..C (GV206–GV211)",
    (regs.POSE_BLOCK_START, regs.POSE_BLOCK_COUNT): "pose, ext axes, joints (412–511)",
    (regs.gv_reg(regs.GV_EXT_AXES), 10): "ext axes J7..J11 (GV212–GV216)",
    (regs.gv_reg(regs.GV_JOINTS), 12): "joints J1..J6 (GV250–GV255)",
    (regs.STATUS_BLOCK_START, regs.STATUS_BLOCK_COUNT): "status (560–583)",
    (regs.STATUS_BLOCK_START, 3): "status (560–562)",
    (_CLOCK_START, _CLOCK_COUNT): "clock (576–579)",
    (_COMMAND_STATUS_REG, 2): "command status GV291 (582–583)",
}


def gv_register_name(address: int) -> str:
    """``GVn_L`` / ``GVn_H`` of a register (``GV220_L`` for 440)."""
    n, half = regs.reg_to_gv(address)
    return f"GV{n}_{half}"


def _gv_role(n: int, params_for: RunCommand | None) -> _GvRole:
    if params_for is not None and n in _PARAM_ROLES.get(params_for, {}):
        return _PARAM_ROLES[params_for][n]
    return _FIXED_GV_ROLES.get(n, ("", None))


# Decoded items by what decides them: a robot streaming its pose changes a few GVs per answer
# and the rest repeat, so most items of an answer were made for an earlier one. Frozen items
# are shared; each cache is cleared when full.
ITEM_CACHE_SIZE: Final = 4096
_FloatKey = tuple[int, int, int, bool, RunCommand | None]  # reg, words, low first, params_for
_FLOAT_ITEMS: dict[_FloatKey, RegisterItem] = {}
_INT_ITEMS: dict[tuple[int, int], RegisterItem] = {}
_PARAM_GVS: Final = frozenset(n for roles in _PARAM_ROLES.values() for n in roles)
# Registers decoded apart from GVs (table 1's integers, the status block with the clock and GV291).
_APART: Final = _NOT_FLOAT | frozenset(_INT_REGISTERS)
_APART_SORTED: Final = sorted(_APART)
_WORD: Final = struct.Struct(">HH")
_FLOAT: Final = struct.Struct(">f")


def _float_item(
    address: int, raw: tuple[int, int], order: WordOrder, params_for: RunCommand | None
) -> RegisterItem:
    n = address // 2
    high, low = (raw[1], raw[0]) if order is WordOrder.LOW_FIRST else raw
    value: float = _FLOAT.unpack(_WORD.pack(high, low))[0]
    role, meaning = _gv_role(n, params_for)
    text = format_float32(value)
    extra = meaning(value) if meaning is not None else None
    if meaning is not None:
        text = f"{text} ({extra or '?'})"
    return RegisterItem(address, raw, ItemKind.FLOAT, f"GV{n}", role, value, text)


def _float_run(
    address: int,
    words: Sequence[int],
    start: int,
    end: int,
    order: WordOrder,
    params_for: RunCommand | None,
    items: list[RegisterItem],
) -> None:
    """The GVs of ``words[start:end]`` (an even count from an even register), cached."""
    low_first = order is WordOrder.LOW_FIRST
    cache = _FLOAT_ITEMS
    for k in range(start, end, 2):
        reg = address + k
        first, second = words[k], words[k + 1]
        params = params_for if reg >> 1 in _PARAM_GVS else None
        key = (reg, first, second, low_first, params)
        item = cache.get(key)
        if item is None:
            item = _float_item(reg, (first, second), order, params)
            if len(cache) >= ITEM_CACHE_SIZE:
                cache.clear()
            cache[key] = item
        items.append(item)


def _run_end(address: int, start: int, count: int) -> int:
    """End of the run of whole GVs from ``words[start]`` (its register even and not apart)."""
    reg = address + start
    k = bisect.bisect_left(_APART_SORTED, reg)
    apart = _APART_SORTED[k] if k < len(_APART_SORTED) else reg + count
    return start + 2 * ((min(apart, address + count) - reg) // 2)


def _int_item(reg: int, value: int, spec: _IntRegister) -> RegisterItem:
    key = (reg, value)
    item = _INT_ITEMS.get(key)
    if item is None:
        item = RegisterItem(reg, (value,), ItemKind.INTEGER, f"reg {reg}", spec.role, value, spec.text(value))
        if len(_INT_ITEMS) >= ITEM_CACHE_SIZE:
            _INT_ITEMS.clear()
        _INT_ITEMS[key] = item
    return item


def _raw_item(address: int, value: int) -> RegisterItem:
    return RegisterItem(address, (value,), ItemKind.RAW, f"reg {address}", "", value, f"0x{value:04X}")


def _words(values: Sequence[int]) -> list[int]:
    try:
        return array("H", values).tolist()  # 16-bit integers already: the usual case, in C
    except (OverflowError, TypeError):
        return [int(v) & 0xFFFF for v in values]


def describe_registers(
    address: int,
    values: Sequence[int],
    word_order: WordOrder = WordOrder.LOW_FIRST,
    *,
    last_command: RunCommand | None = None,
    params_for: RunCommand | None = None,
    clock_layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS,
) -> tuple[RegisterItem, ...]:
    """Name the values of the registers ``address, address + 1, …``.

    Pairs of registers from an even address are GVs decoded as float32 in ``word_order``;
    table 1's and table 2's integers, the clock and GV291 are decoded by their own rules;
    anything else (an odd start, a half GV) is a raw register. ``last_command`` picks the
    table that decodes GV291; ``params_for`` names GV200..GV205 for that command (a bare
    write can't tell a teach frame from a point id).
    """
    if address < 0:
        raise ValueError(f"register address must be >= 0, got {address}")
    words = _words(values)
    count = len(words)
    items: list[RegisterItem] = []
    # A run from an odd GV register is not reading GVs: show its registers raw.
    floats = address % 2 == 0 or address in _NOT_FLOAT
    i = 0
    while i < count:
        reg = address + i
        left = count - i
        if floats and reg % 2 == 0 and left >= 2 and reg not in _APART and reg + 1 not in _APART:
            end = _run_end(address, i, count)
            _float_run(address, words, i, end, word_order, params_for, items)
            i = end
            continue
        spec = _INT_REGISTERS.get(reg)
        if spec is not None:
            items.append(_int_item(reg, words[i], spec))
            i += 1
        elif reg == _CLOCK_START and left >= _CLOCK_COUNT:
            raw = tuple(words[i : i + _CLOCK_COUNT])
            clock = decode_clock(raw, clock_layout)
            text = str(clock.value) if clock.value is not None else f"invalid ({clock.raw_hex})"
            items.append(RegisterItem(reg, raw, ItemKind.CLOCK, "GV288–GV289", "clock", clock.value, text))
            i += _CLOCK_COUNT
        elif reg == _COMMAND_STATUS_REG and left >= 2:
            raw = tuple(words[i : i + 2])
            kind = CommandKind.of(last_command) if last_command is not None else None
            status = decode_command_status(kind, decode_status_registers(raw, word_order))
            text = f"{status.text} (0x{status.code:02X})"
            items.append(RegisterItem(reg, raw, ItemKind.COMMAND_STATUS, "GV291", "", status.code, text))
            i += 2
        else:
            items.append(_raw_item(reg, words[i]))
            i += 1
    return tuple(items)


__all__ = [
    "SUMMARY_LIST_LIMIT",
    "ItemKind",
    "RegisterItem",
    "describe_registers",
    "gv_register_name",
    "run_command_of",
]
