"""The robot model is an engineer's, audited, named on screen, and checked against the controller
(issue 18): its forward kinematics of the joints the simulator reports must land on the pose it
reports, else the 3D view, the planner's checks (which then block Run) and the event log say so
in words."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from app.plan.checks import IssueCode
from app.safety.audit_read import query
from app.safety.roles import Role
from app.view3d.agreement import MODEL_TOLERANCE_DEG, MODEL_TOLERANCE_MM
from app.view3d.profile import default_profile, profile_to_dict
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
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
from ui.panels.view3d_panel import View3DPanel

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

DEMO = Path(__file__).resolve().parents[2] / "resources" / "samples" / "demo.teachpad.json"
SHIPPED = Path(__file__).resolve().parents[2] / "app" / "view3d" / "profiles" / "sim_arm.json"
LONGER_BY = 200.0  # mm the longer forearm adds to the simulator's 420 mm


def longer_model(tmp_path: Path, name: str = "longer forearm") -> Path:
    """A copy of the simulator's arm with a forearm 200 mm longer: its TCP is 200 mm off."""
    data = profile_to_dict(default_profile())
    data["name"] = name
    data["joints"][3]["d"] += LONGER_BY
    path = tmp_path / "long.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def view3d(window: MainWindow, qtbot: Any) -> View3DPanel:
    panel = window.view3d.panel
    window.work_tabs.setCurrentWidget(panel)
    qtbot.waitUntil(panel.isVisible)
    return panel


def audit(window: MainWindow, command: str) -> list[Any]:
    return [r for r in query(window.safety_menu.safety.audit_dir) if r.command == command]


def _sim_writes(sim: Any) -> int:
    with sim.lock:
        return len(sim.writes)


def test_an_operator_cannot_load_a_robot_model(qtbot: Any, window: MainWindow, tmp_path: Path) -> None:
    panel = view3d(window, qtbot)
    robot = window.view3d.robot
    button = panel.profile_button
    assert not button.isEnabled() and button.isVisible()  # greyed, not hidden
    assert "engineer" in button.toolTip()
    path = longer_model(tmp_path)

    assert not panel.load_profile_file(str(path))  # reached another way (a shortcut, a script)
    assert robot.profile == default_profile() and robot.path == ""
    assert window.settings.robot_profile_path == ""  # nothing remembered for the next start
    assert "engineer" in panel.message_label.text() and panel.message_label.isVisible()
    refused = audit(window, "change robot model")
    assert [(r.kind, r.result, r.role, r.args) for r in refused] == [
        (
            "refused",
            "refused",
            "operator",
            # the refusal's reason is kept for the audit viewer's words (issue 21)
            {
                "file": str(path),
                "reason": "role_refused",
                "reason_args": {"need": "engineer", "role": "operator"},
            },
        )
    ]
    panel.choose_profile()  # the button's slot: refused before any file dialog opens
    assert len(audit(window, "change robot model")) == 2
    assert robot.profile == default_profile()


def test_an_engineer_loads_a_robot_model_audited_and_named(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    panel = view3d(window, qtbot)
    robot = window.view3d.robot
    shipped = default_profile().name
    assert shipped in panel.model_label.text()  # the model in use, in the 3D view's header
    log_in(window, Role.ENGINEER)
    assert panel.profile_button.isEnabled() and "engineer" not in panel.profile_button.toolTip().split(";")[0]
    path = longer_model(tmp_path)

    assert panel.load_profile_file(str(path))
    assert robot.profile.name == "longer forearm" and window.settings.robot_profile_path == str(path)
    [loaded] = audit(window, "change robot model")
    assert (loaded.kind, loaded.result, loaded.role) == ("action", "ok", "engineer")
    assert loaded.args == {"file": str(path), "name": "longer forearm"}
    assert "longer forearm" in panel.model_label.text()
    assert str(path) in panel.model_label.toolTip()
    planner = window.planner_panel  # where the reach checks are listed: beside the preview's Fit
    assert "longer forearm" in planner.preview.reach_label.text()
    assert planner.preview.reach_label.isVisibleTo(planner)


def test_a_longer_link_model_disagrees_with_the_simulator_and_blocks_run(
    qtbot: Any, sim: Any, link: Any, window: MainWindow, translator: Any, tmp_path: Path
) -> None:
    assert window.project.open_file(DEMO)
    connect(qtbot, link, sim)
    planner = window.planner_panel
    planner.select_plan(0)
    qtbot.waitUntil(planner.action_run.isEnabled, timeout=SIGNAL_TIMEOUT_MS)
    robot = window.view3d.robot
    qtbot.waitUntil(lambda: robot.agreement is not None, timeout=SIGNAL_TIMEOUT_MS)
    panel = view3d(window, qtbot)
    log_in(window, Role.ENGINEER)

    assert panel.load_profile_file(str(longer_model(tmp_path)))
    agreement = robot.agreement
    assert agreement is not None and not agreement.agrees
    assert agreement.distance_mm == pytest.approx(LONGER_BY, abs=1.0)
    said = (
        "The robot model \u201clonger forearm\u201d disagrees with the controller's pose by 200 mm: "
        "reach checks may be wrong."
    )
    assert panel.agreement_label.isVisible() and panel.agreement_label.text() == said
    assert any("disagrees" in text for text, _colour in panel.canvas.badges)
    assert any(e.text == said for e in window.event_log.model.events())  # said once, in the log too
    # the planner's checks: an error for the whole plan, and Run is blocked
    model_errors = [i for i in planner.issues if i.code is IssueCode.MODEL_DISAGREES]
    assert [(i.segment, i.is_error) for i in model_errors] == [(None, True)]
    assert said in planner.checks_bar.summary.text()
    assert not planner.action_run.isEnabled()
    before = _sim_writes(sim)
    assert not planner.run(0)  # refused before anything is sent
    assert _sim_writes(sim) == before

    assert translator.set_language("zh_CN")  # in words in the other language too
    qtbot.waitUntil(lambda: panel.agreement_label.text() != said, timeout=SIGNAL_TIMEOUT_MS)
    chinese = panel.agreement_label.text()
    assert chinese.startswith("机器人模型“longer forearm”") and "200 mm" in chinese
    assert "可达性检查可能有误" in chinese

    assert panel.load_profile_file(str(SHIPPED))  # the right model again: nothing to say
    assert robot.agreement is not None and robot.agreement.agrees
    assert not panel.agreement_label.isVisible()
    assert not [i for i in planner.issues if i.code is IssueCode.MODEL_DISAGREES]
    assert planner.action_run.isEnabled()


def test_the_shipped_model_agrees_with_the_simulator_wherever_the_arm_is(
    qtbot: Any, sim: Any, link: Any, window: MainWindow
) -> None:
    connect(qtbot, link, sim)
    robot = window.view3d.robot
    for axis, angle in ((0, 0.0), (1, 35.0), (4, -60.0), (3, 120.0)):  # home, then elsewhere
        if axis:
            sim.set_joint(axis, angle)
            qtbot.waitUntil(
                lambda a=axis, v=angle: (
                    link.state.pose is not None
                    and link.state.pose.joints is not None
                    and link.state.pose.joints[a - 1] == pytest.approx(v)
                ),
                timeout=SIGNAL_TIMEOUT_MS,
            )
            robot.compare()
        qtbot.waitUntil(lambda: robot.agreement is not None, timeout=SIGNAL_TIMEOUT_MS)
        agreement = robot.agreement
        assert agreement is not None and agreement.agrees
        assert agreement.distance_mm < MODEL_TOLERANCE_MM / 50  # float32 rounding, nothing more
        assert agreement.angle_deg < MODEL_TOLERANCE_DEG / 50
    panel = view3d(window, qtbot)
    assert not panel.agreement_label.isVisible()
    assert "Agrees with the controller" in panel.model_label.toolTip()
    assert not any("disagrees" in e.text for e in window.event_log.model.events())


def test_a_robot_model_file_that_cannot_be_used_is_refused_in_chinese(
    qtbot: Any, translator: Any, tmp_path: Path
) -> None:
    """(issue 21) The refusal names the file, the field and why in the operator's language: the
    core's English ("joint 2: min_deg 10 is not below max_deg 5") was shown inside Chinese."""
    import re

    from app.view3d.profile import PROFILE_FORMAT
    from ui.panels.view3d_robot import RobotModelSource

    cases = {
        "limits.json": json.dumps(
            {
                "format": PROFILE_FORMAT,
                "version": 1,
                "joints": [{"d": 1, "a": 0, "alpha_deg": 0, "min_deg": 10, "max_deg": 5}],
            }
        ),
        "missing.json": json.dumps({"format": PROFILE_FORMAT, "version": 1, "joints": [{"d": 1}]}),
        "format.json": '{"format": "cad", "version": 1}',
        "broken.json": '{"format": ',
    }
    source = RobotModelSource()
    assert translator.set_language("zh_CN")
    words: dict[str, str | None] = {}
    for name, text in cases.items():
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        words[name] = source.load_file(str(path))
    # what stays as written: the file, JSON and its keys, the format's id, a quoted value
    keys = re.compile(PROFILE_FORMAT + r"|[a-z]+_deg|\bformat\b|'cad'|JSON|TeachPad|[\w/.-]+\.json")
    for name, said in words.items():
        assert said is not None and name in said, said
        assert re.search(r"[\u4e00-\u9fff]", said), said
        assert not re.search(r"[A-Za-z]{3,}", keys.sub("", said)), f"English left in {said!r}"
    assert "关节 1：min_deg 10 不小于 max_deg 5" in (words["limits.json"] or "")
    assert "第 1 行" in (words["broken.json"] or "")
