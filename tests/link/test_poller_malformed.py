"""A malformed poll answer is a failed poll: counted, reported, never published as values.

A small TCP proxy between the client and the simulator garbles chosen answers (a consistent
frame that carries two registers fewer than were asked for): the client must refuse it, the
transport resynchronises (drops the TCP link; the next request reopens it), and the poller goes on.
"""

from __future__ import annotations

import socket
import struct
import threading
from collections.abc import Iterator
from typing import Any

import pytest

from app import timing
from app.link.types import LinkState, Operation
from tests.link.harness import PartsHost


class GarblingProxy:
    """Forwards Modbus TCP to ``port``; the next ``garble`` answers lose their last register pair."""

    def __init__(self, port: int) -> None:
        self._target = port
        self._listener = socket.create_server(("127.0.0.1", 0))
        self._listener.settimeout(0.05)
        self.port: int = self._listener.getsockname()[1]
        self.garble = 0
        self.garbled = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="garbling-proxy", daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        self._listener.close()

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self._listener.accept()
            except TimeoutError:
                continue
            with conn, socket.create_connection(("127.0.0.1", self._target)) as upstream:
                conn.settimeout(0.05)
                self._pump(conn, upstream)

    @staticmethod
    def _frame(sock: socket.socket) -> bytes | None:
        head = b""
        while len(head) < 7:
            chunk = sock.recv(7 - len(head))
            if not chunk:
                return None
            head += chunk
        need = struct.unpack_from(">H", head, 4)[0] - 1
        body = b""
        while len(body) < need:
            chunk = sock.recv(need - len(body))
            if not chunk:
                return None
            body += chunk
        return head + body

    def _pump(self, conn: socket.socket, upstream: socket.socket) -> None:
        while not self._stop.is_set():
            try:
                request = self._frame(conn)
            except TimeoutError:
                continue
            except OSError:
                return
            if request is None:
                return
            upstream.sendall(request)
            answer = self._frame(upstream)
            if answer is None:
                return
            if self.garble > 0 and answer[7] == 0x03 and answer[8] >= 4:
                self.garble -= 1
                self.garbled += 1
                tid, proto, length, unit = struct.unpack_from(">HHHB", answer)
                answer = (
                    struct.pack(">HHHB", tid, proto, length - 4, unit)
                    + bytes([0x03, answer[8] - 4])
                    + answer[9:-4]
                )
            try:
                conn.sendall(answer)
            except OSError:
                return


@pytest.fixture
def proxy(sim: Any) -> Iterator[GarblingProxy]:
    p = GarblingProxy(sim.port)
    try:
        yield p
    finally:
        p.close()


def test_a_malformed_poll_answer_is_a_failed_poll(host: PartsHost, sim: Any, proxy: GarblingProxy) -> None:
    host.connect(sim, port=proxy.port)
    client = host.client
    assert client is not None
    host.poll()
    host.out.clear()
    before = client.stats.malformed
    proxy.garble = 1
    host.poll()  # the status read comes back short
    assert proxy.garbled == 1
    assert client.stats.malformed == before + 1  # counted by the transport
    names = host.names()
    assert "poseChanged" not in names and "statusChanged" not in names and "pollSucceeded" not in names
    errors = host.of("errorOccurred")
    assert len(errors) == 1 and errors[0].operation == Operation.POLL
    assert "malformed answer" in errors[0].message
    assert host.link_up  # one garbled answer is not a lost link
    host.out.clear()
    host.poll()  # the transport reopened the link: the next poll is good
    assert "pollSucceeded" in host.names()


def test_malformed_answers_in_a_row_take_the_link_down(
    host: PartsHost, sim: Any, proxy: GarblingProxy
) -> None:
    host.connect(sim, port=proxy.port)
    host.out.clear()
    proxy.garble = 100
    for _ in range(timing.LINK_LOSS_POLLS):
        host.poll()
    assert not host.link_up and LinkState.DOWN in host.states()
    assert "pollSucceeded" not in host.names() and "poseChanged" not in host.names()
