"""Reach in the planner's checks (the 3D view's robot model, shared) and the robot model
profile remembered across restarts."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from app.plan.checks import IssueCode
from app.plan.issue_kind import IssueKind
from app.safety.roles import Role
from app.view3d.profile import default_profile, profile_to_dict
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    log_in,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from ui.main_window import MainWindow
from ui.models.point_columns import COL_X
from ui.panels.view3d_robot import RobotModelSource
from ui.settings import AppSettings

DEMO = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"
FAR_X = 1500.0  # mm: past the simulator arm's 900 mm reach


def _sim_writes(sim: Any) -> int:
    with sim.lock:
        return len(sim.writes)


def _set_x(window: MainWindow, point_id: int, x: float) -> None:
    model = window.project.points_model
    row = model.row_of(point_id)
    assert row is not None
    assert model.setData(model.index(row, COL_X), x)


def _reach_issues(window: MainWindow) -> list[Any]:
    reach = (IssueCode.UNREACHABLE, IssueCode.JOINT_LIMIT)
    return [i for i in window.planner_panel.issues if i.code in reach]


def test_unreachable_point_blocks_run_in_the_planner(
    qtbot: Any, sim: Any, link: Any, window: MainWindow
) -> None:
    assert window.project.open_file(DEMO)
    connect(qtbot, link, sim)
    planner = window.planner_panel
    planner.select_plan(0)  # pick and place: line to P2, arc via P4 to P3, line to P1
    qtbot.waitUntil(lambda: planner.action_run.isEnabled())
    assert not _reach_issues(window)
    assert not window.view3d.built  # the planner checks reach without the 3D view

    x = window.project.points_model.ledger.get(2).x  # type: ignore[union-attr]
    _set_x(window, 2, FAR_X)
    issues = _reach_issues(window)
    assert [(i.segment, i.point_id, i.kind) for i in issues][:1] == [(0, 2, IssueKind.ERROR)]
    assert "out of the robot model's reach" in issues[0].message
    assert any(i.code is IssueCode.UNREACHABLE for i in planner.segments.issues_of(0))  # on the row
    assert not planner.action_run.isEnabled()
    assert not planner.action_step.isEnabled()
    before = _sim_writes(sim)
    assert not planner.run(0)  # refused before anything is sent
    assert _sim_writes(sim) == before

    # the 3D view marks the same point red, from the same solutions
    panel = window.view3d.panel
    window.work_tabs.setCurrentWidget(panel)
    qtbot.waitUntil(lambda: panel.canvas.isVisible())
    panel.refresh_scene()
    assert panel.reach is window.view3d.robot.reach
    assert [pid for pid, r in panel.point_reach.items() if r.value != "ok"] == [2]

    _set_x(window, 2, x)  # back in reach
    assert not _reach_issues(window)
    assert planner.action_run.isEnabled()


def _profile_file(tmp_path: Path, name: str = "longer forearm") -> Path:
    data = profile_to_dict(default_profile())
    data["name"] = name
    data["joints"][3]["d"] = 620.0
    path = tmp_path / "long.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def test_loaded_profile_is_remembered_across_restarts(qtbot: Any, tmp_path: Path) -> None:
    settings = AppSettings.from_file(tmp_path / "teachpad.ini")
    first = RobotModelSource(settings)
    path = _profile_file(tmp_path)
    assert first.load_file(str(path)) is None
    settings.sync()

    again = RobotModelSource(AppSettings.from_file(tmp_path / "teachpad.ini"))  # the next start
    assert again.restore()
    assert again.profile.name == "longer forearm" and again.path == str(path)
    assert again.problem == ""


@pytest.mark.parametrize("damage", ["gone", "malformed"])
def test_remembered_profile_gone_or_malformed_falls_back_to_the_default(
    qtbot: Any, tmp_path: Path, damage: str
) -> None:
    settings = AppSettings.from_file(tmp_path / "teachpad.ini")
    path = _profile_file(tmp_path)
    assert RobotModelSource(settings).load_file(str(path)) is None
    if damage == "gone":
        path.unlink()
    else:
        path.write_text('{"format": "teachpad-robot-profile", "version": 1, "joints": [', encoding="utf-8")
    source = RobotModelSource(settings)
    with qtbot.waitSignal(source.problemRaised) as raised:
        assert not source.restore()
    assert source.profile == default_profile()
    text = raised.args[0]
    assert text == source.problem
    assert "could not be loaded" in text and str(path) in text
    assert ("cannot read" in text) if damage == "gone" else ("not valid JSON" in text)
    assert "default robot model" in text and "Traceback" not in text
    assert settings.robot_profile_path == ""  # forgotten: the next start is quiet


def test_window_starts_with_the_remembered_profile_or_says_why_not(
    qtbot: Any, link: Any, app_settings: Any, translator: Any, project_dialogs: Any, tmp_path: Path
) -> None:
    app_settings.robot_profile_path = str(tmp_path / "missing.json")
    window = MainWindow(
        link, app_settings, translator, project_dialogs=project_dialogs, autosave_dir=tmp_path / "autosave"
    )
    qtbot.addWidget(window)
    robot = window.view3d.robot
    assert robot.profile == default_profile()
    events = [e.text for e in window.event_log.model.events()]
    assert any("missing.json" in t and "could not be loaded" in t for t in events)
    panel = window.view3d.panel  # built later: it says so too
    assert "could not be loaded" in panel.message_label.text()

    path = _profile_file(tmp_path, "arm B")
    log_in(window, Role.ENGINEER)  # the robot model is an engineer's
    assert panel.load_profile_file(str(path))
    assert app_settings.robot_profile_path == str(path)
    assert window.planner_panel.checks.reach == robot.plan_issues
