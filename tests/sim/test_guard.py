"""The simulator under bad input (checked at the wire with a raw socket) and its watchdog."""

from __future__ import annotations

import logging
import socket
import struct
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from app.protocol.registers import GV_PARAM0, GV_PARAM3, REG_RUN_COMMAND
from app.sim.guard import BadFrames, screen_request
from app.sim.server import SimController
from tests.sim.conftest import Bus

MBAP_HEADER = struct.Struct(">HHHB")


class RawLink:
    """A TCP socket speaking hand-made MBAP frames."""

    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5.0)
        self.buffer = b""

    def close(self) -> None:
        self.sock.close()

    @staticmethod
    def frame(pdu: bytes, *, tid: int = 1, unit: int = 1, pid: int = 0) -> bytes:
        return MBAP_HEADER.pack(tid, pid, len(pdu) + 1, unit) + pdu

    def answer(self) -> tuple[int, int, bytes]:
        """The next answer: (transaction id, unit, PDU)."""
        while True:
            if len(self.buffer) >= 6:
                length = struct.unpack(">H", self.buffer[4:6])[0]
                if len(self.buffer) >= 6 + length:
                    tid, _, _, unit = MBAP_HEADER.unpack(self.buffer[:7])
                    pdu, self.buffer = self.buffer[7 : 6 + length], self.buffer[6 + length :]
                    return tid, unit, pdu
            chunk = self.sock.recv(65536)
            assert chunk, "the simulator closed the connection"
            self.buffer += chunk

    def ask(self, pdu: bytes, **kwargs: Any) -> bytes:
        self.sock.sendall(self.frame(pdu, **kwargs))
        return self.answer()[2]

    def silent_for(self, seconds: float) -> bool:
        """True when nothing arrives for ``seconds``."""
        self.sock.settimeout(seconds)
        try:
            return not self.sock.recv(1)
        except TimeoutError:
            return True
        finally:
            self.sock.settimeout(5.0)


@pytest.fixture
def raw(sim: SimController) -> Iterator[RawLink]:
    link = RawLink(sim.port)
    try:
        yield link
    finally:
        link.close()


def read_request(address: int, count: int) -> bytes:
    return struct.pack(">BHH", 3, address, count)


GOOD_READ = read_request(560, 3)


@pytest.mark.parametrize(
    "pdu",
    [
        struct.pack(">BHH", 0x01, 0, 8),  # read coils
        struct.pack(">BHH", 0x02, 0, 8),  # read discrete inputs
        struct.pack(">BHH", 0x04, 0, 8),  # read input registers
        struct.pack(">BHH", 0x05, 0, 0xFF00),  # write single coil
        struct.pack(">BHHB", 0x0F, 0, 8, 1) + b"\x01",  # write multiple coils
        struct.pack(">BHHHHB", 0x17, 0, 2, 0, 1, 2) + b"\0\0",  # read/write multiple registers
        bytes([0x08, 0, 0, 0x12, 0x34]),  # diagnostics
        bytes([0x2B, 0x0E, 1, 0]),  # device identification
        bytes([0x55, 0, 0]),  # nothing at all
    ],
)
def test_functions_the_controller_lacks_get_exception_1(sim: SimController, raw: RawLink, pdu: bytes) -> None:
    assert raw.ask(pdu) == bytes([pdu[0] | 0x80, 0x01])
    assert sim.bad_frame_counts() == {"illegal function": 1}
    assert raw.ask(GOOD_READ)[:2] == b"\x03\x06"
    assert sim.writes == []


@pytest.mark.parametrize(
    "pdu",
    [
        read_request(412, 0),
        read_request(0, 126),
        struct.pack(">BHHB", 0x10, 400, 0, 0),
        struct.pack(">BHHB", 0x10, 0, 124, 248) + b"\0" * 248,
        struct.pack(">BHHB", 0x10, 400, 2, 3) + b"\0" * 4,  # byte count is not 2 x count
        struct.pack(">BHHB", 0x10, 400, 2, 4) + b"\0" * 2,  # fewer data bytes than the byte count
        struct.pack(">BHH", 0x03, 412, 2) + b"\0",  # a byte too many
    ],
)
def test_illegal_quantities_get_exception_3(sim: SimController, raw: RawLink, pdu: bytes) -> None:
    assert raw.ask(pdu) == bytes([pdu[0] | 0x80, 0x03])
    assert sum(sim.bad_frame_counts().values()) == 1
    assert sim.writes == []
    assert raw.ask(read_request(0, 125))[:2] == b"\x03\xfa"  # the largest legal read


def test_a_bad_mbap_header_does_not_jam_the_connection(sim: SimController, raw: RawLink) -> None:
    # pymodbus 3.16 alone waits for ever on a frame with protocol id 5: nothing answered again
    raw.sock.sendall(raw.frame(GOOD_READ, pid=5))
    assert raw.silent_for(0.05)
    assert raw.ask(GOOD_READ, tid=2)[:2] == b"\x03\x06"
    raw.sock.sendall(b"\x00\x07\x00\x00\xff\xff\x01\x03")  # impossible length: the buffer is dropped
    assert raw.silent_for(0.05)
    assert raw.ask(GOOD_READ, tid=3)[:2] == b"\x03\x06"
    assert sim.bad_frame_counts() == {"bad protocol id": 1, "bad MBAP length": 1}


def test_another_unit_gets_gateway_exception_and_no_traceback(
    sim: SimController, raw: RawLink, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.INFO):
        raw.sock.sendall(raw.frame(GOOD_READ, unit=7))
        _, unit, pdu = raw.answer()
    assert (unit, pdu) == (7, b"\x83\x0b")
    assert "Traceback" not in caplog.text
    assert sim.bad_frame_counts() == {"unit 7": 1}


def test_pipelined_requests_are_all_answered_in_order(sim: SimController, raw: RawLink) -> None:
    raw.sock.sendall(b"".join(raw.frame(read_request(560 + i, 1), tid=100 + i) for i in range(40)))
    answers = [raw.answer() for _ in range(40)]
    assert [tid for tid, _, _ in answers] == list(range(100, 140))
    assert all(pdu[:2] == b"\x03\x02" for _, _, pdu in answers)


def test_a_flood_of_bad_frames_logs_little_and_the_server_answers_right_after(
    sim: SimController, raw: RawLink, caplog: pytest.LogCaptureFixture
) -> None:
    kinds = [
        (struct.pack(">BHH", 0x01, 0, 8), b"\x81\x01"),
        (read_request(412, 0), b"\x83\x03"),
        (struct.pack(">BHHB", 0x10, 400, 2, 3) + b"\0" * 4, b"\x90\x03"),
        (GOOD_READ, None),  # sent with protocol id 9: skipped without an answer
    ]
    flood = b"".join(
        raw.frame(kinds[i % 4][0], tid=i % 60000, pid=9 if i % 4 == 3 else 0) for i in range(10_000)
    )
    with caplog.at_level(logging.DEBUG, logger="app.sim"), caplog.at_level(logging.INFO):
        raw.sock.sendall(flood + raw.frame(GOOD_READ, tid=60001))
        expected = [kinds[i % 4][1] for i in range(10_000) if i % 4 != 3]
        for want in expected:
            assert raw.answer()[2] == want
        tid, _, pdu = raw.answer()
    assert tid == 60001 and pdu[:2] == b"\x03\x06"
    assert sim.bad_frame_counts() == {
        "illegal function": 2500,
        "illegal quantity": 5000,
        "bad protocol id": 2500,
    }
    lines = [r for r in caplog.records if r.levelno >= logging.INFO]
    assert len(lines) <= 3, [r.getMessage() for r in lines]
    assert sum(len(r.getMessage()) for r in lines) < 1000


def test_bad_frame_log_is_one_sample_then_one_summary_per_period(caplog: pytest.LogCaptureFixture) -> None:
    now = [0.0]
    frames = BadFrames(period=5.0, clock=lambda: now[0])
    with caplog.at_level(logging.WARNING, logger="app.sim.guard"):
        for i in range(1000):
            frames.record("illegal function" if i % 2 else "bad CRC", bytes(range(40)))
        frames.flush()  # the period is not over: nothing yet
        assert len(caplog.records) == 1
        assert "00 01 02 03 04 05 06 07 08 09 0a 0b 0c 0d 0e 0f ... (40 bytes)" in caplog.text
        now[0] = 5.0
        frames.flush()
    assert len(caplog.records) == 2
    assert "999 more bad frame(s)" in caplog.records[1].getMessage()
    assert frames.counts() == {"illegal function": 500, "bad CRC": 500}


def test_screen_request_accepts_the_three_functions() -> None:
    assert screen_request(read_request(412, 125)) is None
    assert screen_request(struct.pack(">BHH", 6, 440, 0x80)) is None
    assert screen_request(struct.pack(">BHHB", 0x10, 400, 123, 246) + b"\0" * 246) is None


# --- communication watchdog ---------------------------------------------------------------
def start_jog(bus: Bus, sim: SimController, ratio: float = 20.0) -> None:
    bus.set_gv(GV_PARAM0, [0.0, 1.0, 1.0, 0.0])  # base frame, axis Y, positive, ratio 0
    bus.write(REG_RUN_COMMAND, 0x80)
    assert sim.wait_for(lambda s: s.teach_enabled, 5.0)
    bus.set_gv(GV_PARAM3, [ratio])
    assert sim.wait_for(lambda s: s.jogging, 5.0)


def test_watchdog_stops_the_jog_when_its_connection_closes(
    sim: SimController, make_bus: Callable[..., Bus]
) -> None:
    other = make_bus(sim.port)
    bus = make_bus(sim.port)
    start_jog(bus, sim)
    other.close()  # not the connection that started the jog
    assert not sim.wait_for(lambda s: not s.jogging, 0.1)
    closed = time.monotonic()
    bus.close()
    assert sim.wait_for(lambda s: not s.jogging, 2.0)
    (event,) = sim.watchdog_events()
    assert event.t - closed < 0.25 and "closed" in event.detail
    state = sim.state()
    assert state.teach_ratio == 0 and state.teach_enabled  # teach stays on: the host decides
    check = make_bus(sim.port)
    assert check.gv(GV_PARAM3) == [0.0]  # GV203 reads 0, so teach disable is accepted
    check.write(REG_RUN_COMMAND, 0x81)
    assert sim.wait_for(lambda s: not s.teach_enabled, 5.0)


def test_watchdog_stops_the_jog_when_no_request_arrives(
    sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]
) -> None:
    sim = sim_factory(watchdog=0.1)
    bus = make_bus(sim.port)
    start_jog(bus, sim)
    last_request = sim.writes[-1].t  # the ratio write, as the simulator received it
    assert sim.wait_for(lambda s: not s.jogging, 2.0)
    (event,) = sim.watchdog_events()
    assert 0.09 <= event.t - last_request < 0.1 + 0.25
    assert "no request" in event.detail
    before = sim.state()
    assert sim.wait_for(lambda s: s.t > before.t + 0.1, 5.0)
    assert sim.state().pose == before.pose  # the arm stands still
    assert bus.mode() == 2  # the connection itself is fine


def test_a_polling_host_keeps_its_jog(
    sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]
) -> None:
    sim = sim_factory(watchdog=0.5)
    bus = make_bus(sim.port)
    start_jog(bus, sim)
    end = time.monotonic() + 0.8  # longer than the watchdog
    while time.monotonic() < end:
        bus.mode()
        time.sleep(0.02)  # the GUI's 50 Hz poll
    assert sim.state().jogging and sim.watchdog_events() == []


def test_watchdog_off_keeps_jogging_like_a_controller_without_one(
    sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]
) -> None:
    sim = sim_factory(watchdog=None)
    bus = make_bus(sim.port)
    start_jog(bus, sim)
    bus.close()
    assert sim.wait_for(lambda _: sim.connections_count == 0, 2.0)
    t0 = sim.state().t
    assert sim.wait_for(lambda s: s.t > t0 + 0.3, 5.0)
    assert sim.state().jogging and sim.watchdog_events() == []


def test_another_master_polling_does_not_keep_a_silent_hosts_jog(
    sim_factory: Callable[..., SimController], make_bus: Callable[..., Bus]
) -> None:
    """The watchdog belongs to the connection that jogs (issue 19 section 6): the jogging host goes
    silent (its connection open) while a second master polls at 50 Hz -- the arm stops at the
    watchdog all the same."""
    sim = sim_factory(watchdog=0.2)
    jogger = make_bus(sim.port)
    poller = make_bus(sim.port)
    start_jog(jogger, sim)
    silent_since = sim.writes[-1].t  # the jogger's last request: the ratio write
    deadline = time.monotonic() + 3.0  # well past the watchdog: a jog still going then is a failure
    while sim.state().jogging and time.monotonic() < deadline:
        poller.mode()
        time.sleep(0.02)  # the other master's 50 Hz poll
    state = sim.state()
    assert not state.jogging and state.teach_ratio == 0
    (event,) = sim.watchdog_events()
    assert (
        event.t - silent_since < 0.2 + 0.5 and "connection" in event.detail and "no request" in event.detail
    )
    assert jogger.mode() == 2  # its connection is fine: only silent


def test_requests_are_counted_by_the_connection_that_carried_them(sim: SimController) -> None:
    """Two masters: the simulator tells which connection carried how many requests (a test finds a
    link by what it carries, not by the order its connection opened in)."""
    first = RawLink(sim.port)
    first.ask(GOOD_READ)
    second = RawLink(sim.port)
    try:
        for _ in range(3):
            second.ask(GOOD_READ, tid=2)
        counts = sim.requests_by_connection()
        older, younger = sim.connection_ids()
        assert counts == {older: 1, younger: 3}
        assert sum(counts.values()) == sim.requests_count
    finally:
        first.close()
        second.close()
