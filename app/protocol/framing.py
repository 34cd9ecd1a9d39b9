"""Modbus framing: function codes, the TCP (MBAP) and RTU (CRC16) envelopes, and encoders.

``split_tcp`` / ``split_rtu`` take a frame's envelope apart for the decoder (``frames.py``);
``encode_request`` / ``encode_response`` / ``encode_write_gv`` build frames for FC 03/06/10
(tests, benchmarks).
"""

from __future__ import annotations

import enum
import struct
from collections.abc import Sequence
from typing import Final, Literal

from app.protocol import registers as regs
from app.protocol.codec import WordOrder, encode_floats

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

FUNCTION_VERB: Final[dict[int, str]] = {
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


# --- Envelopes ----------------------------------------------------------------------------


def split_tcp(data: bytes, errors: list[str]) -> tuple[int | None, int | None, bytes]:
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


def split_rtu(data: bytes, errors: list[str]) -> tuple[int | None, bytes]:
    if len(data) < RTU_MIN_SIZE:
        errors.append(f"truncated: {len(data)} bytes, an RTU frame needs at least {RTU_MIN_SIZE}")
        return (data[0] if data else None), b""
    body, sent = data[:-2], int.from_bytes(data[-2:], "little")
    expected = crc16(body)
    if sent != expected:
        errors.append(f"bad CRC 0x{sent:04X}, expected 0x{expected:04X}")
    return data[0], body[1:]


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
    return encode_request(
        FunctionCode.WRITE_MULTIPLE_REGISTERS,
        regs.gv_reg(n),
        registers,
        transaction_id=transaction_id,
        unit=unit,
        transport=transport,
    )


__all__ = [
    "EXCEPTION_FLAG",
    "FUNCTION_VERB",
    "MBAP_SIZE",
    "RTU_MIN_SIZE",
    "Direction",
    "FunctionCode",
    "Transport",
    "crc16",
    "encode_request",
    "encode_response",
    "encode_write_gv",
    "split_rtu",
    "split_tcp",
]
