"""What the planner says between runs, in the window against the simulator (issue 21, "Words that
say what happened"): a new run clears the last run's green "Plan finished"; "Checks passed: ready to
run" is never shown during an emergency stop (the simulator's e-stop bit); the run refusal is one
sentence, not the summary line glued to it ("… — Upload now?. First: …"). Both languages."""

from __future__ import annotations

from typing import Any

import pytest

from app.plan.segments import Plan, Segment
from app.protocol.enums import Alarm
from app.protocol.registers import REG_RUN_COMMAND
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    app_settings_fixture,
    connection_settings,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    register_writes,
    step_by_link,
    teach_here,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.main_window import TAB_PLANNER, TAB_POINTS, MainWindow

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

STEP_MM = 20.0
RUN_TIMEOUT_MS = 20_000


def _two_points_and_a_plan(qtbot: Any, window: MainWindow, sim: Any) -> Plan:
    """P1, P2 taught 20 mm apart along X (the arm ends at P2); a plan P2 -> P1 -> P2."""
    settings = connection_settings(sim, poll_timeout=1.0)  # roomy: a loaded machine must not go silent
    with qtbot.waitSignal(
        window.link.state.connectionChanged, check_params_cb=lambda s: s.connected, timeout=SIGNAL_TIMEOUT_MS
    ):
        window.connect_with(settings)
    window.work_tabs.setCurrentIndex(TAB_POINTS)
    for _ in range(2):
        step_by_link(qtbot, window.link, STEP_MM)
        teach_here(qtbot, window.point_sync)
    plan = Plan("there and back", [Segment.line(1, 200.0), Segment.line(2, 200.0)])
    plans = window.project.plans_model
    row = plans.add_plan(plan)
    window.work_tabs.setCurrentIndex(TAB_PLANNER)
    window.planner_panel.select_plan(row)
    return plan


def test_a_new_run_clears_plan_finished(qtbot: Any, window: MainWindow, sim: Any) -> None:
    _two_points_and_a_plan(qtbot, window, sim)
    panel = window.planner_panel
    runs = window.run_controller
    with qtbot.waitSignal(runs.runFinished, timeout=RUN_TIMEOUT_MS) as finished:
        assert panel.run(0)
    assert finished.args[0].ok and panel.status.text() == "Plan finished"
    seen: list[str] = []
    runs.runningChanged.connect(lambda running: seen.append(panel.status.text()) if running else None)
    with qtbot.waitSignal(runs.runFinished, timeout=RUN_TIMEOUT_MS):
        assert panel.run(0)
    assert seen == [""]  # while the new run went on, the last one's "Plan finished" was gone


def test_no_ready_to_run_during_an_emergency_stop_in_both_languages(
    qtbot: Any, window: MainWindow, sim: Any, translator: Any
) -> None:
    _two_points_and_a_plan(qtbot, window, sim)
    panel = window.planner_panel
    panel.recheck()
    assert panel.summary_text == "Checks passed: ready to run"
    sim.set_alarm(Alarm.ESTOP, True)
    qtbot.waitUntil(lambda: window.motion.alarm_hold, timeout=SIGNAL_TIMEOUT_MS)
    held = panel.summary_text
    assert held.startswith("Checks passed; the plan cannot run until the emergency stop"), held
    panel.recheck()  # a re-check (pose, edits) during the e-stop says the same
    assert panel.summary_text == held
    window.set_language("zh_CN")
    panel.recheck()
    assert_chinese(panel.summary_text)
    assert "可以运行" not in panel.summary_text
    window.set_language("en")
    sim.set_alarm(Alarm.ESTOP, False)
    qtbot.waitUntil(lambda: not window.motion.alarm_hold, timeout=SIGNAL_TIMEOUT_MS)
    assert panel.summary_text == "Checks passed: ready to run"


def test_the_run_refusal_is_one_sentence_in_both_languages(qtbot: Any, window: MainWindow, sim: Any) -> None:
    plan = _two_points_and_a_plan(qtbot, window, sim)
    plan.segments.append(Segment.line(42, 200.0))  # P42 does not exist: an error
    plan.segments.append(Segment.line(43, 200.0))
    panel = window.planner_panel
    since = len(sim.writes)
    assert not panel.run(0)
    text = panel.status.text()
    assert text.startswith("Cannot run: the plan has 2 error(s); the first: "), text
    assert "P42" in text and "Upload now" not in text and "?." not in text and "\n" not in text
    window.set_language("zh_CN")
    assert not panel.run(0)
    assert_chinese(panel.status.text())
    assert not [index for index, _value in register_writes(sim, REG_RUN_COMMAND) if index >= since]
