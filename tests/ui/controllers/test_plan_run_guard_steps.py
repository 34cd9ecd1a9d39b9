"""The guarded run's sequencing, step by step, on the typed fake link (the tests play the
worker): upload of the segment's points first, then the move, then the arrival check."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtGui import QUndoStack

from app.link.ops import MoveToPoint, UploadPoints
from app.link.types import ConnectionState, LinkState, WorkerError
from app.models import Pose
from app.plan.runner import RunState
from app.plan.segments import Plan, Segment
from app.points.point import SyncState, make_point
from app.points.project_model import Project
from tests.ui.fake_link import FakeLink
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from ui.controllers.plan_run_controller import PlanRunController
from ui.models.points_model import PointsModel

P1 = (400.0, 0.0, 300.0, 180.0, 0.0, 0.0)
P2 = (430.0, 0.0, 300.0, 180.0, 0.0, 0.0)
P3 = (430.0, 30.0, 300.0, 180.0, 0.0, 0.0)


@pytest.fixture
def project() -> Project:
    project = Project(plans=[Plan("p", [Segment.line(1), Segment.arc(2, 3)])])
    project.ledger.replace_all([make_point(1, "", P1, tool=3), make_point(2, "", P2), make_point(3, "", P3)])
    return project


@pytest.fixture
def link() -> FakeLink:
    return FakeLink()


@pytest.fixture
def runs(qtbot: Any, link: FakeLink, project: Project) -> PlanRunController:
    return PlanRunController(link, points=PointsModel(project, QUndoStack()))


def _at(link: FakeLink, xyzabc: tuple[float, ...]) -> None:
    x, y, z, a, b, c = xyzabc
    link.state.set_pose(Pose(x, y, z, a, b, c, ext=(0.0,) * 5))


def test_points_first_then_the_move_then_the_arrival(
    qtbot: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    runs.run(project.plans[0])
    assert link.kinds() == [UploadPoints]
    assert link.named(UploadPoints)[0].items == ((1, P1, 3),)  # the ledger's values and tool
    link.point_ok(1)
    link.upload_summary(1, 1)
    assert link.kinds() == [UploadPoints, MoveToPoint]
    _at(link, P1)
    link.finish_move()
    # the arc: its middle and end points, then the move through them
    assert link.named(UploadPoints)[1].items == ((2, P2, 200), (3, P3, 200))
    link.point_ok(2, 3)
    link.upload_summary(2, 2)
    assert (link.named(MoveToPoint)[1].end_id, link.named(MoveToPoint)[1].via_id) == (3, 2)
    _at(link, P3)
    with qtbot.waitSignal(runs.runFinished) as finished:
        link.finish_move()
    assert finished.args[0].state is RunState.FINISHED


def test_an_arrival_elsewhere_fails_the_run_and_marks_the_point_unknown(
    qtbot: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    runs.run(project.plans[0])
    link.point_ok(1)
    link.upload_summary(1, 1)
    _at(link, P2)  # 30 mm off P1
    with qtbot.waitSignal(runs.runFinished) as finished, qtbot.waitSignal(runs.pointMismatch) as mismatch:
        link.finish_move()
    outcome = finished.args[0]
    assert outcome.state is RunState.FAILED and outcome.resume_from == 0 and mismatch.args == [1]
    assert "30.00 mm from P1" in runs.outcome_text(outcome)
    assert project.ledger.point(1).sync is SyncState.UNKNOWN
    assert len(link.named(UploadPoints)) == 1  # nothing more was sent


def test_an_arrival_without_a_pose_is_not_taken_as_done(
    qtbot: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    runs.step(project.plans[0], 0)
    link.point_ok(1)
    link.upload_summary(1, 1)
    with qtbot.waitSignal(runs.runFinished) as finished:
        link.finish_move()
    assert finished.args[0].state is RunState.FAILED
    assert "position after the move to P1 is not known" in runs.outcome_text(finished.args[0])


def test_link_lost_while_the_points_are_created(
    qtbot: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    runs.step(project.plans[0], 1)
    link.point_ok(2)  # P2 made it, P3 did not
    with qtbot.waitSignal(runs.runFinished) as finished:
        link.set_connected(False, "connection reset")
    assert finished.args[0].state is RunState.FAILED and finished.args[0].resume_from == 1
    assert link.named(MoveToPoint) == []
    assert project.ledger.point(2).sync is SyncState.ON_CONTROLLER and set(project.upload_history) == {2}
    link.upload_summary(1, 2, "link lost")  # the worker's late summary: not the run's any more
    assert not runs.running and link.named(MoveToPoint) == []


def test_an_upload_the_worker_refuses_ends_the_run(
    qtbot: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    runs.run(project.plans[0])
    with qtbot.waitSignal(runs.runFinished) as finished:
        link.errorOccurred.emit(
            WorkerError("upload points", "jog is still under way", link.last_id(UploadPoints))
        )
    assert finished.args[0].state is RunState.FAILED and link.named(MoveToPoint) == []
    assert "jog is still under way" in runs.outcome_text(finished.args[0])


def test_a_stop_during_the_upload_ends_the_run_stopped(
    qtbot: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    runs.run(project.plans[0])
    runs.stop()
    assert runs.running  # until the worker ends the upload
    with qtbot.waitSignal(runs.runFinished) as finished:
        link.upload_summary(0, 1, "stopped")
    assert finished.args[0].state is RunState.STOPPED and finished.args[0].resume_from == 0
    assert link.named(MoveToPoint) == []


def test_a_stop_after_the_upload_ended_in_the_worker_sends_no_move(
    qtbot: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    runs.run(project.plans[0])
    link.point_ok(1)
    runs.stop()  # the upload's good summary is still on its way
    with qtbot.waitSignal(runs.runFinished) as finished:
        link.upload_summary(1, 1)
    assert finished.args[0].state is RunState.STOPPED and link.named(MoveToPoint) == []


def test_there_is_no_unguarded_run(link: FakeLink, project: Project) -> None:
    model = PointsModel(project, QUndoStack())
    runs = PlanRunController(points=model)  # as the planner panel builds its own: the link comes later
    runs.set_link(link)
    assert runs.points is model
    runs.run(project.plans[0])
    assert link.kinds() == [UploadPoints]  # the points first, never a bare move


def test_the_guard_speaks_chinese(
    qtbot: Any, translator: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    assert translator.set_language("zh_CN")
    runs.run(project.plans[0])
    link.point_ok(1)
    link.upload_summary(1, 1)
    _at(link, P2)
    with qtbot.waitSignal(runs.runFinished) as finished:
        link.finish_move()
    text = runs.outcome_text(finished.args[0])
    assert "机械臂停在 (430.00, 0.00, 300.00)，距 P1 (400.00, 0.00, 300.00) 30.00 mm" in text
    assert "在第 1 段失败" in text


def _link_leaves_connected(
    qtbot: Any, runs: PlanRunController, link: FakeLink, project: Project, link_state: LinkState
) -> str:
    """Segment 1's move is out when the link leaves CONNECTED: how the run's end reads."""
    runs.run(project.plans[0])
    link.point_ok(1)
    link.upload_summary(1, 1)
    assert link.named(MoveToPoint)
    with qtbot.waitSignal(runs.runFinished) as finished:
        link.state.set_connection(ConnectionState(link_state, "no answer", "fake:502"))
    outcome = finished.args[0]
    assert outcome.state is RunState.FAILED and outcome.resume_from == 0
    return runs.outcome_text(outcome)


@pytest.mark.parametrize(
    ("link_state", "sentence"),
    [
        (
            LinkState.NOT_ANSWERING,
            "The controller at fake:502 is not answering (the connection is still open): "
            "no further segment is sent. The arm may still finish its current move; "
            "check the robot before resuming.",
        ),
        (LinkState.DOWN, "Lost the connection to the controller at fake:502."),
    ],
)
def test_a_silent_controller_is_not_a_lost_link(
    qtbot: Any,
    runs: PlanRunController,
    link: FakeLink,
    project: Project,
    link_state: LinkState,
    sentence: str,
) -> None:
    text = _link_leaves_connected(qtbot, runs, link, project, link_state)
    assert text == f"Failed at segment 1: {sentence}"


def test_not_answering_speaks_chinese(
    qtbot: Any, translator: Any, runs: PlanRunController, link: FakeLink, project: Project
) -> None:
    assert translator.set_language("zh_CN")
    text = _link_leaves_connected(qtbot, runs, link, project, LinkState.NOT_ANSWERING)
    assert "在第 1 段失败" in text and "控制器 fake:502 无应答（连接仍然打开）：不再发送后续段。" in text
    assert "断开" not in text
