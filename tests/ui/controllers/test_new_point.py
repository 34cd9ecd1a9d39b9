"""A point added by hand takes the robot's pose only while a real link to the simulator is
fresh; once the controller is silent it never uses the old pose (issue 9, sane defaults)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtGui import QUndoStack

from app.link.robot_link import RobotLink
from app.points.project import load_project
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    connect,
    fast_reconnect_fixture,
    link_fixture,
)
from ui.controllers.new_point import PoseSource
from ui.controllers.point_sync import PointSyncController
from ui.models.points_model import PointsModel
from ui.panels.points_panel import PointsPanel

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "samples" / "demo.teachpad.json"


def test_add_follows_the_freshness_of_a_real_link(qtbot: Any, link: RobotLink, sim: Any) -> None:
    model = PointsModel(load_project(SAMPLE), QUndoStack())
    sync = PointSyncController(model, link)
    panel = PointsPanel(model, sync, confirm=lambda title, text: False)
    qtbot.addWidget(panel)
    connect(qtbot, link, sim)
    qtbot.waitUntil(lambda: link.state.fresh and link.state.pose is not None)
    live = link.state.pose
    assert live is not None and sync.new_point_pose().source is PoseSource.LIVE
    panel.action_add.trigger()
    added = model.ledger[len(model.ledger) - 1]
    assert added.xyzabc == live.xyzabc and "current pose" in panel.status.text()

    link.state.set_freshness_limit(0.1)
    sim.stop()  # the controller falls silent: its last pose is not the robot's any more
    qtbot.waitUntil(lambda: not link.state.fresh, timeout=5000)
    panel.select_rows([0])
    panel.action_add.trigger()
    copied = model.ledger[1]
    assert copied.xyzabc == model.ledger[0].xyzabc
    text = panel.status.text()
    assert "no live pose" in text and f"copied from P{model.ledger[0].id}" in text
