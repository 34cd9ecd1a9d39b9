"""*Busy* (Modbus exception 6) for a while during an upload: the points are sent again after a
bounded back-off (re-creating the same point at the same pose is idempotent), and all arrive,
right, at the simulator; a move the controller answers busy is not sent again (issue 19 section 4)."""

from __future__ import annotations

from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.errors import ModbusExceptionError
from app.link.upload import RawItem
from app.protocol import registers
from tests.link.harness import PartsHost

BUSY = ExcCodes.DEVICE_BUSY  # Modbus exception 6
N = 40
WINDOW = 1.0  # s the controller answers busy to everything, from the first point's command on


def _items(n: int = N) -> list[RawItem]:
    return [(100 + i, (100.0 + i, -float(i), 300.0, 180.0, 0.0, float(i % 90)), 200) for i in range(n)]


def test_a_busy_window_mid_upload_is_backed_off_and_every_point_arrives(
    host: PartsHost, sim_factory: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "BUSY_RETRY_BUDGET", 10 * WINDOW)  # roomy: the window is the subject
    sim = sim_factory(command_latency=0.005)
    host.connect(sim)
    sim.set_exception(BUSY, after_write=registers.REG_RUN_COMMAND, seconds=WINDOW)
    items = _items()
    assert host.uploader.start(items)
    while host.uploader.step():
        pass
    assert sim.exceptions_answered > 3  # the window was there, and answered busy
    result = host.of("commandFinished")[-1]
    assert result.ok and result.message == f"uploaded {N} of {N} points", result.message
    assert [ok for _, ok, _, _ in host.of("pointUploaded")] == [True] * N
    held = sim.state().points
    assert {pid: held[pid] for pid, _, _ in items} == {pid: pose for pid, pose, _ in items}
    assert host.link_up and host.reconnect_delays == []


def test_busy_longer_than_the_budget_refuses_the_point_in_words(
    host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The back-off is bounded: a controller busy for good refuses the points, each in words, and
    the upload ends (no endless retry); the link is kept."""
    monkeypatch.setattr(timing, "BUSY_RETRY_BUDGET", 0.3)
    host.connect(sim)
    params = 2 * registers.GV_PARAM0
    sim.set_exception(BUSY, range(params, params + 6))
    assert host.uploader.start(_items(2))
    while host.uploader.step():
        pass
    uploaded = host.of("pointUploaded")
    assert [ok for _, ok, _, _ in uploaded] == [False, False]
    assert "busy" in uploaded[0][2], uploaded[0][2]
    assert 2 < sim.exceptions_answered < 40  # tried again, a bounded number of times
    assert sim.state().points == {} and host.link_up


def test_a_move_answered_busy_is_not_sent_again(sim: Any, make_client: Any) -> None:
    client = make_client(sim, timeout=2.0)
    assert client.create_point(100, pose=(300.0, 0.0, 400.0, 180.0, 0.0, 0.0)).ok
    start = sim.state().pose
    commands = len(sim.writes_to(registers.REG_RUN_COMMAND))
    sim.set_exception(BUSY, range(registers.REG_RUN_COMMAND, registers.REG_RUN_COMMAND + 1))
    with pytest.raises(ModbusExceptionError):
        client.move_to_point(100, speed=50.0)
    assert sim.exceptions_answered == 1  # one try: a move is never repeated on its own
    assert len(sim.writes_to(registers.REG_RUN_COMMAND)) == commands
    sim.set_exception(None)
    assert sim.state().pose == start and not sim.state().moving
