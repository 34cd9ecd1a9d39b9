"""The per-request fast paths give the same bytes and the same refusals as the plain ways."""

from __future__ import annotations

import math
import random
import socket
import struct
import threading

import pytest
from pymodbus.framer import FramerSocket
from pymodbus.pdu import DecodePDU

from app.connection import ConnectionSettings
from app.link.frames import (
    FC_WRITE_MULTIPLE,
    answer_registers,
    encode_request,
    read_request,
    write_multiple_request,
    write_single_request,
)
from app.link.streams import TcpStream
from app.protocol.codec import (
    WordOrder,
    check_float32,
    decode_floats,
    encode_floats,
    float_to_registers,
    registers_to_float,
)
from app.protocol.enums import CommandKind, decode_command_status


def _same(a: float, b: float) -> bool:
    return a == b or (math.isnan(a) and math.isnan(b))


@pytest.mark.parametrize("order", list(WordOrder))
def test_float_blocks_encode_and_decode_as_one_float_at_a_time(order: WordOrder) -> None:
    rng = random.Random(7)
    for _ in range(300):
        values = [rng.uniform(-1e7, 1e7) for _ in range(rng.randint(0, 25))]
        one_by_one = [r for v in values for r in float_to_registers(v, order)]
        assert encode_floats(values, order) == one_by_one
        assert encode_floats(iter(values), order) == one_by_one  # any iterable
        regs = [rng.randint(0, 0xFFFF) for _ in range(2 * rng.randint(0, 25))]
        decoded = decode_floats(regs, order)
        expected = [registers_to_float(regs[i : i + 2], order) for i in range(0, len(regs), 2)]
        assert len(decoded) == len(expected) and all(map(_same, decoded, expected))


def test_decoding_keeps_masking_values_outside_16_bits() -> None:
    assert decode_floats([0x1_0000, 0x3F80]) == [registers_to_float([0, 0x3F80])] == [1.0]
    with pytest.raises(ValueError, match="odd register count 3"):
        decode_floats([0, 0, 0])


def test_a_float_too_large_for_float32_is_still_refused() -> None:
    with pytest.raises(OverflowError):
        encode_floats([1.0, 1e39])
    for bad in (math.nan, math.inf, -math.inf, 1e39, -1e39):
        with pytest.raises(ValueError):
            check_float32(bad)
    with pytest.raises(ValueError, match="must be a number"):
        check_float32(True)
    assert check_float32(-12.5) == -12.5


def test_the_mbap_header_is_the_one_pymodbus_writes() -> None:
    framer = FramerSocket(DecodePDU(False))
    requests = [read_request(560, 24), write_single_request(440, 0xE0)]
    for request in [*requests, write_multiple_request(400, [1, 2, 3])]:
        for unit, tid in ((1, 1), (0, 65000), (247, 300)):
            assert encode_request("tcp", request, unit, tid) == bytes(framer.encode(request.pdu, unit, tid))


def test_requests_are_the_same_bytes_built_once_or_again() -> None:
    assert read_request(560, 24) is read_request(560, 24)
    assert read_request(560, 24).pdu == struct.pack(">BHH", 3, 560, 24)
    values = [0, 0xFFFF, 0x1234]
    request = write_multiple_request(400, values)
    assert request.pdu == struct.pack(">BHHB3H", FC_WRITE_MULTIPLE, 400, 3, 6, *values)
    assert (request.count, request.address) == (3, 400)
    with pytest.raises(struct.error):
        write_multiple_request(400, [0x1_0000])  # a register value is still checked
    assert answer_registers(bytes([6, 0x12, 0x34, 0, 1, 0xFF, 0xFF]), 3) == [0x1234, 1, 0xFFFF]


def test_a_decoded_status_is_shared_and_equal_to_a_fresh_one() -> None:
    decoded = decode_command_status(CommandKind.CREATE_POINT, 0xFF)
    assert decoded is decode_command_status(CommandKind.CREATE_POINT, 0xFF)
    assert decoded.is_done and decoded.code == 0xFF and type(decoded.code) is int


def test_a_send_into_a_full_socket_buffer_waits_for_room_and_sends_everything() -> None:
    ours, peer = socket.socketpair()
    stream = TcpStream(ConnectionSettings(timeout=5.0))
    try:
        ours.setblocking(False)
        stream._sock = ours
        filler = b"x" * 65536
        queued = 0
        while True:  # the peer reads nothing yet: fill our send buffer
            try:
                queued += ours.send(filler)
            except BlockingIOError:
                break
        frame = bytes(range(256)) * 16
        received = bytearray()

        def read_all() -> None:
            peer.settimeout(5.0)
            while len(received) < queued + len(frame):
                received.extend(peer.recv(65536))

        reader = threading.Thread(target=read_all)
        reader.start()
        stream.send(frame)
        reader.join(10.0)
        assert not reader.is_alive()
        assert bytes(received[queued:]) == frame
        assert ours.gettimeout() == 0.0  # non-blocking again for the next request
    finally:
        stream.close()
        peer.close()


def test_a_send_that_finds_no_room_gives_up_after_the_request_timeout() -> None:
    ours, peer = socket.socketpair()
    stream = TcpStream(ConnectionSettings(timeout=0.05))
    try:
        ours.setblocking(False)
        stream._sock = ours
        while True:
            try:
                ours.send(b"x" * 65536)
            except BlockingIOError:
                break
        with pytest.raises(TimeoutError):  # an OSError: the transport reports the link lost
            stream.send(b"y" * 4096)
        assert ours.gettimeout() == 0.0
    finally:
        stream.close()
        peer.close()
