"""Modbus frames as text: the decoder behind the traffic inspector and the logs.

``decode_frame`` turns one raw frame, Modbus TCP (MBAP header + PDU) or RTU (unit + PDU +
CRC16), request or response, into a ``DecodedFrame``: the header fields, the register values,
the registers named after the controller's map (``naming.py``) and a short English
``summary`` such as ``write GV200 = 30.0`` or ``teach enable (440 ← 0x80)``. It never raises on
malformed input: what is wrong goes to ``errors`` and the summary says what could be read.

An FC03 response does not carry its start address, so ``FrameDecoder`` pairs each response
with its request (by transaction id over TCP, by order over RTU) to name the values it reads.

The envelopes and the encoders are in ``framing.py``, the exception texts in ``exceptions.py``.
"""

from __future__ import annotations

import struct
from collections import OrderedDict, deque
from collections.abc import Sequence
from dataclasses import dataclass

from app.protocol import registers as regs
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.protocol.enums import CommandKind, RunCommand
from app.protocol.exceptions import exception_text
from app.protocol.framing import (
    EXCEPTION_FLAG,
    FUNCTION_VERB,
    MBAP_SIZE,
    RTU_MIN_SIZE,
    Direction,
    FunctionCode,
    Transport,
    split_rtu,
    split_tcp,
)
from app.protocol.naming import RegisterItem, describe_registers, run_command_of
from app.protocol.summaries import (
    limited_list,
    range_label,
    single_write_text,
    summarize_registers,
    write_summary,
)

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
    count = len(data) // 2  # a trailing odd byte is left out
    return struct.unpack(f">{count}H", data[: 2 * count])


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
    if fc not in FUNCTION_VERB:
        errors.append(f"unknown function 0x{fc:02X}")
        out.is_response = direction == "rx"
        return out
    out.is_response = _looks_like_response(fc, body) if direction is None else direction == "rx"
    if fc == FunctionCode.READ_HOLDING_REGISTERS and out.is_response:
        _parse_read_response(body, out, errors)
        return out
    if fc == FunctionCode.WRITE_SINGLE_REGISTER:
        what = "write register " + ("echo" if out.is_response else "request")
        if _check_size(body, 4, what, errors):
            out.address, value = _words(body[:4])
            out.values, out.count, out.complete = (value,), 1, True
        return out
    _parse_addressed(fc, body, out, errors)
    return out


def _parse_read_response(body: bytes, out: _Pdu, errors: list[str]) -> None:
    """An FC03 response: byte count, then the register values."""
    if not body:
        errors.append("truncated read response: byte count missing")
        return
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


def _parse_addressed(fc: int, body: bytes, out: _Pdu, errors: list[str]) -> None:
    """An FC03 request, FC10 request or FC10 response: address and quantity first."""
    if fc == FunctionCode.READ_HOLDING_REGISTERS:
        what = "read request"
    else:
        what = "write response" if out.is_response else "write request"
    needed = 5 if (fc == FunctionCode.WRITE_MULTIPLE_REGISTERS and not out.is_response) else 4
    if len(body) < needed:
        errors.append(f"truncated {what}: {len(body)} of at least {needed} bytes")
        if len(body) >= 2:
            out.address = _words(body[:2])[0]
        return
    out.address, out.count = _words(body[:4])
    is_write = fc == FunctionCode.WRITE_MULTIPLE_REGISTERS
    limit = regs.MAX_WRITE_REGISTERS if is_write else regs.MAX_READ_REGISTERS
    _check_range(out.address, out.count, limit, errors)
    if needed == 4:
        out.complete = len(body) == 4
        if len(body) > 4:
            errors.append(f"{len(body) - 4} extra bytes after the {what}")
        return
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
    if (
        function == FunctionCode.READ_HOLDING_REGISTERS
        and request.count is not None
        and len(pdu.values) != request.count
    ):
        errors.append(f"{len(pdu.values)} registers returned, {request.count} requested")
    elif function == FunctionCode.WRITE_SINGLE_REGISTER and (pdu.address, pdu.values) != (
        request.address,
        request.values,
    ):
        errors.append("the echo differs from the request")
    elif function == FunctionCode.WRITE_MULTIPLE_REGISTERS and (pdu.address, pdu.count) != (
        request.address,
        request.count,
    ):
        errors.append(
            f"acknowledges {pdu.address}+{pdu.count}, the request wrote {request.address}+{request.count}"
        )


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
        tid, unit, pdu_bytes = split_tcp(raw, errors)
    else:
        unit, pdu_bytes = split_rtu(raw, errors)
    header_ok = not (transport == "tcp" and len(raw) < MBAP_SIZE) and not (
        transport == "rtu" and len(raw) < RTU_MIN_SIZE
    )
    pdu = _parse_pdu(pdu_bytes, direction, errors) if header_ok else _Pdu(is_response=direction == "rx")
    if request is not None and not pdu.is_response:
        request = None  # only a response answers a request
    if request is not None and header_ok:
        _pairing_errors(pdu, unit, request, errors)

    address = pdu.address
    if (
        pdu.function_code == FunctionCode.READ_HOLDING_REGISTERS
        and pdu.is_response
        and request is not None
        and request.function == FunctionCode.READ_HOLDING_REGISTERS
    ):
        address = request.address
    items: tuple[RegisterItem, ...] = ()
    if address is not None and pdu.values:
        items = describe_registers(
            address,
            pdu.values,
            word_order,
            last_command=last_command,
            params_for=params_for,
            clock_layout=clock_layout,
        )
    command: RunCommand | None = None
    if (
        pdu.function_code == FunctionCode.WRITE_SINGLE_REGISTER
        and not pdu.is_response
        and pdu.complete
        and address == regs.REG_RUN_COMMAND
    ):
        command = run_command_of(pdu.values[0])
    summary = _frame_summary(header_ok, pdu, address, items)
    return DecodedFrame(
        raw=raw,
        transport=transport,
        transaction_id=tid,
        unit=unit,
        function_code=pdu.function_code,
        is_response=pdu.is_response,
        is_exception=pdu.is_exception,
        exception_code=pdu.exception_code,
        address=address,
        count=pdu.count,
        values=pdu.values,
        items=items,
        summary=summary,
        errors=tuple(errors),
        command=command,
        request=request,
    )


def _frame_summary(header_ok: bool, pdu: _Pdu, address: int | None, items: Sequence[RegisterItem]) -> str:
    fc = pdu.function_code
    if not header_ok or fc is None:
        return "truncated frame"
    if pdu.is_exception:
        return _exception_summary(pdu)
    if fc not in FUNCTION_VERB:
        return f"function 0x{fc:02X} (unsupported)"
    if fc == FunctionCode.WRITE_SINGLE_REGISTER:
        return _single_write_summary(pdu, address)
    if fc == FunctionCode.READ_HOLDING_REGISTERS and pdu.is_response:
        return _read_answer_summary(pdu, address, items)
    return _range_summary(fc, pdu, address, items)


def _exception_summary(pdu: _Pdu) -> str:
    if pdu.exception_code is None:
        return "exception (code missing)"
    text = exception_text(pdu.exception_code)
    return f"exception {pdu.exception_code:02X} {text}"


def _single_write_summary(pdu: _Pdu, address: int | None) -> str:
    """A write of one register, or its echo (the ack)."""
    if not pdu.complete or address is None:
        return "malformed write register"
    text = single_write_text(address, pdu.values[0])
    return f"ack {text}" if pdu.is_response else text


def _read_answer_summary(pdu: _Pdu, address: int | None, items: Sequence[RegisterItem]) -> str:
    """The answer to a read: the registers by name when the request is known, else raw words."""
    if items and address is not None:
        return summarize_registers(address, items)
    n = len(pdu.values)
    return f"{n} reg{'s' if n != 1 else ''} = {limited_list([f'0x{v:04X}' for v in pdu.values])}"


def _range_summary(fc: int, pdu: _Pdu, address: int | None, items: Sequence[RegisterItem]) -> str:
    """A frame about a range of registers: a read request, a multiple write or its ack."""
    if address is None or pdu.count is None:
        return f"malformed {FUNCTION_VERB[fc]}"
    label = range_label(address, pdu.count)
    if fc == FunctionCode.READ_HOLDING_REGISTERS:
        return f"read {label}"
    if pdu.is_response:
        return f"ack write {label}"
    if not pdu.complete or not items:
        return f"malformed write {label}"
    return write_summary(address, items)


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
        return decode_frame(
            raw,
            transport=self.transport,
            direction=direction,
            word_order=self.word_order,
            last_command=self.last_command,
            params_for=self.params_for,
            clock_layout=self.clock_layout,
            request=request,
        )

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


__all__ = ["DecodedFrame", "FrameDecoder", "decode_frame"]
