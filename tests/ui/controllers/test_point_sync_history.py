"""GUI uploads (upload selected, upload all, restore all) record the upload history in the
project like the CLI's ``points upload``: the points the controller created, with the link's
endpoint; the project turns dirty and the history is in the saved file. Real RobotLink and
simulator. Also: the controllers' ``connected`` is the link state's, never a copy."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from app.link.robot_link import RobotLink
from app.link.types import ConnectionState, LinkState
from app.points.point import make_point
from app.points.project import load_project
from app.points.project_model import Project
from app.points.upload import UploadReport
from tests.ui.controllers.test_project_controller import FakeDialogs
from tests.ui.fake_link import FakeLink
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    connect,
    fast_reconnect_fixture,
    link_fixture,
)
from ui.controllers.plan_run_controller import PlanRunController
from ui.controllers.point_sync import PointSyncController
from ui.controllers.project_controller import ProjectController

pytestmark = pytest.mark.timeout(120)
UPLOAD_TIMEOUT_MS = 20_000


@pytest.fixture
def project(qtbot: Any, tmp_path: Path) -> Any:
    source = Project()
    source.ledger.replace_all(
        [make_point(pid, f"p{pid}", (400.0 + pid, -50.0, 300.0, 180.0, 0.0, 0.0)) for pid in range(1, 6)]
    )
    path = tmp_path / "cell.teachpad.json"
    ctl = ProjectController(
        source, path, dialogs=FakeDialogs(), autosave_interval=0, autosave_dir=tmp_path / "user"
    )
    assert ctl.save()
    yield ctl
    ctl.close()


def _upload(qtbot: Any, sync: PointSyncController, start: Any) -> UploadReport:
    with qtbot.waitSignal(sync.uploadFinished, timeout=UPLOAD_TIMEOUT_MS) as finished:
        assert start()
    report: UploadReport = finished.args[0]
    return report


def test_gui_uploads_record_the_history_in_the_project(
    qtbot: Any, sim: Any, link: RobotLink, project: ProjectController
) -> None:
    connect(qtbot, link, sim, poll_timeout=1.0)  # a loaded machine: see test_plan_run_guard.POLL_TIMEOUT
    sync = PointSyncController(project.points_model, link)
    data = project.points_model.project
    endpoint = f"127.0.0.1:{sim.port}"
    assert data.upload_history == {} and not project.is_dirty

    # upload selected, with one point the controller refuses: only what it created is history
    sim.refuse_point(3)
    report = _upload(qtbot, sync, lambda: sync.upload([2, 3]))
    assert [o.point_id for o in report.outcomes if o.ok] == [2]
    assert set(data.upload_history) == {2}
    assert data.upload_history[2].endpoint == endpoint
    assert project.is_dirty  # history is part of the file
    sim.refuse_point(3, refuse=False)

    # upload all that is not on the controller
    report = _upload(qtbot, sync, sync.upload_needed)
    assert report.all_ok and set(data.upload_history) == {1, 2, 3, 4, 5}
    first_p2 = data.upload_history[2].time

    # restore all after a controller restart: every point again, times not older
    sim.restart_controller()
    report = _upload(qtbot, sync, sync.restore_all)
    assert report.all_ok and sorted(sim.state().points) == [1, 2, 3, 4, 5]
    assert all(r.endpoint == endpoint for r in data.upload_history.values())
    assert data.upload_history[2].time >= first_p2

    assert project.save() and not project.is_dirty
    path = project.path
    assert path is not None
    saved = load_project(path)
    assert set(saved.upload_history) == {1, 2, 3, 4, 5}
    assert saved.upload_history[4].endpoint == endpoint


def test_connected_is_the_link_states(qtbot: Any) -> None:
    link = FakeLink(connected=False)
    points = project_model()
    runs = PlanRunController(link, points=points)
    sync = PointSyncController(points, link)
    assert not runs.connected and not sync.connected
    with (
        qtbot.waitSignal(runs.connectedChanged, check_params_cb=bool),
        qtbot.waitSignal(sync.connectedChanged, check_params_cb=bool),
    ):
        link.set_connected(True)
    assert runs.connected and sync.connected
    # whatever changes the link's state is seen at once: there is no copy to fall behind
    link.state.set_connection(ConnectionState(LinkState.DOWN, "cable pulled"))
    assert not runs.connected and not sync.connected
    assert not hasattr(runs, "_connected") and not hasattr(sync, "_connected")


def project_model() -> Any:
    from PySide6.QtGui import QUndoStack

    from ui.models.points_model import PointsModel

    return PointsModel(Project(), QUndoStack())
