"""Shutdown's safety transactions (jog ratio 0, teach disable) wait the short poll timeout, not
the command timeout: a dead controller holds the worker thread only a moment."""

from __future__ import annotations

import time
from typing import Any

import pytest

from app.link.ops import JogPress
from app.link.robot_link import RobotLink
from app.link.types import JogRequest
from app.protocol.enums import TeachFrame
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    jogging,
    link_fixture,
    ratio_writes,
)

pytestmark = pytest.mark.timeout(60)


def test_shutdown_safety_writes_use_the_short_timeout(qtbot: Any, sim: Any, link: RobotLink) -> None:
    # a command would wait 3 s for an answer; the polls 0.5 s (0.1 s was met by a loaded test
    # process: "not answering" dropped the jog before it started)
    connect(qtbot, link, sim, timeout=3.0, poll_timeout=0.5)
    link.submit(JogPress(JogRequest(TeachFrame.JOINT, 0, 1, 20.0)))
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    sim.set_silent(True)
    t0 = time.monotonic()
    link.shutdown()
    qtbot.waitUntil(lambda: not link.is_running, timeout=10_000)
    took = time.monotonic() - t0
    print(f"shutdown with a silent controller took {took * 1000:.0f} ms")
    assert took < 3.0  # short attempts (0.5 s), never the 3 s command timeout


def test_shutdown_with_a_live_controller_still_stops_the_jog(qtbot: Any, sim: Any, link: RobotLink) -> None:
    connect(qtbot, link, sim, timeout=3.0, poll_timeout=0.5)
    link.submit(JogPress(JogRequest(TeachFrame.JOINT, 0, 1, 20.0)))
    qtbot.waitUntil(lambda: jogging(sim), timeout=SIGNAL_TIMEOUT_MS)
    link.shutdown()
    assert not link.is_running
    assert ratio_writes(sim)[-1] == 0.0 and not sim.state().teach_enabled and not sim.state().jogging
