"""A hostile relay in front of the simulator: the real controller's answers, misbehaving on cue.

The client connects to the relay (127.0.0.1:<free port>, Modbus TCP or RTU framing over TCP);
for each client connection the relay opens one to the simulator. Every request is forwarded to
the simulator (so the controller really acts on it, as a real one would before its answer goes
wrong), the simulator's correct answer is read, and a :data:`Misbehaviour` aimed at that request
(by its index since :meth:`HostileRelay.arm`) decides what the client gets: the answer, a wrong
one, nothing, a hang-up, the previous answer first... Every exchange is logged
(:class:`Exchange`) so a test can tell which request got which answer.

One client connection at a time, in one thread, like a controller with a single Modbus slot
(:class:`~tests.link.hostile.loopback.LoopbackRelay`, the hostile server's start code too).
"""

from __future__ import annotations

import socket
import struct
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from tests.link.hostile.loopback import LoopbackRelay
from tests.link.hostile.server import Answer, Framing, Reply, crc16

__all__ = ["Exchange", "HostileRelay", "Later", "Misbehaviour"]

#: s the relay waits for the simulator's answer to a request before it gives the connection up
ANSWER_WITHIN = 5.0

#: What the client gets for one request: from the correct answer and the answer sent before it
#: on this relay (b"" before the first).
Misbehaviour = Callable[[Answer, bytes], Reply]


@dataclass
class Exchange:
    """One request the relay saw and what it answered."""

    index: int  # requests since arm()
    function: int
    address: int
    count_or_value: int  # a read's count, a 0x06's value, a 0x10's quantity
    correct: bytes  # the simulator's answer, reframed for the client
    sent: bytes | None  # what the client got (None: nothing)
    closed: bool  # the relay hung up after it
    aimed: str = ""  # the misbehaviour's name ("" : answered as the simulator did)
    framing: Framing = "tcp"

    @property
    def is_write(self) -> bool:
        return self.function in (0x06, 0x10)

    @property
    def answered_correctly(self) -> bool:
        """Its own answer came whole: as it was, or (Modbus TCP) after a late answer to an
        earlier request, which a transaction id tells apart (over RTU nothing does)."""
        if self.sent is None or not self.sent.endswith(self.correct):
            return False
        return self.sent == self.correct or (self.framing == "tcp" and self.aimed.startswith("late"))


@dataclass(frozen=True)
class Later(Reply):
    """``data`` first, then after ``gap`` seconds ``then`` (a late answer, then the own one)."""

    then: bytes = b""
    gap: float = 0.02


@dataclass
class _Aim:
    name: str
    misbehaviour: Misbehaviour
    used: bool = field(default=False)


class HostileRelay(LoopbackRelay):
    """See the module docstring. ``with HostileRelay(sim.port, "tcp") as relay: ... relay.port``."""

    thread_name = "hostile-relay"

    def __init__(self, upstream_port: int, framing: Framing = "tcp", *, unit: int = 1) -> None:
        super().__init__(upstream_port)
        self.framing = framing
        self.unit = unit
        self._aims: dict[int, _Aim] = {}
        self._lock = threading.Lock()
        self.count = 0  # requests since arm()
        self.log: list[Exchange] = []
        self._previous = b""

    # -- control ------------------------------------------------------------------------
    def arm(self, aims: dict[int, tuple[str, Misbehaviour]] | None = None) -> None:
        """Count requests from 0 again, forget the log; ``aims``: request index -> misbehaviour."""
        with self._lock:
            self.count = 0
            self.log = []
            self._aims = {i: _Aim(name, m) for i, (name, m) in (aims or {}).items()}

    @property
    def delivered(self) -> bool:
        """Every aimed misbehaviour met its request."""
        with self._lock:
            return all(a.used for a in self._aims.values())

    def exchanges(self) -> list[Exchange]:
        with self._lock:
            return list(self.log)

    # -- the relay thread ---------------------------------------------------------------
    def _read_frame(self, conn: socket.socket, *, answer: bool) -> bytes:
        """One whole frame (a request from the client, or the simulator's answer: within 5 s)."""
        within = ANSWER_WITHIN if answer else None
        if self.framing == "tcp":
            head = self.recv_exact(conn, 7, within=within)
            (length,) = struct.unpack_from(">H", head, 4)
            return head + self.recv_exact(conn, length - 1, within=within)
        head = self.recv_exact(conn, 3, within=within)  # unit, function, 3rd byte
        fc = head[1]
        rest = self._rtu_rest(fc, head[2]) if answer else 5 if fc in (0x03, 0x06) else 4
        frame = head + self.recv_exact(conn, rest, within=within)
        if not answer and fc == 0x10:
            frame += self.recv_exact(conn, frame[6] + 2, within=within)
        return frame

    @staticmethod
    def _rtu_rest(fc: int, third: int) -> int:
        """The bytes of an RTU answer after its first three (unit, function, third byte)."""
        if fc & 0x80:
            return 2  # the CRC
        return third + 2 if fc == 0x03 else 5

    def _pdu(self, frame: bytes) -> tuple[int, int, bytes]:
        """(tid, unit, PDU) of a frame."""
        if self.framing == "tcp":
            tid, _, _, unit = struct.unpack_from(">HHHB", frame)
            return tid, unit, frame[7:]
        assert frame[-2:] == crc16(frame[:-2]), "a bad CRC on the loopback"
        return 0, frame[0], frame[1:-2]

    def relay(self, conn: socket.socket, upstream: socket.socket) -> None:
        self._previous = b""  # a late answer comes on the connection of its request
        while not self.stopping:
            request = self._read_frame(conn, answer=False)
            upstream.sendall(request)
            tid, unit, pdu = self._pdu(request)
            _, _, answer_pdu = self._pdu(self._read_frame(upstream, answer=True))
            answer = Answer(self.framing, tid, unit, pdu, answer_pdu)
            with self._lock:
                index = self.count
                self.count += 1
                aim = self._aims.get(index)
                if aim is not None:
                    aim.used = True
            reply = aim.misbehaviour(answer, self._previous) if aim is not None else Reply(answer.correct)
            fc, address, second = struct.unpack_from(">BHH", pdu)
            exchange = Exchange(
                index,
                fc,
                address,
                second,
                answer.correct,
                reply.data + reply.then
                if isinstance(reply, Later) and reply.data is not None
                else reply.data,
                reply.close,
                aim.name if aim else "",
                self.framing,
            )
            with self._lock:
                self.log.append(exchange)
            if reply.data:
                conn.sendall(reply.data)
            if isinstance(reply, Later):
                time.sleep(reply.gap)
                conn.sendall(reply.then)
            self._previous = answer.correct
            if reply.close:
                return
