"""An operator's Stop ends a plan run as *stopped by the operator* where it stood ("Stopped by
the operator at segment 2, loop 1 of 20"), never as a red failure, whichever STOP it was (the
run's own, or the window's on the link); *Resume* names the loop. Against the real simulator:
the arm stands still at the simulator, in both languages (issue 21)."""

from __future__ import annotations

import math
from typing import Any

import pytest

from app.link.ops import Stop
from app.link.robot_link import RobotLink
from app.models import Pose
from app.plan.runner import RunOutcome, RunState
from app.plan.segments import Plan, Segment
from tests.ui.controllers.test_plan_run_guard import (  # noqa: F401 - fixtures
    POLL_TIMEOUT,
    RUN_TIMEOUT_MS,
    SPEED,
    Bench,
    sentinel_sim_fixture,
)
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    translator_fixture,
)
from tests.ui.test_messages import assert_chinese
from ui.controllers.plan_run_reasons import outcome_text
from ui.panels.planner_actions import PlannerActions

pytestmark = pytest.mark.timeout(120)


@pytest.fixture(name="bench")
def bench_fixture(qtbot: Any, sim: Any, link: RobotLink, make_client: Any) -> Bench:
    connect(qtbot, link, sim, poll_timeout=POLL_TIMEOUT)
    return Bench(qtbot, link, sim, make_client(sim).read_pose().xyzabc)


def _moved(link: RobotLink, start: Pose) -> bool:
    pose = link.state.pose
    return pose is not None and math.dist(pose.xyzabc[:3], start.xyzabc[:3]) > 0.5


def _stop_in_segment_2(bench: Bench, link: RobotLink, stop: Any) -> RunOutcome:
    """Run a 20-loop plan whose segment 2 is slow, press ``stop`` while it moves."""
    plan = Plan("slow", [Segment.line(1, SPEED), Segment.line(2, 5.0), Segment.line(3, SPEED)], loops=20)
    bench.upload_all()
    with bench.qtbot.waitSignal(
        bench.runs.segmentPrepared, check_params_cb=lambda i, _ids: i == 1, timeout=RUN_TIMEOUT_MS
    ):
        bench.runs.start(plan)
    start = link.state.pose
    assert start is not None
    bench.qtbot.waitUntil(lambda: _moved(link, start), timeout=SIGNAL_TIMEOUT_MS)
    with bench.qtbot.waitSignal(bench.runs.runFinished, timeout=RUN_TIMEOUT_MS) as finished:
        stop()
    outcome: RunOutcome = finished.args[0]
    bench.qtbot.waitUntil(lambda: not bench.sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    return outcome


@pytest.mark.parametrize("which", ["window", "run"])
def test_an_operator_stop_is_not_a_failure_in_both_languages(
    bench: Bench, link: RobotLink, translator: Any, which: str
) -> None:
    stop = (lambda: link.submit(Stop())) if which == "window" else bench.runs.stop
    outcome = _stop_in_segment_2(bench, link, stop)
    assert outcome.state is RunState.STOPPED, outcome.message
    assert (outcome.resume_from, outcome.resume_loop, outcome.loops) == (1, 1, 20)
    text = bench.runs.outcome_text(outcome)
    assert text == "Stopped by the operator at segment 2, loop 1 of 20", text
    assert translator.set_language("zh_CN")
    zh = bench.runs.outcome_text(outcome)
    assert_chinese(zh)
    assert "2" in zh and "20" in zh and "失败" not in zh, zh


def test_the_stop_reads_without_a_loop_for_a_single_loop_plan(qapp: Any) -> None:
    from ui.controllers.plan_run_reasons import stopped_by_operator

    once = RunOutcome(RunState.STOPPED, "", 1, 1, 1, loops=1)
    assert (
        outcome_text(once, stopped_by_operator(), by_operator=True) == "Stopped by the operator at segment 2"
    )
    endless = RunOutcome(RunState.STOPPED, "", 0, 7, 1, loops=0)
    assert (
        outcome_text(endless, stopped_by_operator(), by_operator=True)
        == "Stopped by the operator at segment 1, loop 7 (endless)"
    )


def test_resume_names_the_loop_in_both_languages(qtbot: Any, translator: Any) -> None:
    from PySide6.QtWidgets import QWidget

    owner = QWidget()
    qtbot.addWidget(owner)
    from ui.panels.planner_actions import SHORTCUTS

    actions = PlannerActions(owner, dict.fromkeys(SHORTCUTS, lambda: None))
    actions.retranslate()
    actions.set_resume_from(2, 2)
    assert actions["resume_from"].text() == "Resume from segment 2, loop 2"
    actions.set_resume_from(2)
    assert actions["resume_from"].text() == "Resume from segment 2"
    assert translator.set_language("zh_CN")
    actions.set_resume_from(2, 2)
    assert_chinese(actions["resume_from"].text())
