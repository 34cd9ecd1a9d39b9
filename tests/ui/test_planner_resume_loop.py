"""*Resume* names the loop, in the window against the simulator (issue 21, "Words that say what
happened"): a 3-loop plan stopped by the operator in segment 2 of loop 2 reads "Stopped by the
operator at segment 2, loop 2 of 3" (not a red failure), the button reads "Resume from segment 2,
loop 2" in both languages, and pressing it moves the arm again at the simulator from segment 2 of
loop 2 (not from loop 1)."""

from __future__ import annotations

from typing import Any

import pytest

from app.plan.runner import RunEvent, RunProgress, RunState
from app.plan.segments import Plan, Segment
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connection_settings,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    step_by_link,
    teach_here,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.main_window import TAB_PLANNER, TAB_POINTS, MainWindow

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

RUN_TIMEOUT_MS = 30_000
SLOW = 10.0  # mm/s: segment 2 (20 mm) takes 2 s, time to press Stop in it


def _started(loop: int, index: int) -> Any:
    def check(progress: RunProgress) -> bool:
        return progress.event is RunEvent.SEGMENT_STARTED and (progress.loop, progress.index) == (loop, index)

    return check


def test_resume_names_the_loop_and_resumes_it(
    qtbot: Any, window: MainWindow, sim: Any, translator: Any
) -> None:
    settings = connection_settings(sim, poll_timeout=1.0)
    with qtbot.waitSignal(
        window.link.state.connectionChanged, check_params_cb=lambda s: s.connected, timeout=SIGNAL_TIMEOUT_MS
    ):
        window.connect_with(settings)
    window.work_tabs.setCurrentIndex(TAB_POINTS)
    for _ in range(2):  # P1, P2 taught 20 mm apart along X
        step_by_link(qtbot, window.link, 20.0)
        teach_here(qtbot, window.point_sync)
    plan = Plan("three loops", [Segment.line(1, 200.0), Segment.line(2, SLOW)], loops=3)
    row = window.project.plans_model.add_plan(plan)
    window.work_tabs.setCurrentIndex(TAB_PLANNER)
    panel, runs = window.planner_panel, window.run_controller
    panel.select_plan(row)
    with qtbot.waitSignal(runs.progressChanged, check_params_cb=_started(2, 1), timeout=RUN_TIMEOUT_MS):
        assert panel.run(0)
    qtbot.waitUntil(lambda: sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(runs.runFinished, timeout=RUN_TIMEOUT_MS) as finished:
        panel.stop()
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    outcome = finished.args[0]
    assert outcome.state is RunState.STOPPED and (outcome.resume_from, outcome.resume_loop) == (1, 2)
    assert panel.status.text() == "Stopped by the operator at segment 2, loop 2 of 3"
    assert panel.resume_from_button.isVisible()
    assert panel.resume_from_button.text() == "Resume from segment 2, loop 2"
    window.set_language("zh_CN")
    assert_chinese(panel.resume_from_button.text())
    assert "2" in panel.resume_from_button.text()
    window.set_language("en")
    assert panel.resume_from_button.text() == "Resume from segment 2, loop 2"

    # Resume: the arm moves again at the simulator, from segment 2 of loop 2, with the planner's
    # preview on screen (a second run with it shown crashed the process before W's fix this stop)
    stopped_at = sim.robot.pose[:3]
    seen: list[RunProgress] = []
    runs.progressChanged.connect(seen.append)
    with qtbot.waitSignal(runs.progressChanged, check_params_cb=_started(2, 1), timeout=RUN_TIMEOUT_MS):
        panel.resume_from()
    # moved, not only "moving": on a loaded machine a Stop right after the start left it within 0.05 mm
    qtbot.waitUntil(
        lambda: tuple(sim.robot.pose[:3]) != pytest.approx(tuple(stopped_at), abs=0.5),
        timeout=SIGNAL_TIMEOUT_MS,
    )
    starts = [(p.loop, p.index) for p in seen if p.event is RunEvent.SEGMENT_STARTED]
    assert starts[0] == (2, 1), starts
    assert window.work_tabs.currentIndex() == TAB_PLANNER and panel.isVisible()
    with qtbot.waitSignal(runs.runFinished, timeout=RUN_TIMEOUT_MS):
        panel.stop()
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
