"""Modbus request frames and the check of each answer against its request.

Pure functions over bytes (no I/O), so the transport can check an answer as it arrives and the
benchmarks can time the check alone. Frames are the bytes pymodbus's framers make (TCP: the
MBAP header packed here in one call, tests/link/test_hot_path.py compares it with
``FramerSocket``; RTU: unit + CRC by ``FramerRTU``); the answers are checked here rather than
by pymodbus, whose sync client decodes the answer by *its own* function code, skips frames of
another unit or transaction and does not look at byte counts or echoes.

:func:`frame_need` is called with the bytes received so far: it checks every field those bytes
already show (raising :class:`MalformedResponse` at the first wrong one, so garbage is refused
without waiting for the rest) and returns the length the whole answer must have.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Container, Sequence
from dataclasses import dataclass
from typing import Literal

from pymodbus.framer import FramerRTU
from pymodbus.pdu import DecodePDU

from app.errors import MalformedResponse

__all__ = [
    "FC_READ_HOLDING",
    "FC_WRITE_MULTIPLE",
    "FC_WRITE_SINGLE",
    "Framing",
    "Request",
    "answer_registers",
    "crc16",
    "decode_answer",
    "encode_request",
    "frame_need",
    "read_request",
    "stale_answer_length",
    "write_multiple_request",
    "write_single_request",
]

Framing = Literal["tcp", "rtu"]

FC_READ_HOLDING = 0x03
FC_WRITE_SINGLE = 0x06
FC_WRITE_MULTIPLE = 0x10

_FUNCTION_TEXT = {
    FC_READ_HOLDING: "a read of holding registers",
    FC_WRITE_SINGLE: "a write of one register",
    FC_WRITE_MULTIPLE: "a write of several registers",
}
_MBAP = 7  # transaction id, protocol id, length, unit id
_MBAP_HEADER = struct.Struct(">HHHB")  # what FramerSocket.encode writes before the PDU
_MBAP_START = struct.Struct(">HHH")  # transaction id, protocol id, length
_RTU_FRAMER = FramerRTU(DecodePDU(False))


@dataclass(frozen=True, slots=True)
class Request:
    """One request: its PDU and what its answer must echo."""

    function: int
    address: int
    count: int  # registers read or written
    value: int  # the value of a 0x06 write (0 otherwise)
    pdu: bytes  # function code + data


# Requests are immutable: the few reads and single writes a link repeats (the status block, the
# pose block, 440 <- a command) are built once and reused.
@functools.lru_cache(maxsize=256)
def read_request(address: int, count: int) -> Request:
    return Request(FC_READ_HOLDING, address, count, 0, struct.pack(">BHH", FC_READ_HOLDING, address, count))


@functools.lru_cache(maxsize=256)
def write_single_request(address: int, value: int) -> Request:
    return Request(FC_WRITE_SINGLE, address, 1, value, struct.pack(">BHH", FC_WRITE_SINGLE, address, value))


@functools.lru_cache(maxsize=128)
def _write_multiple_struct(count: int) -> struct.Struct:
    return struct.Struct(f">BHHB{count}H")


def write_multiple_request(address: int, values: Sequence[int]) -> Request:
    n = len(values)
    data = _write_multiple_struct(n).pack(FC_WRITE_MULTIPLE, address, n, 2 * n, *values)
    return Request(FC_WRITE_MULTIPLE, address, n, 0, data)


def crc16(data: bytes) -> int:
    """Modbus RTU CRC as the two bytes appear on the wire (big-endian int of them)."""
    return int(FramerRTU.compute_CRC(data))


def encode_request(framing: Framing, request: Request, unit: int, tid: int) -> bytes:
    """The request as sent: MBAP + PDU (TCP; the bytes ``FramerSocket.encode`` makes, packed in
    one call) or unit + PDU + CRC (RTU, pymodbus's framer)."""
    pdu = request.pdu
    if framing == "tcp":
        return _MBAP_HEADER.pack(tid, 0, len(pdu) + 1, unit) + pdu
    return bytes(_RTU_FRAMER.encode(pdu, unit, tid))


def _hex(value: int, width: int = 2) -> str:
    return f"0x{value:0{width}X}"


def _bad(field: str, expected: object, got: object, text: str) -> MalformedResponse:
    return MalformedResponse(text, field=field, expected=expected, got=got)


def _answer_pdu_size(request: Request, buf: bytes, at: int) -> int | None:
    """Size of the answer's PDU (function code onwards), checking the function code and byte
    count found at ``buf[at]``; None when the byte count has not arrived yet."""
    fc = buf[at]
    if fc == request.function | 0x80:
        return 2  # function | 0x80, exception code
    if fc != request.function:
        raise _bad(
            "function",
            request.function,
            fc,
            f"controller answered function {_hex(fc)} to {_FUNCTION_TEXT[request.function]} "
            f"({_hex(request.function)})",
        )
    if request.function != FC_READ_HOLDING:
        return 5  # function, address, value or quantity
    if len(buf) <= at + 1:
        return None
    byte_count = buf[at + 1]
    if byte_count != 2 * request.count:
        raise _bad(
            "byte count",
            2 * request.count,
            byte_count,
            f"byte count {byte_count}, expected {2 * request.count} for {request.count} "
            f"register{'s' if request.count != 1 else ''}",
        )
    return 2 + byte_count


def _check_pdu(request: Request, pdu: bytes) -> None:
    """The complete PDU: exception code, or the write's echo."""
    if pdu[0] & 0x80:
        if pdu[1] == 0:
            raise _bad("exception code", "1..255", 0, "exception answer with exception code 0")
        return
    if request.function == FC_READ_HOLDING:
        return
    address, second = struct.unpack_from(">HH", pdu, 1)
    if address != request.address:
        raise _bad(
            "address",
            request.address,
            address,
            f"the write's answer echoes address {address}, expected {request.address}",
        )
    if request.function == FC_WRITE_SINGLE and second != request.value:
        raise _bad(
            "value",
            request.value,
            second,
            f"the write's answer echoes value {second}, expected {request.value}",
        )
    if request.function == FC_WRITE_MULTIPLE and second != request.count:
        raise _bad(
            "quantity",
            request.count,
            second,
            f"the write's answer echoes {second} registers, expected {request.count}",
        )


def frame_need(framing: Framing, request: Request, unit: int, tid: int, buf: bytes) -> int:
    """Check what ``buf`` holds of the answer; return the answer's full length (so far known).

    When ``len(buf)`` reaches the returned length the answer is complete and fully checked.
    """
    if framing == "tcp":
        return _tcp_need(request, unit, tid, buf)
    return _rtu_need(request, unit, buf)


def _tcp_need(request: Request, unit: int, tid: int, buf: bytes) -> int:
    """:func:`frame_need` of a Modbus TCP answer: the MBAP header, then the PDU."""
    if len(buf) < _MBAP + 1:
        return _MBAP + 1
    length = _check_mbap(buf, unit, tid)
    size = _answer_pdu_size(request, buf, _MBAP)
    if size is None:
        return _MBAP + 2
    if length != 1 + size:
        raise _bad("length", 1 + size, length, f"MBAP length field {length}, expected {1 + size}")
    total = _MBAP + size
    if len(buf) >= total:
        _check_pdu(request, buf[_MBAP:total])
    return total


def _check_mbap(buf: bytes, unit: int, tid: int) -> int:
    """The MBAP header names this request's answer (transaction id, protocol id, unit id); its
    length field, checked by the caller once the PDU's size is known."""
    got_tid, protocol, length, got_unit = struct.unpack_from(">HHHB", buf)
    if got_tid != tid:
        raise _bad(
            "transaction id",
            tid,
            got_tid,
            f"transaction id {got_tid}, expected {tid} (an answer to another request)",
        )
    if protocol != 0:
        raise _bad("protocol id", 0, protocol, f"MBAP protocol id {protocol}, expected 0")
    if got_unit != unit:
        raise _bad("unit id", unit, got_unit, f"unit id {got_unit}, expected {unit}")
    return int(length)


def _rtu_need(request: Request, unit: int, buf: bytes) -> int:
    """:func:`frame_need` of a Modbus RTU answer: unit id, PDU, CRC."""
    if len(buf) < 2:
        return 2
    if buf[0] != unit:
        raise _bad("unit id", unit, buf[0], f"unit id {buf[0]}, expected {unit}")
    size = _answer_pdu_size(request, buf, 1)
    if size is None:
        return 3
    total = 1 + size + 2
    if len(buf) >= total:
        crc = int.from_bytes(buf[total - 2 : total], "big")
        expected = crc16(buf[: total - 2])
        if crc != expected:
            raise _bad("CRC", expected, crc, f"CRC {_hex(crc, 4)}, expected {_hex(expected, 4)}")
        _check_pdu(request, buf[1 : total - 2])
    return total


def stale_answer_length(buf: bytes, earlier: Container[int]) -> int:
    """TCP: the length of the answer to an *earlier* request of this link that ``buf`` starts
    with (its transaction id in ``earlier``, protocol id 0, a plausible MBAP length); 0 when it
    does not start with one (the caller checks it as this request's answer). The length may
    exceed ``len(buf)``: the rest has not arrived yet. Such an answer came late (a duplicate, a
    slow gateway): dropped whole, it cannot be taken for this request's, whose own answer follows."""
    if len(buf) < 6:
        return 0
    got_tid, protocol, length = _MBAP_START.unpack_from(buf)
    if got_tid not in earlier or protocol != 0 or not 2 <= length <= 254:
        return 0
    return 6 + int(length)


@functools.lru_cache(maxsize=128)
def _registers_struct(count: int) -> struct.Struct:
    return struct.Struct(f">{count}H")


def answer_registers(data: bytes, count: int) -> list[int]:
    """The ``count`` registers of a checked 0x03 answer (``data``: after the function code)."""
    return list(_registers_struct(count).unpack_from(data, 1))


def decode_answer(framing: Framing, frame: bytes) -> tuple[int, bytes]:
    """(function code, data after it) of a checked answer."""
    pdu = frame[_MBAP:] if framing == "tcp" else frame[1:-2]
    return pdu[0], pdu[1:]
