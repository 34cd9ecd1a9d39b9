"""A write that stops motion the controller refused (issue 19, item 1), through the GUI's link.

The field report: a jog at 10 %, the controller busy (Modbus exception 6) for 2 s, the operator
let go meanwhile: the refused speed 0 was never sent again and the arm jogged on for 28 s (through
a keep-in box: the envelope guard had stopped watching a jog that counted as released). Now a
jog is over only when the controller has answered its speed 0 (or a Stop) and the pose is seen
still (app/link/halt.py). Everything is asserted at the simulator: its pose and its write log.
"""

from __future__ import annotations

import time
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.link.ops import JogPress, JogRelease, Step, Stop
from app.link.robot_link import RobotLink
from app.link.types import HaltKind, JogRequest, StepFrame, UnconfirmedHalt
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import TeachFrame
from app.safety.box import Box
from app.safety.envelope import Envelope
from app.safety.jog_guard import JogGuard
from app.sim.config import WriteRecord
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    ratio_writes,
    register_writes,
)

pytestmark = pytest.mark.timeout(60)

JOG_RATIO = 10.0  # % of 250 mm/s: 25 mm/s, the field report's jog
Z_AXIS, PLUS = 2, 1
BUSY = ExcCodes.DEVICE_BUSY  # Modbus exception 6
RATIO_REGISTERS = range(registers.gv_reg(registers.GV_PARAM3), registers.gv_reg(registers.GV_PARAM3) + 2)
STOP_REGISTER = range(registers.REG_STOP, registers.REG_STOP + 1)
REFUSED_REQUESTS = 30  # requests answered "busy" before the controller answers again (~0.3-0.6 s)
#: once the controller answers again the arm stops within a poll or two: 20 ms each at 50 Hz,
#: roomy for a loaded machine (the old code never stopped it: 28 s, until teach idle disable)
STOPS_WITHIN = 1.0  # s


@pytest.fixture
def busy_sim(sim_factory: Any) -> Any:
    """The field report's controller: no communication watchdog (nothing stops a jog by itself)."""
    return sim_factory(watchdog=None)


def _keep_in_below(z_face: float) -> JogGuard:
    box = Box("cell", (-5000.0, -5000.0, -5000.0), (5000.0, 5000.0, z_face))
    return JogGuard(Envelope(keep_in=box), poll_period=1.0 / timing.POLL_HZ_DEFAULT)


def _jog_up(qtbot: Any, link: RobotLink, sim: Any) -> float:
    """Jog Z+ at 10 % until the arm is seen moving; returns the Z it started from."""
    z0 = float(sim.state().pose[2])
    link.submit(JogPress(JogRequest(TeachFrame.BASE, Z_AXIS, PLUS, JOG_RATIO)))
    qtbot.waitUntil(lambda: jogging(sim) and sim.state().pose[2] > z0 + 1.0, timeout=SIGNAL_TIMEOUT_MS)
    return z0


def _refused_for_a_while(qtbot: Any, sim: Any) -> None:
    """The controller keeps answering "busy" for :data:`REFUSED_REQUESTS` requests (the polls and
    whatever the link sends again meanwhile)."""
    before = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count >= before + REFUSED_REQUESTS, timeout=SIGNAL_TIMEOUT_MS)


def _halting(write: WriteRecord) -> bool:
    """A write that stops motion: speed 0 (GV203 <- 0.0) or Stop (441 <- 1)."""
    speed_zero = write.address == RATIO_REGISTERS.start and write.values == (0, 0)
    return speed_zero or (write.address == registers.REG_STOP and write.values == (1,))


@pytest.mark.parametrize("boxed", [False, True], ids=["no-envelope", "keep-in-box"])
def test_a_release_refused_as_busy_goes_out_again_and_the_arm_stops_once_answered(
    qtbot: Any, busy_sim: Any, link: RobotLink, boxed: bool
) -> None:
    sim = busy_sim
    connect(qtbot, link, sim)
    halts: list[UnconfirmedHalt | None] = []
    link.state.haltChanged.connect(halts.append)
    z_face = float(sim.state().pose[2]) + 60.0  # 2.4 s of this jog away
    if boxed:
        link.set_jog_guard(_keep_in_below(z_face))
    z0 = _jog_up(qtbot, link, sim)
    sim.set_exception(BUSY)  # every request: reads and writes
    link.submit(JogRelease())
    _refused_for_a_while(qtbot, sim)
    assert jogging(sim)  # nothing got through: the controller still jogs
    writes_before = len(sim.writes)
    sim.set_exception(None)
    answers_again = time.monotonic()
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    first = sim.writes[writes_before]
    assert _halting(first), first  # the first thing the controller got once it answered
    assert first.t - answers_again < STOPS_WITHIN
    # over only once the pose is seen still: then the link says nothing is pending
    qtbot.waitUntil(lambda: link.state.halt is None and bool(halts), timeout=SIGNAL_TIMEOUT_MS)
    z_stop = float(sim.state().pose[2])
    assert z0 < z_stop < z_face
    assert halts[0] is not None and halts[0].kind is HaltKind.RELEASE  # the screen was told
    assert halts[-1] is None
    assert not sim.state().moving and ratio_writes(sim)[-1] == 0.0


def test_the_envelope_guard_keeps_watching_a_jog_whose_release_was_refused(
    qtbot: Any, busy_sim: Any, link: RobotLink, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Only the speed register refuses, for good, and the escalation to Stop is far away: the
    guard, still deciding on the jog being released, sends the Stop before the face."""
    monkeypatch.setattr(timing, "HALT_ESCALATE_AFTER", 60.0)
    sim = busy_sim
    connect(qtbot, link, sim)
    z_face = float(sim.state().pose[2]) + 30.0  # 1.2 s of this jog away
    link.set_jog_guard(_keep_in_below(z_face))
    z0 = _jog_up(qtbot, link, sim)
    sim.set_exception(BUSY, RATIO_REGISTERS)
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)  # the old code: through the face
    assert [v for _, v in register_writes(sim, registers.REG_STOP)] == [1]
    z_stop = float(sim.state().pose[2])
    assert z0 < z_stop < z_face
    sim.set_exception(None)
    qtbot.waitUntil(lambda: link.state.halt is None, timeout=SIGNAL_TIMEOUT_MS)
    assert float(sim.state().pose[2]) == pytest.approx(z_stop, abs=1e-3)


def test_a_release_refused_beyond_the_budget_escalates_to_stop(
    qtbot: Any, busy_sim: Any, link: RobotLink
) -> None:
    sim = busy_sim
    connect(qtbot, link, sim)
    results: list[CommandResult] = []
    link.commandFinished.connect(results.append)
    _jog_up(qtbot, link, sim)
    sim.set_exception(BUSY, RATIO_REGISTERS)  # speed 0 refused for good; 441 and the reads answer
    released = time.monotonic()
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    stops = sim.writes_to(registers.REG_STOP)
    assert [w.values for w in stops] == [(1,)]
    assert stops[0].t - released >= timing.HALT_ESCALATE_AFTER  # speed 0 was tried alone first
    qtbot.waitUntil(lambda: link.state.halt is None, timeout=SIGNAL_TIMEOUT_MS)
    confirmed = [r for r in results if r.reason is not None and r.reason.code == "release_confirmed"]
    assert len(confirmed) == 1 and confirmed[0].ok
    sim.set_exception(None)


def test_a_release_answered_at_once_stays_one_write(qtbot: Any, busy_sim: Any, link: RobotLink) -> None:
    sim = busy_sim
    connect(qtbot, link, sim)
    halts: list[UnconfirmedHalt | None] = []
    link.state.haltChanged.connect(halts.append)
    _jog_up(qtbot, link, sim)
    writes_before = len(sim.writes)
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    polls = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count >= polls + 20, timeout=SIGNAL_TIMEOUT_MS)  # ten polls on
    after = sim.writes[writes_before:]
    assert [(w.address, w.values) for w in after] == [(RATIO_REGISTERS.start, (0, 0))]
    assert halts == [] and link.state.halt is None


def test_a_stop_refused_as_busy_goes_out_again_until_the_controller_takes_it(
    qtbot: Any, busy_sim: Any, link: RobotLink
) -> None:
    """The same for the operator's Stop during a move: refused, it goes out again at every poll."""
    sim = busy_sim
    connect(qtbot, link, sim)
    halts: list[UnconfirmedHalt | None] = []
    link.state.haltChanged.connect(halts.append)
    link.submit(Step(StepFrame.BASE, [0.0, 0.0, -30.0, 0.0, 0.0, 0.0], speed=5.0))  # 6 s
    qtbot.waitUntil(lambda: sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    sim.set_exception(BUSY, STOP_REGISTER)
    link.submit(Stop())
    _refused_for_a_while(qtbot, sim)
    assert sim.state().moving and sim.writes_to(registers.REG_STOP) == []
    sim.set_exception(None)
    answers_again = time.monotonic()
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)  # the old code: 6 s on
    stops = sim.writes_to(registers.REG_STOP)
    assert stops and stops[0].t - answers_again < STOPS_WITHIN
    qtbot.waitUntil(lambda: link.state.halt is None, timeout=SIGNAL_TIMEOUT_MS)
    assert halts[0] is not None and halts[0].kind is HaltKind.STOP  # the screen was told
    assert halts[-1] is None


def test_after_a_jog_stopped_by_stop_alone_the_next_jog_moves_again(
    qtbot: Any, busy_sim: Any, link: RobotLink
) -> None:
    """Speed 0 never got through (GV203 still holds 10 %), a Stop did: the next press of the same
    jog must still start the arm (teach mode is switched off and on, the speed written again)."""
    sim = busy_sim
    connect(qtbot, link, sim)
    _jog_up(qtbot, link, sim)
    sim.set_exception(BUSY, RATIO_REGISTERS)
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim) and link.state.halt is None, timeout=SIGNAL_TIMEOUT_MS)
    sim.set_exception(None)
    _jog_up(qtbot, link, sim)  # the same axis, direction and speed
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
