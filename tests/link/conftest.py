"""Fixtures of the link's tests: a Qt-free host of the real worker parts, closed after the test; a
RobotLink without the stop line; the simulator's timing profiles for the completion tests
(tests/link/sim_profiles.py)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from app import timing
from app.link.robot_link import RobotLink
from tests.link.harness import PartsHost
from tests.link.sim_profiles import profile_sim, quick_profiles  # noqa: F401 - fixtures
from tests.ui.pendant_support import fast_reconnect_fixture  # noqa: F401 - fixture


@pytest.fixture
def host() -> Iterator[PartsHost]:
    parts = PartsHost()
    try:
        yield parts
    finally:
        parts.close()


@pytest.fixture(name="main_only_link")
def main_only_link_fixture(qtbot: Any, fast_reconnect: None) -> Iterator[RobotLink]:
    """A RobotLink without the stop line (and the restart canary): every stop goes on the main link
    alone, and the simulator's requests are the main link's. (With a line that opened before a test
    slowed the simulator, the line's 441 may be answered in time: the Stop then rightly succeeds --
    tests/link/test_stop_line_only.py -- whatever the main link did.)"""
    robot_link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT, canary_gv=None, stop_line=False)
    try:
        yield robot_link
    finally:
        robot_link.shutdown()
        assert not robot_link.is_running
