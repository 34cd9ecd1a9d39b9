"""``teachpad-cli`` end to end: ``app.cli.main.main(argv)`` against the real simulator over TCP.

The project is a copy of ``resources/samples/demo.teachpad.json`` with its speeds raised (the
sample's 50..100 mm/s would make the file slow); points and plans are the sample's own.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from app.cli import main as cli
from app.points.point import SyncState
from app.points.project import load_project
from tests.integration.support import assert_pose_at, move_commands

SAMPLES = Path(__file__).resolve().parents[2] / "resources" / "samples"
FAST = 800.0  # mm/s for every segment of the copy (the CLI's default --max-speed is 1000)

Capsys = pytest.CaptureFixture[str]


@pytest.fixture
def demo(tmp_path: Path) -> Path:
    """A copy of the sample project, every segment at FAST."""
    doc = json.loads((SAMPLES / "demo.teachpad.json").read_text(encoding="utf-8"))
    for plan in doc["plans"]:
        for segment in plan["segments"]:
            segment["speed"] = FAST
    path = tmp_path / "demo.teachpad.json"
    path.write_text(json.dumps(doc, ensure_ascii=False, indent=1), encoding="utf-8")
    return path


def teachpad_cli(port: int, *argv: str) -> int:
    # a roomy request timeout: the simulator runs in this (maybe loaded) process, and no test here is
    # about a timeout (a 1 s stall under a CI neighbour failed a run as "did not answer")
    return cli.main(["--host", "127.0.0.1", "--port", str(port), "--timeout", "3", *argv])


def sample_poses(path: Path) -> dict[int, tuple[float, ...]]:
    return {p.id: p.xyzabc for p in load_project(path).ledger}


def test_run_uploads_the_plans_points_then_runs(sim: Any, demo: Path, capsys: Capsys) -> None:
    # The controller has no points yet: run creates the plan's points first, then runs.
    assert teachpad_cli(sim.port, "run", str(demo), "--plan", "circle") == cli.EXIT_OK
    captured = capsys.readouterr()
    assert captured.err == ""
    lines = captured.out.splitlines()
    assert re.match(r"plan 'circle': 4 segment\(s\), \d+\.\d mm per loop, loops 1, about ", lines[0])
    assert lines[1:] == [
        "uploading the plan's 5 point(s): 5, 6, 7, 8, 1",
        "uploaded 5 point(s)",
        f"loop 1/1, segment 1/4: line to P5, {FAST:g} mm/s",
        f"loop 1/1, segment 2/4: arc via P6 to P7, {FAST:g} mm/s",
        f"loop 1/1, segment 3/4: arc via P8 to P5, {FAST:g} mm/s",
        f"loop 1/1, segment 4/4: line to P1, {FAST:g} mm/s",
        "done: 4 segment(s)",
    ]
    assert move_commands(sim) == 4
    held = sim.state().points
    assert sorted(held) == [1, 5, 6, 7, 8]
    for point_id, pose in sample_poses(demo).items():
        if point_id in held:
            assert_pose_at(held[point_id], pose, f"P{point_id} on the controller")
    state = sim.state()
    assert not state.moving
    assert_pose_at(state.pose, sample_poses(demo)[1], "the final pose")
    project = load_project(demo)
    assert {p.sync for p in project.ledger} == {SyncState.UNKNOWN}  # a file never says "synced"
    assert sorted(project.upload_history) == [1, 5, 6, 7, 8]
    assert project.upload_history[5].endpoint.endswith(str(sim.port))

    assert teachpad_cli(sim.port, "points", "upload", str(demo)) == cli.EXIT_OK
    out = capsys.readouterr().out
    assert "uploaded 8 point(s)" in out
    assert "uploading 8/8: P8 'circle S'" in out  # one progress line per point (not a tty)
    assert sorted(load_project(demo).upload_history) == list(range(1, 9))


def test_run_pick_and_place_two_loops(sim: Any, demo: Path, capsys: Capsys) -> None:
    """``run`` creates only the points the plan needs (``--upload``, the old flag, is accepted)."""
    code = teachpad_cli(sim.port, "run", str(demo), "--plan", "pick and place", "--upload")
    captured = capsys.readouterr()
    assert code == cli.EXIT_OK, captured.err
    assert "uploaded 4 point(s)" in captured.out
    assert sorted(sim.state().points) == [1, 2, 3, 4]
    progress = [line for line in captured.out.splitlines() if line.startswith("loop ")]
    assert progress[0] == f"loop 1/2, segment 1/3: line to P2, {FAST:g} mm/s"
    assert progress[-1] == f"loop 2/2, segment 3/3: line to P1, {FAST:g} mm/s"
    assert len(progress) == 6 and captured.out.rstrip().endswith("done: 6 segment(s)")
    assert_pose_at(sim.state().pose, sample_poses(demo)[1], "the final pose")


def test_a_restarted_controller_gets_its_points_back_unless_no_upload(
    sim: Any, demo: Path, capsys: Capsys
) -> None:
    assert teachpad_cli(sim.port, "points", "upload", str(demo)) == cli.EXIT_OK
    sim.restart_controller()  # the controller forgot every point
    capsys.readouterr()
    # --no-upload: the operator said the controller holds the points; it does not
    assert teachpad_cli(sim.port, "run", str(demo), "--plan", "circle", "--no-upload") == cli.EXIT_FAILED
    captured = capsys.readouterr()
    assert "operator's responsibility" in captured.err
    assert "failed: segment 1/4 (loop 1/1): " in captured.err and "bad end point id" in captured.err
    assert "resume without --no-upload" in captured.err
    assert f"to resume: teachpad-cli run {demo} --plan 'circle' --from 1" in captured.out
    assert not sim.state().moving and move_commands(sim) == 1

    # without it, run restores the lost points first, then the plan runs
    assert teachpad_cli(sim.port, "run", str(demo), "--plan", "circle", "--from", "1") == cli.EXIT_OK
    assert_pose_at(sim.state().pose, sample_poses(demo)[1], "the final pose")


def test_unreachable_controller_is_a_link_error(sim_factory: Any, demo: Path, capsys: Capsys) -> None:
    gone = sim_factory()
    port = gone.port
    gone.stop()
    assert teachpad_cli(port, "points", "upload", str(demo)) == cli.EXIT_LINK
    assert "cannot connect to the controller at 127.0.0.1:" in capsys.readouterr().err
    assert teachpad_cli(port, "run", str(demo), "--plan", "circle") == cli.EXIT_LINK
    assert "cannot read the robot's pose" in capsys.readouterr().err
    assert {p.sync for p in load_project(demo).ledger} == {SyncState.UNKNOWN}


# --------------------------------------------------------------------------------------------
# bad files: refused with a message naming the place, nothing sent, nothing written
# --------------------------------------------------------------------------------------------

CSV_HEADER = "id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note"
GOOD_ROW = "{id},p{id},400,0,{z},180,0,0,0,0,0,0,0,200,"


def csv_text(*bad_rows: tuple[int, str]) -> str:
    """Header (row 1) and good rows 2..6, with ``(row, text)`` replacing some of them."""
    rows = {n: GOOD_ROW.format(id=n + 20, z=300 + n) for n in range(2, 7)}
    rows.update(dict(bad_rows))
    return "\r\n".join([CSV_HEADER, *(rows[n] for n in sorted(rows))]) + "\r\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            csv_text((4, "24,p24,abc,0,300,180,0,0,0,0,0,0,0,200,")),
            "row 4, column 'x': 'abc' is not a number",
        ),
        (csv_text((3, "21,p21,400,0,300")), "row 3: has 5 cells, the header has 15"),
        (csv_text((5, GOOD_ROW.format(id=22, z=305))), "row 5, column 'id': id 22 is already used on row 2"),
        (csv_text((2, GOOD_ROW.format(id=20000, z=300))), "row 2, column 'id': id 20000 is outside 0..10000"),
        (
            csv_text((6, "26,p26,400,0,nan,180,0,0,0,0,0,0,0,200,")),
            "row 6, column 'z': 'nan' is not a finite",
        ),
        (csv_text((6, "26,p26,400,0,300,180,0,0,0,0,0,0,0,7777,")), "row 6, column 'tool': tool 7777"),
        ("id,name,x,y,a,b,c\r\n1,p,1,2,3,4,5\r\n", "row 1, column 'z': the column is missing"),
        ("", "row 1: the file is empty"),
    ],
    ids=[
        "not-a-number",
        "truncated-row",
        "duplicate-id",
        "id-out-of-range",
        "nan",
        "bad-tool",
        "missing-column",
        "empty",
    ],
)
def test_malformed_csv_is_refused_and_the_project_is_unchanged(
    sim: Any, demo: Path, tmp_path: Path, capsys: Capsys, text: str, message: str
) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text(text, encoding="utf-8")
    before = demo.read_bytes()
    mtime = demo.stat().st_mtime_ns
    assert teachpad_cli(sim.port, "points", "import", str(demo), "--csv", str(bad)) == cli.EXIT_USAGE
    err = capsys.readouterr().err
    assert err.startswith("teachpad-cli: error: ")
    assert f"{bad}: {message}" in err, err
    assert len(err.strip().splitlines()) == 1  # one clear line, no traceback
    assert demo.read_bytes() == before and demo.stat().st_mtime_ns == mtime
    assert sim.requests_count == 0  # an offline command never touched the link


def test_a_good_csv_import_does_change_the_project(
    sim: Any, demo: Path, tmp_path: Path, capsys: Capsys
) -> None:
    """The control case of the test above: the same file without its bad row is imported."""
    good = tmp_path / "good.csv"
    good.write_text(csv_text(), encoding="utf-8")
    assert teachpad_cli(sim.port, "points", "import", str(demo), "--csv", str(good), "--merge") == cli.EXIT_OK
    assert "5 added, 0 updated, 0 unchanged, 0 removed" in capsys.readouterr().out
    assert len(load_project(demo).ledger) == 13


@pytest.mark.parametrize("command", [("points", "upload"), ("run",)], ids=["upload", "run"])
def test_malformed_project_is_refused_before_connecting(
    sim: Any, demo: Path, capsys: Capsys, command: tuple[str, ...]
) -> None:
    text = demo.read_text(encoding="utf-8")
    demo.write_text(text.replace('"x": 450.0', '"x": "4S0"', 1), encoding="utf-8")
    before = demo.read_bytes()
    assert teachpad_cli(sim.port, *command, str(demo)) == cli.EXIT_USAGE
    err = capsys.readouterr().err
    assert f"{demo}: points[1] (id 2), field 'x': '4S0' is not a number" in err, err
    assert demo.read_bytes() == before
    assert sim.requests_count == 0 and sim.writes == []

    demo.write_text(text[: len(text) // 2], encoding="utf-8")  # truncated: not JSON any more
    assert teachpad_cli(sim.port, *command, str(demo)) == cli.EXIT_USAGE
    err = capsys.readouterr().err
    assert re.search(rf"{re.escape(str(demo))}: line \d+, column \d+: not valid JSON", err), err
    assert sim.requests_count == 0


def test_plan_with_an_impossible_arc_is_refused_before_moving(sim: Any, demo: Path, capsys: Capsys) -> None:
    doc = json.loads(demo.read_text(encoding="utf-8"))
    # P9 lies on the straight line from P1 (400, 0, 450) to P5 (300, 0, 300): no circle
    doc["points"].append({"id": 9, "x": 350.0, "y": 0.0, "z": 375.0, "a": 180.0, "b": 0.0, "c": 0.0})
    doc["plans"].append(
        {
            "name": "bad arc",
            "segments": [
                {"type": "line", "end": 1, "speed": FAST},
                {"type": "arc", "via": 9, "end": 5, "speed": FAST},
            ],
        }
    )
    demo.write_text(json.dumps(doc), encoding="utf-8")
    assert teachpad_cli(sim.port, "run", str(demo), "--plan", "bad arc", "--upload") == cli.EXIT_USAGE
    err = capsys.readouterr().err
    assert "segment 2: the arc's three points are (nearly) on one line" in err
    assert "plan 'bad arc' has 1 error(s): not running it" in err
    assert sim.writes == []  # nothing uploaded, nothing moved
