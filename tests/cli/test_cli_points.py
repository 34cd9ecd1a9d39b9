"""``points`` and ``run`` commands, with the main parser simulated and a fake client."""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path
from typing import Any

import pytest

from app.cli import points as cli_points
from app.cli import run_plan
from app.cli.context import CliContext
from app.connection import ConnectionSettings
from app.errors import CommandRefused, LinkError
from app.points.point import SyncState
from app.points.project import load_project
from app.protocol.enums import CommandKind, CommandStatus
from tests.fakes import FakeClient

SAMPLES = Path(__file__).resolve().parents[2] / "resources" / "samples"


class Cli:
    """Runs a command like app/cli/main.py: parse, then ``args.handler(ctx)`` with this fake
    client behind ``ctx.client``; the context closes it."""

    def __init__(self, client: Any = None) -> None:
        self.client = client or FakeClient()
        self.clients_made = 0

    def make_client(self) -> Any:
        self.clients_made += 1
        return self.client

    def __call__(self, *argv: str) -> int:
        parser = argparse.ArgumentParser(prog="teachpad-cli")
        parser.add_argument("--host", default="127.0.0.1")  # global options of the main parser
        parser.add_argument("--monitor-only", action="store_true")
        sub = parser.add_subparsers(dest="command", required=True)
        cli_points.register(sub)
        run_plan.register(sub)
        args = parser.parse_args(list(argv))
        ctx = CliContext(args, ConnectionSettings(), make_client=self.make_client)
        try:
            code: int = args.handler(ctx)
        finally:
            ctx.close()
        return code


@pytest.fixture
def demo(tmp_path: Path) -> Path:
    path = tmp_path / "demo.teachpad.json"
    shutil.copy(SAMPLES / "demo.teachpad.json", path)
    return path


def test_list(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cli = Cli()
    assert cli("points", "list", str(demo)) == 0
    out = capsys.readouterr().out
    assert "8 point(s), 2 plan(s)" in out and "取料点" in out and "plan 'circle'" in out
    assert cli.clients_made == 0


def test_export_import_round_trip(demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cli = Cli()
    out_csv = tmp_path / "out.csv"
    assert cli("points", "export", str(demo), "--csv", str(out_csv)) == 0
    assert out_csv.read_bytes().startswith(b"\xef\xbb\xbfid,name,")
    text = out_csv.read_text(encoding="utf-8-sig").replace("450.0,-150.0,250.0", "455.0,-150.0,250.0")
    out_csv.write_text(text + "20,新点,300,0,300,180,0,0,0,0,0,0,0,200,\n", encoding="utf-8")
    assert cli("points", "import", str(demo), "--csv", str(out_csv)) == 0
    assert "1 added, 1 updated, 7 unchanged, 0 removed" in capsys.readouterr().out
    project = load_project(demo)
    assert len(project.ledger) == 9 and project.ledger.point(20).name == "新点"
    assert project.ledger.point(2).x == 455
    assert all(p.sync is SyncState.UNKNOWN for p in project.ledger)  # a loaded file never claims "synced"
    assert cli.clients_made == 0


def test_import_into_a_new_project(tmp_path: Path) -> None:
    target = tmp_path / "fresh.teachpad.json"
    assert Cli()("points", "import", str(target), "--csv", str(SAMPLES / "demo_points.csv")) == 0
    project = load_project(target)
    assert project.name == "fresh" and len(project.ledger) == 8 and project.plans == []


def test_import_of_a_bad_csv_leaves_the_project_as_it_was(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("id,name,x,y,z,a,b,c\n1,a,0,0,0,0,0,0\n2,b,0,abc,0,0,0,0\n", encoding="utf-8")
    before = demo.read_bytes()
    assert Cli()("points", "import", str(demo), "--csv", str(bad), "--merge") == cli_points.EXIT_USAGE
    assert "row 3, column 'y': 'abc' is not a number" in capsys.readouterr().err
    assert demo.read_bytes() == before


def test_import_warns_about_plans_losing_points(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    small = tmp_path / "small.csv"
    small.write_text("id,x,y,z,a,b,c\n1,400,0,450,180,0,0\n", encoding="utf-8")
    assert Cli()("points", "import", str(demo), "--csv", str(small)) == 0
    assert "warning: plan 'circle' uses points that are gone: 5, 6, 7, 8" in capsys.readouterr().err


def test_bad_project_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.teachpad.json"
    bad.write_text('{"format": "teachpad-project", "version": 9}', encoding="utf-8")
    assert Cli()("run", str(bad), "--check") == cli_points.EXIT_USAGE
    assert "version 9 is not supported" in capsys.readouterr().err


def test_upload_selected_ids(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cli = Cli()
    assert cli("points", "upload", str(demo), "--ids", "1,2,5-6") == 0
    assert [c["id"] for c in cli.client.creates] == [1, 2, 5, 6]
    assert cli.client.creates[1]["pose"] == (450.0, -150.0, 250.0, 180.0, 0.0, 0.0)
    assert cli.client.closed
    project = load_project(demo)
    assert all(p.sync is SyncState.UNKNOWN for p in project.ledger)
    assert sorted(project.upload_history) == [1, 2, 5, 6]  # history only
    assert project.upload_history[1].endpoint == "controller"
    assert "uploaded 4 point(s)" in capsys.readouterr().out
    assert cli("points", "list", str(demo)) == 0
    assert "unknown (last uploaded 20" in capsys.readouterr().out
    cli2 = Cli()
    assert cli2("points", "upload", str(demo), "--needed") == 0  # nothing is known to be there
    assert [c["id"] for c in cli2.client.creates] == [1, 2, 3, 4, 5, 6, 7, 8]
    assert Cli()("points", "upload", str(demo), "--ids", "1,99") == cli_points.EXIT_USAGE
    assert Cli()("points", "upload", str(demo), "--ids", "x") == cli_points.EXIT_USAGE


def test_upload_with_lost_link_saves_what_was_done(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cli = Cli(FakeClient(create_script={2: LinkError("connection lost")}))
    assert cli("points", "upload", str(demo)) == cli_points.EXIT_LINK
    assert "not attempted: 3,4,5,6,7,8" in capsys.readouterr().err
    assert sorted(load_project(demo).upload_history) == [1, 2]


def test_run_needs_a_plan_name_when_there_are_several(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert Cli()("run", str(demo)) == cli_points.EXIT_USAGE
    assert "choose one with --plan" in capsys.readouterr().err
    assert Cli()("run", str(demo), "--plan", "nope") == cli_points.EXIT_USAGE


def test_run_uploads_then_recreates_each_segments_points_before_its_move(
    demo: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cli = Cli()
    assert cli("run", str(demo), "--plan", "circle") == 0
    # up front: every point the plan uses; then each segment's (via, end) right before its move
    up_front, per_segment = [5, 6, 7, 8, 1], [5, 6, 7, 8, 5, 1]
    assert [c["id"] for c in cli.client.creates] == up_front + per_segment
    assert [(m["via"], m["end"]) for m in cli.client.moves] == [(None, 5), (6, 7), (8, 5), (None, 1)]
    assert all(m["timeout"] and m["timeout"] >= 10.0 for m in cli.client.moves)
    assert cli.client.gvs.get(99)  # the restart canary is armed
    out = capsys.readouterr().out
    assert "plan 'circle': 4 segment(s)" in out and "loop 1/1, segment 2/4: arc via P6 to P7" in out
    assert "done: 4 segment(s)" in out
    project = load_project(demo)
    assert project.ledger.point(5).sync is SyncState.UNKNOWN and 5 in project.upload_history
    assert cli.client.closed


def test_run_no_upload_sends_no_point_and_warns(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    client = FakeClient(stored={p.id: p.xyzabc for p in load_project(demo).ledger})
    before = demo.read_bytes()
    cli = Cli(client)
    assert cli("run", str(demo), "--plan", "circle", "--no-upload") == 0
    assert client.creates == [] and len(client.moves) == 4 and 99 not in client.gvs
    assert "operator's responsibility" in capsys.readouterr().err
    assert demo.read_bytes() == before


def test_run_no_upload_stops_when_the_arm_arrives_elsewhere(
    demo: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The controller holds a different P7 (another tool wrote it): the arrival check stops the run."""
    stored: dict[int, tuple[float, ...]] = {p.id: p.xyzabc for p in load_project(demo).ledger}
    stored[7] = (100.0, 100.0, 100.0, 180.0, 0.0, 0.0)
    client = FakeClient(stored=stored)
    assert Cli(client)("run", str(demo), "--plan", "circle", "--no-upload") == cli_points.EXIT_FAILED
    err = capsys.readouterr().err
    assert "segment 2/4" in err and "away from P7" in err and "overwritten by another tool" in err
    assert [m["end"] for m in client.moves] == [5, 7]  # nothing sent after the mismatch


def test_run_stops_before_moving_when_a_point_is_refused(
    demo: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tests.fakes import failed

    client = FakeClient(create_script={1: failed(1, "bad point")})
    assert Cli(client)("run", str(demo), "--plan", "circle") == cli_points.EXIT_FAILED
    assert "refused to create P6" in capsys.readouterr().err and client.moves == []


def test_monitor_only_upload_refuses_before_touching_the_file(
    demo: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = demo.read_bytes()
    mtime = demo.stat().st_mtime_ns
    cli = Cli()
    assert cli("--monitor-only", "points", "upload", str(demo)) == cli_points.EXIT_FAILED
    assert "monitor-only" in capsys.readouterr().err
    assert cli.clients_made == 0 and demo.read_bytes() == before and demo.stat().st_mtime_ns == mtime
    unreadable = demo.with_name("missing.teachpad.json")  # not even opened: no "does not exist"
    assert cli("--monitor-only", "points", "upload", str(unreadable)) == cli_points.EXIT_FAILED
    assert "does not exist" not in capsys.readouterr().err
    assert cli("--monitor-only", "run", str(demo), "--plan", "circle") == cli_points.EXIT_FAILED
    assert cli.clients_made == 0 and demo.stat().st_mtime_ns == mtime
    assert cli("--monitor-only", "run", str(demo), "--plan", "circle", "--check") == 0  # reads only


def test_empty_csv_replace_import_needs_allow_empty(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    empty = tmp_path / "empty.csv"
    empty.write_text("id,x,y,z,a,b,c\n", encoding="utf-8")
    before = demo.read_bytes()
    assert Cli()("points", "import", str(demo), "--csv", str(empty)) == cli_points.EXIT_USAGE
    assert "--allow-empty" in capsys.readouterr().err and demo.read_bytes() == before
    assert Cli()("points", "import", str(demo), "--csv", str(empty), "--merge") == 0
    assert len(load_project(demo).ledger) == 8
    assert Cli()("points", "import", str(demo), "--csv", str(empty), "--allow-empty") == 0
    assert len(load_project(demo).ledger) == 0


def test_run_failure_prints_how_to_resume(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    Cli()("points", "upload", str(demo))
    cli = Cli(FakeClient(move_script={4: LinkError("connection lost")}))
    assert cli("run", str(demo), "--plan", "pick and place") == cli_points.EXIT_LINK
    captured = capsys.readouterr()
    assert "failed: segment 2/3 (loop 2/2): connection lost" in captured.err
    assert "--plan 'pick and place' --from 2 --from-loop 2" in captured.out
    cli = Cli()
    assert cli("run", str(demo), "--plan", "pick and place", "--from", "2", "--from-loop", "2") == 0
    assert [m["end"] for m in cli.client.moves] == [3, 1]


def test_run_single_segment_and_loops(demo: Path) -> None:
    Cli()("points", "upload", str(demo))
    cli = Cli()
    assert cli("run", str(demo), "--plan", "circle", "--from", "2", "--single") == 0
    assert [m["end"] for m in cli.client.moves] == [7]
    cli = Cli()
    assert cli("run", str(demo), "--plan", "circle", "--loops", "2") == 0
    assert len(cli.client.moves) == 8


def test_run_refuses_a_plan_with_errors(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    Cli()("points", "upload", str(demo))
    cli = Cli()
    assert cli("run", str(demo), "--plan", "circle", "--max-speed", "60") == cli_points.EXIT_USAGE
    err = capsys.readouterr().err
    assert "segment 1: speed 100 mm/s is not in (0, 60] mm/s" in err and "not running it" in err
    assert cli.client.moves == []


def test_run_check_only_does_not_connect(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cli = Cli()
    assert cli("run", str(demo), "--plan", "pick and place", "--check") == 0
    out = capsys.readouterr().out
    assert "would upload: 2, 4, 3, 1" in out and "check only" in out
    assert cli.clients_made == 0


def test_run_bad_arguments(demo: Path) -> None:
    assert Cli()("run", str(demo), "--plan", "circle", "--from", "9") == cli_points.EXIT_USAGE
    assert Cli()("run", str(demo), "--plan", "circle", "--from-loop", "2") == cli_points.EXIT_USAGE
    assert Cli()("run", str(demo), "--plan", "circle", "--loops", "-1") == cli_points.EXIT_USAGE


def test_run_when_the_controller_is_unreachable(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    class Unreachable(Cli):
        def make_client(self) -> Any:
            raise LinkError("connection refused")

    assert Unreachable()("run", str(demo), "--plan", "circle") == cli_points.EXIT_LINK
    assert "connection refused" in capsys.readouterr().err
    assert Unreachable()("points", "upload", str(demo)) == cli_points.EXIT_LINK


def test_ctrl_c_during_a_run_stops_the_robot(demo: Path, capsys: pytest.CaptureFixture[str]) -> None:
    Cli()("points", "upload", str(demo))
    cli = Cli(FakeClient(move_script={1: KeyboardInterrupt()}))
    assert cli("run", str(demo), "--plan", "circle") == cli_points.EXIT_INTERRUPTED
    assert cli.client.stops == 1
    assert "--plan 'circle' --from 2" in capsys.readouterr().out


def test_ctrl_c_during_upload_keeps_what_was_done(demo: Path) -> None:
    cli = Cli(FakeClient(create_script={3: KeyboardInterrupt()}))
    assert cli("points", "upload", str(demo)) == cli_points.EXIT_INTERRUPTED
    assert sorted(load_project(demo).upload_history) == [1, 2, 3]


def test_failed_segment_exit_code(demo: Path) -> None:
    Cli()("points", "upload", str(demo))
    refused = CommandRefused(CommandStatus(CommandKind.MOVE, 13))
    assert Cli(FakeClient(move_script={0: refused}))("run", str(demo), "--plan", "circle") == 1


def test_through_the_main_cli(
    demo: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """app/cli/main.py registers this module and calls handler(ctx)."""
    from app.cli import main as main_cli
    from app.cli.context import CliContext

    assert main_cli.main(["points", "list", str(demo)]) == 0
    assert "8 point(s), 2 plan(s)" in capsys.readouterr().out
    assert main_cli.main(["run", str(demo), "--plan", "circle", "--check"]) == 0
    assert "check only" in capsys.readouterr().out

    fake = FakeClient()
    monkeypatch.setattr(CliContext, "client", property(lambda self: fake))
    assert main_cli.main(["run", str(demo), "--plan", "circle", "--upload"]) == 0
    assert len(fake.moves) == 4 and len(fake.creates) == 5 + 6
    assert not fake.closed  # the context owns the client (it closes its own, real one)
