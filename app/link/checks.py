"""Checks of values before they go on the wire, and register names for messages."""

from __future__ import annotations

import enum
from collections.abc import Sequence
from typing import Any

from app.connection import ConnectionSettings
from app.errors import InvalidInput
from app.protocol import registers
from app.protocol.codec import WordOrder, check_float32

__all__ = [
    "check_enum",
    "check_float",
    "check_floats",
    "check_int",
    "check_settings",
    "check_tool",
    "gv_name",
    "range_name",
]


def check_int(value: object, lo: int, hi: int, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise InvalidInput(f"{name} must be an integer, got {value!r}")
    if not lo <= value <= hi:
        raise InvalidInput(f"{name} must be in {lo}..{hi}, got {value}")
    return value


def check_float(
    value: object, name: str, lo: float | None = None, hi: float | None = None, *, lo_open: bool = False
) -> float:
    try:
        number = check_float32(value, name)  # type: ignore[arg-type]
    except ValueError as exc:
        raise InvalidInput(str(exc)) from None
    if lo is not None and (number < lo or (lo_open and number == lo)):
        bound = f"> {lo:g}" if lo_open else f">= {lo:g}"
        raise InvalidInput(f"{name} must be {bound}, got {number:g}")
    if hi is not None and number > hi:
        raise InvalidInput(f"{name} must be <= {hi:g}, got {number:g}")
    return number


def check_floats(values: Sequence[float], count: int, name: str) -> list[float]:
    if isinstance(values, (str, bytes)):
        raise InvalidInput(f"{name} must be {count} numbers")
    items = list(values)
    if len(items) != count:
        raise InvalidInput(f"{name} needs {count} values, got {len(items)}")
    return [check_float(v, f"{name}[{i}]") for i, v in enumerate(items)]


def check_enum(value: Any, enum_type: type[enum.IntEnum], name: str) -> Any:
    try:
        return enum_type(value)
    except (ValueError, TypeError):
        allowed = ", ".join(f"{m.name.lower()} ({m.value})" for m in enum_type)
        raise InvalidInput(f"{name} must be one of {allowed}, got {value!r}") from None


def check_tool(tool: int) -> int:
    # GV245: 200 = no tool frame, N = tool N+1.
    return check_int(tool, 0, registers.TOOL_NONE, "tool frame")


def gv_name(register: int) -> str:
    n, half = registers.reg_to_gv(register)
    return f"GV{n}_{half}"


def range_name(address: int, count: int) -> str:
    last = address + count - 1
    if count == 1:
        return f"register {address} ({gv_name(address)})"
    if address % 2 == 0 and last % 2 == 1:
        first_gv, last_gv = address // 2, last // 2
        gvs = f"GV{first_gv}" if first_gv == last_gv else f"GV{first_gv}..GV{last_gv}"
    else:
        gvs = f"{gv_name(address)}..{gv_name(last)}"
    return f"registers {address}..{last} ({gvs})"


def check_settings(s: ConnectionSettings) -> None:
    check_int(s.port, 1, 0xFFFF, "port")
    check_int(s.unit, 0, 247, "unit id")
    check_float(s.timeout, "timeout", 0.0, lo_open=True)
    check_int(s.retries, 0, 100, "retries")
    if not isinstance(s.word_order, WordOrder):
        raise InvalidInput(f"word order must be a WordOrder, got {s.word_order!r}")
    if s.framer not in ("socket", "rtu"):
        raise InvalidInput(f"framer must be socket or rtu, got {s.framer!r}")
    if s.parity not in ("N", "E", "O"):
        raise InvalidInput(f"parity must be N, E or O, got {s.parity!r}")
    if not s.point_id_min <= s.point_id_max:
        raise InvalidInput("point_id_min must not exceed point_id_max")
    if s.completion not in ("auto", "sentinel", "observe"):
        raise InvalidInput(f"completion must be auto, sentinel or observe, got {s.completion!r}")
    if s.unconfirmed_after is not None:
        check_float(s.unconfirmed_after, "unconfirmed_after", 0.0, lo_open=True)
