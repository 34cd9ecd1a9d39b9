"""Another master on the same controller (issue 19 section 2): the restart canary tells a restart
(GV99 reads 0: the controller cleared GV0..GV99) from another host's token, and another master is
seen -- its canary token, GV291 results we did not cause -- within a second (no Qt)."""

from __future__ import annotations

import itertools
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from app import timing
from app.connection import ConnectionSettings
from app.errors import ForeignMasterRefused, OutcomeUnknown
from app.link.client import RobotClient
from app.link.types import ControllerIdentity, StepFrame
from app.protocol.registers import CANARY_GV
from app.safety.audit import AuditLog
from tests.link.harness import PartsHost
from tests.waits import join

CANARY_REG = 2 * CANARY_GV


@pytest.fixture
def fast_canary(monkeypatch: pytest.MonkeyPatch) -> None:
    """The canary is read on every poll (the clock period is not the subject here)."""
    monkeypatch.setattr(timing, "CLOCK_POLL_PERIOD", 0.0)


def _other_master(sim: Any) -> RobotClient:
    client = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=2.0))
    client.connect()
    return client


def _identity(parts: PartsHost) -> ControllerIdentity:
    identity = parts.of("connectionChanged")[-1].controller
    assert isinstance(identity, ControllerIdentity)
    return identity


def test_another_teachpads_canary_token_is_not_a_restart(sim: Any, fast_canary: None) -> None:
    """A second TeachPad (old rule: it rewrites its own token every time it sees ours gone) writes
    its token over and over: we never read it as a restart, never write ours back, keep the same
    controller identity (the points stay on the controller); a real restart is still seen."""
    parts = PartsHost(canary_gv=CANARY_GV)
    other = _other_master(sim)
    try:
        parts.connect(sim)
        one = _identity(parts)
        our_writes = len(sim.writes_to(CANARY_REG))
        tokens = itertools.count(1001)
        canary_reads = 0
        while canary_reads < 40:  # 40 fights of the old rule, each read back by our canary poll
            other.write_gv(CANARY_GV, [float(next(tokens))])
            parts.poll()
            canary_reads += 1
        assert "controllerRestarted" not in parts.names()
        assert len(sim.writes_to(CANARY_REG)) - our_writes == 40  # the other master's only: no fight
        assert _identity(parts).same_boot(one)
        seen = parts.of("foreignMaster")
        assert seen and seen[0] == ("canary", 1001.0)
        # the controller restarts: GV0..GV99 read 0, the canary says so
        sim.restart_controller()
        deadline = time.monotonic() + 10.0
        while "controllerRestarted" not in parts.names() and time.monotonic() < deadline:
            parts.poll()
        assert parts.names().count("controllerRestarted") == 1
        assert not _identity(parts).same_boot(one)
    finally:
        other.close()
        parts.close()


def test_a_reconnect_keeps_the_boot_when_the_canary_holds_the_token_another_master_left(
    sim: Any, fast_canary: None
) -> None:
    parts = PartsHost(canary_gv=CANARY_GV)
    other = _other_master(sim)
    try:
        parts.connect(sim)
        one = _identity(parts)
        other.write_gv(CANARY_GV, [4242.0])
        parts.poll()
        parts.link_lost("test")
        parts.try_connect()
        assert _identity(parts).same_boot(one)
    finally:
        other.close()
        parts.close()


def test_another_masters_command_result_is_seen_within_a_second_and_audited(
    sim: Any, tmp_path: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "FOREIGN_RESULT_WINDOW", 0.2)
    parts = PartsHost()
    parts.audit = AuditLog(tmp_path)
    other = _other_master(sim)
    try:
        parts.connect(sim)
        deadline = time.monotonic() + 0.5
        while time.monotonic() < deadline:  # our own connect writes are long settled
            parts.poll()
        assert "foreignMaster" not in parts.names()
        started = time.monotonic()
        other.create_point(7, pose=[400.0, 0.0, 300.0, 180.0, 0.0, 0.0])  # another master's command
        while "foreignMaster" not in parts.names() and time.monotonic() - started < 5.0:
            parts.poll()
        assert time.monotonic() - started < 1.0 + 2.0  # seen at the next poll (slack for a loaded box)
        assert parts.of("foreignMaster")[0] == ("gv291", 255.0)
        records = [r for r in _audit_lines(tmp_path) if "another Modbus master" in r]
        assert records
    finally:
        other.close()
        parts.close()


def test_our_own_commands_are_not_another_master(sim: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "FOREIGN_RESULT_WINDOW", 0.2)
    client = _other_master(sim)
    try:
        client.read_status()
        for point_id in range(3):
            client.create_point(point_id, pose=[400.0, 0.0, 300.0 + point_id, 180.0, 0.0, 0.0])
            client.read_status()
        assert client.foreign.take() == []
    finally:
        client.close()


def _audit_lines(folder: Any) -> list[str]:
    return [
        line for path in sorted(folder.rglob("*")) if path.is_file() for line in path.read_text().splitlines()
    ]


def test_a_move_is_not_sent_over_another_masters_parameter_write(
    sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Another master writes the step offsets GV204/GV205 (its own step being prepared) while we
    prepare a move to a point (which writes GV200..GV203): the read-back just before our trigger
    sees them, the move is refused before 440 (the arm does not move), in words and audited."""
    monkeypatch.setattr(timing, "FOREIGN_MOVE_HOLD", 5.0)  # the product's (tests/conftest.py sets 0)
    start = sim.state().pose
    target = (start[0] + 20.0, start[1], start[2], start[3], start[4], start[5])
    sim.add_point(1, target)
    client = _other_master(sim)
    other = _other_master(sim)
    audit_dir = Path(tempfile.mkdtemp())
    client.audit = AuditLog(audit_dir)
    client.watch_shared_every = 1.0  # as the GUI's link and the CLI do
    try:
        client.read_status()
        client.watch_shared_registers()  # what the shared registers hold now
        other.write_gv(204, [15.0, 5.0])  # another master's step offsets
        with pytest.raises(ForeignMasterRefused, match="another Modbus master"):
            client.move_to_point(1, speed=50.0)
        assert [w for w in sim.writes_to(440) if w.values == (0x42,)] == []
        assert sim.state().pose == start
        assert any("not sent" in line and "another Modbus master" in line for line in _audit_lines(audit_dir))
    finally:
        other.close()
        client.close()


def test_a_move_that_ends_while_another_master_writes_is_outcome_unknown(sim: Any) -> None:
    """Another master rewrites the step's own offsets while our step runs: the "done" GV291 then
    shows cannot be told from the other master's, so our step ends *outcome unknown* (audited)."""
    client = _other_master(sim)
    other = _other_master(sim)
    audit_dir = Path(tempfile.mkdtemp())
    client.audit = AuditLog(audit_dir)
    client.watch_shared_every = 0.1
    start_z = sim.state().pose[2]
    stop = threading.Event()

    def another_master() -> None:  # writes the offsets once our move is seen under way
        while not stop.wait(0.01):
            if abs(sim.state().pose[2] - start_z) > 0.5:
                other.write_gv(202, [33.0])
                return

    thread = threading.Thread(target=another_master, daemon=True)
    thread.start()
    try:
        with pytest.raises(OutcomeUnknown, match="another Modbus master was seen while it ran"):
            client.step(StepFrame.BASE, (0.0, 0.0, -8.0, 0.0, 0.0, 0.0), speed=8.0)
    finally:
        stop.set()
        join(thread, "another master")
        other.close()
        client.close()
    assert any('"unknown"' in line for line in _audit_lines(audit_dir))


def test_both_teachpads_see_a_restart_before_either_writes_a_fresh_token(
    sim_factory: Any, fast_canary: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two TeachPads on one controller; it restarts. The first to read the canary sees 0 and says
    "restarted", but writes its fresh token only CANARY_REARM_DELAY later: the second, reading
    within that time, sees the 0 (the restart) too, not the first one's token. The first's token
    then stands for the boot: no fight, no second restart."""
    monkeypatch.setattr(timing, "CANARY_REARM_DELAY", 0.3)
    sim = sim_factory()
    first, second = PartsHost(canary_gv=CANARY_GV), PartsHost(canary_gv=CANARY_GV)
    try:
        first.connect(sim)
        second.connect(sim)
        first.poll()  # the second's token: another master, not a restart
        sim.restart_controller()
        first.poll()
        first.poll()
        assert first.names().count("controllerRestarted") == 1
        second.poll()
        assert second.names().count("controllerRestarted") == 1  # it saw the 0 as well
        deadline = time.monotonic() + 10.0
        while first.supervisor.rearm_pending or second.supervisor.rearm_pending:
            assert time.monotonic() < deadline, "the canary was never armed again"
            first.poll()
            second.poll()
        for _ in range(5):
            first.poll()
            second.poll()
        assert first.names().count("controllerRestarted") == 1
        assert second.names().count("controllerRestarted") == 1
        assert len(sim.writes_to(CANARY_REG)) <= 4  # each wrote at most once after the restart
    finally:
        first.close()
        second.close()
