"""The poller keeps at least 10 Hz while jogging, whatever the GUI's poll-rate setting: the
controller's watchdog (0.3 s on the simulator) must never stop the operator's own jog."""

from __future__ import annotations

from typing import Any

import pytest

from app.link.ops import JogPress, JogRelease
from app.link.poller import JOG_POLL_HZ_MIN
from app.link.robot_link import RobotLink
from app.link.types import JogRequest
from app.protocol.enums import TeachFrame
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
)

pytestmark = pytest.mark.timeout(60)


def test_a_slow_poll_setting_does_not_let_the_watchdog_stop_a_jog(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    assert JOG_POLL_HZ_MIN >= 10.0
    link.set_poll_rate(1.0)  # one poll a second: far below the watchdog's 0.3 s
    connect(qtbot, link, sim)
    link.submit(JogPress(JogRequest(TeachFrame.JOINT, 0, 1, 20.0)))
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    # Ten more requests while jogging: at 1 Hz that would take 10 s (and the watchdog would fire
    # after 0.3 s); at >= 10 Hz it takes about a second.
    start = sim.requests_count
    qtbot.waitUntil(lambda: sim.requests_count >= start + 10, timeout=5000)
    assert jogging(sim) and sim.watchdog_events() == []
    link.submit(JogRelease())
    qtbot.waitUntil(lambda: not sim.state().jogging, timeout=SIGNAL_TIMEOUT_MS)
    assert sim.watchdog_events() == []
