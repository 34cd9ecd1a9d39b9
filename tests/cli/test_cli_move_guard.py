"""``teachpad-cli move`` through the point guard (issue 18): with ``--project`` the point is created
again from the project's copy before the move and the arrival is checked (1 mm); an arm that stops
elsewhere is exit 1 in words. Asserted at the simulator: its stored point, the arm's pose, the
write log of register 440 (0xE0 create point, 0x42 move to point)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.points.point import make_point
from app.points.project import save_project
from app.points.project_model import Project
from app.protocol.enums import RunCommand
from app.protocol.registers import REG_RUN_COMMAND
from tests.cli.test_cli import one_line_error, run
from tests.ui.pendant_support import register_writes

CREATE, MOVE = int(RunCommand.CREATE_POINT), int(RunCommand.MOVE_TO_POINT)
TOLERANCE = 0.01  # mm: the simulator reaches a point exactly (float32 on the wire)
OURS = (30.0, 20.0, 0.0)  # the project's P1, from the arm's start
THEIRS = (-40.0, -40.0, 25.0)  # the controller's own P1, from the arm's start


def _near(pose: tuple[float, ...], target: tuple[float, ...]) -> bool:
    return math.dist(pose[:3], target[:3]) <= TOLERANCE


def _offset(pose: tuple[float, ...], by: tuple[float, float, float]) -> tuple[float, ...]:
    return (pose[0] + by[0], pose[1] + by[1], pose[2] + by[2], *pose[3:6])


@pytest.fixture
def csim(sim_factory: Any) -> Any:
    return sim_factory(command_latency=0.02)


@pytest.fixture
def project(csim: Any, tmp_path: Path) -> Path:
    """A project whose P1 (tool 200) is 36 mm from the arm."""
    path = tmp_path / "cell.teachpad.json"
    cell = Project()
    cell.ledger.replace_all([make_point(1, "pick", _offset(csim.state().pose, OURS))])
    save_project(cell, path)
    return path


def _commands(sim: Any, since: int) -> list[int]:
    return [value for index, value in register_writes(sim, REG_RUN_COMMAND) if index >= since]


def test_move_creates_the_projects_point_first_and_goes_there(
    csim: Any, project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    start = csim.state().pose
    theirs, ours = _offset(start, THEIRS), _offset(start, OURS)
    csim.add_point(1, theirs)  # the controller holds another P1 (another tool wrote it)

    code, out, err = run(csim, capsys, "move", "1", "--project", str(project), "--speed", "400")

    assert (code, err) == (ExitCode.OK, ""), err
    assert _commands(csim, 0) == [CREATE, MOVE]  # P1 from the project's copy, then the move
    final = csim.state()
    assert _near(final.points[1], ours) and _near(final.pose, ours) and not _near(final.pose, theirs)
    assert "move to temp point: done" in out and out.strip().splitlines()[-1].startswith("pose X=")


def test_an_arm_that_stops_elsewhere_is_exit_1_in_words(
    csim: Any, project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Another master writes its P1 right after our create, before our move (the guard's stated
    window): the arm goes there once, and the command fails saying where it is."""
    theirs = _offset(csim.state().pose, THEIRS)
    csim.overwrite_after_create(1, theirs)
    csim.add_point(1, theirs)

    code, out, err = run(csim, capsys, "move", "1", "--project", str(project), "--speed", "400")

    assert code == ExitCode.FAILED
    line = one_line_error(err)
    assert line.startswith("teachpad-cli: error: the arm stopped at (")
    assert "mm away from P1 'pick' at (" in line and "The move failed" in line
    assert "done" not in out
    assert _commands(csim, 0) == [CREATE, MOVE]
    assert _near(csim.state().pose, theirs) and not csim.state().moving


def test_a_point_the_controller_does_not_create_is_not_moved_to(
    csim: Any, project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    csim.refuse_point(1)
    start = csim.state().pose
    code, _, err = run(csim, capsys, "move", "1", "--project", str(project))
    assert code == ExitCode.FAILED and "refused to create P1 'pick'" in one_line_error(err)
    assert _commands(csim, 0) == [CREATE]  # no 0x42
    assert csim.state().pose == start


def test_a_point_the_project_does_not_have_is_a_usage_error(
    csim: Any, project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run(csim, capsys, "move", "2", "--project", str(project))
    assert code == ExitCode.USAGE and "the project has no point P2" in one_line_error(err)
    code, _, err = run(csim, capsys, "move", "1", "--via", "3", "--project", str(project))
    assert code == ExitCode.USAGE and "no point P3" in one_line_error(err)
    code, _, err = run(csim, capsys, "move", "1", "--via", "1", "--project", str(project))
    assert code == ExitCode.USAGE and "middle point must differ" in one_line_error(err)
    assert csim.writes == []


@pytest.mark.usefixtures("open_envelope")  # a move without --project: no keep-in box
def test_without_a_project_the_move_says_the_point_was_not_checked(
    csim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    theirs = _offset(csim.state().pose, THEIRS)
    csim.add_point(1, theirs)
    code, out, err = run(csim, capsys, "move", "1", "--speed", "400")
    assert code == ExitCode.OK and "done" in out
    assert _commands(csim, 0) == [MOVE] and _near(csim.state().pose, theirs)
    assert err.strip() == (
        "teachpad-cli: warning: P1 was not checked: without --project the arm went to whatever the "
        "controller holds under that id (give the project holding the point to create it from its copy "
        "and check the arrival)"
    )
