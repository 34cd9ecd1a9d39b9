"""RobotClient's two layers: RegisterClient (link, write guard, raw access, pose/status reads)
and the commands on top. Against the simulator; what reached it is read from its write log."""

from __future__ import annotations

from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.errors import InvalidInput, WriteBlocked
from app.link.client import RobotClient
from app.link.register_client import RegisterClient
from app.protocol import registers
from app.protocol.enums import ControllerMode

TOOL_REGISTER = registers.gv_reg(registers.GV_TOOL_FRAME)


def _settings(sim: Any, **kwargs: Any) -> ConnectionSettings:
    return ConnectionSettings(host="127.0.0.1", port=sim.port, word_order=sim.config.word_order, **kwargs)


def test_the_register_layer_alone_reads_and_writes(sim: Any) -> None:
    with RegisterClient(_settings(sim)) as client:
        assert client.read_status().mode is ControllerMode.AUTO
        assert client.last_status is not None
        assert client.read_pose().xyzabc == pytest.approx(sim.state().pose, abs=1e-3)
        client.write_gv(10, [1.5, -2.0])
        assert client.read_gv(10, 2) == [1.5, -2.0]
        assert client.write_count == 1 and client.stats.requests == 4
    (record,) = sim.writes
    assert record.address == registers.gv_reg(10) and len(record.values) == 4
    assert not hasattr(client, "step") and not hasattr(client, "completion_rule")  # commands live above


def test_the_write_guard_refuses_before_the_wire(sim: Any) -> None:
    with RegisterClient(_settings(sim, monitor_only=True)) as client:
        with pytest.raises(WriteBlocked, match="monitor-only"):
            client.write_register(444, 1)
        client.read_registers(440, 6)  # reads still go out
    with RegisterClient(_settings(sim)) as client, pytest.raises(InvalidInput, match="control registers"):
        client.write_registers(438, [0, 0, 0, 0])  # a 0x10 over 440
    assert sim.writes == []


def test_the_commands_cache_is_dropped_when_the_link_is_made_again(sim: Any) -> None:
    """The register layer owns the link; the command layer's parameter cache follows it."""
    with RobotClient(_settings(sim)) as client:
        client.create_point(1, pose=(400, 0, 300, 180, 0, 0), tool=1)
        client.create_point(2, pose=(410, 0, 300, 180, 0, 0), tool=1)
        assert len(sim.writes_to(TOOL_REGISTER)) == 1  # written once, then cached
        client.close()
        client.connect()  # a new connection may be a restarted controller
        client.create_point(3, pose=(420, 0, 300, 180, 0, 0), tool=1)
    assert len(sim.writes_to(TOOL_REGISTER)) == 2
    assert sorted(sim.state().points) == [1, 2, 3]
