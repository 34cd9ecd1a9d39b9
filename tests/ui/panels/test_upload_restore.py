"""Upload, cancel and restore through the points panel on a real RobotLink and simulator:
the ledger ends up exactly as the controller is, and a restart seen by the canary offers
"Restore all", which brings every point back."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtGui import QUndoStack

from app.link.progress import PointUploaded
from app.link.robot_link import RobotLink
from app.points.point import SyncState, make_point
from app.points.project_model import Project
from tests.link.progress_log import ProgressLog
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    canary_link_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    register_writes,
)
from ui.controllers.point_sync import PointSyncController
from ui.models.points_model import PointsModel
from ui.panels.points_panel import PointsPanel

pytestmark = pytest.mark.timeout(120)
UPLOAD_TIMEOUT_MS = 30_000


@pytest.fixture(name="sim")
def sentinel_sim_fixture(sim_factory: Any) -> Any:
    """A simulator whose GV291 the host may write: the link proves every result with a sentinel.
    With GV291 ignored (the default) the link only observes it, and a command whose answer or
    first status read a loaded test process holds past the simulator's 0.25 s read-hold of the
    0 phase ends rightly *done, unconfirmed* (the point then reads "unconfirmed", not "on the
    controller"); these tests are about the ledger matching the controller, not that rule."""
    return sim_factory(gv291="writable")


def _panel(qtbot: Any, link: RobotLink, count: int, tools: tuple[int, ...] = (200,)) -> PointsPanel:
    project = Project()
    project.ledger.replace_all(
        [
            make_point(
                pid,
                f"p{pid}",
                (400.0 + pid * 0.01, -50.0, 300.0, 180.0, 0.0, 0.0),
                tool=tools[pid % len(tools)],
            )
            for pid in range(1, count + 1)
        ]
    )
    model = PointsModel(project, QUndoStack())
    panel = PointsPanel(model, PointSyncController(model, link), confirm=lambda _title, _text: True)
    qtbot.addWidget(panel)
    return panel


def _on_controller(panel: PointsPanel) -> list[int]:
    return [p.id for p in panel.model.ledger if p.sync is SyncState.ON_CONTROLLER]


def test_cancel_half_way_leaves_the_ledger_exactly_as_the_controller(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    connect(qtbot, link, sim)
    panel = _panel(qtbot, link, 300, tools=(200, 2))
    controller = panel.controller
    reported: list[int] = []

    def on_point(point: PointUploaded) -> None:
        if point.ok:
            reported.append(point.point_id)
        if len(reported) == 150:
            controller.cancel_upload()

    ProgressLog(link, on_point)
    with qtbot.waitSignal(controller.uploadFinished, timeout=60_000) as finished:
        panel.upload_all()
    report = finished.args[0]
    on_sim = sorted(sim.state().points)
    assert 150 <= len(on_sim) < 300
    assert sorted(_on_controller(panel)) == on_sim == sorted(reported)
    assert report.ok_count == len(on_sim) and report.aborted == "cancelled"
    assert sorted(report.not_attempted) == sorted(set(range(1, 301)) - set(on_sim))
    assert all(panel.model.ledger.point(pid).sync is SyncState.CHANGED for pid in report.not_attempted)
    assert register_writes(sim, 441) == []  # a cancel is not a controller stop
    with sim.lock:
        tools = {pid: point.tool for pid, point in sim.robot.points.items()}
    assert tools == {pid: panel.model.ledger.point(pid).tool for pid in on_sim}
    assert not controller.busy and not panel.progress_row.isVisibleTo(panel)


def test_link_loss_half_way_keeps_every_reported_point(qtbot: Any, sim: Any, link: RobotLink) -> None:
    # the upload must end where the test silences the simulator (after 100 points), not earlier
    # because one create-point of a loaded test process took longer than the tests' short
    # request timeout (an unanswered write ends the upload: its outcome is unknown)
    connect(qtbot, link, sim, timeout=1.0)
    panel = _panel(qtbot, link, 300)
    controller = panel.controller
    reported: list[int] = []

    def on_point(point: PointUploaded) -> None:
        if point.ok:
            reported.append(point.point_id)
        if len(reported) == 100:
            sim.set_silent(True)

    ProgressLog(link, on_point)
    try:  # the simulator answers again whatever happens: a failure is then one failure, not also
        # a shutdown that waits on the silence in the fixture's teardown
        with qtbot.waitSignal(controller.uploadFinished, timeout=60_000) as finished:
            panel.upload_all()
        report = finished.args[0]
        assert report.aborted and report.not_attempted
        on_controller = set(_on_controller(panel))
        assert on_controller == set(reported) and len(on_controller) >= 100
        failed = {o.point_id for o in report.failed}  # the point the link died on: outcome unknown
        assert len(failed) <= 1
        for pid in failed:
            assert panel.model.ledger.point(pid).sync is SyncState.FAILED
        assert on_controller <= set(sim.state().points) <= on_controller | failed
    finally:
        sim.set_silent(False)


def test_a_restart_seen_by_the_canary_offers_restore_all(
    qtbot: Any, sim: Any, canary_link: RobotLink
) -> None:
    link = canary_link
    connect(qtbot, link, sim)
    panel = _panel(qtbot, link, 40, tools=(200, 1, 3))
    controller = panel.controller
    # an upload of 40 points is a chain of ~200 requests: more than a signal's usual 5 s on a
    # loaded machine
    with qtbot.waitSignal(controller.uploadFinished, timeout=UPLOAD_TIMEOUT_MS) as finished:
        panel.upload_all()
    assert finished.args[0].all_ok and len(_on_controller(panel)) == 40
    assert not panel.banner.isVisibleTo(panel)

    with qtbot.waitSignal(link.controllerRestarted, timeout=SIGNAL_TIMEOUT_MS):
        sim.restart_controller()
    assert sim.state().points == {}
    assert all(p.sync is SyncState.UNKNOWN for p in panel.model.ledger)
    assert panel.banner.isVisibleTo(panel) and panel.restore_button.isEnabled()
    assert "Restore all" in panel.status.text()

    with qtbot.waitSignal(controller.uploadFinished, timeout=UPLOAD_TIMEOUT_MS) as finished:
        panel.restore_button.click()
    assert finished.args[0].all_ok
    assert sorted(sim.state().points) == list(range(1, 41))
    assert len(_on_controller(panel)) == 40 and not panel.banner.isVisibleTo(panel)
    with sim.lock:
        assert {pid: p.tool for pid, p in sim.robot.points.items()} == {
            p.id: p.tool for p in panel.model.ledger
        }
