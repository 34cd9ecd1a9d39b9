"""A malformed poll answer is a failed poll: counted, reported, never published as values.

A small TCP proxy between the client and the simulator garbles chosen answers (a consistent
frame that carries two registers fewer than were asked for): the client must refuse it, the
transport resynchronises (drops the TCP link; the next request reopens it), and the poller goes on.
"""

from __future__ import annotations

import socket
import struct
from collections.abc import Iterator
from typing import Any

import pytest

from app import timing
from app.link.types import LinkState, Operation
from tests.link.harness import PartsHost
from tests.link.hostile.loopback import LoopbackRelay


class GarblingProxy(LoopbackRelay):
    """Forwards Modbus TCP to ``port``; the next ``garble`` answers lose their last register pair."""

    thread_name = "garbling-proxy"

    def __init__(self, port: int) -> None:
        super().__init__(port)
        self.garble = 0
        self.garbled = 0

    def _frame(self, sock: socket.socket, *, within: float | None = None) -> bytes:
        head = self.recv_exact(sock, 7, within=within)
        need = struct.unpack_from(">H", head, 4)[0] - 1
        return head + self.recv_exact(sock, need, within=within)

    def relay(self, conn: socket.socket, upstream: socket.socket) -> None:
        while not self.stopping:
            upstream.sendall(self._frame(conn))
            answer = self._frame(upstream, within=5.0)
            if self.garble > 0 and answer[7] == 0x03 and answer[8] >= 4:
                self.garble -= 1
                self.garbled += 1
                tid, proto, length, unit = struct.unpack_from(">HHHB", answer)
                answer = (
                    struct.pack(">HHHB", tid, proto, length - 4, unit)
                    + bytes([0x03, answer[8] - 4])
                    + answer[9:-4]
                )
            conn.sendall(answer)


@pytest.fixture
def proxy(sim: Any) -> Iterator[GarblingProxy]:
    with GarblingProxy(sim.port) as p:
        yield p


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
