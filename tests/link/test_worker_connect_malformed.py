"""A malformed answer while connecting (before the first good poll) is a link failure: the link
shows DOWN with the transport's reason and retries; it never shows CONNECTED on that answer, nothing
read from it is published, and the worker lives on (the next attempt connects)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from app.link.robot_link import RobotLink
from app.link.types import ConnectionState, LinkState, WorkerError
from tests.link.test_poller_malformed import GarblingProxy
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connection_settings,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
)

pytestmark = pytest.mark.timeout(60)


@pytest.fixture
def proxy(sim: Any) -> Iterator[GarblingProxy]:
    with GarblingProxy(sim.port) as p:
        yield p


@pytest.mark.parametrize("garbled", [1, 2], ids=["one attempt", "two attempts in a row"])
def test_a_malformed_answer_at_connect_is_a_link_failure(
    qtbot: Any, sim: Any, link: RobotLink, proxy: GarblingProxy, garbled: int
) -> None:
    states: list[ConnectionState] = []
    errors: list[WorkerError] = []
    events: list[str] = []  # the order the GUI thread hears of the link and of poses
    link.connectionChanged.connect(states.append)
    link.connectionChanged.connect(lambda s: events.append(s.state.value))
    link.errorOccurred.connect(errors.append)
    link.state.poseChanged.connect(lambda _pose: events.append("pose"))
    proxy.garble = garbled  # the connect's first reads come back two registers short
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.CONNECTED), timeout=SIGNAL_TIMEOUT_MS
    ):
        link.connect_to(connection_settings(sim, port=proxy.port))
    assert proxy.garbled == garbled
    kinds = [s.state for s in states]
    down = kinds.index(LinkState.DOWN)  # a link failure: DOWN, retrying by itself ...
    assert kinds[:down] == [LinkState.CONNECTING]  # ... never CONNECTED on the malformed answer
    reason = states[down].reason
    assert reason is not None and reason.code == "malformed_answer"
    assert "malformed answer" in states[down].message
    assert kinds[-1] is LinkState.CONNECTED  # the worker lived on: a later attempt connected
    assert all(e.reason is not None for e in errors), errors  # no bare exception (a crash) reported
    qtbot.waitUntil(lambda: "pose" in events, timeout=SIGNAL_TIMEOUT_MS)
    # nothing read from the malformed answer (or beside it) was published before the link was up
    assert events.index("pose") > events.index(LinkState.CONNECTED.value), events
