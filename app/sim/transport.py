"""The simulator's Modbus servers: TCP (MBAP or RTU framing) and RTU on a serial line.

pymodbus 3.16's per-connection handler is replaced by :class:`GuardedHandler`, which

* serves every complete frame of a receive buffer, in order (pymodbus serves one frame per
  read and drops a buffer over 264 bytes, so pipelined requests go unanswered), and does not
  wipe a half-received next request when it sends an answer;
* screens requests (:mod:`app.sim.guard`) before pymodbus decodes them, and answers a request
  for another unit with exception 0x0B on TCP, not at all on RTU (another slave's frame);
* on RTU, drops a partial frame after a silent gap longer than 3.5 characters (at least
  :data:`RTU_GAP_MIN`), so line noise does not swallow the next request;
* tells the :class:`~app.sim.guard.CommWatchdog` of requests and of closed connections, and
  marks each request with its connection (:data:`~app.sim.guard.CURRENT_CONNECTION`).
"""

from __future__ import annotations

import asyncio
import itertools
import logging
import threading
import time
from collections import deque
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any

from pymodbus.constants import ExcCodes
from pymodbus.framer import FramerType
from pymodbus.pdu import ModbusPDU
from pymodbus.server import ModbusSerialServer, ModbusTcpServer
from pymodbus.server.requesthandler import ServerRequestHandler
from pymodbus.simulator import SimDevice

from app.sim.guard import (
    CURRENT_CONNECTION,
    BadFrames,
    CommWatchdog,
    RejectedRequest,
    ScreenedRtuFramer,
    ScreenedSocketFramer,
    ScreeningDecoder,
)

log = logging.getLogger(__name__)

RECV_BUFFER_MAX = 1 << 20  # bytes a connection may buffer (asyncio reads up to 256 KiB at once)
RTU_BUFFER_MAX = 512  # bytes: two RTU frames; more is noise
RTU_GAP_MIN = 0.02  # s: a partial RTU frame is dropped after this much silence (or 3.5 chars)
RTU_ANSWER_MAX = 256  # bytes of the longest RTU answer (125 registers)
SERIAL_REOPEN_DELAY = 1.0  # s before the server reopens a serial port that went away

_ids = itertools.count(1)


@dataclass
class ServerGuard:
    """What the handlers of one simulator share."""

    unit: int
    bad_frames: BadFrames
    watchdog: CommWatchdog
    rtu_gap: float = RTU_GAP_MIN


class GuardedHandler(ServerRequestHandler):  # type: ignore[misc]  # pymodbus is untyped here
    """One connection (or the serial line) of the simulator; see the module docstring."""

    def __init__(self, owner: Any, guard: ServerGuard, trace_packet: Callable[[bool, bytes], bytes]) -> None:
        super().__init__(owner, trace_packet, None, None)
        self.guard = guard
        self.connection_id = next(_ids)
        self._rtu = isinstance(self.framer, ScreenedRtuFramer)
        self.max_buffer_size = RTU_BUFFER_MAX if self._rtu else RECV_BUFFER_MAX
        self._pending: deque[tuple[ModbusPDU, tuple[Any, ...] | None]] = deque()
        self._drain_task: asyncio.Task[None] | None = None
        self._last_rx = 0.0
        self._leftover = 0

    def connection_lost(self, exc: Exception | None) -> None:
        self._pending.clear()
        self.guard.watchdog.closed(self.connection_id)
        super().connection_lost(exc)

    def send(self, data: bytes, addr: tuple[Any, ...] | None = None) -> None:
        """Write an answer; unlike pymodbus, keep what has been received meanwhile."""
        transport = self.transport
        if transport is not None and data:
            transport.write(data)

    def callback_data(self, data: bytes, addr: tuple[Any, ...] | None = None) -> int:
        data = self.trace_packet(False, data)
        now = time.monotonic()
        used = 0
        if self._rtu and self._leftover and now - self._last_rx > self.guard.rtu_gap:
            used = min(self._leftover, len(data))  # a frame cut short by silence: noise
            self.guard.bad_frames.record("incomplete frame", data[:used])
        self._last_rx = now
        while used < len(data):
            size, dev_id, tid, frame = self.framer.decode(data[used:])
            if not size:
                break
            used += size
            if frame:
                self._accept(dev_id, tid, frame, addr)
        self._leftover = len(data) - used
        if self._pending and self._drain_task is None:
            self._drain_task = asyncio.get_running_loop().create_task(self._drain())
        return used

    def _accept(self, dev_id: int, tid: int, frame: bytes, addr: tuple[Any, ...] | None) -> None:
        pdu: ModbusPDU | None
        if dev_id != self.guard.unit and self.guard.unit != 0:
            self.guard.bad_frames.record(f"unit {dev_id}", frame)
            if self._rtu:
                return  # another slave on the line
            pdu = RejectedRequest(frame[0], ExcCodes.GATEWAY_NO_RESPONSE)
        else:
            pdu = self.server.decoder.decode(frame)
            if pdu is None:
                return
        pdu.dev_id = dev_id
        pdu.transaction_id = tid
        self._pending.append((pdu, addr))

    async def _drain(self) -> None:
        CURRENT_CONNECTION.set(self.connection_id)  # this task's context only
        try:
            while self._pending:
                pdu, addr = self._pending.popleft()
                if not isinstance(pdu, RejectedRequest):
                    self.guard.watchdog.request(self.connection_id)
                self.last_pdu, self.last_addr = pdu, addr
                await self.handle_request()
        finally:
            self._drain_task = None


class GuardedTcpServer(ModbusTcpServer):  # type: ignore[misc]
    def __init__(
        self,
        device: SimDevice,
        guard: ServerGuard,
        *,
        framer: FramerType,
        address: tuple[str, int],
        trace_packet: Callable[[bool, bytes], bytes],
    ) -> None:
        super().__init__(device, framer=framer, address=address, trace_packet=trace_packet)
        _screen(self, guard, framer)

    def callback_new_connection(self) -> GuardedHandler:
        return GuardedHandler(self, self.guard, self.trace_packet)


class GuardedSerialServer(ModbusSerialServer):  # type: ignore[misc]
    def __init__(
        self,
        device: SimDevice,
        guard: ServerGuard,
        *,
        port: str,
        baudrate: int,
        parity: str,
        stopbits: int,
        trace_packet: Callable[[bool, bytes], bytes],
    ) -> None:
        super().__init__(
            device,
            framer=FramerType.RTU,
            port=port,
            baudrate=baudrate,
            parity=parity,
            stopbits=stopbits,
            bytesize=8,
            reconnect_delay=SERIAL_REOPEN_DELAY,
            trace_packet=trace_packet,
        )
        guard.rtu_gap = max(guard.rtu_gap, 3.5 * 11 / baudrate)
        guard.watchdog.allowance = RTU_ANSWER_MAX * 11 / baudrate  # 9600 baud: 0.29 s
        _screen(self, guard, FramerType.RTU)

    def callback_new_connection(self) -> GuardedHandler:
        return GuardedHandler(self, self.guard, self.trace_packet)


def _screen(server: Any, guard: ServerGuard, framer: FramerType) -> None:
    server.guard = guard
    server.decoder = ScreeningDecoder(guard.bad_frames)
    server.framer = ScreenedRtuFramer if framer == FramerType.RTU else ScreenedSocketFramer


async def shutdown_server(server: Any) -> None:
    """Stop accepting first and let accepted connections finish their setup: closing the asyncio
    Server while an accept is half done makes the new transport's __init__ fail (Server._attach
    asserts) and leaks its socket."""
    loop = asyncio.get_running_loop()
    for sock in getattr(server.transport, "sockets", None) or ():
        loop.remove_reader(sock.fileno())
    for _ in range(3):
        await asyncio.sleep(0)
    await server.shutdown()
    await asyncio.sleep(0)


def close_loop(loop: asyncio.AbstractEventLoop) -> None:
    """Cancel what is left (repeating: a cancelled task may start another), then close."""
    for _ in range(10):
        tasks = asyncio.all_tasks(loop)
        if not tasks:
            break
        for task in tasks:
            task.cancel()
        loop.run_until_complete(asyncio.gather(*tasks, return_exceptions=True))
    for _ in range(3):  # let closed transports release their sockets
        loop.run_until_complete(asyncio.sleep(0))
    loop.run_until_complete(loop.shutdown_asyncgens())
    loop.close()


def _stop_loop(loop: asyncio.AbstractEventLoop) -> None:
    """Ask ``loop`` (another thread's) to stop; nothing when it has closed meanwhile."""
    try:
        loop.call_soon_threadsafe(loop.stop)
    except RuntimeError:  # closed: its thread has ended
        pass


class ServerRunner:
    """A guarded server on its own asyncio loop in a daemon thread (``start``/``stop``)."""

    START_TIMEOUT = 5.0  # s
    STOP_TIMEOUT = 2.0  # s

    def __init__(self) -> None:
        self.port: int | None = None  # the bound TCP port (None on a serial line)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._server: GuardedTcpServer | GuardedSerialServer | None = None
        self._thread: threading.Thread | None = None

    def start(
        self, serve: Callable[[], Awaitable[GuardedTcpServer | GuardedSerialServer]], endpoint: str
    ) -> None:
        """Run ``serve()`` (which listens and returns the server) on a new loop; OSError if it fails."""
        ready = threading.Event()
        errors: list[BaseException] = []
        loop = asyncio.new_event_loop()
        self._loop = loop

        def run_loop() -> None:
            asyncio.set_event_loop(loop)
            try:
                self._server = loop.run_until_complete(serve())
            except BaseException as exc:  # reported to start()
                errors.append(exc)
                ready.set()
                close_loop(loop)
                return
            ready.set()
            loop.run_forever()
            close_loop(loop)

        self._thread = threading.Thread(target=run_loop, name="sim-modbus", daemon=True)
        self._thread.start()
        started = ready.wait(self.START_TIMEOUT)
        if not started or errors:
            if not started:  # still starting: stop its loop, or it would serve on, unowned, for good
                _stop_loop(loop)
            self._thread.join(self.STOP_TIMEOUT)
            why = errors[0] if started else f"timeout ({self.START_TIMEOUT:g} s)"
            raise OSError(f"simulator could not listen on {endpoint}: {why}")
        sockets = getattr(self._server.transport, "sockets", None) if self._server is not None else None
        if sockets:
            self.port = int(sockets[0].getsockname()[1])

    def stop(self) -> None:
        loop, server = self._loop, self._server
        if loop is not None and server is not None and not loop.is_closed():
            try:
                asyncio.run_coroutine_threadsafe(shutdown_server(server), loop).result(self.STOP_TIMEOUT)
            except Exception as exc:  # the loop is going away anyway
                log.warning("server shutdown: %s", exc)
            _stop_loop(loop)
        if self._thread is not None:
            self._thread.join(self.STOP_TIMEOUT)

    @property
    def connections_count(self) -> int:
        server = self._server
        return 0 if server is None else len(server.active_connections)

    def connection_ids(self) -> list[int]:
        """The open connections' ids, oldest first (read in the server's loop)."""
        loop, server = self._loop, self._server
        if loop is None or server is None or loop.is_closed():
            return []

        async def ids() -> list[int]:
            conns = server.active_connections.values()
            return sorted(int(getattr(conn, "connection_id", -1)) for conn in conns)

        return list(asyncio.run_coroutine_threadsafe(ids(), loop).result(self.STOP_TIMEOUT))

    def drop_connections(self) -> int:
        """Close the connected clients' sockets (the server keeps listening)."""
        loop, server = self._loop, self._server
        if loop is None or server is None or loop.is_closed():
            return 0

        async def drop() -> int:
            conns = list(server.active_connections.values())
            for conn in conns:
                conn.close()
            return len(conns)

        return int(asyncio.run_coroutine_threadsafe(drop(), loop).result(self.STOP_TIMEOUT))
