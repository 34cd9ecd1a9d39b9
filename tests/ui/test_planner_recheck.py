"""The planner's checks and estimates follow the robot (issue 21, "Words that say what happened"):
a check made from the current pose ("the line goes nowhere ... from the current pose") is made again
when the arm moves, and the estimates refresh when the pose or the connection changes (the link
down: segment 1 from an assumed start, the end of the plan). In the window against the simulator;
the arm is moved by another Modbus client (as the hand pendant would), its pose read back at the
simulator. Both languages."""

from __future__ import annotations

from typing import Any

import pytest

from app.link.types import StepFrame
from app.plan.checks import IssueCode
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
from ui.messages_plan import issue_line
from ui.models.plan_columns import COL_LENGTH

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

STEP_MM = 20.0


def _connect(qtbot: Any, window: MainWindow, sim: Any) -> None:
    settings = connection_settings(sim, poll_timeout=1.0)  # roomy: a loaded machine must not go silent
    with qtbot.waitSignal(
        window.link.state.connectionChanged, check_params_cb=lambda s: s.connected, timeout=SIGNAL_TIMEOUT_MS
    ):
        window.connect_with(settings)


def _length(window: MainWindow, row: int) -> str:
    segments = window.planner_panel.segments
    return str(segments.data(segments.index(row, COL_LENGTH)))


def _goes_nowhere(window: MainWindow) -> list[Any]:
    return [i for i in window.planner_panel.checks.issues if i.code is IssueCode.ZERO_LENGTH]


def test_checks_and_estimates_follow_the_pose_and_the_connection(
    qtbot: Any, window: MainWindow, sim: Any, make_client: Any, translator: Any
) -> None:
    _connect(qtbot, window, sim)
    window.work_tabs.setCurrentIndex(TAB_POINTS)
    stepper = make_client(sim)
    for _ in range(2):  # P1, P2 taught 20 mm apart along X; the arm ends at P2
        step_by_link(qtbot, window.link, STEP_MM)
        teach_here(qtbot, window.point_sync)
    x_p2 = sim.robot.pose[0]
    plan = Plan("to P2 and back", [Segment.line(2, 200.0), Segment.line(1, 200.0)])
    window.project.plans_model.add_plan(plan)
    window.work_tabs.setCurrentIndex(TAB_PLANNER)
    panel = window.planner_panel
    panel.select_plan(window.project.plans_model.rowCount() - 1)
    qtbot.waitUntil(lambda: len(_goes_nowhere(window)) == 1, timeout=SIGNAL_TIMEOUT_MS)
    (stale,) = _goes_nowhere(window)
    assert "from the current pose" in issue_line(stale) and _length(window, 0) == "0.0 mm"
    window.set_language("zh_CN")
    assert_chinese(issue_line(stale))
    window.set_language("en")

    # The arm moves 30 mm back (another master, at the simulator): segment 1 goes somewhere now.
    assert stepper.step(StepFrame.BASE, (-30.0, 0, 0, 0, 0, 0), speed=200.0).ok
    assert sim.robot.pose[0] == pytest.approx(x_p2 - 30.0, abs=0.01)
    qtbot.waitUntil(lambda: not _goes_nowhere(window), timeout=SIGNAL_TIMEOUT_MS)
    qtbot.waitUntil(lambda: _length(window, 0) == "30.0 mm", timeout=SIGNAL_TIMEOUT_MS)
    assert "segment 1" not in panel.summary_text
    window.set_language("zh_CN")
    assert_chinese(panel.summary_text)
    window.set_language("en")

    # The link down: the pose is not known, segment 1 starts at the plan's end (P1, 20 mm from P2).
    window.link.disconnect()
    qtbot.waitUntil(lambda: _length(window, 0) == "20.0 mm", timeout=SIGNAL_TIMEOUT_MS)
    # Connected again: from the robot's pose once more.
    _connect(qtbot, window, sim)
    qtbot.waitUntil(lambda: _length(window, 0) == "30.0 mm", timeout=SIGNAL_TIMEOUT_MS)


def test_a_moving_arm_rechecks_a_few_times_a_second_not_at_the_poll_rate(
    qtbot: Any, window: MainWindow, sim: Any, make_client: Any
) -> None:
    """Poses come at the poll rate (50 Hz): the re-checks are coalesced; a hidden planner does not
    re-check at all and catches up once when shown."""
    _connect(qtbot, window, sim)
    window.project.plans_model.add_plan(Plan("one", [Segment.line(1, 200.0)]))
    panel = window.planner_panel
    panel.select_plan(window.project.plans_model.rowCount() - 1)
    window.work_tabs.setCurrentIndex(TAB_POINTS)
    calls: list[int] = []
    real = panel.checks.recheck

    def counted(plan: Any, selected: int | None) -> None:
        calls.append(1)
        real(plan, selected)

    panel.checks.recheck = counted  # type: ignore[method-assign]
    poses: list[Any] = []
    window.link.state.poseChanged.connect(poses.append)
    stepper = make_client(sim)
    x0 = sim.robot.pose[0]
    assert stepper.step(StepFrame.BASE, (STEP_MM, 0, 0, 0, 0, 0), speed=200.0).ok
    qtbot.waitUntil(
        lambda: bool(poses) and abs(poses[-1].x - (x0 + STEP_MM)) < 0.01, timeout=SIGNAL_TIMEOUT_MS
    )
    assert calls == []  # the planner is hidden
    window.work_tabs.setCurrentIndex(TAB_PLANNER)
    assert calls == [1]  # shown: checked from where the arm is now
    poses.clear()
    for _ in range(5):
        assert stepper.step(StepFrame.BASE, (STEP_MM, 0, 0, 0, 0, 0), speed=200.0).ok
    qtbot.waitUntil(lambda: len(calls) >= 2, timeout=SIGNAL_TIMEOUT_MS)
    assert len(calls) - 1 <= len(poses) // 3 + 2, (len(calls), len(poses))
