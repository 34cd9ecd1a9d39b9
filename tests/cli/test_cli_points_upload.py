"""``teachpad-cli points upload`` sends what the GUI's upload sends (RobotClient.upload_points,
staged), against the real simulator: its writes, its request count, Ctrl-C mid-upload."""

from __future__ import annotations

import itertools
import threading
from pathlib import Path
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app.cli.exit_codes import ExitCode
from app.points.project import load_project
from app.protocol import registers
from app.protocol.registers import CANARY_GV, UPLOAD_POSE_GV, stage_gv_for
from tests.cli.ctrl_c import interrupt_cli
from tests.cli.test_cli import SCAN, run

N = 60  # points: enough for the per-point bound to tell the staged upload from the point-by-point one
TOOLS = (200, 3)  # the first half without a tool, the second with tool 3: two batches, GV245 once each


def _tool(point_id: int, n: int) -> int:
    return TOOLS[0] if 2 * point_id <= n else TOOLS[1]


def _project(sim: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path, n: int = N) -> Path:
    csv = tmp_path / "points.csv"
    header = "id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note"
    rows = [f"{i},P{i},{300 + i},{-i},400,180,0,{i % 90},0,0,0,0,0,{_tool(i, n)}," for i in range(1, n + 1)]
    csv.write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")
    project = tmp_path / "many.teachpad.json"
    code, _, err = run(sim, capsys, "points", "import", str(project), "--csv", str(csv))
    assert code == ExitCode.OK, err
    return project


def test_points_upload_is_staged_and_at_the_staged_request_bound(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    sim = sim_factory(command_latency=SCAN)  # the controller works a while on each point
    project = _project(sim, capsys, tmp_path)
    requests, writes = sim.requests_count, len(sim.writes)
    code, out, err = run(sim, capsys, "points", "upload", str(project))
    assert code == ExitCode.OK, err
    assert f"uploaded {N} point(s)" in out
    requests = sim.requests_count - requests
    probe = 2 * registers.GV_COMMAND_STATUS  # the completion rule's probe of GV291 (once a connection)
    canary = 2 * CANARY_GV  # the restart canary's token, written once (it read 0: none armed)
    assert [w.address for w in sim.writes[writes:]].count(canary) == 1
    wire = [w for w in sim.writes[writes:] if w.address not in (probe, canary)]
    # writes: GV245 once per tool, then per point its pose, GV200-202 and 440 -- nothing more
    params, command, tool = 2 * registers.GV_PARAM0, registers.REG_RUN_COMMAND, 2 * registers.GV_TOOL_FRAME
    assert [w.address for w in wire].count(tool) == len(TOOLS)
    assert [w.address for w in wire].count(params) == N and [w.address for w in wire].count(command) == N
    poses = [w for w in wire if w.address < params]
    assert len(poses) == N and len(wire) == len(TOOLS) + 3 * N
    # the poses alternate between GV0.. and the canary-aware second block (GV6.. with the canary
    # in GV99), each batch from GV0; most go out while the controller works on the point before
    blocks = [2 * UPLOAD_POSE_GV, 2 * stage_gv_for(CANARY_GV)]
    half = N // 2
    assert [w.address for w in poses] == [blocks[i % 2] for i in range(half)] * 2
    order = [w.address for w in wire]
    staged = sum(a == command and b in blocks for a, b in itertools.pairwise(order))
    assert staged >= N // 2, staged  # N - 2 when nothing stalls (each batch's first pose goes before)
    # the staged bound: per point its 3 writes and at most 3 reads of its outcome (about 2.5 here),
    # plus a fixed part (connect, the probe of the completion rule, each batch's status read). The
    # point-by-point upload (a status read before every point) took about 6.4 requests a point.
    assert requests <= 6 * N + 10, requests
    print(f"points upload of {N}: {requests} requests ({requests / N:.2f} a point), {staged} poses staged")
    held = sim.state().points
    assert all(held[i] == (300.0 + i, -i, 400.0, 180.0, 0.0, float(i % 90)) for i in range(1, N + 1))
    assert all(sim.robot.points[i].tool == _tool(i, N) for i in range(1, N + 1))
    assert sorted(load_project(project).upload_history) == list(range(1, N + 1))


def test_ctrl_c_in_a_staged_upload_keeps_what_was_done(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    sim = sim_factory(command_latency=0.05)
    project = _project(sim, capsys, tmp_path)
    code, err = interrupt_cli(sim, ["points", "upload", str(project)], lambda s: len(s.points) >= 6)
    assert code == ExitCode.INTERRUPTED, err
    assert "upload stopped (interrupted); not attempted:" in err
    recorded = set(load_project(project).upload_history)
    held = set(sim.state().points)
    # every point recorded as uploaded is on the controller; at most the one under way is there
    # without being recorded (its outcome was not known when Ctrl-C came)
    assert len(recorded) >= 5 and recorded <= held and len(held - recorded) <= 1


def test_a_point_refused_with_a_modbus_exception_is_failed_and_the_upload_goes_on(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The rule the GUI's upload follows too (CommandResult.link_failed): a Modbus exception is the
    controller's refusal of that point, not a lost link -- the point is reported failed in the
    controller's words, the others are created, the exit code is "failed", not "link"."""
    n = 10
    sim = sim_factory(command_latency=0.02)  # the controller works a while: the poses are staged
    project = _project(sim, capsys, tmp_path, n)
    sim.refuse_point_write(3)  # in the first batch (tool 200) ...
    sim.refuse_point_write(8)  # ... and in the second (tool 3)
    code, out, err = run(sim, capsys, "points", "upload", str(project))
    assert code == ExitCode.FAILED, err
    assert f"uploaded {n - 2} point(s)" in out
    assert "upload stopped" not in err and "not attempted" not in err
    for pid in (3, 8):
        assert (
            f"P{pid}: controller refused write to registers 400..405 (GV200..GV202): illegal data value"
            in err
        )
    held = sim.state().points
    assert set(held) == set(range(1, n + 1)) - {3, 8}
    assert all(held[i] == (300.0 + i, -i, 400.0, 180.0, 0.0, float(i % 90)) for i in held)
    assert sorted(load_project(project).upload_history) == sorted(held)


def test_a_link_lost_mid_upload_still_ends_it(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The controller falls silent after a few points: no answer in time is a link failure -- the
    upload ends there (exit code "link"), the rest not attempted, what was recorded is held."""
    n = 20
    sim = sim_factory(command_latency=0.02)
    project = _project(sim, capsys, tmp_path, n)

    def silence() -> None:
        assert sim.wait_for(lambda s: len(s.points) >= 4, 20.0)
        sim.set_silent(True)

    thread = threading.Thread(target=silence, daemon=True)
    thread.start()
    try:
        # 1 s, not 0.3: the points before the silence must be answered, and a loaded test process
        # (the simulator answers from it) can hold an answer 0.3 s -- the upload then ended early
        code, _, err = run(sim, capsys, "--timeout", "1.0", "points", "upload", str(project))
    finally:
        thread.join(5.0)
        sim.set_silent(False)
    assert code == ExitCode.LINK, err
    assert "upload stopped (" in err and "not attempted:" in err and "did not answer" in err
    recorded = set(load_project(project).upload_history)
    assert len(recorded) >= 3 and recorded <= set(sim.state().points)


def test_a_refused_tool_frame_refuses_the_points_of_that_tool_and_records_the_others(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Every GV245 write answered with exception 3: each batch is refused before its first point
    (the GUI's upload does the same): every point reported refused, none "not attempted", the exit
    code "failed" (the link is fine), and nothing escapes as an error that would lose the record."""
    n = 6
    sim = sim_factory()
    project = _project(sim, capsys, tmp_path, n)
    tool = 2 * registers.GV_TOOL_FRAME
    sim.set_exception(ExcCodes.ILLEGAL_VALUE, range(tool, tool + 2))
    code, out, err = run(sim, capsys, "points", "upload", str(project))
    assert code == ExitCode.FAILED, err
    assert "uploaded 0 point(s)" in out and "upload stopped" not in err
    for pid in range(1, n + 1):
        assert f"P{pid}: controller refused write to register" in err and "illegal data value" in err
    assert sim.state().points == {}
