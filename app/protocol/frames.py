"""Modbus frames as text: the decoder behind the traffic inspector and the logs.

``decode_frame`` turns one raw frame, Modbus TCP (MBAP header + PDU) or RTU (unit + PDU +
CRC16), request or response, into a ``DecodedFrame``: the header fields, the register values,
the registers named after the controller's map (PROTOCOL.md sections 2-4) and a short English
``summary`` such as ``write GV200 = 30.0`` or ``teach enable (440 ← 0x80)``. It never raises on
malformed input: what is wrong goes to ``errors`` and the summary says what could be read.

An FC03 response does not carry its start address, so ``FrameDecoder`` pairs each response
with its request (by transaction id over TCP, by order over RTU) to name the values it reads.

``encode_request`` / ``encode_response`` build frames for FC 03/06/10 (tests, benchmarks).
"""

from __future__ import annotations

import datetime as dt
import enum
import math
import struct
from collections import OrderedDict, deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Final, Literal

from app.protocol import registers as regs
from app.protocol.codec import WordOrder, encode_floats, registers_to_float
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

Transport = Literal["tcp", "rtu"]
Direction = Literal["tx", "rx"]


class FunctionCode(enum.IntEnum):
    """The three function codes the controller uses."""

    READ_HOLDING_REGISTERS = 0x03
    WRITE_SINGLE_REGISTER = 0x06
    WRITE_MULTIPLE_REGISTERS = 0x10


EXCEPTION_FLAG: Final = 0x80
MBAP_SIZE: Final = 7  # transaction id, protocol id, length, unit
RTU_MIN_SIZE: Final = 4  # unit, function, CRC (2)
SUMMARY_LIST_LIMIT: Final = 8  # values shown in a summary before "…"

EXCEPTION_TEXT: dict[int, str] = {
    0x01: "illegal function",
    0x02: "illegal data address",
    0x03: "illegal data value",
    0x04: "server device failure",
    0x05: "acknowledge",
    0x06: "server device busy",
    0x08: "memory parity error",
    0x0A: "gateway path unavailable",
    0x0B: "gateway target failed to respond",
}

_FUNCTION_VERB: dict[int, str] = {
    FunctionCode.READ_HOLDING_REGISTERS: "read",
    FunctionCode.WRITE_SINGLE_REGISTER: "write register",
    FunctionCode.WRITE_MULTIPLE_REGISTERS: "write registers",
}


# --- CRC ----------------------------------------------------------------------------------


def _crc_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
        table.append(crc)
    return tuple(table)


_CRC_TABLE: Final = _crc_table()


def crc16(data: bytes) -> int:
    """Modbus RTU CRC-16 (poly 0xA001 reflected, init 0xFFFF); sent low byte first."""
    crc = 0xFFFF
    for byte in data:
        crc = (crc >> 8) ^ _CRC_TABLE[(crc ^ byte) & 0xFF]
    return crc


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


def format_float32(value: float) -> str:
    """The shortest text that reads back as the same float32 (``30.0``, ``0.1``, ``-1.0``)."""
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    try:
        packed = struct.pack(">f", value)
    except OverflowError:
        return repr(value)

    def shortened(digits: int) -> float | None:
        candidate = float(f"{value:.{digits}g}")
        try:
            return candidate if struct.pack(">f", candidate) == packed else None
        except OverflowError:
            return None

    # 9 significant digits always read back as the same float32; find the fewest that do
    # (a binary search: this runs for every value the inspector shows).
    low, high = 1, 9
    best = shortened(high)
    while low < high:
        middle = (low + high) // 2
        candidate = shortened(middle)
        if candidate is None:
            low = middle + 1
        else:
            best, high = candidate, middle
    return repr(best if best is not None else value)


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
    return f"tool {n + 1}" if n is not None and n >= 0 else None


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
    **{regs.GV_EXT_AXES + i: (f"EJ{i + 1}", None) for i in range(regs.NUM_EXTERNAL_AXES)},
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


def _run_command(value: int) -> RunCommand | None:
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


def _int_register(role: str, text: Callable[[int], str], *, bare: bool = False, hex_value: bool = False,
                  action: Callable[[int], str] | None = None) -> _IntRegister:
    if action is None:
        action = (lambda _v: role) if bare else (lambda v: f"{role} {text(v)}")
    return _IntRegister(role, text, action, hex_value)


_INT_REGISTERS: dict[int, _IntRegister] = {
    regs.REG_RUN_COMMAND: _int_register("run command", _run_command_text, action=_run_command_text,
                                        hex_value=True),
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
    [*range(regs.REG_RUN_COMMAND, regs.REG_PROGRAM_SPEED + 1), regs.REG_RESOURCE_TYPE,
     regs.REG_RESOURCE_PARAM,
     *range(regs.STATUS_BLOCK_START, regs.STATUS_BLOCK_START + regs.STATUS_BLOCK_COUNT)]
)
# Unused registers inside the status block: listed as items, left out of summaries.
_STATUS_SPARE: Final = frozenset(
    r for r in range(regs.STATUS_BLOCK_START, regs.STATUS_BLOCK_START + regs.STATUS_BLOCK_COUNT)
    if r not in _INT_REGISTERS and not _CLOCK_START <= r < _CLOCK_START + _CLOCK_COUNT
    and r not in (_COMMAND_STATUS_REG, _COMMAND_STATUS_REG + 1)
)

_KNOWN_BLOCKS: dict[tuple[int, int], str] = {
    (regs.POSE_BLOCK_START, 12): "pose X..C (GV206–GV211)",
    (regs.POSE_BLOCK_START, regs.POSE_BLOCK_COUNT): "pose, ext axes, joints (412–511)",
    (regs.gv_reg(regs.GV_EXT_AXES), 10): "ext axes EJ1..EJ5 (GV212–GV216)",
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


def _float_item(address: int, raw: tuple[int, ...], order: WordOrder, params_for: RunCommand | None
                ) -> RegisterItem:
    n = address // 2
    value = registers_to_float(raw, order)
    role, meaning = _gv_role(n, params_for)
    text = format_float32(value)
    extra = meaning(value) if meaning is not None else None
    if meaning is not None:
        text = f"{text} ({extra or '?'})"
    return RegisterItem(address, raw, ItemKind.FLOAT, f"GV{n}", role, value, text)


def _raw_item(address: int, value: int) -> RegisterItem:
    return RegisterItem(address, (value,), ItemKind.RAW, f"reg {address}", "", value, f"0x{value:04X}")


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
    words = [int(v) & 0xFFFF for v in values]
    kind = CommandKind.of(last_command) if last_command is not None else None
    items: list[RegisterItem] = []
    # A run from an odd GV register is not reading GVs: show its registers raw.
    floats = address % 2 == 0 or address in _NOT_FLOAT
    i = 0
    while i < len(words):
        reg = address + i
        left = len(words) - i
        spec = _INT_REGISTERS.get(reg)
        if spec is not None:
            value = words[i]
            items.append(RegisterItem(reg, (value,), ItemKind.INTEGER, f"reg {reg}", spec.role, value,
                                      spec.text(value)))
            i += 1
        elif reg == _CLOCK_START and left >= _CLOCK_COUNT:
            raw = tuple(words[i : i + _CLOCK_COUNT])
            clock = decode_clock(raw, clock_layout)
            text = str(clock.value) if clock.value is not None else f"invalid ({clock.raw_hex})"
            items.append(RegisterItem(reg, raw, ItemKind.CLOCK, "GV288–GV289", "clock", clock.value, text))
            i += _CLOCK_COUNT
        elif reg == _COMMAND_STATUS_REG and left >= 2:
            raw = tuple(words[i : i + 2])
            status = decode_command_status(kind, decode_status_registers(raw, word_order))
            text = f"{status.text} (0x{status.code:02X})"
            items.append(RegisterItem(reg, raw, ItemKind.COMMAND_STATUS, "GV291", "", status.code, text))
            i += 2
        elif floats and reg % 2 == 0 and left >= 2 and reg not in _NOT_FLOAT and reg + 1 not in _NOT_FLOAT:
            items.append(_float_item(reg, (words[i], words[i + 1]), word_order, params_for))
            i += 2
        else:
            items.append(_raw_item(reg, words[i]))
            i += 1
    return tuple(items)


# --- Summaries ----------------------------------------------------------------------------


def _gv_span(address: int, count: int) -> str:
    first, last = address // 2, (address + count - 1) // 2
    return f"GV{first}" if first == last else f"GV{first}–GV{last}"


def _is_gv_run(address: int, count: int) -> bool:
    """Whole GVs from an even address, none of them an integer register."""
    return (address % 2 == 0 and count % 2 == 0 and count > 0
            and not any(r in _NOT_FLOAT for r in range(address, address + count)))


def range_label(address: int, count: int) -> str:
    """``pose X..C (GV206–GV211)``, ``GV200 (400–401)``, ``regs 107–109``, ``reg 1``."""
    known = _KNOWN_BLOCKS.get((address, count))
    if known is not None:
        return known
    last = address + count - 1
    if count <= 0:
        return f"no regs at {address}"
    if _is_gv_run(address, count):
        return f"{_gv_span(address, count)} ({address}–{last})"
    return f"reg {address}" if count == 1 else f"regs {address}–{last}"


def _limited(texts: Sequence[str], limit: int = SUMMARY_LIST_LIMIT) -> str:
    if len(texts) <= limit:
        return ", ".join(texts)
    return ", ".join(texts[:limit]) + f", … (+{len(texts) - limit})"


def _plain(items: Sequence[RegisterItem]) -> bool:
    """Items that read best as one list of values: role-less GVs, or raw registers."""
    return bool(items) and (all(it.kind is ItemKind.FLOAT and not it.role for it in items)
                            or all(it.kind is ItemKind.RAW for it in items))


def _summary_items(items: Sequence[RegisterItem]) -> list[RegisterItem]:
    named = [it for it in items if it.address not in _STATUS_SPARE]
    return named or list(items)


def summarize_registers(address: int, items: Sequence[RegisterItem]) -> str:
    """``pose X..C (GV206–GV211): X=1.0, Y=2.0, …`` for a run of decoded registers."""
    if not items:
        return range_label(address, 0)
    label = range_label(address, items[-1].last - address + 1)
    shown = _summary_items(items)
    if _plain(shown):
        return f"{label} = {_limited([it.text for it in shown])}"
    return f"{label}: {_limited([it.short for it in shown])}"


def _write_summary(address: int, items: Sequence[RegisterItem]) -> str:
    if _plain(items):
        count = items[-1].last - address + 1
        who = _gv_span(address, count) if items[0].kind is ItemKind.FLOAT else range_label(address, count)
        return f"write {who} = {_limited([it.text for it in items])}"
    if len(items) == 1:
        return f"write {items[0].label}"
    return f"write {_limited([it.short for it in items])}"


def single_write_text(address: int, value: int) -> str:
    """FC06 in words: ``teach enable (440 ← 0x80)``, ``write reg 1 (GV0_H) = 0x0003``."""
    spec = _INT_REGISTERS.get(address)
    if spec is None:
        return f"write reg {address} ({gv_register_name(address)}) = 0x{value:04X}"
    shown = f"0x{value:02X}" if spec.hex_value else str(value)
    return f"{spec.action(value)} ({address} ← {shown})"


# --- The decoded frame --------------------------------------------------------------------


@dataclass(frozen=True)
class DecodedFrame:
    """One frame taken apart. ``errors`` is empty for a well-formed frame."""

    raw: bytes
    transport: Transport
    transaction_id: int | None  # TCP only
    unit: int | None
    function_code: int | None  # as on the wire: 0x83 for an exception to 0x03
    is_response: bool
    is_exception: bool
    exception_code: int | None
    address: int | None  # first register (an FC03 response knows it only from its request)
    count: int | None  # registers addressed (requests) or carried (responses)
    values: tuple[int, ...]  # register values carried by the frame
    items: tuple[RegisterItem, ...]  # the values named (empty when the address is unknown)
    summary: str
    errors: tuple[str, ...]
    command: RunCommand | None = None  # the run command an FC06 request writes to 440
    request: DecodedFrame | None = None  # the request a response was paired with

    @property
    def hex(self) -> str:
        """Spaced uppercase bytes, as in the seed: ``00 01 00 00 00 0B 01 10 …``."""
        return self.raw.hex(" ").upper()

    @property
    def function(self) -> int | None:
        """The function code without the exception flag."""
        return None if self.function_code is None else self.function_code & ~EXCEPTION_FLAG & 0xFF

    @property
    def ok(self) -> bool:
        """Well formed, and not an exception response."""
        return not self.errors and not self.is_exception

    @property
    def direction(self) -> Direction:
        return "rx" if self.is_response else "tx"


@dataclass
class _Pdu:
    function_code: int | None = None
    is_response: bool = False
    is_exception: bool = False
    exception_code: int | None = None
    address: int | None = None
    count: int | None = None
    values: tuple[int, ...] = ()
    complete: bool = False  # every field and value the layout needs is present and consistent


def _words(data: bytes) -> tuple[int, ...]:
    return tuple(int.from_bytes(data[i : i + 2], "big") for i in range(0, len(data) - 1, 2))


def _looks_like_response(function: int, body: bytes) -> bool:
    """Tell request from response by layout (FC06 requests and echoes are the same)."""
    if function == FunctionCode.READ_HOLDING_REGISTERS:
        return len(body) != 4  # request: address, quantity; response: byte count, data
    if function == FunctionCode.WRITE_MULTIPLE_REGISTERS:
        return len(body) == 4  # response: address, quantity
    return False


def _check_size(body: bytes, size: int, what: str, errors: list[str]) -> bool:
    if len(body) < size:
        errors.append(f"truncated {what}: {len(body)} of {size} data bytes")
        return False
    if len(body) > size:
        errors.append(f"{len(body) - size} extra bytes after the {what}")
    return True


def _check_range(address: int, count: int, limit: int, errors: list[str]) -> None:
    if not 1 <= count <= limit:
        errors.append(f"quantity {count} outside 1..{limit}")
    if address + count > 0x10000:
        errors.append(f"registers {address}+{count} run past 65535")


def _parse_pdu(pdu: bytes, direction: Direction | None, errors: list[str]) -> _Pdu:
    out = _Pdu()
    if not pdu:
        errors.append("no PDU: the function code is missing")
        out.is_response = direction == "rx"
        return out
    fc = pdu[0]
    body = pdu[1:]
    out.function_code = fc
    if fc & EXCEPTION_FLAG:
        out.is_response = out.is_exception = True
        if direction == "tx":
            errors.append("an exception response sent as a request")
        if _check_size(body, 1, "exception response", errors):
            out.exception_code = body[0]
            out.complete = True
        return out
    if fc not in _FUNCTION_VERB:
        errors.append(f"unknown function 0x{fc:02X}")
        out.is_response = direction == "rx"
        return out
    out.is_response = _looks_like_response(fc, body) if direction is None else direction == "rx"
    if fc == FunctionCode.READ_HOLDING_REGISTERS and out.is_response:
        if not body:
            errors.append("truncated read response: byte count missing")
            return out
        byte_count, data = body[0], body[1:]
        if byte_count % 2:
            errors.append(f"odd byte count {byte_count}")
        if len(data) != byte_count:
            errors.append(f"byte count {byte_count}, but {len(data)} data bytes")
        out.values = _words(data[:byte_count])
        out.count = len(out.values)
        out.complete = len(data) == byte_count and byte_count % 2 == 0 and byte_count > 0
        if byte_count == 0:
            errors.append("byte count 0")
        return out
    if fc == FunctionCode.WRITE_SINGLE_REGISTER:
        what = "write register " + ("echo" if out.is_response else "request")
        if _check_size(body, 4, what, errors):
            out.address, value = _words(body[:4])
            out.values, out.count, out.complete = (value,), 1, True
        return out
    # FC03 request, FC10 request or FC10 response: address and quantity first.
    if fc == FunctionCode.READ_HOLDING_REGISTERS:
        what = "read request"
    else:
        what = "write response" if out.is_response else "write request"
    needed = 5 if (fc == FunctionCode.WRITE_MULTIPLE_REGISTERS and not out.is_response) else 4
    if len(body) < needed:
        errors.append(f"truncated {what}: {len(body)} of at least {needed} bytes")
        if len(body) >= 2:
            out.address = _words(body[:2])[0]
        return out
    out.address, out.count = _words(body[:4])
    is_write = fc == FunctionCode.WRITE_MULTIPLE_REGISTERS
    limit = regs.MAX_WRITE_REGISTERS if is_write else regs.MAX_READ_REGISTERS
    _check_range(out.address, out.count, limit, errors)
    if needed == 4:
        out.complete = len(body) == 4
        if len(body) > 4:
            errors.append(f"{len(body) - 4} extra bytes after the {what}")
        return out
    byte_count, data = body[4], body[5:]
    good = True
    if byte_count != 2 * out.count:
        errors.append(f"byte count {byte_count} for {out.count} registers (expected {2 * out.count})")
        good = False
    if len(data) != byte_count:
        errors.append(f"byte count {byte_count}, but {len(data)} data bytes")
        good = False
    out.values = _words(data[:byte_count])
    out.complete = good
    return out


def _split_tcp(data: bytes, errors: list[str]) -> tuple[int | None, int | None, bytes]:
    if len(data) < MBAP_SIZE:
        errors.append(f"truncated: {len(data)} bytes, the MBAP header alone needs {MBAP_SIZE}")
        tid = int.from_bytes(data[:2], "big") if len(data) >= 2 else None
        return tid, None, b""
    tid, protocol, length = struct.unpack(">HHH", data[:6])
    if protocol != 0:
        errors.append(f"protocol id {protocol}, expected 0")
    follow = len(data) - 6
    if length != follow:
        errors.append(f"MBAP length {length}, but {follow} bytes follow it")
    return tid, data[6], data[MBAP_SIZE:]


def _split_rtu(data: bytes, errors: list[str]) -> tuple[int | None, bytes]:
    if len(data) < RTU_MIN_SIZE:
        errors.append(f"truncated: {len(data)} bytes, an RTU frame needs at least {RTU_MIN_SIZE}")
        return (data[0] if data else None), b""
    body, sent = data[:-2], int.from_bytes(data[-2:], "little")
    expected = crc16(body)
    if sent != expected:
        errors.append(f"bad CRC 0x{sent:04X}, expected 0x{expected:04X}")
    return data[0], body[1:]


def _pairing_errors(pdu: _Pdu, unit: int | None, request: DecodedFrame, errors: list[str]) -> None:
    function = None if pdu.function_code is None else pdu.function_code & ~EXCEPTION_FLAG & 0xFF
    if request.is_response:
        errors.append("paired with a frame that is not a request")
        return
    if function is not None and request.function is not None and function != request.function:
        errors.append(f"function 0x{function:02X} answers a request of function 0x{request.function:02X}")
        return
    if unit is not None and request.unit is not None and unit != request.unit:
        errors.append(f"unit {unit} answers a request to unit {request.unit}")
    if pdu.is_exception or not pdu.complete:
        return
    if function == FunctionCode.READ_HOLDING_REGISTERS and request.count is not None \
            and len(pdu.values) != request.count:
        errors.append(f"{len(pdu.values)} registers returned, {request.count} requested")
    elif function == FunctionCode.WRITE_SINGLE_REGISTER and (pdu.address, pdu.values) != (
            request.address, request.values):
        errors.append("the echo differs from the request")
    elif function == FunctionCode.WRITE_MULTIPLE_REGISTERS and (pdu.address, pdu.count) != (
            request.address, request.count):
        errors.append(f"acknowledges {pdu.address}+{pdu.count}, the request wrote "
                      f"{request.address}+{request.count}")


def decode_frame(
    data: bytes | bytearray | memoryview,
    *,
    transport: Transport,
    direction: Direction | None = None,
    word_order: WordOrder = WordOrder.LOW_FIRST,
    last_command: RunCommand | None = None,
    params_for: RunCommand | None = None,
    clock_layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS,
    request: DecodedFrame | None = None,
) -> DecodedFrame:
    """Take one frame apart; never raises on malformed bytes (see ``errors``).

    ``direction`` None infers request or response from the layout (an FC06 echo reads as a
    request). ``request`` is the request a response answers: it gives an FC03 response its
    start address and is checked against the response. ``last_command`` decodes GV291,
    ``params_for`` names GV200..GV205 (see ``describe_registers``).
    """
    if transport not in ("tcp", "rtu"):
        raise ValueError(f"transport must be 'tcp' or 'rtu', got {transport!r}")
    raw = bytes(data)
    errors: list[str] = []
    tid: int | None = None
    if transport == "tcp":
        tid, unit, pdu_bytes = _split_tcp(raw, errors)
    else:
        unit, pdu_bytes = _split_rtu(raw, errors)
    header_ok = not (transport == "tcp" and len(raw) < MBAP_SIZE) and not (
        transport == "rtu" and len(raw) < RTU_MIN_SIZE)
    pdu = _parse_pdu(pdu_bytes, direction, errors) if header_ok else _Pdu(is_response=direction == "rx")
    if request is not None and not pdu.is_response:
        request = None  # only a response answers a request
    if request is not None and header_ok:
        _pairing_errors(pdu, unit, request, errors)

    address = pdu.address
    if (pdu.function_code == FunctionCode.READ_HOLDING_REGISTERS and pdu.is_response and request is not None
            and request.function == FunctionCode.READ_HOLDING_REGISTERS):
        address = request.address
    items: tuple[RegisterItem, ...] = ()
    if address is not None and pdu.values:
        items = describe_registers(address, pdu.values, word_order, last_command=last_command,
                                   params_for=params_for, clock_layout=clock_layout)
    command: RunCommand | None = None
    if (pdu.function_code == FunctionCode.WRITE_SINGLE_REGISTER and not pdu.is_response and pdu.complete
            and address == regs.REG_RUN_COMMAND):
        command = _run_command(pdu.values[0])
    summary = _frame_summary(header_ok, pdu, address, items)
    return DecodedFrame(
        raw=raw, transport=transport, transaction_id=tid, unit=unit,
        function_code=pdu.function_code, is_response=pdu.is_response, is_exception=pdu.is_exception,
        exception_code=pdu.exception_code, address=address, count=pdu.count, values=pdu.values,
        items=items, summary=summary, errors=tuple(errors), command=command, request=request,
    )


def _frame_summary(header_ok: bool, pdu: _Pdu, address: int | None, items: Sequence[RegisterItem]) -> str:
    fc = pdu.function_code
    if not header_ok or fc is None:
        return "truncated frame"
    if pdu.is_exception:
        if pdu.exception_code is None:
            return "exception (code missing)"
        text = EXCEPTION_TEXT.get(pdu.exception_code, "unknown exception")
        return f"exception {pdu.exception_code:02X} {text}"
    if fc not in _FUNCTION_VERB:
        return f"function 0x{fc:02X} (unsupported)"
    if fc == FunctionCode.WRITE_SINGLE_REGISTER:
        if not pdu.complete or address is None:
            return "malformed write register"
        text = single_write_text(address, pdu.values[0])
        return f"ack {text}" if pdu.is_response else text
    if fc == FunctionCode.READ_HOLDING_REGISTERS and pdu.is_response:
        if items and address is not None:
            return summarize_registers(address, items)
        n = len(pdu.values)
        return f"{n} reg{'s' if n != 1 else ''} = {_limited([f'0x{v:04X}' for v in pdu.values])}"
    if address is None or pdu.count is None:
        return f"malformed {_FUNCTION_VERB[fc]}"
    label = range_label(address, pdu.count)
    if fc == FunctionCode.READ_HOLDING_REGISTERS:
        return f"read {label}"
    if pdu.is_response:
        return f"ack write {label}"
    if not pdu.complete or not items:
        return f"malformed write {label}"
    return _write_summary(address, items)


# --- Pairing responses with requests ------------------------------------------------------


class FrameDecoder:
    """Decodes a stream of frames, pairing responses with their requests.

    TCP pairs by transaction id, RTU by order (RTU is half-duplex: a response answers the
    oldest pending request of its unit and function; older unanswered ones are dropped).
    ``last_command`` follows the run commands written to 440 that GV291 reports on; set it,
    and ``params_for``, when the caller knows better. Not thread-safe: one thread feeds it.
    """

    def __init__(
        self,
        transport: Transport = "tcp",
        *,
        word_order: WordOrder = WordOrder.LOW_FIRST,
        last_command: RunCommand | None = None,
        params_for: RunCommand | None = None,
        clock_layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS,
        max_pending: int = 256,
    ) -> None:
        if transport not in ("tcp", "rtu"):
            raise ValueError(f"transport must be 'tcp' or 'rtu', got {transport!r}")
        self.transport: Transport = transport
        self.word_order = word_order
        self.last_command = last_command
        self.params_for = params_for
        self.clock_layout = clock_layout
        self._max_pending = max_pending
        self._by_tid: OrderedDict[int, DecodedFrame] = OrderedDict()
        self._in_order: deque[DecodedFrame] = deque(maxlen=max_pending)

    @property
    def pending(self) -> int:
        """Requests still waiting for their response."""
        return len(self._by_tid) if self.transport == "tcp" else len(self._in_order)

    def reset(self) -> None:
        """Forget pending requests (after a reconnect)."""
        self._by_tid.clear()
        self._in_order.clear()

    def decode(
        self, data: bytes | bytearray | memoryview, direction: Direction | None = None
    ) -> DecodedFrame:
        """Decode one frame; ``direction`` None guesses it (and spots FC06 echoes)."""
        raw = bytes(data)
        if direction is None:
            direction = self._guess_direction(raw)
        if direction == "tx":
            frame = self._decode(raw, "tx", None)
            self._remember(frame)
            if frame.command is not None and CommandKind.of(frame.command) is not None:
                self.last_command = frame.command
            return frame
        return self._decode(raw, "rx", self._take(raw))

    def _decode(self, raw: bytes, direction: Direction, request: DecodedFrame | None) -> DecodedFrame:
        return decode_frame(raw, transport=self.transport, direction=direction, word_order=self.word_order,
                            last_command=self.last_command, params_for=self.params_for,
                            clock_layout=self.clock_layout, request=request)

    def _guess_direction(self, raw: bytes) -> Direction:
        probe = decode_frame(raw, transport=self.transport, word_order=self.word_order)
        if probe.is_response:
            return "rx"
        if probe.function_code == FunctionCode.WRITE_SINGLE_REGISTER:
            # An FC06 echo is byte for byte its request: a pending twin makes it a response.
            if self.transport == "tcp" and probe.transaction_id is not None:
                twin = self._by_tid.get(probe.transaction_id)
                return "rx" if twin is not None and twin.raw == raw else "tx"
            return "rx" if any(r.raw == raw for r in self._in_order) else "tx"
        return "tx"

    def _remember(self, frame: DecodedFrame) -> None:
        if frame.is_response or frame.function_code is None:
            return
        if self.transport == "rtu":
            self._in_order.append(frame)
            return
        if frame.transaction_id is None:
            return
        self._by_tid.pop(frame.transaction_id, None)
        self._by_tid[frame.transaction_id] = frame
        while len(self._by_tid) > self._max_pending:
            self._by_tid.popitem(last=False)

    def _take(self, raw: bytes) -> DecodedFrame | None:
        if self.transport == "tcp":
            if len(raw) < 2:
                return None
            return self._by_tid.pop(int.from_bytes(raw[:2], "big"), None)
        if len(raw) < 2:
            return None
        unit, function = raw[0], raw[1] & ~EXCEPTION_FLAG & 0xFF
        for index, request in enumerate(self._in_order):
            if request.unit == unit and request.function == function:
                for _ in range(index + 1):
                    self._in_order.popleft()
                return request
        return None


# --- Encoding -----------------------------------------------------------------------------


def _check(name: str, value: int, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise ValueError(f"{name} must be an integer in {low}..{high}, got {value!r}")
    return value


def _wrap(pdu: bytes, transaction_id: int, unit: int, transport: Transport) -> bytes:
    _check("unit", unit, 0, 0xFF)
    if transport == "tcp":
        _check("transaction id", transaction_id, 0, 0xFFFF)
        return struct.pack(">HHHB", transaction_id, 0, len(pdu) + 1, unit) + pdu
    if transport == "rtu":
        body = bytes([unit]) + pdu
        return body + crc16(body).to_bytes(2, "little")
    raise ValueError(f"transport must be 'tcp' or 'rtu', got {transport!r}")


def _pack_words(values: Sequence[int]) -> bytes:
    return b"".join(_check("register value", v, 0, 0xFFFF).to_bytes(2, "big") for v in values)


def encode_request(
    function: int,
    address: int,
    values: Sequence[int] = (),
    *,
    count: int | None = None,
    transaction_id: int = 0,
    unit: int = 1,
    transport: Transport = "tcp",
) -> bytes:
    """A request frame: FC03 reads ``count`` registers, FC06 writes ``values[0]``, FC10 ``values``."""
    _check("address", address, 0, 0xFFFF)
    if function == FunctionCode.READ_HOLDING_REGISTERS:
        if count is None or values:
            raise ValueError("a read request takes count=, not values")
        _check("quantity", count, 1, regs.MAX_READ_REGISTERS)
        pdu = struct.pack(">BHH", function, address, count)
    elif function == FunctionCode.WRITE_SINGLE_REGISTER:
        if len(values) != 1:
            raise ValueError(f"FC06 writes exactly one value, got {len(values)}")
        pdu = struct.pack(">BH", function, address) + _pack_words(values)
    elif function == FunctionCode.WRITE_MULTIPLE_REGISTERS:
        _check("quantity", len(values), 1, regs.MAX_WRITE_REGISTERS)
        pdu = struct.pack(">BHHB", function, address, len(values), 2 * len(values)) + _pack_words(values)
    else:
        raise ValueError(f"unsupported function 0x{function:02X}")
    if address + (count or len(values)) > 0x10000:
        raise ValueError("registers run past 65535")
    return _wrap(pdu, transaction_id, unit, transport)


def encode_response(
    function: int,
    address: int = 0,
    values: Sequence[int] = (),
    *,
    count: int | None = None,
    exception: int | None = None,
    transaction_id: int = 0,
    unit: int = 1,
    transport: Transport = "tcp",
) -> bytes:
    """A response frame: FC03 carries ``values``, FC06 echoes ``address``/``values[0]``,
    FC10 acknowledges ``address`` and ``count`` (default ``len(values)``); ``exception``
    makes an exception response to ``function`` instead."""
    _check("function", function, 1, 0x7F)
    if exception is not None:
        _check("exception code", exception, 0, 0xFF)
        return _wrap(bytes([function | EXCEPTION_FLAG, exception]), transaction_id, unit, transport)
    _check("address", address, 0, 0xFFFF)
    if function == FunctionCode.READ_HOLDING_REGISTERS:
        _check("quantity", len(values), 1, regs.MAX_READ_REGISTERS)
        pdu = bytes([function, 2 * len(values)]) + _pack_words(values)
    elif function == FunctionCode.WRITE_SINGLE_REGISTER:
        if len(values) != 1:
            raise ValueError(f"FC06 echoes exactly one value, got {len(values)}")
        pdu = struct.pack(">BH", function, address) + _pack_words(values)
    elif function == FunctionCode.WRITE_MULTIPLE_REGISTERS:
        quantity = len(values) if count is None else count
        _check("quantity", quantity, 1, regs.MAX_WRITE_REGISTERS)
        pdu = struct.pack(">BHH", function, address, quantity)
    else:
        raise ValueError(f"unsupported function 0x{function:02X}")
    return _wrap(pdu, transaction_id, unit, transport)


def encode_write_gv(
    n: int,
    values: float | Sequence[float],
    *,
    word_order: WordOrder = WordOrder.LOW_FIRST,
    transaction_id: int = 0,
    unit: int = 1,
    transport: Transport = "tcp",
) -> bytes:
    """FC10 writing float32 ``values`` to ``GVn``, ``GVn+1``, … (``encode_write_gv(200, 30.0)``)."""
    floats = [float(values)] if isinstance(values, (int, float)) else [float(v) for v in values]
    registers = encode_floats(floats, word_order)
    return encode_request(FunctionCode.WRITE_MULTIPLE_REGISTERS, regs.gv_reg(n), registers,
                          transaction_id=transaction_id, unit=unit, transport=transport)


__all__ = [
    "EXCEPTION_TEXT",
    "DecodedFrame",
    "Direction",
    "FrameDecoder",
    "FunctionCode",
    "ItemKind",
    "RegisterItem",
    "Transport",
    "crc16",
    "decode_frame",
    "describe_registers",
    "encode_request",
    "encode_response",
    "encode_write_gv",
    "format_float32",
    "gv_register_name",
    "range_label",
    "single_write_text",
    "summarize_registers",
]
