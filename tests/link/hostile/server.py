"""A small raw-socket Modbus server that answers the way a hostile or broken peer would.

It speaks Modbus TCP (MBAP) or RTU framing over TCP, on 127.0.0.1:<free port>, and serves
0x03 / 0x06 / 0x10 from a register bank. For every request it builds the *correct* answer and
then hands it to a :data:`Mutation` (the next one queued with :meth:`HostileServer.push`, else
the default) which decides what is really sent: the correct frame, a malformed one, nothing
(silence), and whether the connection is closed afterwards. One connection at a time, in one
thread, like a controller with a single Modbus slot (:class:`~tests.link.hostile.loopback.Loopback`,
the hostile relay's start code too).
"""

from __future__ import annotations

import socket
import struct
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

from tests.link.hostile.loopback import Loopback

Framing = Literal["tcp", "rtu"]


def crc16(data: bytes) -> bytes:
    crc = 0xFFFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return struct.pack("<H", crc)


def bank_value(address: int) -> int:
    """The initial value of a register: distinct per address, so a shifted read is visible."""
    return (address * 31 + 7) & 0xFFFF


@dataclass(frozen=True)
class Answer:
    """The correct answer the server is about to send, and a builder of variants of it."""

    framing: Framing
    tid: int
    unit: int
    request: bytes  # the request's PDU (function code + data)
    pdu: bytes  # the correct answer's PDU

    @property
    def function(self) -> int:
        return self.request[0]

    def frame(
        self,
        pdu: bytes | None = None,
        *,
        tid: int | None = None,
        unit: int | None = None,
        protocol: int = 0,
        length_delta: int = 0,
        bad_crc: bool = False,
    ) -> bytes:
        """A frame around ``pdu`` (default: the correct one), with the header fields given."""
        pdu = self.pdu if pdu is None else pdu
        unit = self.unit if unit is None else unit
        if self.framing == "tcp":
            tid = self.tid if tid is None else tid
            return struct.pack(">HHHB", tid & 0xFFFF, protocol, len(pdu) + 1 + length_delta, unit) + pdu
        body = bytes([unit]) + pdu
        crc = crc16(body)
        if bad_crc:
            crc = bytes([crc[0] ^ 0xFF, crc[1]])
        return body + crc

    @property
    def correct(self) -> bytes:
        return self.frame()


@dataclass(frozen=True)
class Reply:
    data: bytes | None  # None: stay silent
    close: bool = False  # close the connection after sending


Mutation = Callable[[Answer], Reply]


def correct(answer: Answer) -> Reply:
    return Reply(answer.correct)


def silent(answer: Answer) -> Reply:
    return Reply(None)


class HostileServer(Loopback):
    """See the module docstring. ``with HostileServer("tcp") as server: ... server.port``."""

    thread_name = "hostile-server"

    def __init__(self, framing: Framing, unit: int = 1) -> None:
        super().__init__()
        self.framing = framing
        self.unit = unit
        self.registers = [bank_value(a) for a in range(0x10000)]
        self.default: Mutation = correct
        self._script: deque[Mutation] = deque()
        self.requests = 0
        self.last: tuple[bytes, bytes | None] | None = None  # (correct frame, what was sent)
        self._conn: socket.socket | None = None
        self._lock = threading.Lock()

    # -- control ------------------------------------------------------------------------
    def push(self, *mutations: Mutation) -> None:
        """Answer the next requests with these, in order (then the default again)."""
        self._script.extend(mutations)

    def send_raw(self, data: bytes) -> None:
        """Send bytes nobody asked for on the current connection."""
        with self._lock:
            assert self._conn is not None
            self._conn.sendall(data)

    # -- the server thread ----------------------------------------------------------------
    def serve(self, conn: socket.socket) -> None:
        self._conn = conn
        try:
            self._serve_connection(conn)
        finally:
            with self._lock:
                self._conn = None

    def _read_request(self, conn: socket.socket) -> tuple[int, int, bytes]:
        """(tid, unit, request PDU)."""
        if self.framing == "tcp":
            tid, _, length, unit = struct.unpack(">HHHB", self.recv_exact(conn, 7))
            return tid, unit, self.recv_exact(conn, length - 1)
        head = self.recv_exact(conn, 7)  # unit, fc, address, count/value, first byte after
        rest = 1 if head[1] in (0x03, 0x06) else head[6] + 2  # CRC's 2nd byte / data + CRC
        frame = head + self.recv_exact(conn, rest)
        assert frame[-2:] == crc16(frame[:-2]), "the client sent a bad CRC"
        return 0, frame[0], frame[1:-2]

    def _answer_pdu(self, pdu: bytes) -> bytes:
        fc, address, second = struct.unpack_from(">BHH", pdu)
        if fc == 0x03:
            values = self.registers[address : address + second]
            return struct.pack(f">BB{second}H", fc, 2 * second, *values)
        if fc == 0x06:
            self.registers[address] = second
            return pdu[:5]
        if fc == 0x10:
            written = struct.unpack_from(f">{second}H", pdu, 6)
            self.registers[address : address + second] = written
            return pdu[:5]
        return bytes([fc | 0x80, 0x01])

    def _serve_connection(self, conn: socket.socket) -> None:
        while not self.stopping:
            tid, unit, request = self._read_request(conn)
            self.requests += 1
            answer = Answer(self.framing, tid, unit, request, self._answer_pdu(request))
            mutation = self._script.popleft() if self._script else self.default
            reply = mutation(answer)
            self.last = (answer.correct, reply.data)
            if reply.data is not None:
                with self._lock:
                    conn.sendall(reply.data)
            if reply.close:
                return


def with_pdu(change: Callable[[Answer], bytes]) -> Mutation:
    """A mutation that sends a frame built around a changed PDU (the header stays consistent)."""
    return lambda a: Reply(a.frame(change(a)))


__all__ = [
    "Answer",
    "HostileServer",
    "Mutation",
    "Reply",
    "bank_value",
    "correct",
    "crc16",
    "silent",
    "with_pdu",
]
