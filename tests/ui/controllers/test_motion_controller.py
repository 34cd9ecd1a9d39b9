"""MotionController with the typed fake link and the real panels: intents become requests, the
gate follows ``link.state`` and plan runs, a jog ends when the link leaves CONNECTED."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoStack
from PySide6.QtWidgets import QWidget

from app.link.ops import GoZero, JogPress, JogRelease, Pause, Resume, SetMode, Stop
from app.link.types import ConnectionState, LinkState
from app.points.project_model import Project
from app.protocol.enums import TeachFrame, WorkMode
from tests.ui.fake_link import FakeLink
from ui.controllers.motion import MotionController
from ui.controllers.plan_run_controller import PlanRunController
from ui.models.points_model import PointsModel
from ui.panels.control_bar import ControlBar
from ui.panels.jog_panel import JogPanel
from ui.panels.program_panel import ProgramPanel, ZeroRequest
from ui.panels.step_panel import StepPanel


class Rig:
    def __init__(self, qtbot: Any, link: FakeLink) -> None:
        self.host = QWidget()
        qtbot.addWidget(self.host)
        self.link = link
        self.bar = ControlBar(self.host)
        self.jog = JogPanel(self.host)
        self.step = StepPanel(self.host)
        self.program = ProgramPanel(self.host)
        self.runs = PlanRunController(link, points=PointsModel(Project(), QUndoStack()))
        self.motion = MotionController(link, self.bar, self.jog, self.step, self.program, self.runs)

    def panels_enabled(self) -> bool:
        return (
            self.jog.axes_box.isEnabled()
            and self.step.move_button.isEnabled()
            and self.program.run_button.isEnabled()
        )


@pytest.fixture
def rig(qtbot: Any) -> Rig:
    return Rig(qtbot, FakeLink(connected=False))


def test_the_gate_follows_the_link_state(rig: Rig) -> None:
    changes: list[bool] = []
    rig.motion.motionEnabledChanged.connect(changes.append)
    assert not rig.motion.motion_enabled and not rig.panels_enabled()
    rig.link.set_connected(True)
    assert rig.motion.motion_enabled and rig.panels_enabled() and rig.bar.pause_button.isEnabled()
    rig.link.set_connected(True, monitor_only=True)
    assert not rig.motion.motion_enabled and not rig.panels_enabled()
    assert rig.bar.stop_button.isEnabled()  # Stop stays reachable
    rig.link.state.set_connection(ConnectionState(LinkState.NOT_ANSWERING, "silent"))
    assert not rig.motion.motion_enabled
    assert changes == [True, False]


def test_a_plan_run_holds_the_panels_but_not_pause(rig: Rig) -> None:
    rig.link.set_connected(True)
    rig.runs.runningChanged.emit(True)
    assert not rig.panels_enabled() and rig.bar.pause_button.isEnabled() and rig.motion.run_active
    rig.runs.runningChanged.emit(False)
    assert rig.panels_enabled()


def test_a_held_jog_ends_when_the_link_stops_answering(qtbot: Any, rig: Rig) -> None:
    rig.link.set_connected(True)
    rig.host.show()
    qtbot.mousePress(rig.jog.button(0, 1), Qt.MouseButton.LeftButton)
    presses = [op.request for op in rig.link.named(JogPress)]
    assert [(r.frame, r.axis, r.direction) for r in presses] == [(TeachFrame(rig.jog.frame), 0, 1)]
    rig.link.state.set_connection(ConnectionState(LinkState.NOT_ANSWERING, "silent"))
    assert len(rig.link.named(JogRelease)) == 1  # the dead-man, before anything else
    qtbot.mouseRelease(rig.jog.button(0, 1), Qt.MouseButton.LeftButton)
    assert len(rig.link.named(JogRelease)) == 1


def test_intents_become_requests(rig: Rig) -> None:
    rig.link.set_connected(True)
    rig.bar.stopRequested.emit()
    rig.bar.pauseRequested.emit()
    rig.bar.resumeRequested.emit()
    rig.bar.modeRequested.emit(WorkMode.MANUAL)
    rig.program.goZeroRequested.emit(ZeroRequest(2))
    rig.program.goZeroRequested.emit(ZeroRequest(None, switch_to_auto=True))  # the operator said yes to it
    assert rig.link.kinds() == [Stop, Pause, Resume, SetMode, GoZero, GoZero]
    assert rig.link.named(SetMode) == [SetMode(WorkMode.MANUAL)]
    assert rig.link.named(GoZero) == [GoZero(2, switch_to_auto=False), GoZero(None, switch_to_auto=True)]


def test_the_windows_resume_goes_through_a_run_paused_by_another_master(
    rig: Rig, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A run that paused itself at a sign of another master is not resumed past the move hold by
    the window's Resume (issue 19): the control bar's Resume goes through the run, which refuses it
    while the hold lasts; its Pause pauses the run (which then holds its next move)."""
    from app import timing
    from app.plan.segments import Plan, Segment
    from app.points.point import make_point

    monkeypatch.setattr(timing, "FOREIGN_MOVE_HOLD", 60.0)
    rig.link.set_connected(True)
    project = Project(plans=[Plan("one", [Segment.line(1, 50.0)])])
    project.ledger.replace_all([make_point(1, "a", (400.0, 0.0, 300.0, 180.0, 0.0, 0.0))])
    runs = PlanRunController(rig.link, points=PointsModel(project, QUndoStack()))
    bar = ControlBar(rig.host)
    motion = MotionController(rig.link, bar, rig.jog, None, None, runs)
    assert not motion.run_active  # (made before the run)
    runs.start(project.plans[0])
    assert runs.running and not runs.paused and motion.run_active
    refused: list[str] = []
    runs.resumeRefused.connect(refused.append)
    rig.link.foreignMaster.emit("registers", 409.0)
    assert runs.paused and len(rig.link.named(Pause)) == 1
    bar.resumeRequested.emit()
    assert rig.link.named(Resume) == [] and runs.paused and len(refused) == 1
    monkeypatch.setattr(timing, "FOREIGN_MOVE_HOLD", 0.0)
    bar.resumeRequested.emit()
    assert len(rig.link.named(Resume)) == 1 and not runs.paused
    bar.pauseRequested.emit()
    assert runs.paused and len(rig.link.named(Pause)) == 2
