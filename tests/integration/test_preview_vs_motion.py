"""What the host predicts (plan preview, checks) against what the controller then does.

The planner's preview (``app.plan.segments.plan_path``) and checks (``check_plan``) are what an operator
sees before pressing run; the simulator is the stand-in for the controller. For every kind of
segment the arm must move along the path the preview drew, and a resume that would move the
arm somewhere the operator did not plan must be flagged before it is sent.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from app.plan.checks import check_plan
from app.plan.geometry import plan_geometry, plan_path
from app.plan.runner import PlanRunner, RunState
from app.plan.segments import Plan, Segment
from tests.integration.support import (
    ARC_CENTRE,
    ARC_U,
    ARC_V,
    WAIT,
    MakeClient,
    arc_point,
    ledger_of,
    restore,
)

START, VIA, END = 11, 12, 13
PREVIEW_SAMPLES = 1000  # per segment: < 0.1 mm apart along the test arc
PATH_TOL_MM = 0.2


@pytest.mark.parametrize(
    "segment",
    [
        Segment.line(END, speed=200.0),
        Segment.arc(VIA, END, speed=200.0),
        Segment.arc(VIA, END, speed=200.0, orientation_changes=False),
        Segment.arc(VIA, END, speed=200.0, ignore_middle=True),
    ],
    ids=["line", "arc", "arc-orientation-kept", "arc-ignore-middle"],
)
def test_the_arm_moves_along_the_previewed_path(sim: Any, make_client: MakeClient, segment: Segment) -> None:
    client = make_client(sim)
    ledger = ledger_of({START: arc_point(0.0), VIA: arc_point(70.0), END: arc_point(140.0)})
    restore(client, ledger)
    plan = Plan("preview", [Segment.line(START, speed=500.0), segment])
    home = client.read_pose()
    preview = plan_path(plan, ledger, start=home, samples=PREVIEW_SAMPLES)
    drawn = preview.xyz[preview.segment == 1]
    planned_length = float(plan_geometry(plan, ledger, home).lengths[1])

    runner = PlanRunner(plan)
    while (cmd := runner.next_command()) is not None:
        result = cmd.send(client)
        moved = np.array([s.pose[:3] for s in sim.trajectory()])
        runner.on_result(result)
    assert runner.state is RunState.FINISHED, runner.message

    # every position the arm went through lies on the drawn path ...
    gaps = np.min(np.linalg.norm(moved[:, None, :] - drawn[None, :, :], axis=2), axis=1)
    worst = int(np.argmax(gaps))
    assert gaps[worst] < PATH_TOL_MM, (
        f"the arm passed {tuple(round(float(v), 2) for v in moved[worst])}, "
        f"{gaps[worst]:.2f} mm away from the path "
        f"the preview drew for {segment.text}{' (ignore middle)' if segment.ignore_middle else ''}"
    )
    # ... and it went all the way along it
    travelled = float(np.linalg.norm(np.diff(moved, axis=0), axis=1).sum())
    assert travelled == pytest.approx(planned_length, rel=0.01), (
        f"the arm travelled {travelled:.1f} mm, the planner said {planned_length:.1f} mm"
    )


def test_resuming_an_arc_stopped_past_its_middle_point_is_flagged(sim: Any, make_client: MakeClient) -> None:
    """Stopped after the middle point, the interrupted arc re-sent from where the arm stands
    goes through the middle point again: the long way round the circle (hundreds of mm to
    close a gap of a few). The checks a resume runs (``check_plan`` from the current pose at
    ``start_index=resume_from``) must say so before anything moves."""
    client = make_client(sim)
    ledger = ledger_of({START: arc_point(0.0), VIA: arc_point(70.0), END: arc_point(140.0)})
    restore(client, ledger)
    plan = Plan("arc", [Segment.line(START, speed=500.0), Segment.arc(VIA, END, speed=100.0)])
    runner = PlanRunner(plan)
    cmd = runner.next_command()
    assert cmd is not None
    runner.on_result(cmd.send(client))
    cmd = runner.next_command()
    assert cmd is not None and cmd.index == 1
    cmd.send(client, wait=False)
    tracker = client.last_tracker
    assert tracker is not None

    def past_the_middle(s: Any) -> bool:
        assert client.poll(tracker) is None, "the arc ended before the test could stop it"
        rel = np.array(s.pose[:3]) - ARC_CENTRE
        return math.degrees(math.atan2(float(rel @ ARC_V), float(rel @ ARC_U))) > 110.0

    assert sim.wait_for(past_the_middle, WAIT)
    client.stop()
    runner.on_stopped()
    assert sim.wait_for(lambda s: not s.moving, WAIT)
    assert runner.resume_from == 1
    here = client.read_pose()

    gap = math.dist(here.xyzabc[:3], arc_point(140.0)[:3])
    resumed = plan_geometry(plan.segments[1:], ledger, here)
    sweep = math.degrees(float(resumed.arcs.sweep[0]))
    assert gap < 25.0 and sweep > 300.0  # the hazard itself: ~330 degrees to close a short gap
    issues = [i for i in check_plan(plan, ledger, current_pose=here, start_index=1) if i.segment == 1]
    assert issues, (
        f"resuming segment 2 would sweep {sweep:.0f} degrees of the circle "
        f"({float(resumed.lengths[0]):.0f} mm) to reach an end {gap:.1f} mm away, "
        "and check_plan reports nothing"
    )
