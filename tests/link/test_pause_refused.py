"""A Pause the controller refused (issue 19, item 1: "the same for every write that stops motion").

The gap: a Pause answered *server device busy* (Modbus exception 6) was never sent again -- the
program ran on after the controller answered again, while the GUI's plan run said "paused". Now a
Pause is over only when the controller has answered it (or the program state reads paused): it is
sent again at every poll, the link says "pausing -- the controller has not confirmed", and the
Pause's own request ends with the outcome (app/link/halt.py). Asserted at the simulator: its
program state and its write log.
"""

from __future__ import annotations

import time
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.link.link_port import Pending
from app.link.ops import Pause, Resume, RunProgram, Stop
from app.link.robot_link import RobotLink
from app.link.types import HaltKind, UnconfirmedHalt
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, ProgramState
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)

pytestmark = pytest.mark.timeout(60)

BUSY = ExcCodes.DEVICE_BUSY  # Modbus exception 6
PAUSE_REGISTER = range(registers.REG_PAUSE, registers.REG_PAUSE + 1)
BUSY_FOR = 1.0  # s the controller answers the Pause "busy"
#: once the controller takes writes again the program is paused within a poll or two (20 ms
#: each at 50 Hz), roomy for a loaded machine (the old code never paused it)
PAUSED_WITHIN = 0.5  # s


def _run_program(qtbot: Any, link: RobotLink, sim: Any) -> None:
    link.submit(RunProgram(1, ProgramMotionMode.CYCLE, 0, 20))
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)


def _pause_while_busy(qtbot: Any, link: RobotLink, sim: Any) -> tuple[Pending, float]:
    """Pause with the controller refusing 442 for :data:`BUSY_FOR` s; the Pause's pending and
    the time the refusals end (``time.monotonic()``, the simulator's write-log clock)."""
    sim.set_exception(BUSY, PAUSE_REGISTER, seconds=BUSY_FOR)
    busy_until = time.monotonic() + BUSY_FOR
    pause = link.track(link.submit(Pause()))
    return pause, busy_until


def test_a_pause_refused_as_busy_goes_out_again_and_the_program_is_paused_once_answered(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    connect(qtbot, link, sim, timeout=2.0)
    halts: list[UnconfirmedHalt | None] = []
    link.state.haltChanged.connect(halts.append)
    _run_program(qtbot, link, sim)
    pause, busy_until = _pause_while_busy(qtbot, link, sim)
    # the link says it: pausing, the controller has not confirmed
    qtbot.waitUntil(lambda: bool(halts) and halts[0] is not None, timeout=SIGNAL_TIMEOUT_MS)
    assert halts[0] is not None and halts[0].kind is HaltKind.PAUSE and not halts[0].escalated
    assert not pause.done  # the Pause is not over: its request waits for the controller
    assert sim.state().program_state == ProgramState.RUNNING  # refused: the program runs on
    with qtbot.waitSignal(pause.finished, timeout=SIGNAL_TIMEOUT_MS) as finished:
        pass
    result = finished.args[0]
    assert result.ok and result.reason is not None and result.reason.code == "pause_confirmed", result
    state = sim.state()
    assert state.program_state == ProgramState.PAUSED and state.paused  # paused at the simulator
    taken = sim.writes_to(registers.REG_PAUSE)
    assert taken and taken[0].t - busy_until < PAUSED_WITHIN  # sent again at the next poll
    assert not sim.writes_to(registers.REG_STOP)  # a busy second is not a Stop: resumable
    qtbot.waitUntil(lambda: link.state.halt is None, timeout=SIGNAL_TIMEOUT_MS)
    link.submit(Resume())
    qtbot.waitUntil(lambda: sim.state().program_state == ProgramState.RUNNING, timeout=SIGNAL_TIMEOUT_MS)
    link.submit(Stop())
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)


def test_a_pause_refused_past_the_bound_becomes_a_stop(
    qtbot: Any, sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Refused for longer than ``timing.PAUSE_ESCALATE_AFTER`` (here 0.3 s of the 1 s busy; the
    simulator's busy register block also refuses the status reads): the operator asked for the
    arm to halt, a Stop goes out instead; the Pause's request says so."""
    monkeypatch.setattr(timing, "PAUSE_ESCALATE_AFTER", 0.3)
    connect(qtbot, link, sim, timeout=2.0)
    halts: list[UnconfirmedHalt | None] = []
    link.state.haltChanged.connect(halts.append)
    _run_program(qtbot, link, sim)
    pause, busy_until = _pause_while_busy(qtbot, link, sim)
    with qtbot.waitSignal(pause.finished, timeout=SIGNAL_TIMEOUT_MS) as finished:
        pass
    result = finished.args[0]
    assert not result.ok and result.reason is not None and result.reason.code == "pause_stopped", result
    stops = sim.writes_to(registers.REG_STOP)
    assert stops and stops[0].t < busy_until  # the Stop reached the simulator while it was busy
    assert sim.state().program_state == ProgramState.STOPPED and not sim.state().moving
    assert not sim.writes_to(registers.REG_PAUSE)  # none of the Pauses was taken
    assert any(h is not None and h.kind is HaltKind.PAUSE and h.escalated for h in halts)
    qtbot.waitUntil(lambda: link.state.halt is None, timeout=SIGNAL_TIMEOUT_MS)
