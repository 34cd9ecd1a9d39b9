"""The points panel's upload hears its own upload's progress, not another's on the same link
(issue 22: progress keyed by the ticket). Another user of the link -- a script, a second panel --
uploaded P1..P3 at poses of its own, the controller refusing its P2; the panel's upload of its
ledger's P1..P3 begins while those reports are still on their way to the GUI thread. Real
RobotLink and simulator."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtGui import QUndoStack

from app.link.ops import UploadPoints
from app.link.robot_link import RobotLink
from app.points.point import SyncState, make_point
from app.points.project_model import Project
from tests.link.progress_log import WorkerEnded
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)
from ui.controllers.point_sync import PointSyncController
from ui.models.points_model import PointsModel

pytestmark = pytest.mark.timeout(120)
IDS = (1, 2, 3)


def _ledger_pose(pid: int) -> tuple[float, ...]:
    return (400.0 + pid, -50.0, 300.0, 180.0, 0.0, 0.0)


def _other_pose(pid: int) -> tuple[float, ...]:
    return (350.0 + pid, 20.0, 310.0, 180.0, 0.0, 0.0)


def test_the_panels_upload_is_not_told_another_uploads_points(
    qtbot: Any, sim_factory: Any, link: RobotLink
) -> None:
    sim = sim_factory(gv291="writable")  # every result proven: "on the controller", not "unconfirmed"
    connect(qtbot, link, sim, timeout=1.0)  # roomy: a loaded machine's late answer is not the subject
    project = Project()
    project.ledger.replace_all([make_point(pid, f"p{pid}", _ledger_pose(pid)) for pid in IDS])
    model = PointsModel(project, QUndoStack())
    sync = PointSyncController(model, link)
    ended = WorkerEnded(link)

    sim.refuse_point_write(2)  # the other upload's P2: refused once (its GV200 write)
    other = link.submit(UploadPoints.of([(pid, _other_pose(pid)) for pid in IDS]))
    ended.wait(other)  # over on the worker; its reports still queued for the GUI thread
    with qtbot.waitSignal(sync.uploadFinished, timeout=SIGNAL_TIMEOUT_MS) as finished:
        assert sync.upload(IDS)

    report = finished.args[0]
    assert [(o.point_id, o.ok) for o in report.outcomes] == [(1, True), (2, True), (3, True)], report
    assert report.all_ok and report.aborted is None
    assert [p.sync for p in model.ledger] == [SyncState.ON_CONTROLLER] * 3
    # at the simulator: the panel's poses, sent by the panel's own upload
    assert {pid: sim.state().points[pid] for pid in IDS} == {pid: _ledger_pose(pid) for pid in IDS}
