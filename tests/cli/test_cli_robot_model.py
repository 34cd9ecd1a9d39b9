"""``run --robot-profile``: the robot model is checked against the controller before its reach
verdicts are used, as in the GUI (issue 18). Against the simulator over TCP."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.cli.run_plan import reach_check, robot_model
from app.plan.checks import IssueCode, check_plan
from app.points.project import load_project
from app.view3d.profile import default_profile, profile_to_dict

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "resources" / "samples" / "demo.teachpad.json"
SHIPPED = ROOT / "app" / "view3d" / "profiles" / "sim_arm.json"


def longer_model(tmp_path: Path) -> Path:
    data = profile_to_dict(default_profile())
    data["name"] = "longer forearm"
    data["joints"][3]["d"] += 200.0
    path = tmp_path / "long.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def test_a_model_that_disagrees_with_the_controller_refuses_the_run(
    sim: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    demo = tmp_path / "demo.teachpad.json"  # a run that went ahead would record its uploads in it
    shutil.copy(DEMO, demo)
    argv = ["--port", str(sim.port), "run", str(demo), "--plan", "circle"]
    code = main([*argv, "--robot-profile", str(longer_model(tmp_path))])
    err = capsys.readouterr().err
    assert code == ExitCode.FAILED and "Traceback" not in err
    assert (
        "the robot model 'longer forearm' disagrees with the controller's pose by 200 mm: "
        "reach checks may be wrong"
    ) in err
    assert "(the robot model disagrees with the controller): not running it" in err
    assert sim.writes == []  # nothing created, nothing moved: the pose was only read


def test_the_shipped_model_agrees_with_the_simulator(make_client: Any, sim: Any) -> None:
    pose = make_client(sim).read_pose()
    assert pose.joints is not None
    reach = reach_check(robot_model(SHIPPED), pose)
    project = load_project(DEMO)
    for plan in project.plans:
        issues = check_plan(plan, project.ledger, current_pose=pose, reach=reach)
        assert not [i for i in issues if i.code is IssueCode.MODEL_DISAGREES], plan.name
