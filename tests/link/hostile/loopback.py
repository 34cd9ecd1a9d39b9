"""The one way the link's tests start a peer of their own on 127.0.0.1: a Modbus server that
misbehaves (:class:`~tests.link.hostile.server.HostileServer`), or a relay in front of the
simulator (:class:`~tests.link.hostile.relay.HostileRelay`,
``tests/link/test_poller_malformed.py``'s garbling proxy).

:class:`Loopback` listens on a free port and serves one connection at a time in one daemon
thread, like a controller with a single Modbus slot; a subclass says what it does with a
connection (:meth:`Loopback.serve`). :class:`LoopbackRelay` opens a connection to the upstream
port (the simulator) for each client connection and hands both to :meth:`LoopbackRelay.relay`.
Either is started by ``with`` (or :meth:`Loopback.start` / :meth:`Loopback.close`); ``.port`` is
where a client connects.
"""

from __future__ import annotations

import socket
import threading
import time
from types import TracebackType
from typing import Self

__all__ = ["TICK", "Loopback", "LoopbackRelay"]

#: s a socket waits before the thread looks at its stop flag again
TICK = 0.05


class Loopback:
    """See the module docstring. Subclasses implement :meth:`serve`."""

    thread_name = "loopback"

    def __init__(self) -> None:
        self._listener = socket.create_server(("127.0.0.1", 0))
        self._listener.settimeout(TICK)
        self.port: int = self._listener.getsockname()[1]
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._accept, name=self.thread_name, daemon=True)

    # -- control ------------------------------------------------------------------------
    def start(self) -> Self:
        self._thread.start()
        return self

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(5)
        self._listener.close()

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()

    @property
    def stopping(self) -> bool:
        return self._stop.is_set()

    # -- the thread -----------------------------------------------------------------------
    def serve(self, conn: socket.socket) -> None:
        """One client connection, until it ends (a ConnectionError / OSError ends it quietly);
        it is closed afterwards."""
        raise NotImplementedError

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self._listener.accept()
            except TimeoutError:
                continue
            conn.settimeout(TICK)
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            try:
                self.serve(conn)
            except (ConnectionError, OSError):
                pass  # the client went away (or the upstream): take the next connection
            finally:
                conn.close()

    def recv_exact(self, conn: socket.socket, n: int, *, within: float | None = None) -> bytes:
        """``n`` bytes from ``conn``; ConnectionError when it closes, when the loopback stops, or
        (``within`` s given) when they have not all come by then."""
        buf = b""
        deadline = None if within is None else time.monotonic() + within
        while len(buf) < n:
            if self._stop.is_set():
                raise ConnectionError("stopping")
            try:
                chunk = conn.recv(n - len(buf))
            except TimeoutError:
                if deadline is not None and time.monotonic() > deadline:
                    raise ConnectionError(f"no answer within {within:g} s") from None
                continue
            if not chunk:
                raise ConnectionError("closed")
            buf += chunk
        return buf


class LoopbackRelay(Loopback):
    """A :class:`Loopback` in front of ``upstream_port`` (the simulator): one upstream connection
    per client connection. Subclasses implement :meth:`relay`."""

    thread_name = "loopback-relay"

    def __init__(self, upstream_port: int) -> None:
        super().__init__()
        self.upstream_port = upstream_port

    def relay(self, conn: socket.socket, upstream: socket.socket) -> None:
        """One client connection and its upstream one, until either ends (both are closed after)."""
        raise NotImplementedError

    def serve(self, conn: socket.socket) -> None:
        try:
            upstream = socket.create_connection(("127.0.0.1", self.upstream_port), timeout=5)
        except OSError:
            return  # the upstream is not there (yet): the client's connection is closed
        with upstream:
            upstream.settimeout(TICK)
            upstream.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self.relay(conn, upstream)
