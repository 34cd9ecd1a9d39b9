"""A jog whose speed write the controller carried out but answered with a Modbus exception that
does not say "not carried out" (4 device failure, 0x0B a gateway's target, an undefined code):
the arm may be jogging (issue 19 §4, the hostile-server check's neighbour, left at E's sweep).

The press must not read "refused" and be forgotten: the operator is told the outcome is unknown,
the envelope guard keeps watching that jog, and the release stops it. Asserted at the simulator.
"""

from __future__ import annotations

from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app import timing
from app.link.ops import JogPress, JogRelease
from app.link.robot_link import RobotLink
from app.link.types import JogRequest, WorkerError
from app.protocol import registers
from app.protocol.enums import TeachFrame
from app.safety.box import Box
from app.safety.envelope import Envelope
from app.safety.jog_guard import JogGuard
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    ratio_writes,
)

pytestmark = pytest.mark.timeout(60)

Z_AXIS, PLUS = 2, 1
RATIO_REGISTER = registers.gv_reg(registers.GV_PARAM3)


@pytest.fixture
def quiet_sim(sim_factory: Any) -> Any:
    """No communication watchdog: nothing but the host stops a jog."""
    return sim_factory(watchdog=None)


def _press_answered(qtbot: Any, link: RobotLink, sim: Any, code: int) -> list[WorkerError]:
    errors: list[WorkerError] = []
    link.errorOccurred.connect(errors.append)
    sim.answer_after_applying(code, RATIO_REGISTER)
    link.submit(JogPress(JogRequest(TeachFrame.BASE, Z_AXIS, PLUS, 10.0)))
    qtbot.waitUntil(lambda: bool(errors) and jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    return errors


ODD = [ExcCodes.ACKNOWLEDGE, ExcCodes.DEVICE_FAILURE, ExcCodes.GATEWAY_NO_RESPONSE]  # not "not carried out"


@pytest.mark.parametrize("code", ODD)
def test_a_jog_whose_speed_write_met_an_odd_exception_is_unknown_and_released(
    qtbot: Any, quiet_sim: Any, link: RobotLink, code: int
) -> None:
    sim = quiet_sim
    connect(qtbot, link, sim)
    errors = _press_answered(qtbot, link, sim, code)
    text = errors[0].message
    assert "unknown" in text and "refused" not in text, text  # the arm may move: said so
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    assert ratio_writes(sim)[-1] == 0.0


def test_the_guard_watches_a_jog_whose_start_is_unknown(qtbot: Any, quiet_sim: Any, link: RobotLink) -> None:
    sim = quiet_sim
    connect(qtbot, link, sim)
    z_face = float(sim.state().pose[2]) + 40.0
    box = Box("cell", (-5000.0, -5000.0, -5000.0), (5000.0, 5000.0, z_face))
    link.set_jog_guard(JogGuard(Envelope(keep_in=box), poll_period=1.0 / timing.POLL_HZ_DEFAULT))
    _press_answered(qtbot, link, sim, ExcCodes.DEVICE_FAILURE)  # and the operator holds on
    qtbot.waitUntil(lambda: not jogging(sim), timeout=SIGNAL_TIMEOUT_MS)  # the guard stopped it
    qtbot.waitUntil(lambda: not sim.state().moving, timeout=SIGNAL_TIMEOUT_MS)
    assert float(sim.state().pose[2]) < z_face
