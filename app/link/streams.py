"""The byte streams under :class:`~app.link.transport.Transport`: a TCP socket or a serial line.

Each offers ``open``/``close``/``is_open``, ``send`` (the whole frame), ``recv`` (what arrives
within a timeout; :class:`PeerClosed` at the end of the stream) and ``drain`` (drop what waits).
"""

from __future__ import annotations

import select
import socket
import time
from typing import TYPE_CHECKING, Any

from app.errors import LinkError
from app.link.hostname import host_problem_text

if TYPE_CHECKING:
    from app.connection import ConnectionSettings

__all__ = ["SIMULATOR_PORT", "PeerClosed", "SerialStream", "TcpStream"]

SIMULATOR_PORT = 5020  # the simulator's default port, hinted when 502 refuses
_RECV_SIZE = 4096


def _seconds(value: float) -> str:
    return str(round(value, 3))


class PeerClosed(Exception):
    """The other end closed the byte stream."""


# --------------------------------------------------------------------------------------------
# Byte streams: a TCP socket or a serial line
# --------------------------------------------------------------------------------------------


class TcpStream:
    def __init__(self, settings: ConnectionSettings) -> None:
        self._settings = settings
        self._sock: socket.socket | None = None

    @property
    def is_open(self) -> bool:
        return self._sock is not None

    def open(self, timeout: float) -> None:
        s = self._settings
        problem = host_problem_text(s.host)
        if problem is not None:  # a typo: said as such, never handed to the resolver
            raise LinkError(
                f"the host name {s.host[:60]!r} is not valid: {problem}",
                code="host_invalid",
                params={"host": s.host[:60]},
            )
        try:
            sock = socket.create_connection((s.host, s.port), timeout=timeout)
        except (socket.gaierror, UnicodeError):  # UnicodeError: the IDNA codec refused the name
            raise LinkError(
                f"the host name {s.host[:60]!r} cannot be resolved",
                code="host_unresolved",
                params={"host": s.host[:60]},
            ) from None
        except ConnectionRefusedError:
            hint = (
                f" (nothing listens on port 502; the simulator's port is {SIMULATOR_PORT})"
                if s.port == 502
                else ""
            )
            raise LinkError(
                f"connection refused{hint}", code="connection_refused", params={"port": s.port}
            ) from None
        except TimeoutError:
            raise LinkError(
                f"no answer to the connection request within {_seconds(timeout)} s",
                code="connect_timeout",
                params={"seconds": timeout},
            ) from None
        except OSError as exc:
            raise LinkError(
                str(exc.strerror or exc).lower(), code="connect_failed", params={"errno": exc.errno}
            ) from None
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        # Non-blocking from here on, waits by select(): a request costs select + send + select +
        # recv, not two more syscalls to switch the socket's timeout for sendall and for recv.
        sock.setblocking(False)
        self._sock = sock

    def close(self) -> None:
        if self._sock is not None:
            try:
                self._sock.close()
            finally:
                self._sock = None

    def send(self, data: bytes) -> None:
        """The whole frame (a frame is far smaller than the socket's buffer: one ``send``)."""
        sock = self._sock
        assert sock is not None
        try:
            sent = sock.send(data)
        except BlockingIOError:
            sent = 0
        if sent < len(data):  # the buffer was full: the rest, blocking at most the request timeout
            sock.settimeout(self._settings.timeout)
            try:
                sock.sendall(data[sent:])
            finally:
                sock.setblocking(False)

    def recv(self, timeout: float) -> bytes:
        """Whatever arrives within ``timeout`` (b"" for nothing); PeerClosed at end of stream."""
        sock = self._sock
        assert sock is not None
        if not select.select((sock,), (), (), max(timeout, 1e-4))[0]:
            return b""
        try:
            data = sock.recv(_RECV_SIZE)
        except BlockingIOError:  # a readiness that went away
            return b""
        if not data:
            raise PeerClosed
        return data

    def drain(self) -> int:
        """Drop the bytes already waiting; their count. PeerClosed when the peer hung up."""
        sock = self._sock
        assert sock is not None
        dropped = 0
        while select.select((sock,), (), (), 0)[0]:
            try:
                data = sock.recv(_RECV_SIZE)
            except BlockingIOError:
                break
            if not data:
                raise PeerClosed
            dropped += len(data)
        return dropped


class SerialStream:
    """RTU over a serial line (pyserial, which pymodbus[serial] brings)."""

    def __init__(self, settings: ConnectionSettings) -> None:
        self._settings = settings
        self._port: Any = None

    @property
    def is_open(self) -> bool:
        return self._port is not None

    def open(self, timeout: float) -> None:
        import serial

        s = self._settings
        try:
            self._port = serial.Serial(
                s.serial_port,
                baudrate=s.baudrate,
                parity=s.parity,
                stopbits=s.stopbits,
                bytesize=s.bytesize,
                timeout=timeout,
                exclusive=True,
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            raise LinkError(
                f"cannot open the serial port: {exc}",
                code="serial_open_failed",
                params={"port": (s.serial_port or "")[:60]},
            ) from None

    def close(self) -> None:
        if self._port is not None:
            try:
                self._port.close()
            finally:
                self._port = None

    def send(self, data: bytes) -> None:
        self._port.write(data)
        self._port.flush()

    def recv(self, timeout: float) -> bytes:
        self._port.timeout = max(timeout, 1e-4)
        return bytes(self._port.read(max(1, self._port.in_waiting)))

    def drain(self) -> int:
        waiting = int(self._port.in_waiting)
        self._port.reset_input_buffer()
        return waiting

    def settle(self, quiet: float, limit: float) -> int:
        """Drop what arrives until nothing has for ``quiet`` s (at most ``limit`` s in all: a
        babbling line); the bytes dropped. After a bad frame: the rest of it is on the wire still."""
        port = self._port
        end = time.monotonic() + limit
        dropped = self.drain()
        port.timeout = quiet
        while time.monotonic() < end:
            data = port.read(max(1, int(port.in_waiting)))
            if not data:
                break
            dropped += len(data)
        return dropped
