"""The Step and Program motion tabs are built when first shown (ui/window_column.py, LazyTab), and
are held from the moment they exist: a tab built during an emergency stop, without a link or
while a plan runs shows its motion controls disabled, and an intent that still arrives writes
nothing at the simulator. Changing to a tab being built still ends a held jog (the dead-man)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoStack
from PySide6.QtWidgets import QWidget

from app.link.types import StepFrame
from app.points.project_model import Project
from app.protocol import registers
from app.protocol.enums import Alarm, ProgramMotionMode
from tests.ui.fake_link import FakeLink
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    project_dialogs_fixture,
    ratio_writes,
    translator_fixture,
    window_fixture,
)
from ui.controllers.motion import MotionController
from ui.controllers.plan_run_controller import PlanRunController
from ui.main_window import MainWindow
from ui.models.points_model import PointsModel
from ui.panels.control_bar import ControlBar
from ui.panels.jog_panel import JogPanel
from ui.panels.program_panel import ProgramPanel, ProgramRequest
from ui.panels.step_panel import StepPanel, StepRequest

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

TAB_JOG, TAB_STEP, TAB_PROGRAM = range(3)
ONE_MM = StepRequest(StepFrame.BASE, (1.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0.0,) * 5, 10.0)


def _live(qtbot: Any, window: MainWindow, sim: Any) -> None:
    connect(qtbot, window.link, sim, poll_timeout=1.0)  # roomy: a loaded machine must not go silent
    qtbot.waitUntil(window.pose_strip.is_live, timeout=SIGNAL_TIMEOUT_MS)


def _step_held(panel: StepPanel) -> bool:
    return not panel.move_button.isEnabled() and not panel.axes_box.isEnabled()


def _program_held(panel: ProgramPanel) -> bool:
    return not panel.run_button.isEnabled() and not panel.zero_button.isEnabled()


def test_the_motion_tabs_are_not_built_with_the_window(window: MainWindow) -> None:
    assert not window.step_tab.built and not window.program_tab.built
    assert window.tabs.count() == 3 and window.tabs.tabText(TAB_STEP) == "Step"
    assert window.tabs.tabText(TAB_PROGRAM) == "Program"


def test_tabs_built_during_an_emergency_stop_are_held_and_write_nothing(
    qtbot: Any, sim: Any, window: MainWindow
) -> None:
    _live(qtbot, window, sim)
    sim.set_alarm(Alarm.ESTOP, True)
    qtbot.waitUntil(lambda: window.motion.alarm_hold, timeout=SIGNAL_TIMEOUT_MS)
    assert not window.step_tab.built and not window.program_tab.built
    window.tabs.setCurrentIndex(TAB_STEP)  # the operator opens Step: it is built now
    assert window.step_tab.built and window.tabs.currentWidget() is window.step_panel
    assert window.tabs.tabText(TAB_STEP) == "Step"
    assert _step_held(window.step_panel)
    window.tabs.setCurrentIndex(TAB_PROGRAM)
    assert window.program_tab.built and _program_held(window.program_panel)
    # intents that arrive anyway are dropped: the Stop behind them is the only write
    before = len(sim.writes)
    stops = len(sim.writes_to(registers.REG_STOP))
    window.step_panel.stepRequested.emit(ONE_MM)
    window.program_panel.programRequested.emit(ProgramRequest(2, ProgramMotionMode.SINGLE_RUN, 1, 50))
    window.program_panel.goZeroRequested.emit(None)
    qtbot.mouseClick(window.control_bar.stop_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: len(sim.writes_to(registers.REG_STOP)) > stops, timeout=SIGNAL_TIMEOUT_MS)
    after = list(sim.writes)[before:]
    assert after and all(w.address <= registers.REG_STOP < w.address + len(w.values) for w in after)
    sim.set_alarm(Alarm.ESTOP, False)
    qtbot.waitUntil(lambda: window.program_panel.run_button.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    assert window.step_panel.move_button.isEnabled() and window.program_panel.zero_button.isEnabled()


def test_tabs_built_without_a_link_are_held_until_it_is_up(qtbot: Any, sim: Any, window: MainWindow) -> None:
    assert _step_held(window.step_panel) and _program_held(window.program_panel)  # asked for: built
    _live(qtbot, window, sim)
    assert window.step_panel.move_button.isEnabled() and window.program_panel.run_button.isEnabled()


def test_changing_to_a_tab_being_built_ends_a_held_jog_at_the_simulator(
    qtbot: Any, sim: Any, window: MainWindow
) -> None:
    _live(qtbot, window, sim)
    qtbot.waitUntil(lambda: window.jog_panel.axes_box.isEnabled(), timeout=SIGNAL_TIMEOUT_MS)
    button = window.jog_panel.button(0, 1)
    x0 = sim.state().pose[0]
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: jogging(sim) and abs(sim.state().pose[0] - x0) > 1.0, timeout=SIGNAL_TIMEOUT_MS)
    assert not window.step_tab.built
    jogging_at_build: list[bool] = []
    window.step_tab.on_built(lambda _panel: jogging_at_build.append(window.jog_panel.is_jogging))
    window.tabs.setCurrentIndex(TAB_STEP)  # first show: the jog is let go, then the tab is built
    assert jogging_at_build == [False]  # the release did not wait for the build
    assert window.step_tab.built and not window.jog_panel.is_jogging
    let_go = lambda: not sim.state().jogging and ratio_writes(sim)[-1] == 0.0  # noqa: E731
    qtbot.waitUntil(let_go, timeout=SIGNAL_TIMEOUT_MS)
    qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)  # the release behind it starts nothing
    assert not sim.state().jogging


def test_a_panel_attached_during_a_plan_run_is_held(qtbot: Any) -> None:
    host = QWidget()
    qtbot.addWidget(host)
    link = FakeLink(connected=True)
    runs = PlanRunController(link, points=PointsModel(Project(), QUndoStack()))
    motion = MotionController(link, ControlBar(host), JogPanel(host), None, None, runs)
    runs.runningChanged.emit(True)
    step, program = StepPanel(host), ProgramPanel(host)
    motion.add_step_panel(step)
    motion.add_program_panel(program)
    assert _step_held(step) and _program_held(program)
    runs.runningChanged.emit(False)
    assert step.move_button.isEnabled() and program.run_button.isEnabled()
    with pytest.raises(RuntimeError, match="already attached"):
        motion.add_step_panel(StepPanel(host))
