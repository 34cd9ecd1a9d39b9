"""The 3D view: the arm drawn where FK puts it, selection both ways with the points table,
unreachable points in red, the dry run (nothing written at the simulator)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QImage, QPainter

from app.plan.checks import IssueCode
from app.safety.roles import Role
from app.sim import kinematics as sim_kin
from app.view3d.camera import Preset
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
from ui.panels.view3d_panel import View3DPanel

DEMO = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"


def _panel(window: MainWindow, qtbot: Any) -> View3DPanel:
    panel = window.view3d.panel
    window.work_tabs.setCurrentWidget(panel)
    qtbot.waitUntil(lambda: panel.canvas.isVisible())
    return panel


def _draw(panel: View3DPanel) -> None:
    panel.canvas.repaint()


def _sim_writes(sim: Any) -> int:
    with sim.lock:
        return len(sim.writes)


def test_known_joints_draw_the_flange_where_fk_puts_it(qtbot: Any, window: MainWindow) -> None:
    panel = _panel(window, qtbot)
    for preset in Preset:
        panel.set_preset(preset)
        for q in ([0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [30.0, 10.0, -20.0, 40.0, 60.0, 90.0]):
            panel.on_joints(tuple(q))
            panel._update_arm()
            _draw(panel)
            expected = panel.canvas.project(sim_kin.forward(q)[:3, 3])
            assert np.allclose(panel.canvas.drawn["flange"], expected, atol=1e-6)
            assert not panel.tracker.estimated


def test_live_arm_follows_the_simulator(qtbot: Any, sim: Any, link: Any, window: MainWindow) -> None:
    panel = _panel(window, qtbot)
    connect(qtbot, link, sim)
    qtbot.waitUntil(lambda: panel._joints is not None, timeout=5000)
    qtbot.waitUntil(lambda: "flange" in panel.canvas.drawn, timeout=5000)
    joints = sim.state().joints[:6]
    panel.on_joints(joints)
    panel._update_arm()
    _draw(panel)
    expected = panel.canvas.project(sim_kin.forward(joints)[:3, 3])
    assert np.allclose(panel.canvas.drawn["flange"], expected, atol=1e-6)


def test_pose_without_joints_is_an_estimate(qtbot: Any, window: MainWindow) -> None:
    from app.models import Pose

    panel = _panel(window, qtbot)
    q = [10.0, 25.0, 15.0, 0.0, 45.0, 0.0]
    panel.on_pose(Pose(*sim_kin.forward_pose(q)))
    panel._update_arm()
    _draw(panel)
    assert panel.tracker.estimated
    assert any("estimate" in text for text, _c in panel.canvas.badges)
    expected = panel.canvas.project(sim_kin.forward(q)[:3, 3])
    assert np.allclose(panel.canvas.drawn["flange"], expected, atol=0.5)


def test_selection_follows_the_table_and_the_view(qtbot: Any, window: MainWindow) -> None:
    assert window.project.open_file(DEMO)
    panel = _panel(window, qtbot)
    panel.refresh_scene()
    panel.set_preset(Preset.TOP)
    _draw(panel)
    points = window.points_panel
    model = window.project.points_model
    row = model.row_of(6)
    assert row is not None
    points.select_rows([row])
    _draw(panel)
    assert panel.canvas.selected_ids == {6}
    expected = panel.canvas.project(np.array(model.point_at(row).xyz))
    assert np.allclose(panel.canvas.drawn["selected"], expected)
    # click point 3 in the view: the table selects it
    x, y = panel.canvas.project(np.array(model.point_at(model.row_of(3)).xyz))[0]  # type: ignore[arg-type]
    qtbot.mouseClick(panel.canvas, Qt.MouseButton.LeftButton, pos=QPoint(round(x), round(y)))
    assert points.selected_rows() == [model.row_of(3)]
    assert panel.canvas.selected_ids == {3}
    # a click on nothing clears both
    panel.canvas.click_at(2.0, 2.0)
    assert points.selected_rows() == [] and panel.canvas.selected_ids == set()


def test_unreachable_point_is_red_and_reported(qtbot: Any, window: MainWindow) -> None:
    assert window.project.open_file(DEMO)
    panel = _panel(window, qtbot)
    model = window.project.points_model
    model.add_point(name="far", pose=(1500.0, 0.0, 300.0, 180.0, 0.0, 180.0))
    far = max(p.id for p in model.ledger)
    panel.refresh_scene()
    _draw(panel)
    row = [p.id for p in model.ledger].index(far)
    assert np.allclose(panel.canvas.drawn["bad_points"], panel.canvas.drawn["points"][[row]])
    assert f"P{far}" in panel.reach_label.text()
    plan = window.planner_panel.current_plan()
    assert plan is not None
    from app.plan.checks import check_plan
    from app.plan.segments import Segment

    plan.segments.append(Segment.line(far))
    issues = check_plan(plan, model.ledger, reach=panel.reach.plan_issues)
    assert any(i.code is IssueCode.UNREACHABLE and i.point_id == far for i in issues)


@pytest.mark.parametrize("plan_row", [0, 1])
def test_dry_run_moves_the_arm_and_writes_nothing(
    qtbot: Any, sim: Any, link: Any, window: MainWindow, plan_row: int
) -> None:
    assert window.project.open_file(DEMO)
    connect(qtbot, link, sim)
    panel = _panel(window, qtbot)
    window.planner_panel.select_plan(plan_row)
    planner = window.planner_panel
    qtbot.waitUntil(lambda: panel.plan is planner.current_plan() and panel.dry_bar.run is not None)
    bar = panel.dry_bar
    assert bar.run is not None and bar.run.duration > 0
    before = _sim_writes(sim)
    positions = []
    for value in (50, 250, 500, 750, 1000):
        bar.slider.setValue(value)
        _draw(panel)
        positions.append(panel.canvas.drawn["ghost_flange"][0].copy())
        state = bar.run.at(bar.time)
        assert state.pose is not None
        assert np.allclose(
            panel.canvas.drawn["ghost_flange"], panel.canvas.project(np.array(state.pose[:3])), atol=0.5
        )
    assert len({tuple(np.round(p, 1)) for p in positions}) >= 3
    assert panel.canvas.active_segment is not None
    bar.slider.setValue(0)
    bar.play_button.setChecked(True)
    start = bar.time
    qtbot.waitUntil(lambda: bar.time > start + 0.2, timeout=5000)
    bar.play_button.setChecked(False)
    assert any("dry run" in text for text, _c in panel.canvas.badges)
    bar.leave()
    assert "ghost_flange" not in panel.canvas.drawn or panel.canvas.ghost_arm is None
    assert _sim_writes(sim) == before


def test_beside_the_planner_and_back(qtbot: Any, window: MainWindow) -> None:
    panel = _panel(window, qtbot)
    panel.beside_button.setChecked(True)
    assert window.view3d.dock.widget() is panel
    assert window.work_tabs.indexOf(panel) == -1
    assert window.work_tabs.currentWidget() is window.planner_panel
    panel.beside_button.setChecked(False)
    assert window.work_tabs.indexOf(panel) >= 0


def test_another_robot_model_and_a_bad_profile_file(qtbot: Any, window: MainWindow, tmp_path: Path) -> None:
    import json

    from app.view3d.profile import default_profile, profile_to_dict

    panel = _panel(window, qtbot)
    log_in(window, Role.ENGINEER)  # the robot model is an engineer's
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "teachpad-robot-profile", "version": 2}', encoding="utf-8")
    assert not panel.load_profile_file(str(bad))
    assert "version 2 is not supported" in panel.message_label.text()
    assert panel.model.profile == default_profile()
    data = profile_to_dict(default_profile())
    data["name"] = "longer forearm"
    data["joints"][3]["d"] = 620.0
    good = tmp_path / "long.json"
    good.write_text(json.dumps(data), encoding="utf-8")
    assert panel.load_profile_file(str(good))
    assert panel.message_label.isHidden()
    q = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    panel.on_joints(tuple(q))
    panel._update_arm()
    _draw(panel)
    assert np.allclose(panel.canvas.drawn["flange"], panel.canvas.project(np.array([725.0, 0.0, 890.0])))


def test_drag_level_of_detail_keeps_selection_and_red_points(qtbot: Any) -> None:
    """While dragging only every k-th marker is projected and drawn, but the selected and the
    unreachable ones are always drawn where the full projection puts them."""
    from ui.panels.view3d_canvas import LOD_MAX_POINTS, View3DCanvas

    canvas = View3DCanvas()
    qtbot.addWidget(canvas)
    canvas.resize(600, 400)
    n = 3 * LOD_MAX_POINTS
    rng = np.random.default_rng(3)
    xyz = np.column_stack([rng.uniform(200, 700, n), rng.uniform(-400, 400, n), rng.uniform(50, 700, n)])
    bad = np.zeros(n, dtype=bool)
    bad[[1, 4, n - 2]] = True  # not on the thinned rows
    canvas.set_points(xyz, list(range(1, n + 1)), [f"P{i}" for i in range(1, n + 1)], ["#2e7d32"] * n, bad)
    canvas.set_selected({2, n})
    canvas.fit_all()
    full = canvas.project(xyz)

    def draw() -> None:
        image = QImage(600, 400, QImage.Format.Format_ARGB32_Premultiplied)
        painter = QPainter(image)
        canvas.render_scene(painter)
        painter.end()

    canvas.set_dragging(True)
    draw()
    assert len(canvas.drawn["points"]) < n
    assert np.allclose(canvas.drawn["bad_points"], full[bad])
    assert np.allclose(canvas.drawn["selected"], full[[1, n - 1]])
    assert canvas.click_at(*full[5]) == 6  # picking projects everything again
    canvas.set_dragging(False)
    draw()
    assert np.allclose(canvas.drawn["points"], full)
