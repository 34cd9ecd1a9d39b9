"""A plan run pauses itself at a sign of another Modbus master and says why (issue 19 section 2,
"a run pauses and says why"): the arm is held as the operator's Pause would hold it, no further
move goes out, the run says "Paused: another master wrote to the controller (...)" (and audits
it); Resume is refused while the hold lasts, then the run continues from where it was.

PlanRunController on a real RobotLink; another master is a second client writing a parameter
register of its own mid-move. Asserted at the simulator: its program state (paused), its pose, its
write log (440: 0xE0 create point, 0x42 move to point)."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtGui import QUndoStack

from app import timing
from app.link.robot_link import RobotLink
from app.plan.runner import RunState
from app.plan.segments import Plan, Segment
from app.points.point import make_point
from app.points.project_model import Project
from app.protocol.enums import ProgramState, RunCommand
from app.protocol.registers import REG_RUN_COMMAND
from app.safety.audit import AuditLog
from app.safety.audit_read import query
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    register_writes,
)
from tests.waits import join
from ui.controllers.plan_run_controller import PlanRunController
from ui.controllers.plan_run_reasons import foreign_pause_text
from ui.models.points_model import PointsModel

pytestmark = pytest.mark.timeout(120)

SPEED = 30.0  # mm/s: 30 mm moves of 1 s (the other master writes during the first)
HOLD = 1.0  # s: FOREIGN_MOVE_HOLD here
RUN_TIMEOUT_MS = 30_000
CREATE, MOVE = int(RunCommand.CREATE_POINT), int(RunCommand.MOVE_TO_POINT)


@pytest.fixture(name="sim")
def sentinel_sim_fixture(sim_factory: Any) -> Any:
    return sim_factory(gv291="writable")  # each point's creation proven (./test_plan_run_guard.py)


@pytest.fixture
def hold(monkeypatch: pytest.MonkeyPatch) -> float:
    monkeypatch.setattr(timing, "FOREIGN_MOVE_HOLD", HOLD)  # the product's is 5 s; conftest sets 0
    monkeypatch.setattr(timing, "CLOCK_POLL_PERIOD", 0.05)  # the shared registers read often
    return HOLD


class OtherMaster:
    """A second client that writes GV204 (its own step offset) once the arm is on its way."""

    def __init__(self, sim: Any, make_client: Any) -> None:
        self.sim = sim
        self.client = make_client(sim)
        self.wrote_at: int | None = None  # index in sim.writes of its write
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, daemon=True)

    def arm(self) -> None:
        self._start = self.sim.state().pose
        self._thread.start()

    def _watch(self) -> None:
        while not self._stop.wait(0.005):
            if math.dist(self.sim.state().pose[:3], self._start[:3]) > 3.0:
                self.client.write_gv(204, [15.0])
                self.wrote_at = len(self.sim.writes) - 1
                return

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive() or self._thread.ident is not None:
            join(self._thread, "another master")


@pytest.fixture
def other(sim: Any, make_client: Any) -> Iterator[OtherMaster]:
    master = OtherMaster(sim, make_client)
    yield master
    master.close()


def _bench(link: RobotLink, start: tuple[float, ...]) -> tuple[Project, PlanRunController]:
    x, y, z, a, b, c = start
    project = Project(
        plans=[Plan("square", [Segment.line(1, SPEED), Segment.line(2, SPEED), Segment.line(3, SPEED)])]
    )
    project.ledger.replace_all(
        [
            make_point(1, "a", (x + 30, y, z, a, b, c)),
            make_point(2, "b", (x + 30, y + 30, z, a, b, c)),
            make_point(3, "c", (x, y + 30, z, a, b, c)),
        ]
    )
    model = PointsModel(project, QUndoStack())
    return project, PlanRunController(link, points=model)


def _near(pose: tuple[float, ...], target: tuple[float, ...]) -> bool:
    return math.dist(pose[:3], target[:3]) <= 0.01


def test_a_run_pauses_at_another_masters_write_and_continues_after_the_hold(
    qtbot: Any,
    sim: Any,
    link: RobotLink,
    make_client: Any,
    other: OtherMaster,
    hold: float,
    tmp_path: Path,
) -> None:
    connect(qtbot, link, sim, poll_timeout=1.0)
    project, runs = _bench(link, make_client(sim).read_pose().xyzabc)
    runs.audit = AuditLog(tmp_path)
    said: list[str] = []
    runs.pausedByForeign.connect(lambda what, value: said.append(foreign_pause_text(what, value)))
    refused: list[str] = []
    runs.resumeRefused.connect(refused.append)
    since = len(sim.writes)
    other.arm()
    finished: list[Any] = []
    runs.runFinished.connect(finished.append)
    runs.run(project.plans[0])

    # the sign: the run pauses itself, the arm is held mid-segment 1 (as the operator's Pause)
    qtbot.waitUntil(lambda: runs.paused and bool(said), timeout=SIGNAL_TIMEOUT_MS)
    assert sim.wait_for(lambda s: s.program_state == ProgramState.PAUSED, 5.0)
    held_at = sim.state().pose
    paused_at = time.monotonic()
    assert said[0].startswith("Paused: another master wrote to the controller (register ")
    assert runs.running and not finished
    records = [r for r in query(tmp_path) if r.command == "plan run paused"]
    assert len(records) == 1 and "another master" in records[0].detail

    # Resume at once: refused while the hold lasts, in words; the arm stays held
    runs.resume()
    assert runs.paused and refused and "another master" in refused[0]
    assert sim.state().program_state == ProgramState.PAUSED
    # nothing moved and no move went out after the other master's write
    assert other.wrote_at is not None
    assert sim.state().pose == held_at
    assert [v for i, v in register_writes(sim, REG_RUN_COMMAND) if i > other.wrote_at] == []

    # after the hold: Resume continues the run to its end
    qtbot.waitUntil(lambda: time.monotonic() - paused_at > hold, timeout=SIGNAL_TIMEOUT_MS)
    with qtbot.waitSignal(runs.runFinished, timeout=RUN_TIMEOUT_MS) as done:
        runs.resume()
    outcome = done.args[0]
    assert outcome.state is RunState.FINISHED, runs.outcome_text(outcome)
    assert _near(sim.state().pose, project.ledger.point(3).xyzabc)
    assert [v for i, v in register_writes(sim, REG_RUN_COMMAND) if i >= since] == [CREATE, MOVE] * 3
    assert len(refused) == 1
