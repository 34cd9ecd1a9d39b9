"""An upload's staged poses (RobotClient.upload_points) and CommandClient.wait(meanwhile=), over the wire.

The batched upload's own wire sequence with staging is in test_client_sim.py
(``test_upload_points_batched``); every timing profile in test_completion_profiles.py.
"""

from __future__ import annotations

from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app.errors import InvalidInput
from app.protocol.enums import RunCommand
from tests.link.test_client_sim import FC06, FC10, SCAN, MakeClient, wire


@pytest.fixture
def scan_sim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=SCAN)


def test_upload_points_staging_off_and_its_block_checked(scan_sim: Any, make_client: MakeClient) -> None:
    c = make_client(scan_sim)
    batch = [(i, [300.0 + i, 10.0, 400.0, 180.0, 0.0, 0.0]) for i in range(1, 5)]
    n = len(scan_sim.writes)
    assert all(r.ok for r in c.upload_points(batch, stage=False))
    assert wire(scan_sim, n)[1:] == [(FC10, 0, 12), (FC10, 400, 6), (FC06, 440, 1)] * 4  # the old way
    with pytest.raises(InvalidInput, match="overlap"):
        c.upload_points(batch, gv_start=10, stage_gv=13)
    # at the top of GV0..GV99 the second block lies below the first
    n = len(scan_sim.writes)
    assert all(r.ok for r in c.upload_points(batch, gv_start=94))
    assert {w.address for w in scan_sim.writes[n:] if w.address < 400} == {188, 176}
    assert {pid: scan_sim.state().points[pid] for pid, _ in batch} == {pid: tuple(p) for pid, p in batch}


def test_upload_points_goes_on_when_the_spare_gvs_are_refused(
    sim_factory: Any, make_client: MakeClient
) -> None:
    sim = sim_factory(command_latency=SCAN)
    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, range(12, 24))  # GV6..GV11: not writable here
    c = make_client(sim)
    batch = [(i, [300.0 + i, -5.0 * i, 400.0, 180.0, 0.0, float(i)]) for i in range(1, 7)]
    results = c.upload_points(batch, tool=3)
    assert [r.ok for r in results] == [True] * 6, [r.message for r in results]
    assert {pid: sim.state().points[pid] for pid, _ in batch} == {pid: tuple(p) for pid, p in batch}
    assert all(sim.robot.points[pid].tool == 3 for pid, _ in batch)
    assert c.stats.exceptions == 1  # one refused staging write, then the poses went one at a time
    assert [w.address for w in sim.writes if w.address < 400] == [0] * 6  # (a refused write is not stored)


@pytest.mark.parametrize(("profile", "expected"), [("classic", [1]), ("fast", [])])
def test_wait_runs_meanwhile_once_while_the_command_is_under_way(
    sim_factory: Any, make_client: MakeClient, profile: str, expected: list[int]
) -> None:
    """After the first read, only when the command has not ended there (classic: 0 first)."""
    sim = sim_factory(command_latency=SCAN, timing=profile, gv291="writable")
    c = make_client(sim)
    c.write_gv(0, [300.0, 0.0, 400.0, 180.0, 0.0, 0.0])
    c.write_gv(200, [5.0, 1.0, 0.0])
    tracker = c.begin_command(RunCommand.CREATE_POINT, c.read_status(), None)
    calls: list[int] = []
    result = c.wait(tracker, meanwhile=lambda: calls.append(tracker.reads))
    assert result.ok and calls == expected
    assert sim.state().points[5] == (300.0, 0.0, 400.0, 180.0, 0.0, 0.0)
