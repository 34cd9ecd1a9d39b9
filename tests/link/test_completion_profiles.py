"""Command completion against every simulator timing profile (issue 13), over the wire.

Completion must hold on a fast controller (result within one scan, no visible 0), a slow one
(tens of ms, jitter) and with GV291 writable, ignoring writes or read-only: never a false
success, never "did not acknowledge" for a command the controller did. Safety and truth are
asserted at the simulator (its stored points, its write log), not only in the results.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from app.cli import main as cli
from app.errors import ModbusExceptionError, WriteBlocked
from app.link.types import StepFrame
from app.points.ledger import PointLedger
from app.points.point import SyncState, make_point
from app.points.project import save_project
from app.points.project_model import Project
from app.protocol.enums import STATUS_SENTINEL, CreatePointStatus, TeachFrame

GV291_REG = 582
POSE = [400.0, 50.0, 300.0, 180.0, 0.0, 0.0]


def expected_rule(sim: Any) -> str:
    return "sentinel" if sim.config.gv291 == "writable" else "observe"


def points(n: int, first: int = 1) -> list[tuple[int, list[float]]]:
    return [
        (i, [300.0 + i % 100, -50.0 + i % 40, 300.0 + i % 30, 180.0, 0.0, float(i % 90)])
        for i in range(first, first + n)
    ]


def test_create_point_and_teach_on_every_profile(profile_sim: Any, make_client: Any) -> None:
    sim = profile_sim
    c = make_client(sim)
    for pid, pose in points(5):
        result = c.create_point(pid, pose=pose)
        assert result.ok, result.message
        assert sim.state().points[pid] == tuple(pose)  # a success is a point the controller holds
    assert c.completion_rule == expected_rule(sim)
    sentinel_writes = [w for w in sim.writes_to(GV291_REG) if sim.config.gv291 != "read-only"]
    if c.completion_rule == "sentinel":
        assert len(sentinel_writes) == 1 + 5  # the probe, then one before each command
    else:
        assert len(sim.writes_to(GV291_REG)) == 1  # the probe only
    enabled = c.teach_enable(TeachFrame.BASE, 0, 1)
    assert enabled.ok and not enabled.unconfirmed and sim.state().teach_enabled
    disabled = c.teach_disable()
    assert disabled.ok and not disabled.unconfirmed and not sim.state().teach_enabled


def test_moves_confirm_on_every_profile(profile_sim: Any, make_client: Any) -> None:
    sim = profile_sim
    c = make_client(sim)
    x0 = sim.state().pose[0]
    result = c.step(StepFrame.BASE, [5.0, 0.0, 0.0, 0.0, 0.0, 0.0], speed=200.0)
    assert result.ok and not result.unconfirmed, result.message
    assert sim.state().pose[0] == pytest.approx(x0 + 5.0, abs=0.01)
    target = (x0 - 10.0, *sim.state().pose[1:])
    assert c.create_point(7, pose=list(target)).ok
    moved = c.move_to_point(7, speed=200.0)
    assert moved.ok and not moved.unconfirmed, moved.message
    assert sim.state().pose[0] == pytest.approx(target[0], abs=0.01) and not sim.state().moving


def test_error_injected_mid_upload_is_reported_for_that_point_only(
    profile_sim: Any, make_client: Any
) -> None:
    sim = profile_sim
    sim.refuse_point(17)
    c = make_client(sim)
    batch = points(40)
    results = c.upload_points(batch)
    assert len(results) == 40
    failed = [int(r.details["point_id"]) for r in results if not r.ok]
    assert failed == [17]
    bad = results[16]
    assert bad.status is not None and bad.status.member is CreatePointStatus.BAD_POINT_ID
    held = sim.state().points
    for (pid, pose), result in zip(batch, results, strict=True):
        if result.ok:  # no false success: every success is a point the controller holds
            assert held[pid] == tuple(pose)
            assert not result.unconfirmed or c.completion_rule == "observe"
    assert 17 not in held
    unconfirmed = [r for r in results if r.unconfirmed]
    if c.completion_rule == "sentinel":
        assert not unconfirmed  # the controller's own write proves every result
    elif sim.config.timing == "fast":
        assert len(unconfirmed) >= 30  # nothing visible changes: honest, and no failure
    # the point after the refused one starts from a stale error code: still its own result
    assert results[17].ok


def test_fast_read_only_says_unconfirmed_and_sentinel_confirms(
    sim_factory: Any, make_client: Any, quick_profiles: None
) -> None:
    ro = make_client(sim_factory(timing="fast", gv291="read-only"))
    assert ro.create_point(1, pose=POSE).ok  # from 0 (initial) at power-on: a visible change
    second = ro.create_point(2, pose=POSE)
    assert second.ok and second.unconfirmed and "done, unconfirmed" in second.message
    assert ro.stats.exceptions == 1  # the probe's refused write, once
    wr_sim = sim_factory(timing="fast", gv291="writable")
    wr = make_client(wr_sim)
    results = [wr.create_point(i, pose=POSE) for i in (1, 2, 3)]
    assert all(r.ok and not r.unconfirmed for r in results)
    assert [w.values for w in wr_sim.writes_to(GV291_REG + 1)][-1] != ()  # sentinel high word sent


def test_forced_rules_and_monitor_only(sim_factory: Any, make_client: Any, quick_profiles: None) -> None:
    ro_sim = sim_factory(timing="fast", gv291="read-only")
    forced = make_client(ro_sim, completion="sentinel")
    with pytest.raises(ModbusExceptionError, match="illegal data address"):
        forced.create_point(1, pose=POSE)
    observe = make_client(sim_factory(timing="fast", gv291="writable"), completion="observe")
    assert observe.create_point(1, pose=POSE).ok
    assert observe.completion_rule == "observe"
    monitor_sim = sim_factory(timing="fast", gv291="writable")
    monitor = make_client(monitor_sim, monitor_only=True)
    with pytest.raises(WriteBlocked):
        monitor.create_point(1, pose=POSE)
    with pytest.raises(WriteBlocked):
        monitor.probe_gv291()
    assert monitor_sim.writes == [] and monitor.completion_rule is None


def test_sentinel_is_what_the_status_shows_until_the_controller_answers(
    sim_factory: Any, make_client: Any
) -> None:
    sim = sim_factory(timing="classic", gv291="writable", status_delay=0.05)
    c = make_client(sim)
    assert c.probe_gv291()
    status = c.read_status()
    assert status.command_status_code == STATUS_SENTINEL
    result = c.create_point(3, pose=POSE)
    assert result.ok and not result.unconfirmed and result.details["ack_after"] >= 0.04


# --- teachpad-cli points upload, a few hundred points, every profile ---------------------------


def write_project(path: Path, n: int) -> None:
    ledger = PointLedger(
        [make_point(pid, f"p{pid}", pose, sync=SyncState.UNKNOWN) for pid, pose in points(n)]
    )
    save_project(Project("profiles", ledger), path)


@pytest.mark.parametrize("timing_name", ["classic", "fast", "slow"])
@pytest.mark.parametrize("gv291", ["writable", "read-only"])
def test_cli_points_upload_on_every_profile(
    timing_name: str,
    gv291: str,
    sim_factory: Any,
    tmp_path: Path,
    quick_profiles: None,
    capsys: pytest.CaptureFixture[str],
) -> None:
    sim = sim_factory(timing=timing_name, gv291=gv291)
    sim.refuse_point(123)
    path = tmp_path / "profiles.teachpad.json"
    write_project(path, 200)
    # a roomy request timeout: the profiles are the subject, not a loaded test process's stalls
    where = ["--host", "127.0.0.1", "--port", str(sim.port), "--timeout", "3"]
    code = cli.main([*where, "points", "upload", str(path)])
    captured = capsys.readouterr()
    assert code == cli.EXIT_FAILED
    assert "uploaded 199 point(s)" in captured.out
    reported = [line for line in captured.err.splitlines() if ": P" in line]
    assert len(reported) == 1 and "P123: create temp point refused: bad point id" in reported[0]
    held = sim.state().points
    assert len(held) == 199 and 123 not in held
    if gv291 == "writable":
        assert "unconfirmed" not in captured.out  # the sentinel proves every result
