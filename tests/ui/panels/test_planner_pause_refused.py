"""A plan run's Pause the controller refused (issue 19, item 1): the run box tells the truth.

The gap: ``PlanRunController.pause()`` marked the run *paused* at the press; a Pause the controller
answered *busy* (Modbus exception 6) was never sent again, and the run box said "paused" while the
arm moved on. Now the run holds its next segment at once but is *pausing* until the controller
answered the Pause (sent again at every poll, app/link/halt.py), *paused* only after; the words
in both languages. The planner panel on a real RobotLink; asserted at the simulator: its program
state at every sentence the run box showed, and its write log (442).
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from typing import Any

import pytest
from pymodbus.constants import ExcCodes
from PySide6.QtGui import QUndoStack

from app import timing
from app.errors import Reason
from app.link.robot_link import RobotLink
from app.link.types import HaltKind, UnconfirmedHalt
from app.plan.runner import RunState
from app.plan.segments import Plan, Segment
from app.points.point import make_point
from app.points.project_model import Project
from app.protocol import registers
from app.protocol.enums import ProgramState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    translator_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.controllers.plan_run_controller import PauseState, PlanRunController
from ui.controllers.point_sync import PointSyncController
from ui.messages import reason_text
from ui.models.plan_model import PlanListModel
from ui.models.points_model import PointsModel
from ui.panels.jog_panel import JogPanel
from ui.panels.planner_panel import PlannerPanel

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

BUSY = ExcCodes.DEVICE_BUSY  # Modbus exception 6
BUSY_FOR = 1.0  # s the controller answers the Pause "busy"
PAUSED_WITHIN = 0.5  # s from the end of the refusals to the Pause taken (a poll is 20 ms)
SPEED = 15.0  # mm/s: a 60 mm segment of 4 s, under way through the whole busy second
RUN_TIMEOUT_MS = 20_000


@pytest.fixture(name="sim")
def sentinel_sim_fixture(sim_factory: Any) -> Any:
    return sim_factory(gv291="writable")  # each point's creation proven (the point guard)


@pytest.fixture
def planner(qtbot: Any, sim: Any, link: RobotLink, make_client: Any) -> Iterator[PlannerPanel]:
    connect(qtbot, link, sim, timeout=2.0, poll_timeout=1.0)
    x, y, z, a, b, c = make_client(sim).read_pose().xyzabc
    project = Project(plans=[Plan("one", [Segment.line(1, SPEED)])])
    project.ledger.replace_all([make_point(1, "a", (x + 60.0, y, z, a, b, c))])
    stack = QUndoStack()
    points = PointsModel(project, stack)
    panel = PlannerPanel(
        PlanListModel(project, stack),
        points,
        PlanRunController(link, points=points),
        PointSyncController(points, link),
        confirm=lambda _title, _text: True,
    )
    qtbot.addWidget(panel)
    panel.resize(1280, 700)
    yield panel
    if panel.run_controller.running:
        panel.run_controller.stop()


def test_a_refused_pause_is_pausing_until_the_controller_answers_then_paused(
    qtbot: Any, sim: Any, link: RobotLink, planner: PlannerPanel
) -> None:
    runs = planner.run_controller
    label = planner.run_box.run_label
    shown: list[tuple[str, int]] = []  # each sentence of the run box, and the simulator's program state then
    set_text = label.setText

    def record(text: str) -> None:
        shown.append((text, int(sim.state().program_state)))
        set_text(text)

    label.setText = record  # type: ignore[method-assign]
    start = sim.state().pose
    runs.start(planner.current_plan() or Plan("none", []))
    qtbot.waitUntil(lambda: math.dist(sim.state().pose[:3], start[:3]) > 3.0, timeout=RUN_TIMEOUT_MS)
    sim.set_exception(BUSY, range(registers.REG_PAUSE, registers.REG_PAUSE + 1), seconds=BUSY_FOR)
    busy_until = time.monotonic() + BUSY_FOR
    planner.planner_actions.all["pause"].trigger()
    qtbot.waitUntil(lambda: runs.pause_state is PauseState.UNCONFIRMED, timeout=SIGNAL_TIMEOUT_MS)
    assert sim.state().program_state == ProgramState.RUNNING  # refused: the arm moves on ...
    assert label.text().startswith("Pausing — the controller has not confirmed"), label.text()
    assert "Press STOP" in label.text()
    qtbot.waitUntil(lambda: runs.pause_state is PauseState.PAUSED, timeout=SIGNAL_TIMEOUT_MS)
    state = sim.state()
    assert state.program_state == ProgramState.PAUSED and state.paused  # ... and is paused now
    taken = sim.writes_to(registers.REG_PAUSE)
    assert taken and taken[0].t - busy_until < PAUSED_WITHIN  # sent again at the next poll
    assert not sim.writes_to(registers.REG_STOP)  # a busy second is not a Stop: resumable
    assert label.text().startswith("Paused (confirmed by the controller)"), label.text()
    # the run box never said "paused" while the simulator's program ran
    said_paused = [(text, st) for text, st in shown if text.startswith("Paused")]
    assert said_paused and all(st == ProgramState.PAUSED for _text, st in said_paused), shown
    assert any(text.startswith("Pausing…") for text, _st in shown), shown
    assert runs.running and runs.paused  # the next segment is held; Resume goes on
    runs.resume()
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    assert runs.pause_state is PauseState.NONE


def test_the_words_of_a_pause_not_confirmed_in_chinese(
    qtbot: Any, translator: Any, planner: PlannerPanel
) -> None:
    flow = planner.run_flow
    states = tuple(state for state in PauseState if state is not PauseState.NONE)
    english = [flow.pause_text(state) for state in states]
    assert english[states.index(PauseState.REFUSED)].startswith(
        "Pause refused by the controller: the arm was not paused. Press STOP"
    )
    jog = JogPanel()
    qtbot.addWidget(jog)
    jog.show_halt(UnconfirmedHalt(HaltKind.PAUSE, 0.0, False))
    assert jog.hold_label.text() == "Pausing — the controller has not confirmed; press STOP"
    reasons = [
        Reason("pause_unconfirmed", {"seconds": 0.1}),
        Reason("pause_escalated", {"seconds": 2.0}),
        Reason("pause_confirmed", {"seconds": 1.1}),
        Reason("pause_stopped", {"seconds": 2.0}),
        Reason("pause_nothing_running", {"seconds": 0.5}),
        Reason("pause_dropped", {"why": "superseded by Resume"}),
    ]
    assert all(reason_text(r) for r in reasons)
    assert translator.set_language("zh_CN")
    for state, before in zip(states, english, strict=True):
        text = flow.pause_text(state)
        assert text != before
        assert_chinese(text)
    jog.show_halt(UnconfirmedHalt(HaltKind.PAUSE, 0.0, True))
    assert_chinese(jog.hold_label.text())
    assert_chinese(jog.hold_label.toolTip())
    for reason in reasons:
        assert_chinese(reason_text(reason) or "")


def test_a_pause_not_confirmed_in_time_stops_the_run_and_never_says_paused(
    qtbot: Any, sim: Any, link: RobotLink, planner: PlannerPanel, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Busy past ``timing.PAUSE_ESCALATE_AFTER``: a Stop instead; the run ends stopped (resumable
    from the segment), and the run box said "pausing", then the Stop, never "paused"."""
    monkeypatch.setattr(timing, "PAUSE_ESCALATE_AFTER", 0.3)
    runs = planner.run_controller
    states: list[PauseState] = []
    runs.pauseStateChanged.connect(states.append)
    start = sim.state().pose
    runs.start(planner.current_plan() or Plan("none", []))
    qtbot.waitUntil(lambda: math.dist(sim.state().pose[:3], start[:3]) > 3.0, timeout=RUN_TIMEOUT_MS)
    sim.set_exception(BUSY, range(registers.REG_PAUSE, registers.REG_PAUSE + 1), seconds=BUSY_FOR)
    busy_until = time.monotonic() + BUSY_FOR
    with qtbot.waitSignal(runs.runFinished, timeout=RUN_TIMEOUT_MS) as finished:
        planner.planner_actions.all["pause"].trigger()
    outcome = finished.args[0]
    assert outcome.state is RunState.STOPPED and runs.can_resume, outcome
    stops = sim.writes_to(registers.REG_STOP)
    assert stops and stops[0].t < busy_until  # the Stop went out while the Pause was refused
    assert not sim.state().moving and not sim.writes_to(registers.REG_PAUSE)
    assert PauseState.STOPPING in states and PauseState.PAUSED not in states, states
    text = planner.run_box.run_label.text()  # the run says why it stopped, never "paused"
    assert text == (
        "Stopped at segment 1: the controller did not confirm the Pause in time: Stop was sent instead"
    ), text
