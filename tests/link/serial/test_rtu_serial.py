"""RTU on a serial line: the simulator serves a pty, RobotClient opens the other end of a relay."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.errors import TeachPadError
from app.link.client import RobotClient
from app.protocol.enums import TeachFrame, WorkMode
from app.protocol.registers import REG_WORK_MODE
from app.sim.config import SimConfig
from app.sim.server import SimController
from tests.link.serial.relay import PtyRelay

pytestmark = pytest.mark.skipif(not hasattr(__import__("os"), "openpty"), reason="needs POSIX ptys")


@pytest.fixture(params=[115200, 9600], ids=lambda b: f"{b}baud")
def line(request: pytest.FixtureRequest) -> Iterator[tuple[PtyRelay, SimController, RobotClient]]:
    baud = int(request.param)
    relay = PtyRelay(baud)
    sim = SimController(SimConfig(serial_port=relay.sim_port, baudrate=baud))
    client: RobotClient | None = None
    try:
        sim.start()
        # 1 s: at 9600 baud the pose answer alone is 0.24 s on the wire; 0.3 s left a loaded
        # machine 60 ms for the relay, the simulator and the host (a timeout under load)
        client = RobotClient(ConnectionSettings(serial_port=relay.host_port, baudrate=baud, timeout=1.0))
        client.connect()
        yield relay, sim, client
    finally:
        if client is not None:
            client.close()
        sim.stop()
        relay.close()


def test_status_pose_and_a_write_over_the_serial_line(line: tuple[PtyRelay, SimController, Any]) -> None:
    relay, sim, client = line
    status = client.read_status()
    assert status.mode == 1
    pose = client.read_pose()
    assert pose.xyzabc == pytest.approx(sim.state().pose, abs=1e-3)
    started = time.monotonic()
    client.set_work_mode(WorkMode.MANUAL)
    elapsed = time.monotonic() - started
    assert sim.writes_to(REG_WORK_MODE)[-1].values == (0,)
    assert sim.state().work_mode is WorkMode.MANUAL
    assert elapsed >= relay.wire_time(8 + 8)  # request and echo, 8 bytes each, at the line's speed
    assert sim.bad_frame_counts() == {}


def test_a_corrupted_crc_is_rejected_both_ways(line: tuple[PtyRelay, SimController, Any]) -> None:
    """A damaged frame is never data; a read is sent again (app/link/line_retry.py), a mode write
    is not (its damaged answer is an error)."""
    relay, sim, client = line
    relay.corrupt_next_request = True
    assert client.read_status().mode == 1  # not answered (bad CRC at the controller): read again
    assert sim.bad_frame_counts() == {"bad CRC": 1}
    assert client.stats.timeouts == 1
    relay.corrupt_next_answer = True
    assert client.read_pose().xyzabc == pytest.approx(sim.state().pose, abs=1e-3)
    assert client.stats.malformed == 1  # the damaged answer was rejected, the read sent again
    relay.corrupt_next_answer = True
    with pytest.raises(TeachPadError):
        client.set_work_mode(WorkMode.MANUAL)  # a damaged answer to a mode change: an error
    assert len(sim.writes_to(REG_WORK_MODE)) == 1  # never sent again
    assert sim.state().work_mode is WorkMode.MANUAL  # it took: only its answer was damaged
    assert client.read_status().mode == 0  # the line recovers


def test_line_noise_before_a_request_is_dropped_at_the_silent_gap(
    line: tuple[PtyRelay, SimController, Any],
) -> None:
    relay, sim, client = line
    relay.noise_before_next_request = b"\x01\x03\x07"  # looks like the start of a frame
    assert client.read_status().mode == 1
    assert sim.bad_frame_counts() == {"incomplete frame": 1}


def test_a_host_polling_at_9600_baud_keeps_its_jog() -> None:
    """The longest answer takes 0.29 s on a 9600 baud line: the watchdog allows for it."""
    relay = PtyRelay(9600)
    sim = SimController(SimConfig(serial_port=relay.sim_port, baudrate=9600))
    client = RobotClient(ConnectionSettings(serial_port=relay.host_port, baudrate=9600, timeout=1.0))
    try:
        sim.start()
        client.connect()
        client.teach_enable(TeachFrame.JOINT, 0, 1)
        client.teach_set_ratio(10.0)
        assert sim.wait_for(lambda s: s.jogging, 5.0)
        for _ in range(3):
            client.read_registers(0, 125)  # 255 bytes back: 0.27 s on the wire
        assert sim.state().jogging and sim.watchdog_events() == []
        client.close()  # the serial line stays open on the simulator's side: silence stops the jog
        assert sim.wait_for(lambda s: not s.jogging, 2.0)
        assert "no request" in sim.watchdog_events()[0].detail
    finally:
        client.close()
        sim.stop()
        relay.close()
