"""Every malformed answer is refused with words that name the field, then the link resyncs.

Each case runs over Modbus TCP (MBAP) and RTU framing over TCP, against the raw-socket
HostileServer (tests/link/hostile/server.py), through RobotClient's public API.
"""

from __future__ import annotations

import re
import select
import struct
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from app.errors import LinkError, MalformedResponse, ModbusExceptionError, ResponseTimeout
from app.link.client import RobotClient
from tests.link.hostile.server import Answer, HostileServer, Mutation, Reply, bank_value, silent, with_pdu

# The client's request timeout in these tests (only the cut-short case waits it). After a resync
# the good answer comes from the server's thread in this process, once it has seen the old
# connection close and accepted the new one: 0.3 s was too short for that under load (a full run).
TIMEOUT = 0.8
WITHIN = f"within {TIMEOUT:g} s"
STATUS = (560, 24)  # the status block: 24 registers


@pytest.fixture(params=["tcp", "rtu"])
def framing(request: pytest.FixtureRequest) -> str:
    return str(request.param)


@pytest.fixture
def server(framing: str) -> Iterator[HostileServer]:
    with HostileServer(framing) as s:  # type: ignore[arg-type]
        yield s


@pytest.fixture
def client(server: HostileServer, make_client: Callable[..., RobotClient]) -> RobotClient:
    return make_client(
        port=server.port, framer="rtu" if server.framing == "rtu" else "socket", timeout=TIMEOUT
    )


def _shift_word(pdu: bytes, at: int, delta: int) -> bytes:
    (word,) = struct.unpack_from(">H", pdu, at)
    return pdu[:at] + struct.pack(">H", (word + delta) & 0xFFFF) + pdu[at + 2 :]


def _byte_count(delta: int) -> Mutation:
    def change(a: Answer) -> bytes:
        data = a.pdu[2:]
        data = data + b"\x00" * delta if delta > 0 else data[: len(data) + delta]
        return bytes([0x03, a.pdu[1] + delta]) + data

    return with_pdu(change)


READ, WRITE1, WRITEN = "read", "write one", "write several"
OPS: dict[str, tuple[Callable[[RobotClient], Any], str]] = {
    READ: (lambda c: c.read_registers(*STATUS), "read of registers 560..583 (GV280..GV291)"),
    WRITE1: (lambda c: c.write_register(100, 0x1234), "write to register 100 (GV50_L)"),
    WRITEN: (lambda c: c.write_registers(0, [1, 2, 3, 4]), "write to registers 0..3 (GV0..GV1)"),
}
TCP_READ_LEN, RTU_READ_LEN = 7 + 2 + 48, 1 + 2 + 48 + 2

# (case, operation, mutation, {framing: (field, message after "<endpoint>: ")})
CASES: list[tuple[str, str, Mutation, dict[str, tuple[str, str]]]] = [
    (
        "function 04",
        READ,
        with_pdu(lambda a: b"\x04" + a.pdu[1:]),
        dict.fromkeys(
            ("tcp", "rtu"),
            ("function", "controller answered function 0x04 to a read of holding registers \\(0x03\\)"),
        ),
    ),
    (
        "function 23",
        READ,
        with_pdu(lambda a: b"\x17" + a.pdu[1:]),
        dict.fromkeys(
            ("tcp", "rtu"),
            ("function", "controller answered function 0x17 to a read of holding registers \\(0x03\\)"),
        ),
    ),
    (
        "exception 0x83 with a bad length",
        READ,
        with_pdu(lambda a: b"\x83\x02\x00"),
        {"tcp": ("length", "MBAP length field 4, expected 3"), "rtu": ("CRC", "CRC 0x.{4}, expected 0x.{4}")},
    ),
    (
        "wrong unit",
        READ,
        lambda a: Reply(a.frame(unit=a.unit + 1)),
        dict.fromkeys(("tcp", "rtu"), ("unit id", "unit id 2, expected 1")),
    ),
    (
        "wrong transaction id",
        READ,
        lambda a: Reply(a.frame(tid=a.tid + 1)),
        {"tcp": ("transaction id", r"transaction id 2, expected 1 \(an answer to another request\)")},
    ),
    (
        "protocol id not 0",
        READ,
        lambda a: Reply(a.frame(protocol=1)),
        {"tcp": ("protocol id", "MBAP protocol id 1, expected 0")},
    ),
    (
        "MBAP length off by one",
        READ,
        lambda a: Reply(a.frame(length_delta=1)),
        {"tcp": ("length", "MBAP length field 52, expected 51")},
    ),
    (
        "byte count too large",
        READ,
        _byte_count(2),
        dict.fromkeys(("tcp", "rtu"), ("byte count", "byte count 50, expected 48 for 24 registers")),
    ),
    (
        "byte count too small",
        READ,
        _byte_count(-2),
        dict.fromkeys(("tcp", "rtu"), ("byte count", "byte count 46, expected 48 for 24 registers")),
    ),
    (
        "odd byte count",
        READ,
        _byte_count(-1),
        dict.fromkeys(("tcp", "rtu"), ("byte count", "byte count 47, expected 48 for 24 registers")),
    ),
    (
        "extra trailing bytes",
        READ,
        lambda a: Reply(a.correct + b"\x00\x01\x02"),
        {
            "tcp": ("length", f"3 bytes more than the {TCP_READ_LEN}-byte answer"),
            "rtu": ("length", f"3 bytes more than the {RTU_READ_LEN}-byte answer"),
        },
    ),
    (
        "short frame, then silence",
        READ,
        lambda a: Reply(a.correct[:-3]),
        {
            "tcp": ("length", f"answer cut short: {TCP_READ_LEN - 3} of {TCP_READ_LEN} bytes {WITHIN}"),
            "rtu": ("length", f"answer cut short: {RTU_READ_LEN - 3} of {RTU_READ_LEN} bytes {WITHIN}"),
        },
    ),
    (
        "short frame, then hang-up",
        READ,
        lambda a: Reply(a.correct[:10], close=True),
        dict.fromkeys(
            ("tcp", "rtu"),
            ("length", r"answer cut short: the controller closed the link after 10 of \d+ bytes"),
        ),
    ),
    (
        "bad CRC",
        READ,
        lambda a: Reply(a.frame(bad_crc=True)),
        {"rtu": ("CRC", "CRC 0x.{4}, expected 0x.{4}")},
    ),
    (
        "0x06 echoes another address",
        WRITE1,
        with_pdu(lambda a: _shift_word(a.pdu, 1, 1)),
        dict.fromkeys(("tcp", "rtu"), ("address", "the write's answer echoes address 101, expected 100")),
    ),
    (
        "0x06 echoes another value",
        WRITE1,
        with_pdu(lambda a: _shift_word(a.pdu, 3, 1)),
        dict.fromkeys(("tcp", "rtu"), ("value", "the write's answer echoes value 4661, expected 4660")),
    ),
    (
        "0x06 answered with 0x10",
        WRITE1,
        with_pdu(lambda a: b"\x10" + a.pdu[1:]),
        dict.fromkeys(
            ("tcp", "rtu"),
            ("function", r"controller answered function 0x10 to a write of one register \(0x06\)"),
        ),
    ),
    (
        "0x10 echoes another address",
        WRITEN,
        with_pdu(lambda a: _shift_word(a.pdu, 1, 2)),
        dict.fromkeys(("tcp", "rtu"), ("address", "the write's answer echoes address 2, expected 0")),
    ),
    (
        "0x10 echoes another quantity",
        WRITEN,
        with_pdu(lambda a: _shift_word(a.pdu, 3, -1)),
        dict.fromkeys(("tcp", "rtu"), ("quantity", "the write's answer echoes 3 registers, expected 4")),
    ),
]


PARAMS = [
    (framing, op, mutation, *expect[framing])
    for _, op, mutation, expect in CASES
    for framing in ("tcp", "rtu")
    if framing in expect
]
IDS = [f"{framing}-{case}" for case, _, _, expect in CASES for framing in ("tcp", "rtu") if framing in expect]


@pytest.mark.parametrize(("framing", "op", "mutation", "field", "text"), PARAMS, ids=IDS)
def test_malformed_answer_is_refused_then_the_link_resyncs(
    framing: str,
    server: HostileServer,
    client: RobotClient,
    op: str,
    mutation: Mutation,
    field: str,
    text: str,
) -> None:
    call, what = OPS[op]
    server.push(mutation)
    with pytest.raises(MalformedResponse) as info:
        call(client)
    prefix = re.escape(f"malformed answer to the {what} from 127.0.0.1:{server.port}: ")
    assert re.fullmatch(prefix + text, str(info.value)), str(info.value)
    assert info.value.field == field
    stats = client.stats
    assert (stats.requests, stats.answers, stats.malformed, stats.resyncs) == (1, 0, 1, 1)
    assert stats.last_error == str(info.value)
    # The next good answer is read correctly (on a fresh link).
    assert client.read_registers(*STATUS) == [bank_value(a) for a in range(560, 584)]
    stats = client.stats
    assert (stats.answers, stats.malformed, stats.timeouts, stats.reconnects) == (1, 1, 0, 1)


def test_a_well_formed_exception_is_a_modbus_exception(server: HostileServer, client: RobotClient) -> None:
    server.push(lambda a: Reply(a.frame(bytes([a.function | 0x80, 0x02]))))
    with pytest.raises(
        ModbusExceptionError,
        match=r"^controller refused read of registers 560\.\.583 "
        r"\(GV280\.\.GV291\): illegal data address$",
    ):
        client.read_status()
    assert (client.stats.exceptions, client.stats.malformed, client.stats.resyncs) == (1, 0, 0)
    assert client.read_registers(*STATUS) == [bank_value(a) for a in range(560, 584)]


def test_a_malformed_status_never_becomes_a_status(server: HostileServer, client: RobotClient) -> None:
    client.read_status()
    good = client.last_status
    server.push(with_pdu(lambda a: b"\x04" + a.pdu[1:]))
    with pytest.raises(MalformedResponse):
        client.read_status()
    assert client.last_status is good


def test_silence_is_a_timeout_within_the_poll_timeout(server: HostileServer, client: RobotClient) -> None:
    poll_timeout = client.settings.effective_poll_timeout
    assert poll_timeout <= 0.15
    server.push(silent)
    t0 = time.monotonic()
    with pytest.raises(ResponseTimeout) as info:
        client.read_pose(timeout=poll_timeout)
    elapsed = time.monotonic() - t0
    assert str(info.value) == (
        f"controller did not answer within {round(poll_timeout, 3)} s (127.0.0.1:{server.port})"
    )
    # seen after the poll timeout, and well before the 1 s request timeout (a loaded machine may
    # wake the reader late: the upper bound is roomy)
    assert poll_timeout <= elapsed < poll_timeout + 0.5
    stats = client.stats
    assert (stats.timeouts, stats.malformed, stats.resyncs) == (1, 0, 1)
    assert client.read_registers(*STATUS) == [bank_value(a) for a in range(560, 584)]


def test_stray_bytes_after_a_good_answer_do_not_poison_the_next(
    server: HostileServer, client: RobotClient
) -> None:
    assert client.read_registers(*STATUS) == [bank_value(a) for a in range(560, 584)]
    server.send_raw(b"\x00\x07\x00")
    sock: Any = client._transport._stream._sock  # type: ignore[union-attr]
    deadline = time.monotonic() + 5
    while not select.select([sock], [], [], 0.01)[0]:  # wait until the stray bytes are here
        assert time.monotonic() < deadline
    assert client.read_registers(*STATUS) == [bank_value(a) for a in range(560, 584)]
    stats = client.stats
    assert (stats.answers, stats.malformed, stats.resyncs) == (2, 0, 1)
    assert stats.last_error == f"dropped 3 stray bytes from 127.0.0.1:{server.port}"


def test_connection_errors_name_the_cause(make_client: Callable[..., RobotClient]) -> None:
    c = make_client(host="no-such-host.invalid", port=5020, connect=False)
    with pytest.raises(
        LinkError,
        match=r"^cannot connect to the controller at no-such-host\.invalid:5020: "
        r"the host name 'no-such-host\.invalid' cannot be resolved$",
    ):
        c.connect()
    assert c.stats.link_errors == 1
    c = make_client(port=502, connect=False)
    try:
        c.connect()
    except LinkError as exc:
        assert str(exc) == (
            "cannot connect to the controller at 127.0.0.1:502: connection refused "
            "(nothing listens on port 502; the simulator's port is 5020)"
        )
    else:
        pytest.skip("something listens on 127.0.0.1:502 here")


def test_lost_during_a_request(server: HostileServer, client: RobotClient) -> None:
    server.push(lambda a: Reply(None, close=True))
    with pytest.raises(
        LinkError,
        match=r"^lost the connection to the controller at 127\.0\.0\.1:\d+ "
        r"during the read of registers 560\.\.583",
    ):
        client.read_registers(*STATUS)
    assert client.read_registers(*STATUS) == [bank_value(a) for a in range(560, 584)]


def test_a_link_closed_while_idle_is_reported_once(server: HostileServer, client: RobotClient) -> None:
    server.push(lambda a: Reply(a.correct, close=True))
    assert client.read_registers(*STATUS) == [bank_value(a) for a in range(560, 584)]
    with pytest.raises(LinkError, match=r"^lost the connection to the controller at 127\.0\.0\.1:\d+"):
        client.read_registers(*STATUS)  # the hang-up is seen before or during this request
    assert client.read_registers(*STATUS) == [bank_value(a) for a in range(560, 584)]
    assert (client.stats.link_errors, client.stats.reconnects) == (1, 1)
