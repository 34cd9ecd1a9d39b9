"""One poll reaches the GUI thread as one delivery (the worker's ``polled``), and RobotLink
replays it in the order of the separate signals it replaced: each datum into RobotState first,
then the link's own signal (the pose has none: ``RobotState.poseChanged`` is its one signal), the
good poll after them, and the command a poll completed after that poll's pose (issue 8's race)."""

from __future__ import annotations

from typing import Any

from app.link.ops import Step
from app.link.robot_link import RobotLink
from app.link.types import StepFrame
from app.models import CommandResult
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)


def test_a_poll_is_replayed_in_the_old_order(qtbot: Any, sim: Any, link: RobotLink) -> None:
    state = link.state
    seen: list[tuple[str, Any]] = []
    model_first: list[bool] = []
    state.poseChanged.connect(lambda p: seen.append(("state.pose", p)))
    state.statusChanged.connect(lambda s: seen.append(("state.status", s)))
    state.alarmsChanged.connect(lambda a: seen.append(("state.alarms", a)))

    def on_link(name: str, value: Any, current: Any) -> None:
        seen.append((name, value))
        model_first.append(current == value)

    link.statusChanged.connect(lambda s: on_link("link.status", s, state.status))
    link.alarmsChanged.connect(lambda a: seen.append(("link.alarms", a)))
    link.commandFinished.connect(lambda r: seen.append(("link.result", r)))
    connect(qtbot, link, sim)  # after the wiring: the first poll (alarms None -> 0) is always seen

    pending = link.track(link.submit(Step(StepFrame.JOINT, [2.0, 0, 0, 0, 0, 0], speed=20.0)))
    qtbot.waitUntil(lambda: pending.result is not None, timeout=SIGNAL_TIMEOUT_MS * 3)
    assert pending.result is not None and pending.result.ok

    assert model_first and all(model_first)  # a view of the link's signal reads the new value
    names = [name for name, _ in seen]
    for i, name in enumerate(names):
        if name == "state.status":  # the link's own signal right after the model's
            after = names[i + 1 :]
            while after and after[0] == "state.alarms":  # the model's alarms follow (None -> 0 first)
                after = after[1:]
            assert after and after[0] == name.replace("state.", "link."), names[i : i + 4]
    done = next(
        i for i, (name, value) in enumerate(seen) if name == "link.result" and value is pending.result
    )
    assert isinstance(seen[done][1], CommandResult)
    last_pose = next(value for name, value in reversed(seen[:done]) if name == "state.pose")
    final = sim.state().joints[0]  # the step ended there: its pose was delivered before its result
    assert last_pose.joints is not None and abs(last_pose.joints[0] - final) < 1e-3
    assert state.fresh


def test_the_pose_has_one_signal_the_link_state_s() -> None:
    """Views connect to ``RobotState.poseChanged`` (the link's one picture of the robot): neither the
    link nor the plan run controller forwards the pose on a signal of its own (issue 22)."""
    from app.link.state import RobotState
    from ui.controllers.plan_run_controller import PlanRunController

    assert hasattr(RobotState, "poseChanged")
    assert not hasattr(RobotLink, "poseChanged") and not hasattr(PlanRunController, "poseChanged")
